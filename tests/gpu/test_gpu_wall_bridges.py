"""Sphere–wall bridges (pendular.gpu.wall_bridges) on the GPU against the CPU under Numba's
CUDA simulator: the scenes of wall_bridges_checks.py (the wet miniature triaxial with bridges
on the walls), whose checks run in one process of their own so that no other test meets the
simulator. The simulator does not contract multiply-adds as the CPU's hot kernels do, and the
device sums the pulls on a wall before subtracting them, hence round-off bounds."""

import pytest

from conftest import requires
from simulator import simulated

pytestmark = requires("numba_cuda")

QUANTITIES = ("velocity", "angular_velocity", "force", "torque", "springs", "wall_force",
              "wall_stress", "bridges_volume", "bridges_force", "bridges_filling",
              "bridges_moment")


@pytest.fixture(scope="module")
def measured():
    return simulated("wall_bridges_checks.py", "agreement", "persist", "refusal",
                     "order")


@pytest.mark.parametrize("name", ["agreement", "persist"])
@pytest.mark.parametrize("case", ["agreement", "handed_over"])
def test_the_wall_bridges_on_the_gpu_agree_with_the_cpu_to_round_off(measured, name, case):
    agreement = measured[name][case]
    cpu, gpu = agreement["wall_bridges"]
    assert cpu == gpu > 5
    assert agreement["bridges_exists"] == 0.0
    assert agreement["position"] < 1e-13 and agreement["wall_position"] < 1e-13
    for quantity in QUANTITIES:
        assert agreement[quantity] < 1e-10, quantity


def test_the_wall_bridges_matter(measured):
    """What the comparison would miss if the device left the wall bridges out."""
    without = measured["agreement"]["without"]
    assert without["wall_force"] > 1e-3 and without["position"] > 1e-9


def test_wall_bridges_while_radii_grow_are_refused_by_name(measured):
    assert "does not run sphere-wall bridges" in (measured["refusal"] or "")
    assert "RadiusGrowth" in measured["refusal"]


def test_wall_bridges_listed_before_the_wall_forces_are_refused_by_name(measured):
    assert "listed after the wall forces only" in (measured["order"] or "")
