"""Strength envelope of triaxial tests: ``pendular envelope`` (``--help`` for options).

    python scenarios/envelope.py --confining 250,500,1000,2000 [--suction PA] [--out DIR] ...

The study is pendular.studies.envelope; the options are pendular.cli.commands.envelope.
"""

import sys

from pendular.cli import main

if __name__ == "__main__":
    sys.exit(main(["envelope", *sys.argv[1:]], prog="envelope.py"))
