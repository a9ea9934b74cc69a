"""Soil-water characteristic curve of a DEM sample, drying then wetting: ``pendular swcc``.

    python scenarios/swcc.py --particles N --confining PA --suctions S1,S2,... [--contact-angle DEG]
        [--form-gap F] [--out DIR]

Writes swcc.json, swcc.png, history.h5 and sample.h5 into DIR (pendular.procedures.swcc).
"""

import sys

from pendular.cli import main

if __name__ == "__main__":
    sys.exit(main(["swcc", *sys.argv[1:]], prog="swcc.py"))
