"""Thesis Chapter 4: regular packings (SCP, BCC, FCP), SWCC, chi_ij, B_ij, psi_ij, a_psi and the
Kim (2001) comparison: tables (DIR/chapter4_tables.txt) and figures (DIR/fig4_*.png)."""

from pendular.studies.chapter4 import write_chapter4
from pendular.cli import UsageError, add_run_options


def add_arguments(parser):
    parser.add_argument("--out", default="runs/chapter4", help="output folder")
    parser.add_argument("--points", type=int, default=40, help="states per curve (10-400)")
    add_run_options(parser)


def run(args):
    if not 10 <= args.points <= 400:
        raise UsageError(f"--points {args.points} is outside the valid range [10, 400]")
    write_chapter4(args.out, args.points)
    return 0
