"""CI: compile pendular's kernels into Numba's cache (and build the default bridge tables)
while pip installs the extras, so that the tests' workers and the documentation's examples
load them instead of compiling each its own copy at once (docs/testing.md 'Time').

    python .ci/warm_cache.py THREADS

runs small scenes of every kind of physics the tests run on THREADS Numba threads (1: the
serial kernels, 2: the parallel ones; .ci/run runs both side by side) in this process; their
outputs are thrown away. A scene that fails here only leaves its kernels to be compiled by
the tests.
"""

import sys
import tempfile

from pendular.cli import run_command

#: (command, options) of the scenes: dry, wet at a suction and at a water content, Hertz–Mindlin
#: with rolling resistance, gravity and sphere–wall bridges, a periodic cell, a simple shear.
SCENES = (
    ("triaxial", ["--max-strain", "0.002", "--records", "4"]),
    ("triaxial", ["--max-strain", "0.002", "--records", "4", "--suction", "30000"]),
    ("triaxial", ["--max-strain", "0.002", "--records", "4", "--water-content", "2"]),
    ("triaxial", ["--max-strain", "0.002", "--records", "4", "--suction", "30000",
                  "--contact", "hertz-mindlin", "--rolling-friction", "0.1", "--gravity",
                  "9.81", "--wall-bridges", "--wall-friction", "0.3"]),
    ("triaxial", ["--max-strain", "0.002", "--records", "4", "--suction", "30000",
                  "--periodic"]),
    ("simple-shear", ["--max-strain", "0.002", "--suction", "30000"]),
)
COMMON = ["--particles", "60", "--quiet", "--no-plots", "--vtk-every", "0"]


def main(threads):
    failed = 0
    with tempfile.TemporaryDirectory() as folder:
        for number, (command, options) in enumerate(SCENES):
            argv = [*COMMON, *options, "--threads", threads, "--out", f"{folder}/{number}"]
            try:
                status = run_command(command, argv)
            except SystemExit as stop:
                status = stop.code
            if status:
                failed += 1
                print(f"warm-up: pendular {command} {' '.join(argv)} exited {status}",
                      file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
