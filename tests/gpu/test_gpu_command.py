"""``--device gpu`` on the commands (issue 38's done-means): a wet triaxial's loading on the GPU
path, under Numba's CUDA simulator in a process of its own, records the history of the same
command on the CPU; a checkpoint written on either device resumes on the other; what the GPU
path does not run yet is refused in one line before any work.

The run: a 60-sphere sample prepared on the CPU (``pendular triaxial --particles 60``, its
sample.h5), then ``pendular triaxial --sample S --particles 60 --suction 30000 --max-strain
0.002 --inertial-number 1e-3 --checkpoint-every 45`` with ``--device cpu`` and ``--device gpu``.
The inertial number is 1e-3 instead of the default 3e-4 (still quasi-static) so that the shear
takes 162 steps, not 538: the simulator runs about 10 steps a second at 60 spheres.

Measured (simulator, 162 steps, a record every step): the rows, bridge and contact counts are
the CPU's; every other column differs from the CPU's by at most 5.4e-13 of its largest value
(volumetric strain; sigma_wall 3.0e-13), the unbalanced force, a residual ratio, by 6.9e-11
(538 steps at the default inertial number: 4.4e-12 and 1.7e-9). The CPU's hot kernels contract
multiply-adds, the simulator does not: the difference is round-off grown over the steps.
TOLERANCE and UNBALANCED_TOLERANCE hold it with a margin of about 20 and 140.
"""

import os
import shutil
import subprocess
import sys

import h5py
import numpy as np
import pytest

from conftest import ROOT, refused, run_in_process

try:
    import numba_cuda  # noqa: F401
    HAVE_NUMBA_CUDA = True
except ImportError:
    HAVE_NUMBA_CUDA = False
needs_numba_cuda = pytest.mark.skipif(not HAVE_NUMBA_CUDA, reason="numba-cuda is not "
                                      "installed (pip install -e '.[gpu]')")

#: Largest difference of a history column from the CPU's over its largest magnitude [-].
TOLERANCE = 1e-11
#: The same for the unbalanced force, a ratio of a residual to the mean force [-].
UNBALANCED_TOLERANCE = 1e-8
#: The command of the done-means (its sample added by the tests).
TRIAXIAL = ["--particles", "60", "--suction", "30000", "--max-strain", "0.002",
            "--inertial-number", "1e-3", "--checkpoint-every", "45", "--quiet"]


def pendular(argv, simulated):
    """Run ``pendular triaxial argv``: in this process on the CPU, in one of its own under
    Numba's CUDA simulator when ``simulated`` (so that no other test meets the simulator)."""
    argv = [str(a) for a in argv]
    if not simulated:
        from pendular.cli import run_command

        assert run_command("triaxial", argv) == 0
        return
    environment = dict(os.environ, NUMBA_ENABLE_CUDASIM="1")
    done = subprocess.run([sys.executable, "-m", "pendular", "triaxial", *argv],
                          capture_output=True, text=True, env=environment, cwd=ROOT, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]


def history(folder):
    """The history.h5 columns of a run folder."""
    with h5py.File(os.path.join(folder, "history.h5")) as handle:
        return {name: data[()] for name, data in handle["history"].items()}


def differences(cpu, other):
    """Largest difference of each column of two histories over the CPU column's largest
    magnitude (the plain difference where that is 0)."""
    assert cpu.keys() == other.keys() and len(other["step"]) == len(cpu["step"])
    out = {}
    for name, values in cpu.items():
        if values.dtype == object:                  # the axis and component labels
            assert np.array_equal(values, other[name]), name
            continue
        scale = np.max(np.abs(values))
        difference = np.max(np.abs(other[name] - values))
        out[name] = difference / scale if scale > 0 else difference
    return out


def assert_agrees(cpu, other):
    for name, difference in differences(cpu, other).items():
        bound = UNBALANCED_TOLERANCE if name == "unbalanced_force" else TOLERANCE
        assert difference <= bound, (name, difference)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Folders of the sample, the CPU run and the GPU run."""
    root = tmp_path_factory.mktemp("gpu_command")
    pendular(["--particles", 60, "--max-strain", 1e-4, "--quiet", "--out", root / "prep"],
             simulated=False)
    sample = root / "prep" / "sample.h5"
    for device in ("cpu", "gpu"):
        pendular([*TRIAXIAL, "--sample", sample, "--device", device, "--out", root / device],
                 simulated=device == "gpu")
    return root


def checkpoint_step(folder):
    with h5py.File(os.path.join(folder, "checkpoint.h5")) as handle:
        return int(handle.attrs["step"])


@needs_numba_cuda
def test_the_gpu_command_records_the_cpu_history(runs):
    cpu, gpu = history(runs / "cpu"), history(runs / "gpu")
    assert len(cpu["step"]) == 163 and np.array_equal(cpu["step"], gpu["step"])
    assert cpu["bridges"].min() > 20 and np.array_equal(cpu["bridges"], gpu["bridges"])
    assert np.array_equal(cpu["coordination"], gpu["coordination"])
    assert_agrees(cpu, gpu)
    assert np.ptp(cpu["sigma_wall"][:, 2]) > 100.0           # the shear loads the sample
    for folder in ("cpu", "gpu"):
        assert os.path.exists(runs / folder / "triaxial.png")
        assert os.listdir(runs / folder / "vtk")


@needs_numba_cuda
@pytest.mark.parametrize("written, resumed", [("gpu", "cpu"), ("cpu", "gpu")])
def test_a_checkpoint_resumes_on_the_other_device(runs, written, resumed):
    copy = runs / f"{written}_on_{resumed}"
    shutil.copytree(runs / written, copy)
    step = checkpoint_step(copy)
    steps = history(copy)["step"]
    assert steps[0] < step < steps[-1]              # written by the loading, partway
    pendular(["--resume", copy, "--device", resumed, "--quiet"], simulated=resumed == "gpu")
    again = history(copy)
    assert np.array_equal(again["step"], steps)
    assert_agrees(history(runs / "cpu"), again)


@pytest.mark.parametrize("options, words", [
    (["--periodic"], ["periodic cell's preparation", "--sample"]),
    (["--water-content", "5"], ["volume-controlled bridges"]),
    (["--suction", "30000", "--persist-bridges"], ["bridges across gaps"])])
def test_what_the_gpu_does_not_run_is_refused_before_any_work(tmp_path, capsys, options,
                                                             words):
    out = tmp_path / "out"
    status, err = run_in_process("triaxial", ["--device", "gpu", "--particles", "60",
                                              "--out", out, *options], capsys)
    refused(status, err, "--device gpu", "does not run", *words)
    assert not out.exists()


def test_a_gpu_run_without_a_gpu_says_how_to_get_one(tmp_path, capsys):
    if HAVE_NUMBA_CUDA:
        from numba import cuda

        if cuda.is_available():
            pytest.skip("a GPU (or the simulator) is here")
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
