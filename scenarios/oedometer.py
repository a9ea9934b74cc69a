"""Oedometric (K0) compression: ``pendular oedometer`` (``--help`` for options).

    python scenarios/oedometer.py [--particles N] [--confining PA] --axial-stress PA
        [--unload-to PA] [--suction PA] [--out DIR] ...
    python scenarios/oedometer.py --resume DIR

The test itself is pendular.procedures.oedometer.OedometerTest; the options are
pendular.cli.commands.oedometer.
"""

import sys

from pendular.cli import main

if __name__ == "__main__":
    sys.exit(main(["oedometer", *sys.argv[1:]], prog="oedometer.py"))
