"""Sweeps from a parameter table: ``pendular campaign TABLE.toml --out DIR``.

The TOML table names the command (``command = "triaxial"``, the default, or ``"tension"``),
holds fixed options in ``[fixed]`` and lists to sweep in ``[sweep]`` (every combination) or
explicit ``[[runs]]`` rows; keys are the command's options with underscores
(``max_strain = 0.02``). Each run goes to DIR/runs/<name>/ (local processes, or an existing Dask
cluster with --scheduler); DIR/campaign.csv has one row per run with its options and summary.
Started again, finished runs with equal configurations are reused.
"""

import os

from ..campaign import run_campaign, sweep_from_table, write_campaign_csv
from ..cli import UsageError, add_run_options, positive_int


def add_arguments(parser):
    parser.add_argument("table", help="TOML parameter table")
    parser.add_argument("--out", default="runs/campaign", help="output folder")
    parser.add_argument("--jobs", type=positive_int("--jobs", 1), default=1,
                        help="parallel processes")
    parser.add_argument("--scheduler", metavar="ADDRESS", default=None,
                        help="run on the Dask cluster of this scheduler instead of --jobs "
                             "local processes")
    add_run_options(parser)


def run(args):
    if args.out == "":
        raise UsageError("--out '': an output folder is required")
    command, runs = sweep_from_table(args.table)
    out = os.path.abspath(args.out)
    summaries, reused = run_campaign(runs, out, jobs=args.jobs, scheduler=args.scheduler,
                                     quiet=args.quiet)
    write_campaign_csv(os.path.join(out, "campaign.csv"), runs, summaries)
    print(f"campaign: {len(runs)} {command} runs ({reused} reused); outputs in {args.out} "
          "(campaign.csv, runs/)")
    return 0
