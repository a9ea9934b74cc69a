"""Direct tension of wet sand at fixed water content (Kim 2001): ``pendular tension``.

    python scenarios/direct_tension.py [--void-ratio E[,E...]] [--water-content W[,W...]]
        [--particles N] [--radius M] [--contact-angle DEG] [--roughness H_OVER_R] [--out DIR]

Without --void-ratio / --water-content it runs Kim's six cases (pendular.procedures.tension).
"""

import sys

from pendular.cli import main

if __name__ == "__main__":
    sys.exit(main(["tension", *sys.argv[1:]], prog="direct_tension.py"))
