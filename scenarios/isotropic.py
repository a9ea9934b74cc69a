"""Isotropic loading and unloading in stages: ``pendular isotropic`` (``--help`` for options).

    python scenarios/isotropic.py [--particles N] [--stresses 500,1000,2000,1000,500]
        [--suction PA] [--out DIR] ...
    python scenarios/isotropic.py --resume DIR

The test itself is pendular.procedures.isotropic.IsotropicTest; the options are
pendular.cli.commands.isotropic.
"""

import sys

from pendular.cli import main

if __name__ == "__main__":
    sys.exit(main(["isotropic", *sys.argv[1:]], prog="isotropic.py"))
