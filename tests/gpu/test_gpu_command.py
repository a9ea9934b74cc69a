"""``--device gpu`` on the commands: a wet triaxial on the GPU path
(the loaded sample's equilibrium, the wetting and the loading), under Numba's CUDA simulator
in a process of its own, records the history of the same command on the CPU; a checkpoint
written on either device resumes on the other; a GPU run where no GPU can run is refused in
one line before any work.

The run: a 60-sphere sample prepared on the CPU (``pendular triaxial --particles 60``, its
sample.h5), then ``pendular triaxial --sample S --particles 60 --suction 30000 --max-strain
0.002 --inertial-number 1e-3 --checkpoint-every 45`` with ``--device cpu`` and ``--device gpu``.
The inertial number is 1e-3 instead of the default 3e-4 (still quasi-static) so that the shear
takes 162 steps, not 538. Before the
shear the sample is equilibrated at the confining stress (200 steps) and wetted (200 steps),
on the device too.

The rows, bridge and contact counts are the CPU's; the other columns differ from the CPU's by
round-off that the 400 steps of equilibrium and wetting before the shear amplify as they
amplify the CPU's own: the CPU run with one coordinate of the loaded sample moved by one ulp
differs from the CPU run by as much (docs/gpu.md). The CPU's hot kernels contract
multiply-adds, the simulator does not, so the test runs the one-ulp CPU run too and holds each
column to MARGIN times that run's difference (at least ROUND_OFF), B, the surface-tension
stress (a deviator whose bridge terms cancel), against psi's magnitude (SCALE_OF).
"""

import contextlib
import importlib.util
import os
import shutil

import h5py
import numpy as np
import pytest

from conftest import refused, requires, run_in_process
from simulator import WALLED_SAMPLE, history, prepared_sample, simulated_commands

#: Whether the gpu extra is installed (what the refusal of a GPU run says depends on it).
HAVE_NUMBA_CUDA = importlib.util.find_spec("numba_cuda") is not None

#: A column may differ from the CPU's by MARGIN times the difference that one ulp in one
#: coordinate of the loaded sample makes on the CPU (the dynamics' amplification of round-off) ...
MARGIN = 10.0
#: ... or by ROUND_OFF of its scale, whichever is larger [-].
ROUND_OFF = 1e-12
#: The column whose largest magnitude is the scale of a column whose terms cancel: B (Eq. 3.45),
#: the bridges' surface-tension stress, a deviator of terms of psi's size (psi = chi s + B).
SCALE_OF = {"B": "psi"}
#: The command of the done-means (its sample added by the tests).
TRIAXIAL = ["--particles", "60", "--suction", "30000", "--max-strain", "0.002",
            "--inertial-number", "1e-3", "--checkpoint-every", "45", "--quiet"]


def on_the_cpu(argv):
    """Run ``pendular triaxial argv`` in this process on the CPU (the GPU's runs are in one
    process of their own under Numba's CUDA simulator, so that no other test meets it)."""
    from pendular.cli import run_command

    assert run_command("triaxial", [str(a) for a in argv]) == 0


def differences(cpu, other):
    """Largest difference of each column of two histories over the CPU column's largest
    magnitude, or that of the column SCALE_OF names (the plain difference where it is 0)."""
    assert cpu.keys() == other.keys() and len(other["step"]) == len(cpu["step"])
    out = {}
    for name, values in cpu.items():
        if values.dtype == object:                  # the axis and component labels
            assert np.array_equal(values, other[name]), name
            continue
        scale = np.max(np.abs(cpu[SCALE_OF.get(name, name)]))
        difference = np.max(np.abs(other[name] - values))
        out[name] = difference / scale if scale > 0 else difference
    return out


def assert_agrees(cpu, other, sensitivity):
    """Every column of ``other`` within MARGIN times ``sensitivity`` (the differences of the
    one-ulp CPU run) of the CPU's, or ROUND_OFF."""
    for name, difference in differences(cpu, other).items():
        bound = max(ROUND_OFF, MARGIN * sensitivity[name])
        assert difference <= bound, (name, difference, bound)


@contextlib.contextmanager
def one_ulp_off(sample):
    """Within the block, a run loading the sample file ``sample`` gets its first coordinate
    moved by one ulp (the CPU's sensitivity to round-off, module docstring)."""
    from pendular.procedures import laboratory

    load_sample = laboratory.load_sample

    def moved(path, expected=None):
        particles, walls, report, extra = load_sample(path, expected=expected)
        if os.path.samefile(path, sample):
            particles.position[0, 0] = np.nextafter(particles.position[0, 0], np.inf)
        return particles, walls, report, extra

    laboratory.load_sample = moved
    try:
        yield
    finally:
        laboratory.load_sample = load_sample


