"""Speed against accuracy of the numerical settings: ``pendular tradeoff``.

    python scenarios/tradeoff.py --out DIR [--particles N] [--max-strain X] [--quick]
        [--docs FOLDER]

Writes DIR/tradeoff.json, tradeoff.md and tradeoff.png (pendular.studies.tradeoff).
"""

import sys

from pendular.cli import main

if __name__ == "__main__":
    sys.exit(main(["tradeoff", *sys.argv[1:]], prog="tradeoff.py"))
