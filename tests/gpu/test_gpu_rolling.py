"""Rolling and twisting resistance (pendular.dem.rolling) and gravity (pendular.dem.gravity) on
the GPU against the CPU under Numba's CUDA simulator: the scenes of rolling_checks.py (walled
with the weight, in a periodic cell, on damped Hertz–Mindlin contacts), whose checks run in one
process of their own so that no other test meets the simulator. The simulator does not
contract multiply-adds as the CPU's hot kernels do, hence round-off bounds (docs/gpu.md gives
the differences measured).
"""

import pytest

from conftest import requires
from simulator import simulated

pytestmark = requires("numba_cuda")


@pytest.fixture(scope="module")
def measured():
    return simulated("rolling_checks.py", "walls", "periodic", "hertz", "refusal")


@pytest.fixture(scope="module")
def resisting(measured):
    return measured["walls"]


def test_rolling_resistance_and_gravity_on_the_gpu_agree_with_the_cpu_to_round_off(resisting):
    agreement = resisting["agreement"]
    assert agreement["touching_cpu"] == agreement["touching_gpu"] == agreement["touching_both"]
    assert agreement["touching_both"] > 20
    assert resisting["rebuilds"] == resisting["rebuilds_cpu"] >= 3
    assert agreement["position"] < 1e-13 and agreement["wall_position"] < 1e-13
    for name in ("velocity", "angular_velocity", "force", "torque", "springs",
                 "rolling_moment", "twisting_moment", "moment"):
        assert agreement[name] < 1e-10, name


def test_the_moments_and_the_weight_matter(resisting):
    """What the comparison would miss if the device left them out: springs on their limits
    and off them, and a trajectory that neither force leaves unchanged by far more than
    round-off."""
    on_limit, below = resisting["rolling_on_limit"]
    assert on_limit > 0 and below > 0
    assert resisting["without"]["moments"]["angular_velocity"] > 1e-3
    assert resisting["without"]["weight"]["position"] > 1e-6


def test_the_springs_are_carried_across_the_devices_rebuilds(resisting):
    """A run forced to rebuild its list every 10 steps equals the plain run bit for bit."""
    assert resisting["rebuilds_forced"] >= 2 * resisting["rebuilds"]
    assert resisting["forced_equals_plain"]


def test_the_springs_go_to_the_device_and_come_back(resisting):
    """Half the run on the CPU, the other half on the device from the host's springs: the
    CPU's whole run, to round-off."""
    handed = resisting["handed_over"]
    assert handed["touching_cpu"] == handed["touching_gpu"] == handed["touching_both"]
    assert handed["position"] < 1e-13
    for name in ("angular_velocity", "rolling_moment", "twisting_moment", "moment"):
        assert handed[name] < 1e-10, name


def test_the_rolling_resistance_in_a_periodic_cell_agrees_with_the_cpu(measured):
    periodic = measured["periodic"]
    assert periodic["touching_cpu"] == periodic["touching_gpu"] == periodic["touching_both"]
    assert periodic["position"] < 1e-13 and periodic["cell"] < 1e-13
    for name in ("angular_velocity", "torque", "rolling_moment", "twisting_moment", "moment"):
        assert periodic[name] < 1e-10, name


def test_the_rolling_resistance_on_damped_hertz_mindlin_contacts_agrees_with_the_cpu(measured):
    """The moments read the damped law's per-pair normal force (its spring's) on the device as
    on the CPU; over periodic_checks.HERTZ_STEPS, before the damped scene's round-off grows."""
    hertz = measured["hertz"]
    assert hertz["touching_cpu"] == hertz["touching_gpu"] == hertz["touching_both"] > 100
    assert hertz["position"] < 1e-13 and hertz["cell"] < 1e-13
    for name in ("angular_velocity", "torque", "rolling_moment", "twisting_moment", "moment"):
        assert hertz[name] < 1e-10, name
    assert hertz["on_limit"][0] > 0


def test_a_rolling_resistance_before_the_contact_law_is_refused(measured):
    assert "RollingResistance listed after the contact law only" in (measured["refusal"] or "")
