"""Extremes grid, one input at a time to the ends of its range: ``pendular extremes``.

    python scenarios/extremes.py --out DIR [--quick]

Writes DIR/extremes.json and prints the table (pendular.studies.extremes).
"""

import sys

from pendular.cli import main

if __name__ == "__main__":
    sys.exit(main(["extremes", *sys.argv[1:]], prog="extremes.py"))
