"""Run the YADE triaxial driver (``benchmarks/yade_triaxial.py``) from Python and read its result.

YADE is an optional, external cross-check: nothing in pendular imports it. The benchmarks
(bench_triaxial.py, bench_capillary.py) and scenarios/yade_crosscheck.py import this module by
path: it stays here, outside the installed packages, with the driver it runs.
``run_yade_triaxial`` needs a ``yade`` executable on PATH (Debian/Ubuntu package ``yade``,
tested with 2023.02a).

Self-check (about a minute on two cores): ``python benchmarks/yade_runner.py [N]`` writes a random
packing of N spheres (default 1000, R = 0.024 mm), times it with 1 and 2 threads, prints both.
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

DRIVER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "yade_triaxial.py")
YADE_EXECUTABLES = ("yade", "yadedaily")


def find_yade():
    """Path of the YADE executable, or RuntimeError saying how to get one."""
    for name in YADE_EXECUTABLES:
        path = shutil.which(name)
        if path:
            return path
    raise RuntimeError(f"no YADE executable ({' or '.join(YADE_EXECUTABLES)}) on PATH; install "
                       "the Debian/Ubuntu package 'yade' (apt-get install yade) to run the "
                       "YADE cross-checks")


def yade_environment(extra=None):
    """os.environ for a YADE subprocess: without VIRTUAL_ENV, PYTHONPATH and PYTHONHOME, which
    make YADE's system Python load a virtual environment's packages (numpy, matplotlib) built
    for another interpreter; plus ``extra`` variables."""
    environment = {key: value for key, value in os.environ.items()
                   if key not in ("VIRTUAL_ENV", "PYTHONPATH", "PYTHONHOME")}
    environment.update(extra or {})
    return environment


def run_yade_triaxial(config, threads=1, timeout=None, yade=None, env=None):
    """Run ``yade -n -x -j threads yade_triaxial.py CONFIG.json``; return its result dict.

    config: the driver's configuration (see the header of ``yade_triaxial.py``; a
    ``capillary`` entry runs the wet test with YADE's capillary law); ``output``
    defaults to a file in a temporary folder, and relative paths are taken from the current
    folder. threads: OpenMP threads (>= 1). timeout: seconds, None for no limit. yade: the
    executable (default: the first of ``yade``, ``yadedaily`` on PATH). env: extra environment
    variables, e.g. ``{"OMP_WAIT_POLICY": "PASSIVE"}`` when the cores are shared with other jobs
    (busy-waiting OpenMP threads then slow a multi-threaded run several times).
    Raises RuntimeError when YADE is missing, fails, or writes no result.
    """
    if isinstance(threads, bool) or int(threads) != threads or threads < 1:
        raise ValueError(f"threads = {threads!r} must be an integer >= 1")
    executable = yade or find_yade()
    with tempfile.TemporaryDirectory(prefix="yade_triaxial_") as folder:
        config = dict(config)
        for key in ("spheres", "history", "output"):
            if config.get(key):
                config[key] = os.path.abspath(config[key])
        if config.get("capillary"):
            config["capillary"] = dict(config["capillary"])
            config["capillary"]["files"] = os.path.abspath(config["capillary"]["files"])
        output = config.setdefault("output", os.path.join(folder, "result.json"))
        config_path = os.path.join(folder, "config.json")
        with open(config_path, "w") as out:
            json.dump(config, out, indent=1)
        command = [executable, "-n", "-x", "-j", str(int(threads)), DRIVER, config_path]
        try:
            done = subprocess.run(command, cwd=folder, capture_output=True, text=True,
                                  timeout=timeout, env=yade_environment(env))
        except subprocess.TimeoutExpired:
            raise RuntimeError(f"YADE ran past {timeout} s: {' '.join(command)}") from None
        if done.returncode != 0 or not os.path.exists(output):
            tail = (done.stdout + done.stderr)[-3000:]
            raise RuntimeError(f"YADE failed (exit status {done.returncode}): "
                               f"{' '.join(command)}\n{tail}")
        with open(output) as source:
            return json.load(source)


def random_packing(count, radius, solid_fraction, seed=0, tolerance=1e-3, max_sweeps=20000):
    """Equal spheres in a cube without overlap (> tolerance R), by pushing overlapping pairs apart.

    Returns (positions (N, 3), radii (N,), box_lo, box_hi) in metres, the box a cube at the given
    solid fraction with its corner at the origin. Fit for benchmarks, not for physics: the
    fabric is whatever the relaxation leaves. It converges fast up to ~0.5 (~0.55 for 1000
    spheres; walls make small samples jam earlier), RuntimeError otherwise.
    """
    from scipy.spatial import cKDTree

    side = (count * 4.0 / 3.0 * np.pi * radius ** 3 / solid_fraction) ** (1.0 / 3.0)
    rng = np.random.default_rng(seed)
    position = rng.uniform(radius, side - radius, size=(count, 3))
    for _ in range(max_sweeps):
        pairs = cKDTree(position).query_pairs(2.0 * radius, output_type="ndarray")
        if len(pairs) == 0:
            break
        branch = position[pairs[:, 1]] - position[pairs[:, 0]]
        distance = np.linalg.norm(branch, axis=1)
        overlap = 2.0 * radius - distance
        if overlap.max() < tolerance * radius:
            break
        # half the overlap (plus a little) to each side, summed over all pairs of a sphere
        push = (0.55 * overlap / np.maximum(distance, 1e-12 * radius))[:, None] * branch
        shift = np.zeros_like(position)
        np.add.at(shift, pairs[:, 1], push)
        np.add.at(shift, pairs[:, 0], -push)
        position = np.clip(position + shift, radius, side - radius)
    else:
        raise RuntimeError(f"no non-overlapping packing after {max_sweeps} sweeps at solid "
                           f"fraction {solid_fraction}")
    return position, np.full(count, radius), np.zeros(3), np.full(3, side)


def _self_check(count=1000):
    from dem.yade_io import read_plot_data, write_spheres

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
    _self_check(int(sys.argv[1]) if len(sys.argv) > 1 else 1000)
