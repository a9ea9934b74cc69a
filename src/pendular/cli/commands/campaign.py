"""Sweeps from a parameter table: ``pendular campaign TABLE.toml --out DIR``.

The TOML table names the laboratory command (``command = "triaxial"``, the default, or
"oedometer", "isotropic", "cyclic", "simple-shear", "path", "tension", "swcc"), holds fixed
options in ``[fixed]`` and lists to sweep in ``[sweep]`` (every combination) or explicit
``[[runs]]`` rows; keys are the command's options with underscores (``max_strain = 0.02``),
flags take true/false, ``force = true`` runs a laboratory test refused as not quasi-static:

    command = "triaxial"
    [fixed]
    particles = 300
    max_strain = 0.02
    [sweep]
    suction = [0, 30000]
    confining = [250, 750]

Each run goes to DIR/runs/<name>/ (its outputs and log.txt), in --jobs local processes (at
most 4 per CPU) with --threads Numba threads each, or on an existing Dask cluster with
--scheduler; DIR/campaign.csv has one row per run with its options and its summary's numbers
(an SWCC's: Sr, chi and volumetric strain at each suction of each branch). Started
again, finished runs with equal configurations are reused. The campaign holds DIR while it
runs: a second campaign or run into DIR is refused. A failed run does not stop the others; the
command then ends with an error naming it (its traceback is in its log.txt).
"""

import os

from pendular.studies.campaign import (Campaign, RunRefused, sweep_from_table,
                                       write_campaign_csv)
from pendular.cli import UsageError, add_executor_options, print_result, start_executor_run
from pendular.io.outputs import OutputFolder

#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular campaign campaign.toml --out runs/campaign --jobs 2",
           "every row of a table of any command's options, two at a time, collected in "
           "campaign.csv (the table: the tutorial 'A campaign from a table')")


def add_arguments(parser):
    parser.add_argument("table", help="TOML parameter table")
    parser.add_argument("--out", default="runs/campaign", help="output folder")
    add_executor_options(parser)


def run(args):
    options = start_executor_run(args)   # before the output folder is made
    command, runs = sweep_from_table(args.table)
    # keep: the finished runs of an earlier campaign there are reused; runs/ is never owned
    with OutputFolder(args.out, ["campaign", args.table], keep=True) as folder:
        csv_path = folder.claim("campaign.csv")
        try:
            result = Campaign(runs).run(os.path.abspath(args.out), options)
        except RunRefused as error:
            raise UsageError(f"table = {args.table!r}: {error}") from None
        write_campaign_csv(csv_path, result)
    print_result(args.quiet, f"campaign: {len(runs)} {command} runs ({len(result.reused)} "
                 f"reused, {len(result.failed)} failed); outputs in {args.out} (campaign.csv, "
                 "runs/)", command=command, runs=len(runs), reused=len(result.reused),
                 failed=len(result.failed), out=args.out)
    result.check()
    return 0