def sensitivity(runs):
    """The differences of the one-ulp CPU run from the CPU run."""
    return differences(history(runs / "cpu"), history(runs / "cpu_ulp"))


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Folders of the CPU run, the GPU run and the one-ulp CPU run of the sample prepared on
    the CPU (simulator.prepared_sample), and of a copy of each device's run resumed from its
    checkpoint on the other device (W_on_R: written on W, resumed on R); the GPU's run and
    resume in one process."""
    root = tmp_path_factory.mktemp("gpu_command")
    sample = prepared_sample(tmp_path_factory, WALLED_SAMPLE)
    on_the_cpu([*TRIAXIAL, "--sample", sample, "--device", "cpu", "--out", root / "cpu"])
    shutil.copytree(root / "cpu", root / "cpu_on_gpu")
    simulated_commands(
        ("triaxial", [*TRIAXIAL, "--sample", sample, "--device", "gpu", "--out", root / "gpu"]),
        ("triaxial", ["--resume", root / "cpu_on_gpu", "--device", "gpu", "--quiet"]))
    shutil.copytree(root / "gpu", root / "gpu_on_cpu")
    on_the_cpu(["--resume", root / "gpu_on_cpu", "--device", "cpu", "--quiet"])
    with one_ulp_off(sample):
        on_the_cpu([*TRIAXIAL, "--sample", sample, "--out", root / "cpu_ulp"])
    return root


def checkpoint_step(folder):
    with h5py.File(os.path.join(folder, "checkpoint.h5")) as handle:
        return int(handle.attrs["step"])


@requires("numba_cuda")
def test_the_gpu_command_records_the_cpu_history(runs):
    cpu, gpu = history(runs / "cpu"), history(runs / "gpu")
    assert len(cpu["step"]) == 163 and np.array_equal(cpu["step"], gpu["step"])
    assert cpu["bridges"].min() > 20 and np.array_equal(cpu["bridges"], gpu["bridges"])
    assert np.array_equal(cpu["coordination"], gpu["coordination"])
    ulp = sensitivity(runs)
    assert 0.0 < ulp["sigma_wall"] < 1e-7        # one ulp is felt, as round-off
    assert_agrees(cpu, gpu, ulp)
    assert np.ptp(cpu["sigma_wall"][:, 2]) > 100.0           # the shear loads the sample
    for folder in ("cpu", "gpu"):
        assert os.path.exists(runs / folder / "triaxial.png")
        assert os.listdir(runs / folder / "vtk")


@requires("numba_cuda")
@pytest.mark.parametrize("written, resumed", [("gpu", "cpu"), ("cpu", "gpu")])
def test_a_checkpoint_resumes_on_the_other_device(runs, written, resumed):
    """The copy of the run on ``written`` resumed on ``resumed`` (runs) from the checkpoint
    that the run wrote partway records the run's steps, the CPU's history within bounds."""
    steps = history(runs / written)["step"]
    assert steps[0] < checkpoint_step(runs / written) < steps[-1]  # written by the loading
    again = history(runs / f"{written}_on_{resumed}")
    assert np.array_equal(again["step"], steps)
    assert_agrees(history(runs / "cpu"), again, sensitivity(runs))


@requires("no gpu")
def test_a_gpu_run_without_a_gpu_says_how_to_get_one(tmp_path, capsys):
    out = tmp_path / "out"
    status, err = run_in_process("triaxial", ["--device", "gpu", "--particles", "60",
                                              "--out", out], capsys)
    line = refused(status, err, "--device gpu cannot run here")
    assert ("no CUDA GPU is visible" in line if HAVE_NUMBA_CUDA
            else "pip install -e '.[gpu]'" in line)
    assert not out.exists()


def test_the_device_is_a_checked_run_option():
    from pendular.dem.simulation import Simulation
    from pendular.dem.state import Particles, Walls
    from pendular.dem.integrate import Integrator
    from pendular.dem.neighbors import NeighborList

    with pytest.raises(ValueError, match="device = 'tpu' is not one of 'cpu', 'gpu'"):
        Simulation(Particles(np.zeros((1, 3)), [1e-3], 2650.0), Walls.box([-1] * 3, [1] * 3),
                   1e-6, neighbors=NeighborList(1e-4), integrator=Integrator(0.2),
                   device="tpu")
