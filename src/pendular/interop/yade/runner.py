"""YADE, the external reference of the cross-checks: run its triaxial driver, give it pendular's
sample and capillary tables, read what it writes.

YADE is optional: nothing here imports it. ``run_yade_triaxial(settings)`` runs
``yade -n -x -j THREADS scripts/triaxial.py CONFIG.json`` (the driver shipped beside this module,
``DRIVER``, a YADE script never imported by Python) and returns its result; it needs a ``yade``
executable on PATH (Debian/Ubuntu package ``yade``, tested with 2023.02a).

Shared by the cross-check (pendular.studies.crosscheck) and the benchmarks (benchmarks/bench_*.py):

- ``cached_sample(config)``: a prepared sample (pendular.procedures.preparation.prepare_sample), saved once in
  the cache folder (pendular.capillary.cache_directory: $PENDULAR_CACHE or ~/.cache/pendular) with its
  configuration and prepared again when the configuration differs;
- ``yade_capillary_files(contact_angle)``: YADE's capillary files M(r=1) ... M(r=10) of the
  exact bridge tables (pendular.interop.yade.capillary_files), written once into the cache folder;
- ``yade_history(path, box_volume)``: the driver's history in the layout of pendular's;
- ``random_packing``: a quick non-overlapping packing for driver checks.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import tempfile
import time

import numpy as np

from pendular import capillary
from pendular.utils.threads import OPENMP_DEFAULTS
from pendular.procedures.preparation import PREPARATION_VERSION, PrepareConfig, prepare_sample
from pendular.dem.sample import load_sample, save_sample
from pendular.interop.yade.capillary_files import write_table_files
from pendular.interop.yade.formats import read_plot_data

from pendular.procedures.config import sample_made_with
from pendular.procedures.config import config_json, config_to_dict

#: The YADE script run by ``run_yade_triaxial`` (package data beside this module).
DRIVER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "scripts", "triaxial.py")
#: Names of the YADE executable, tried in this order.
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
    for another interpreter, and without the OpenMP settings pendular made for itself
    (pendular.utils.threads.OPENMP_DEFAULTS: YADE runs as a user would run it); plus ``extra`` variables."""
    environment = {key: value for key, value in os.environ.items()
                   if key not in ("VIRTUAL_ENV", "PYTHONPATH", "PYTHONHOME", *OPENMP_DEFAULTS)}
    environment.update(extra or {})
    return environment


def run_yade_triaxial(config, threads=1, timeout=None, yade=None, env=None):
    """Run ``yade -n -x -j threads scripts/triaxial.py CONFIG.json``; return its result dict.

    config: the driver's configuration (see the header of ``scripts/triaxial.py``; a
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
        with open(config_path, "w", encoding="utf-8") as out:
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


def yade_history(path, box_volume):
    """The history the driver wrote at ``path`` (plot.saveDataTxt) in the layout of pendular's:
    step, axial_strain, sigma_wall (rows, 3) [Pa], volumetric_strain (1 - V / ``box_volume``
    [m^3]), porosity, and saturation and bridges (YADE's menisci) when wet."""
    data = read_plot_data(path)
    history = {"step": data["i"], "axial_strain": data["eps_axial"],
               "sigma_wall": np.column_stack([data["sx"], data["sy"], data["sz"]]),
               "volumetric_strain": 1.0 - data["lx"] * data["ly"] * data["lz"] / box_volume,
               "porosity": data["porosity"]}
    if "saturation" in data:
        history.update(saturation=data["saturation"], bridges=data["menisci"])
    return history


# ---------------------------------------------------------------- cached inputs

def cache_folder():
    """Where prepared samples and YADE's capillary files are kept (pendular.capillary.cache_directory)."""
    return str(capillary.cache_directory())


def cached_sample(config, *, progress=True, threads=None):
    """(Particles, Walls, preparation report) of the sample of ``config`` (a PrepareConfig),
    prepared once (thesis Ch. 5.2.2, at config.confining; ``threads``: Numba threads of the
    preparation, pendular.dem.simulation's policy by default) and saved in the cache folder under a name
    keyed by its configuration, which the saved sample holds and is checked against."""
    if not isinstance(config, PrepareConfig):
        raise TypeError(f"config must be a PrepareConfig, got {type(config).__name__}")
    key = hashlib.sha256(f"{PREPARATION_VERSION} {config_json(config)}".encode()).hexdigest()[:12]
    path = os.path.join(cache_folder(), "samples", f"sample_{config.particles}_"
                        f"{config.confining:g}_seed{config.seed}_{key}.h5")
    if not sample_made_with(path, config):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        started = time.perf_counter()
        sim, report = prepare_sample(config, progress=progress, threads=threads)
        report["preparation_wall_time_s"] = time.perf_counter() - started
        save_sample(path, sim, report, {"sample": config_to_dict(config)},
                    identity={"seed": config.seed})
    particles, walls, report, _ = load_sample(path, expected=config)
    return particles, walls, report


def benchmark_sample(count, confining, progress=True):
    """(PrepareConfig, Particles, Walls, report) of the thesis-default sample (Table 5.2) of
    ``count`` spheres at ``confining`` [Pa]: ``cached_sample`` of PrepareConfig(count,
    confining)."""
    config = PrepareConfig(particles=count, confining=confining)
    return (config, *cached_sample(config, progress=progress))


def yade_capillary_files(contact_angle=0.0):
    """Folder with YADE's ten capillary files M(r=1) ... M(r=10) of the exact bridge tables at
    ``contact_angle`` [deg] (capillary_files.write_table_files; written once, cached)."""
    folder = os.path.join(cache_folder(), f"yade_capillary_theta{contact_angle:g}")
    if not os.path.exists(os.path.join(folder, "M(r=10)")):
        os.makedirs(os.path.dirname(folder), exist_ok=True)
        partial = folder + f".partial{os.getpid()}"
        write_table_files(capillary.BridgeTable.cached(contact_angle), partial)
        try:
            os.replace(partial, folder)
        except OSError:           # another process put it there first
            shutil.rmtree(partial, ignore_errors=True)
    return folder


# ---------------------------------------------------------------- driver checks

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
