"""Mixed stress conditions (pendular.dem.mixed_stress.MixedStress) on the GPU against the CPU,
under Numba's CUDA simulator in a process of its own (tests/gpu/mixed_checks.py): the
27-sphere scene of simulated.py sheared at a constant mean stress p (one servo for x and y) and at a constant b (sigma_3 given on x, y set), the servos'
targets set on the device each step from the walls' stresses. A condition that needs walls to
pull raises the CPU's StageFailed, at the same step, with the same message. The differences
from the CPU are round-off, as in tests/gpu/test_gpu_dem.py.
"""

import pytest

from conftest import requires
from mixed_checks import STEPS
from simulator import simulated

pytestmark = requires("numba_cuda")


@pytest.fixture(scope="module")
def mixed():
    return simulated("mixed_checks.py", "mixed")["mixed"]


@pytest.mark.parametrize("condition", ["constant_p", "constant_b"])
def test_a_mixed_condition_on_the_gpu_agrees_with_the_cpu_to_round_off(mixed, condition):
    run = mixed[condition]
    agreement, history = run["agreement"], run["history"]
    assert agreement["touching_cpu"] == agreement["touching_gpu"] == agreement["touching_both"]
    assert agreement["position"] < 1e-13 and agreement["wall_position"] < 1e-13
    assert agreement["wall_stress"] < 1e-12
    for name in ("velocity", "force", "springs"):
        assert agreement[name] < 1e-10, name
    assert history["records"] == [STEPS // 50] * 2
    assert history["targets"] < 1e-12
    # the condition moved the targets away from the servos' first ones
    assert run["target_change"] > 0.05


def test_the_targets_set_on_the_device_come_back_to_the_servos(mixed):
    """After the run the host's servos hold the device's targets (a checkpoint saves them)."""
    for condition in ("constant_p", "constant_b"):
        targets = mixed[condition]["final_targets"]
        assert targets["gpu"] == pytest.approx(targets["cpu"], rel=1e-12)


def test_runs_in_a_row_copy_nothing_and_equal_one_run(mixed):
    """A GpuSimulation driven directly, two runs in a row: no copy back between them (the
    second run's set-up reads the scene, not its state), and the state after them equals one
    run of the same steps bit for bit; the next run's set-up keeps the targets the device set
    (the host's are stale while the device holds the state)."""
    assert mixed["in_a_row"]["copies"] == ["all"]
    assert mixed["in_a_row"]["targets_kept"]
    assert mixed["in_a_row"]["equals_one_run"]


def test_a_condition_that_needs_walls_to_pull_fails_on_the_gpu_as_on_the_cpu(mixed):
    """Simulation(device="gpu").run: StageFailed with the CPU's message (its step included),
    the history ends where the CPU's does, and the host holds the state afterwards."""
    cpu, gpu = mixed["failing"]["cpu"], mixed["failing"]["gpu"]
    assert cpu["error"] == "StageFailed" and gpu["error"] == "StageFailed"
    assert "walls cannot pull" in cpu["message"]
    assert gpu["message"] == cpu["message"]
    assert 2 < cpu["failed_at"] < STEPS
    assert gpu["records"] == cpu["records"] == list(range(2, cpu["failed_at"] + 1, 2))
    assert gpu["released"] == []
    # with nothing reading the state, the check after the failure raises it
    checked = mixed["failing"]["checked"]
    assert checked["error"] == "StageFailed" and checked["message"] == cpu["message"]
    assert checked["step"] == 25
