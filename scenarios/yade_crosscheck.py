"""Cross-check of pendular's drained triaxial shear against YADE's on the same packing:
``pendular crosscheck`` (``--help`` for options).

    python scenarios/yade_crosscheck.py [--particles N] [--suction PA] [--confining PA]
        [--max-strain X] [--out DIR] [--periodic] [--mimic-yade] [--records N] [--threads T]
        [--settle-steps N] [--packing FILE] [--concurrent] [--quiet]

Writes DIR/crosscheck.json, crosscheck.png, yade_history.txt and pendular_history.h5
(pendular.studies.crosscheck; docs/yade_crosscheck.md). Needs ``yade`` on PATH.
"""

import sys

from pendular.cli import main

if __name__ == "__main__":
    sys.exit(main(["crosscheck", *sys.argv[1:]], prog="yade_crosscheck.py"))
