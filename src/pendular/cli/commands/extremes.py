"""Extremes grid: around a small wet base case, one input at a time (suction, contact angle,
radius, stiffness, time step, particle count, confining stress, water content) takes values
across its range and beyond; every case ends ok (finite, every check within its bound) or
refused (an error naming the parameter, its value and the valid range), never failed. Writes
DIR/extremes.json and prints the table; exit status 1 if a case failed (pendular.studies.extremes)."""

import contextlib
import sys

from pendular.cli import (add_declared_options, add_run_options, declared_values, print_result,
    set_threads)
from pendular.studies.extremes import OPTIONS, run_grid

#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular extremes --quick --out runs/extremes",
           "each extreme input of a small wet case: runs, or is refused in one line")


def add_arguments(parser):
    parser.add_argument("--out", required=True, help="output folder")
    add_declared_options(parser, OPTIONS)
    add_run_options(parser)


def run(args):
    set_threads(args.threads)
    quick = declared_values(OPTIONS, args)["quick"]
    with contextlib.redirect_stdout(sys.stderr if args.quiet else sys.stdout):
        counts = run_grid(args.out, quick)          # its table: on stderr with --quiet
    print_result(args.quiet, f"outputs in {args.out}", **counts, out=args.out)
    return 1 if counts["failed"] else 0
