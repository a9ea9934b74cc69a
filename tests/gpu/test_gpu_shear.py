"""The periodic cell's controls on the GPU path (pendular.gpu.cell) against the CPU path under
Numba's CUDA simulator: simple shear (dry, wet), mixed stress conditions and a radius growth in
a cell (the scenes of shear_checks.py, whose checks run in one process of their own so that no
other test meets the simulator), then ``pendular simple-shear --sample S --device gpu`` against
``--device cpu``. The CPU's hot kernels contract multiply-adds and take reciprocals; the
simulator computes each operation as written, hence round-off bounds (docs/gpu.md gives the
differences measured).
"""

import numpy as np
import pytest

from conftest import requires
from shear_checks import GROWTH_TARGET, MIXED_STEPS, START_OFFSET
from simulator import (PERIODIC_SAMPLE, command_runs_fixture, histories_on_both, on_the_gpu,
                       simulated)

pytestmark = requires("numba_cuda")


#: The sample that the command test loads, and the folder of its runs.
command_runs = command_runs_fixture(PERIODIC_SAMPLE)


@pytest.fixture(scope="module")
def measured(command_runs):
    """The checks' measurements, in one process, after the command test's GPU run there."""
    sample, folder = command_runs
    return simulated("shear_checks.py", "dry", "wet", "mixed", "growth",
                     commands=[on_the_gpu("simple-shear", sample, COMMAND, folder)])


@pytest.fixture(scope="module")
def dry(measured):
    return measured["dry"]


@pytest.fixture(scope="module")
def wet(measured):
    return measured["wet"]


@pytest.fixture(scope="module")
def mixed(measured):
    return measured["mixed"]


@pytest.fixture(scope="module")
def growth(measured):
    return measured["growth"]


def assert_agrees(measured):
    assert measured["touching"][0] == measured["touching"][1] > 80     # a packing, not a gas
    assert measured["position"] < 1e-13
    assert measured["cell"] < 1e-13
    assert measured["rate"] < 1e-10             # a servo's rate: a velocity
    assert measured["stress"] < 1e-12 and measured["shear_stress"] < 1e-11
    assert measured["stiffness"] < 1e-12
    assert measured["offset"] < 1e-12 and measured["shear_strain"] < 1e-14
    assert measured["shear_rate"] == 0.0
    for name in ("velocity", "angular_velocity"):
        assert measured[name] < 1e-10, name


def test_simple_shear_agrees_with_the_cpu_to_round_off_dry(dry):
    x, _, z = dry["wrapped"]
    assert x > 0 and z > 0                      # through the x faces and the sheared z faces
    assert dry["rebuilds"][0] == dry["rebuilds"][1] > 3
    # the offset passed half the width and lost a whole width at a rebuild
    assert START_OFFSET + dry["gamma"] > 0.5 and abs(dry["offset_fraction"]) < 0.5
    assert dry["gamma"] > 0.2 and dry["tau"] > 0.0
    assert_agrees(dry)


def test_simple_shear_agrees_with_the_cpu_to_round_off_wet(wet):
    assert wet["rebuilds"][0] == wet["rebuilds"][1] > 2
    assert_agrees(wet)


def test_a_sheared_gpu_run_continued_on_the_cpu_equals_the_cpu_run(dry, wet):
    assert_agrees(dry["continued"])
    assert_agrees(wet["continued"])



@pytest.mark.parametrize("condition", ["constant_p", "constant_b"])
def test_a_mixed_condition_in_a_cell_agrees_with_the_cpu_to_round_off(mixed, condition):
    run = mixed[condition]
    assert_agrees(run)
    assert run["targets"] < 1e-12 and run["final_targets"] < 1e-12
    assert run["target_change"] > 0.05      # the condition moved the servos' targets


def test_a_mixed_condition_that_cannot_hold_in_a_cell_fails_as_on_the_cpu(mixed):
    """The CPU's StageFailed, its message (the step of the failure included), raised on the
    GPU at the run's next check (every 100 steps: nothing reads the device's state before)."""
    cpu, gpu = mixed["failing"]["cpu"], mixed["failing"]["gpu"]
    assert cpu["error"] == gpu["error"] == "StageFailed"
    assert gpu["message"] == cpu["message"] and "walls cannot pull" in cpu["message"]
    assert 0 < cpu["step"] < MIXED_STEPS and gpu["step"] == 100 * (cpu["step"] // 100 + 1)



def test_a_radius_growth_in_a_cell_agrees_with_the_cpu_to_round_off(growth):
    assert growth["touching"][0] == growth["touching"][1] > 0
    for name in ("radius", "mass", "inertia", "position", "dt"):
        assert growth[name] < 1e-12, name
    assert growth["stress"] < 1e-11                 # a dense packing's contact forces
    assert growth["velocity"] < 1e-9                # a residual of the damped motion
    assert growth["cell"] == 0.0                    # the cell holds still
    assert growth["rebuilds"][0] == growth["rebuilds"][1] >= 4
    # the run the docstring describes: grown by more than 10 %, the cell's stress near its
    # target (the rate falls as it nears it), dt followed
    assert growth["radius_growth"] > 1.1 and growth["peak_stress"] > 0.8 * GROWTH_TARGET
    assert growth["dt_change"] > 0.05
    for name, difference in growth["split"].items():
        assert difference < 1e-12, name


def test_a_periodic_preparation_runs_its_growth_on_the_gpu(growth):
    """prepare_sample(device="gpu") of a periodic sample runs the growth there: cut short at a
    step limit, it stops with the CPU's message."""
    prepared = growth["prepare"]
    assert prepared["device_steps"] == prepared["max_steps"]
    assert prepared["gpu"] == prepared["cpu"]
    assert "radius growth not reached" in prepared["gpu"]


#: The simple shear command on both devices (its sample, prepared on the CPU, added).
COMMAND = ["--particles", "60", "--max-strain", "0.002", "--inertial-number", "1e-3",
           "--quiet"]
#: Largest difference of a history column from the CPU's over its largest magnitude [-], and
#: the same for the unbalanced force (a ratio of a residual to the mean force).
TOLERANCE = 2e-9
UNBALANCED_TOLERANCE = 1e-7


def test_the_simple_shear_command_records_the_cpu_history(command_runs, measured):
    """``pendular simple-shear --sample S --device gpu`` (S a periodic sample prepared on the
    CPU) shears on the device and records the CPU's history: the same rows, contact
    counts and shear strains, the other columns to round-off grown over the steps."""
    sample, folder = command_runs
    cpu, gpu = histories_on_both("simple-shear", sample, COMMAND, folder)
    assert cpu.keys() == gpu.keys() and len(cpu["step"]) > 5
    for name in ("step", "coordination", "shear_strain"):
        assert np.array_equal(cpu[name], gpu[name]), name
    assert cpu["shear_strain"][-1] >= 0.002
    for name, values in cpu.items():
        if values.dtype == object:
            assert np.array_equal(values, gpu[name]), name
            continue
        bound = UNBALANCED_TOLERANCE if name == "unbalanced_force" else TOLERANCE
        assert np.max(np.abs(gpu[name] - values)) <= bound * np.max(np.abs(values)), name
