"""Shared fixtures and helpers: small scenes built with the public API.

The tests are split by reach: tests/unit (one function or kernel against a closed form or an
independent computation), tests/integration (simulations through the library), tests/e2e (the
commands as a user runs them, marked ``slow``: ``pytest -m "not slow"`` leaves them out)."""

import importlib.metadata
import importlib.util
import json
import os
import shutil
import subprocess
import sys

# Before numpy and Numba load: idle OpenMP threads (Numba's threading layer) sleep instead of
# spinning, and BLAS runs on one thread; otherwise the parallel workers' waiting threads take
# the cores from one another. The results are the same bit for bit; the tests' processes
# inherit both.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import h5py
import numba
import numpy as np
import pytest

from pendular.dem.contact_law import ContactForces, normal_stiffness
from pendular.dem.measure import elastic_energy
from pendular.dem.integrate import Integrator
from pendular.dem.neighbors import NeighborList
from pendular.procedures.preparation import PrepareConfig, prepare_sample
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.walls import WallForces

#: The repository's root folder (scenarios/, benchmarks/, src/).
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RADIUS = 1e-3
DENSITY = 2650.0
YOUNG = 1e6


#: How to install what a test may need, by its name in ``requires``.
INSTALL = {"numba_cuda": "pip install -e '.[gpu]'", "vtk": "pip install -e '.[test]'",
           "dask.distributed": "pip install -e '.[test]'",
           "grainlearning": "pip install -e '.[calibrate]' && pip install --no-deps "
                            "grainlearning==2.0.5"}


def requires(need):
    """The skip mark of a test that needs what a machine may lack (the tests' one way to
    skip): ``need`` an importable module ("numba_cuda", "vtk", "meshio", "dask.distributed",
    "grainlearning"), "yade" (its executable on PATH), "threads" (two Numba threads), "cuda
    compiler" (the gpu extra's NVVM and NVRTC wheels) or "no gpu" (no CUDA GPU visible, for
    what a machine without one does). Use it as a decorator, or as ``pytestmark =
    requires(...)`` for a whole module."""
    if need == "yade":
        have, missing = any(shutil.which(name) for name in ("yade", "yadedaily")), \
            "YADE (yade or yadedaily on PATH) is not installed"
    elif need == "cuda compiler":
        have, missing = True, ""
        for wheel in ("nvidia-nvvm", "nvidia-cuda-nvrtc"):
            try:
                importlib.metadata.distribution(wheel)
            except importlib.metadata.PackageNotFoundError:
                have, missing = False, (f"the gpu extra's CUDA compiler ({wheel}) is not "
                                        f"installed ({INSTALL['numba_cuda']})")
    elif need == "no gpu":
        have, missing = True, "a CUDA GPU is visible"
        if importlib.util.find_spec("numba_cuda") is not None:
            from numba import cuda

            have = not cuda.is_available()
    elif need == "threads":
        have, missing = numba.config.NUMBA_NUM_THREADS >= 2, "needs two Numba threads"
    else:
        have = importlib.util.find_spec(need.split(".")[0]) is not None and (
            "." not in need or importlib.util.find_spec(need) is not None)
        missing = f"{need} is not installed" + (f" ({INSTALL[need]})" if need in INSTALL
                                                else "")
    return pytest.mark.skipif(not have, reason=missing)


class PrescribedGap:
    """Replaces the integrator: sphere 1 on the x axis at a surface gap ``start + rate (step + 1)``
    [m] from sphere 0."""

    def __init__(self, start, rate):
        self.start = start
        self.rate = rate

    def apply(self, sim):
        p = sim.particles
        p.position[1] = [p.radius[0] + p.radius[1] + self.start + self.rate * (sim.step + 1), 0, 0]
        p.velocity[:] = 0.0


class Still:
    """Replaces the integrator: nothing moves."""

    def apply(self, sim):
        sim.particles.velocity[:] = 0.0


def zero_bytes(path, dataset, count=16):
    """Overwrite the first ``count`` bytes of a (contiguous) HDF5 dataset's data with zeros."""
    with h5py.File(path, "r") as handle:
        offset = handle[dataset].id.get_offset()
    with open(path, "r+b") as raw:
        raw.seek(offset)
        raw.write(bytes(count))


def two_body_scene(positions, velocities, radius=RADIUS, young=YOUNG, friction_deg=0.0,
                   damping=0.0, dt=None, extra=(), box=1.0):
    """Spheres of ``radius`` (scalar or one per sphere) in a box [-box, box]^3 (walls out of
    reach unless placed near them) with the standard dry pipeline; ``extra``: further forces
    (after the contact and wall forces)."""
    radii = np.broadcast_to(np.asarray(radius, float), (len(positions),))
    particles = Particles(np.array(positions, float), radii, DENSITY,
                          velocity=np.array(velocities, float))
    walls = Walls.box([-box] * 3, [box] * 3)
    if dt is None:
        smallest = radii.min()
        dt = 0.01 * np.sqrt(particles.mass.min() / normal_stiffness(young, smallest, smallest))
    return Simulation(particles, walls, dt, neighbors=NeighborList(0.2 * radii.min()),
                      forces=[ContactForces(young, 0.3, friction_deg), WallForces(young), *extra],
                      integrator=Integrator(damping))


