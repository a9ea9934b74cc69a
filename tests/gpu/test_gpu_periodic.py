"""The GPU path in a periodic cell (pendular.gpu.cell) against the CPU path under Numba's CUDA
simulator: the scene of periodic_checks.py, dry, wet and with damped Hertz–Mindlin contacts,
its checks run in one process of their own so that no other test meets the simulator; then the
periodic triaxial command on both devices. The CPU's hot kernels contract multiply-adds and
take reciprocals; the simulator computes each operation as written, hence round-off bounds
(docs/gpu.md gives the differences measured).
"""

import numpy as np
import pytest

from conftest import requires
from periodic_checks import scene
from simulator import (PERIODIC_SAMPLE, assert_same_records, command_runs_fixture,
                       histories_on_both, on_the_gpu, simulated)

pytestmark = requires("numba_cuda")


#: The sample that the command test loads, and the folder of its runs.
command_runs = command_runs_fixture(PERIODIC_SAMPLE)


@pytest.fixture(scope="module")
def measured(command_runs):
    """The checks' measurements, in one process, after the command test's GPU run there."""
    sample, folder = command_runs
    return simulated("periodic_checks.py", "dry", "wet", "hertz",
                     commands=[on_the_gpu("triaxial", sample, COMMAND, folder)])


@pytest.fixture(scope="module")
def dry(measured):
    return measured["dry"]


@pytest.fixture(scope="module")
def wet(measured):
    return measured["wet"]


def assert_agrees(measured):
    assert measured["touching"][0] == measured["touching"][1] > 100    # a packing, not a gas
    assert measured["position"] < 1e-13
    assert measured["cell"] < 1e-13 and measured["rate"] < 1e-13
    assert measured["stress"] < 1e-13 and measured["stiffness"] < 1e-13
    for name in ("velocity", "angular_velocity"):
        assert measured[name] < 1e-10, name


def test_a_periodic_cell_agrees_with_the_cpu_to_round_off_dry(dry):
    assert sum(dry["wrapped"]) > 0                        # through the faces
    assert dry["rebuilds"][0] == dry["rebuilds"][1] > 2   # several lists
    assert dry["strain"] > 0.0
    assert_agrees(dry)


def test_a_periodic_cell_agrees_with_the_cpu_to_round_off_wet(wet):
    assert wet["rebuilds"][0] == wet["rebuilds"][1] > 1
    assert_agrees(wet)


def test_hertz_mindlin_contacts_agree_with_the_cpu_to_round_off(measured):
    """The damped Hertz–Mindlin law on the device (pendular.gpu.forces.pair_forces compiles
    the CPU's _evaluate_damped_pair) against the CPU's."""
    hertz = measured["hertz"]
    assert hertz["rebuilds"][0] == hertz["rebuilds"][1] > 1
    # the servo's rate, a difference of near stresses over a stiffness, takes the
    # sensitivity of the damped scene soonest (periodic_checks.HERTZ_STEPS)
    for run in (hertz, hertz["continued"]):
        assert run["touching"][0] == run["touching"][1] > 100
        for name, bound in (("position", 1e-13), ("cell", 1e-13), ("velocity", 1e-10),
                            ("angular_velocity", 1e-10), ("stress", 1e-10), ("rate", 1e-6)):
            assert run[name] < bound, (name, run[name])


def test_a_gpu_run_continued_on_the_cpu_equals_the_cpu_run(dry, wet):
    assert_agrees(dry["continued"])
    assert_agrees(wet["continued"])


#: The periodic triaxial command on both devices (its sample, prepared on the CPU, added).
COMMAND = ["--particles", "60", "--periodic", "--max-strain", "0.002", "--inertial-number",
           "1e-3", "--quiet"]


def test_the_periodic_triaxial_command_records_the_cpu_history(command_runs, measured):
    """``pendular triaxial --periodic --sample S --device gpu`` (S a periodic sample prepared on
    the CPU) runs the sample's equilibrium and the shear on the device and records the CPU's
    history: the same rows and contact counts, the other columns to round-off grown over the
    steps (the unbalanced force, a residual ratio, looser)."""
    sample, folder = command_runs
    cpu, gpu = histories_on_both("triaxial", sample, COMMAND, folder)
    assert_same_records(cpu, gpu, 100)
    for name, values in cpu.items():
        if values.dtype == object:
            continue
        bound = 1e-7 if name == "unbalanced_force" else 1e-9
        assert np.max(np.abs(gpu[name] - values)) <= bound * np.max(np.abs(values)), name


def test_a_radius_growth_in_a_moving_cell_is_refused_by_name():
    """A radius growth runs on the device in a cell whose faces no control moves only (its
    rebuild test does not follow the cell's stretching)."""
    from pendular.dem.growth import RadiusGrowth
    from pendular.gpu.simulation import check_scene

    sim = scene()
    sim.controls = [RadiusGrowth(1e4, 1.0), *sim.controls]
    with pytest.raises(ValueError, match="RadiusGrowth in a periodic cell whose faces no "
                                         "control moves only.*StressServo"):
        check_scene(sim)
