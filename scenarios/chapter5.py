"""Thesis Chapter 5 campaign (Table 5.3): ``pendular chapter5`` (``--help`` for options).

    python scenarios/chapter5.py [--particles N] [--suctions 0,15000,30000,300000]
        [--confining 250,500,750,1000] [--jobs J] [--out DIR] [--seed S] [--max-strain X]
        [--inertial-number I] [--prep-friction DEG] [--scheduler ADDRESS] [--threads T]
        [--quiet]

The grid defaults to the table src/pendular/campaigns/chapter5.toml (--suction is an alias of
--suctions). Writes DIR/campaign.json, DIR/campaign.csv, DIR/report.md and DIR/plots/
(pendular.studies.chapter5); started again with the same DIR, finished runs are reused.
"""

import sys

from pendular.cli import main

if __name__ == "__main__":
    sys.exit(main(["chapter5", *sys.argv[1:]], prog="chapter5.py"))
