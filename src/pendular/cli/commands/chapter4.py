"""Thesis Chapter 4: regular packings (SCP, BCC, FCP), SWCC, chi_ij, B_ij, psi_ij, a_psi and the
Kim (2001) comparison: tables (DIR/chapter4_tables.txt) and figures (DIR/fig4_*.png)."""

from pendular.studies.chapter4 import POINTS as POINTS_PARAMETER, write_chapter4
from pendular.utils.parameters import option_from

from pendular.cli import add_declared_options, add_run_options, declared_values

#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular chapter4 --out runs/chapter4",
           "the regular packings' SWCC, chi, B and psi of thesis Chapter 4: tables and figures")

#: States per curve of the figures, checked as the option is read.
POINTS = option_from(POINTS_PARAMETER, 40, checked=True)


def add_arguments(parser):
    parser.add_argument("--out", default="runs/chapter4", help="output folder")
    add_declared_options(parser, (POINTS,))
    add_run_options(parser)


def run(args):
    points = declared_values((POINTS,), args)["points"]
    write_chapter4(args.out, points)
    return 0
