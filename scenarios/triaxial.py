"""Drained triaxial test of thesis Chapter 5: ``pendular triaxial`` (``--help`` for options).

    python scenarios/triaxial.py [--particles N] [--confining PA] [--suction PA] [--out DIR] ...
    python scenarios/triaxial.py --resume DIR

The test itself is pendular.procedures.triaxial.TriaxialTest; the options are pendular.cli.commands.triaxial.
"""

import sys

from pendular.cli import main

if __name__ == "__main__":
    sys.exit(main(["triaxial", *sys.argv[1:]], prog="triaxial.py"))
