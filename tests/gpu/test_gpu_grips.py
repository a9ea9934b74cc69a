"""Grips (pendular.dem.grips.Grip) on the GPU against the CPU under Numba's CUDA simulator: the
pull of grips_checks.py, whose check runs in a process of its own so that no other test meets
the simulator. The CPU adds a grip's forces pairwise (np.sum), the device in chunks: the pulls
are the same terms in another order, on forces that differ by round-off (the simulator does
not contract multiply-adds).
"""

import pytest

from conftest import requires
from grips_checks import RECORD_PERIOD, STEPS
from simulator import simulated

pytestmark = requires("numba_cuda")


@pytest.fixture(scope="module")
def grips():
    return simulated("grips_checks.py", "pull")["pull"]


def test_grips_on_the_gpu_agree_with_the_cpu_to_round_off(grips):
    agreement = grips["agreement"]
    assert agreement["touching_cpu"] == agreement["touching_gpu"] == agreement["touching_both"]
    assert agreement["position"] < 1e-13 and agreement["wall_position"] < 1e-13
    assert agreement["wall_force"] < 1e-12
    for name in ("velocity", "angular_velocity", "force", "torque", "springs"):
        assert agreement[name] < 1e-10, name
    assert grips["gripped_velocity"] == 0.0       # the walls' velocities, on both devices


def test_the_pulls_are_the_cpus_at_every_record(grips):
    history = grips["history"]
    assert history["records"] == [STEPS // RECORD_PERIOD + 1] * 2
    assert history["pull"] < 1e-12 and history["wall_force"] < 1e-12
    # the grips first push (compression), then the sample comes apart from them
    smallest, largest = grips["pull_magnitude"]
    assert grips["pull_range"][0] < -1.0 and smallest < 1e-6 * largest
    assert grips["members"] == [32, 16] and grips["chunks"] == [2, 1]


def test_a_record_of_the_pulls_brings_back_the_walls_alone(grips):
    """The recorder reads the walls and the pulls every RECORD_PERIOD steps: walls only, and
    everything once at the end of the run (Simulation.run)."""
    assert grips["copies"] == ["walls"] * (STEPS // RECORD_PERIOD) + ["all"]


def test_what_the_device_cannot_hold_is_refused_by_name(grips):
    before, shared = grips["refusals"]
    assert "after every wall control" in before and "ConstantStrainRate" in before
    assert "in two grips" in shared
