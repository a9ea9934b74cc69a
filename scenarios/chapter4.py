"""Thesis Chapter 4 (regular packings, SWCC, chi, B, psi, Kim 2001): ``pendular chapter4``.

    python scenarios/chapter4.py [--out DIR] [--points N]

Writes DIR/chapter4_tables.txt and the figures DIR/fig4_*.png (pendular.studies.chapter4).
"""

import sys

from pendular.cli import main

if __name__ == "__main__":
    sys.exit(main(["chapter4", *sys.argv[1:]], prog="chapter4.py"))
