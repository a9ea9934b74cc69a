"""One collision of a sphere with a sphere or a rigid wall: ``pendular impact``.

    python scenarios/impact.py --target wall --contact hertz-mindlin --radius 0.01 --young 2e11
        --poisson 0.3 --density 7800 --velocity 1 [--restitution E] [--angle DEG] [--out DIR]

Writes summary.json, history.h5 and impact.png into DIR (pendular.procedures.impact).
"""

import sys

from pendular.cli import main

if __name__ == "__main__":
    sys.exit(main(["impact", *sys.argv[1:]], prog="impact.py"))