@pytest.fixture(scope="session")
def wet_triaxial_run(tmp_path_factory):
    """Output folder of scenarios/triaxial.py: 200 spheres at 30 kPa to 1 % strain, with
    ParaView frames of the preparation (--vtk-prep), run once for every test that reads it."""
    out = tmp_path_factory.mktemp("wet_triaxial") / "wet"
    subprocess.run([sys.executable, os.path.join(ROOT, "scenarios", "triaxial.py"),
                    "--particles", "200", "--max-strain", "0.01", "--inertial-number", "2e-3",
                    "--suction", "30000", "--vtk-prep", "--quiet", "--out", str(out)],
                   check=True, capture_output=True, text=True)
    return out


@pytest.fixture(scope="session")
def small_sample():
    """A 300-sphere sample prepared as in thesis Ch. 5.2.2 and held at 750 Pa (seed 1)."""
    config = PrepareConfig(particles=300, confining=750.0, seed=1, unload_steps=2000)
    sim, report = prepare_sample(config, progress=False)
    return config, sim, report


def pytest_collection_modifyitems(items):
    """Mark the end-to-end tests ``slow``, and put the GPU tests first: each module of them
    waits on one long process under the simulator, which pytest-xdist (whole files, in this
    order) then starts while the other workers take the shorter files, instead of last."""
    for item in items:
        if f"{os.sep}e2e{os.sep}" in str(item.path):
            item.add_marker(pytest.mark.slow)
    items.sort(key=lambda item: f"{os.sep}gpu{os.sep}" not in str(item.path))


class SpringEnergyProbe:
    """Test operation placed before the integrator: spring energy at x(t), v(t - dt/2)."""

    def __init__(self, young):
        self.young = young

    def apply(self, sim):
        self.energy = elastic_energy(sim.particles, sim.contacts, sim.walls, self.young, 0.3)
        self.velocity_before = sim.particles.velocity.copy()


def run_in_process(name, argv, capsys, prog=None):
    """(exit status, stderr) of command ``name`` with ``argv`` run in-process
    (pendular.cli.run_command)."""
    from pendular.cli import run_command

    try:
        status = run_command(name, [str(a) for a in argv], prog=prog)
    except SystemExit as stop:
        status = stop.code
    return status, capsys.readouterr().err


def refused(status, err, *words):
    """Exit status 2, no traceback and one ``error:`` line holding every word of ``words``;
    returns the line."""
    lines = [line for line in err.splitlines() if line.strip()]
    assert status == 2 and "Traceback" not in err, err
    assert len(lines) == 1 and ": error: " in lines[0], err
    for word in words:
        assert word in lines[0], (word, lines[0])
    return lines[0]


def summary_of(out):
    """The summary.json of the run folder ``out`` (dict)."""
    return json.loads((out / "summary.json").read_text())


def history_of(out, units=False):
    """The history.h5 columns of the run folder ``out`` (name -> array, the dimension labels
    left out); with ``units``, (columns, name -> unit attribute)."""
    with h5py.File(out / "history.h5") as handle:
        group = handle["history"]
        history = {name: group[name][()] for name in group
                   if name not in ("record", "axis", "component")}
        found = {name: group[name].attrs.get("units") for name in group}
    return (history, found) if units else history


def assert_drawn(path, min_size=(200, 150), min_inked=0.01):
    """Check that ``path`` is a PNG image of at least ``min_size`` (width, height) pixels in
    which more than ``min_inked`` of the pixels differ from its background (the colour of its
    corner): a figure with something drawn, not an empty or blank file."""
    import matplotlib.image

    pixels = matplotlib.image.imread(str(path))
    height, width = pixels.shape[:2]
    assert width >= min_size[0] and height >= min_size[1], (path, pixels.shape)
    inked = np.any(np.abs(pixels[..., :3] - pixels[0, 0, :3]) > 0.05, axis=-1).mean()
    assert inked > min_inked, (path, inked)


class StressScene:
    """Stand-in for a scene whose walls report the stresses ``sigma`` (3,) [Pa] at ``step``:
    what a control or guard reading ``sim.walls.stress()`` and ``sim.step`` sees."""

    class _Walls:
        def __init__(self, sigma):
            self.sigma = np.asarray(sigma, float)

        def stress(self):
            return self.sigma

    def __init__(self, sigma, step=0):
        self.walls, self.step = self._Walls(sigma), step

    def fetch(self, *parts):
        """Nothing is held by a device run here (Simulation.fetch): the scene itself."""
        return self
