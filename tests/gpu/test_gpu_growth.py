"""The radius growth of a preparation (pendular.dem.growth) on the GPU against the CPU under
Numba's CUDA simulator: the scene of growth_checks.py, whose checks run in a process of their own
so that no other test meets the simulator.
"""

import pytest

from conftest import requires
from growth_checks import TARGET
from simulator import simulated

pytestmark = requires("numba_cuda")


@pytest.fixture(scope="module")
def growth():
    return simulated("growth_checks.py", "growth")["growth"]


def test_the_growth_on_the_gpu_agrees_with_the_cpu_to_round_off(growth):
    agreement = growth["agreement"]
    for name in ("radius", "mass", "inertia", "position", "wall_stress", "dt"):
        assert agreement[name] < 1e-12, name
    assert agreement["velocity"] < 1e-9
    assert agreement["wall_position"] == 0.0          # the walls hold still
    assert growth["touching"]["cpu"] == growth["touching"]["gpu"] > 0


def test_the_growth_grew_then_shrank_and_set_the_step_at_each_rebuild(growth):
    """The run is the one the module docstring describes (else the agreement proves little):
    radii grown by more than 10 %, the stress past the target, several rebuilds, the same
    number on both devices, and the time step followed the radii."""
    assert growth["radius_growth"] > 1.1
    assert growth["peak_stress"] > TARGET
    assert growth["rebuilds"]["gpu"] == growth["rebuilds"]["cpu"] >= 4
    assert growth["rebuilds"]["growth_only"] >= 1
    assert growth["dt_change"] > 0.05


def test_a_growth_split_between_two_device_runs_agrees_too(growth):
    """The second run starts from the host's list (its per-pair state in rows sized for the
    grown radii) and rebuilds at its first step without setting dt (the CPU would not)."""
    for name, difference in growth["split"].items():
        assert difference < 1e-12, name


def test_a_preparation_runs_its_growth_on_the_gpu(growth):
    """prepare_sample(device="gpu") runs the growth there: cut short at a step limit, it stops
    with the CPU's message (stress, porosity and unbalanced force as the CPU's)."""
    prepared = growth["prepare"]
    assert prepared["device_steps"] == prepared["max_steps"]
    assert prepared["gpu"] == prepared["cpu"]
    assert "radius growth not reached" in prepared["gpu"]


def test_a_growth_the_gpu_cannot_follow_is_refused_by_name(growth):
    """Two growths, or the time step set before the radii grow (it would read the radii of
    the step before), are refused before anything runs."""
    refused = growth["refused"]
    assert refused["two"] == ("device='gpu' runs at most one RadiusGrowth among the controls")
    assert refused["order"] == ("device='gpu' runs a GrowthTimeStep after the RadiusGrowth "
                                "only (it reads the grown radii)")
