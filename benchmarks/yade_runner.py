"""Self-check of the YADE driver (pendular.interop.yade.runner, pendular/interop/yade/scripts/triaxial.py) on this machine.

    python benchmarks/yade_runner.py [N]

Writes a random packing of N spheres (default 1000, R = 0.024 mm), shears it with YADE with 1
and 2 threads (about a minute on two cores) and prints both results. The runner itself is
``pendular.interop.yade.runner`` (find_yade, run_yade_triaxial, random_packing), re-exported here.
"""

import json
import os
import sys
import tempfile

import numpy as np

from pendular.interop.yade.formats import read_plot_data, write_spheres
from pendular.interop.yade.runner import find_yade, random_packing, run_yade_triaxial  # noqa: F401


def self_check(count=1000):
    radius, young, density = 2.4e-5, 1e6, 2650.0
    positions, radii, lo, hi = random_packing(count, radius, solid_fraction=0.55, seed=1)
    folder = tempfile.mkdtemp(prefix="yade_check_")
    spheres = os.path.join(folder, "spheres.txt")
    write_spheres(spheres, positions, radii, lo, hi)
    pwave = radius / np.sqrt(young / density)
    config = {"spheres": spheres, "box_lo": lo.tolist(), "box_hi": hi.tolist(), "young": young,
              "poisson": 0.3, "friction_deg": 18.0, "density": density, "damping": 0.2,
              "dt": 0.5 * pwave, "confining": 750.0, "strain_rate": 10.0, "max_vel": 0.05,
              "steps": 3000, "warmup_steps": 6000, "record_every": 500}
    print(f"{count} spheres, box side {hi[0] * 1e3:.4f} mm, dt = {config['dt']:.3e} s "
          f"(0.5 x P-wave), folder {folder}")
    for threads in (1, 2):
        history = os.path.join(folder, f"history_{threads}.txt")
        result = run_yade_triaxial(dict(config, history=history), threads=threads)
        print(json.dumps(result))
        data = read_plot_data(history)
        print("  history:", {k: np.round(v[-3:], 6).tolist() for k, v in data.items()})


if __name__ == "__main__":
    self_check(int(sys.argv[1]) if len(sys.argv) > 1 else 1000)
