"""Sweeps from a parameter table: ``pendular campaign TABLE.toml --out DIR``.

The TOML table names the command (``command = "triaxial"``, the default, or ``"tension"``),
holds fixed options in ``[fixed]`` and lists to sweep in ``[sweep]`` (every combination) or
explicit ``[[runs]]`` rows; keys are the command's options with underscores
(``max_strain = 0.02``), flags take true/false:

    command = "triaxial"
    [fixed]
    particles = 300
    max_strain = 0.02
    [sweep]
    suction = [0, 30000]
    confining = [250, 750]

Each run goes to DIR/runs/<name>/ (its outputs and log.txt), in --jobs local processes with
--threads Numba threads each, or on an existing Dask cluster with --scheduler;
DIR/campaign.csv has one row per run with its options and summary. Started again, finished
runs with equal configurations are reused. A failed run does not stop the others; the command
then ends with an error naming it (its traceback is in its log.txt).
"""

import os

from ..campaign import Campaign, sweep_from_table, write_campaign_csv
from ..cli import UsageError, add_executor_options, set_threads


def add_arguments(parser):
    parser.add_argument("table", help="TOML parameter table")
    parser.add_argument("--out", default="runs/campaign", help="output folder")
    add_executor_options(parser)


def run(args):
    if args.out == "":
        raise UsageError("--out '': an output folder is required")
    set_threads(args.threads)
    command, runs = sweep_from_table(args.table)
    out = os.path.abspath(args.out)
    result = Campaign(runs).run(out, jobs=args.jobs, scheduler=args.scheduler,
                                threads=args.threads, quiet=args.quiet)
    write_campaign_csv(os.path.join(out, "campaign.csv"), result)
    print(f"campaign: {len(runs)} {command} runs ({len(result.reused)} reused, "
          f"{len(result.failed)} failed); outputs in {args.out} (campaign.csv, runs/)")
    result.check()
    return 0
