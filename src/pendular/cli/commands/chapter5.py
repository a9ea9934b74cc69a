"""Thesis Chapter 5 campaign (Table 5.3): drained triaxial tests at every suction and confining
stress, from one sample per confining stress; campaign.json, report.md (every Table 5.3 cell
and Sr beside the thesis's, Mohr–Coulomb envelopes in net and effective stress) and plots/
(Figs. 5.3-5.8). The default grid is the table pendular/campaigns/chapter5.toml; options
override it. Finished runs with equal configurations are reused. Each run has --threads Numba
threads (one by default) and its own log.txt with its progress."""

from pendular.studies.chapter5 import Chapter5Campaign, grid_from_options, grid_options
from pendular.cli import (add_declared_options, add_executor_options, declared_values,
    print_result, start_executor_run)

#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular chapter5 --particles 1000 --suctions 0,30000 --confining 250,750 "
           "--max-strain 0.1 --out runs/chapter5",
           "four triaxial tests of thesis Table 5.3 and their strength envelopes; campaign.json, "
           "report.md, plots/")


def add_arguments(parser):
    add_declared_options(parser, grid_options())
    parser.add_argument("--out", default="runs/chapter5", help="output folder")
    add_executor_options(parser)


def run(args):
    options = start_executor_run(args)   # before the output folder is made
    grid = grid_from_options(declared_values(grid_options(), args))
    summary = Chapter5Campaign(grid).run(args.out, options)
    runs, reused = len(summary["runs"]), summary["reused"]
    print_result(args.quiet, (f"chapter5: {reused} finished runs in {args.out} reused, "
                              f"{runs - reused} run\n" if reused else "")
                 + f"chapter5: {runs} runs; outputs in {args.out} (campaign.json, report.md, "
                   "plots/)", runs=runs, reused=reused, out=args.out)
    return 0
