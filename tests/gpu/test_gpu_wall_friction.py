"""Walls with tangential springs (pendular.gpu.wall_friction) on the GPU against the CPU under
Numba's CUDA simulator: the scenes of wall_friction_checks.py (frictional linear walls under
gravity, Hertz–Mindlin walls of their own material, with bridges at contact, with rolling and
twisting resistance on the walls: pendular.gpu.wall_rolling), whose checks
run in one process of their own so that no other test meets the simulator. The simulator
does not contract multiply-adds as the CPU's hot kernels do, hence round-off bounds."""

import pytest

from conftest import requires
from simulator import simulated

pytestmark = requires("numba_cuda")

QUANTITIES = ("velocity", "angular_velocity", "force", "torque", "springs", "wall_force",
              "wall_moment", "wall_stiffness", "wall_shear")


@pytest.fixture(scope="module")
def measured():
    return simulated("wall_friction_checks.py", "linear", "hertz", "wet", "rolling", "refusal")


@pytest.mark.parametrize("name", ["linear", "hertz", "wet", "rolling"])
def test_the_walls_springs_on_the_gpu_agree_with_the_cpu_to_round_off(measured, name):
    for case in ("agreement", "handed_over"):
        agreement = measured[name][case]
        assert agreement["touching_cpu"] == agreement["touching_gpu"] == \
            agreement["touching_both"] > 10, case
        cpu, gpu = agreement["springs_on_walls"]
        assert cpu == gpu > 5, case
        assert agreement["position"] < 1e-13 and agreement["wall_position"] < 1e-13, case
        for quantity in QUANTITIES:
            assert agreement[quantity] < 1e-10, (case, quantity)


@pytest.mark.parametrize("name", ["linear", "hertz"])
def test_the_wall_friction_matters(measured, name):
    """What the comparison would miss if the device left the walls' springs out."""
    without = measured[name]["without_friction"]
    assert without["angular_velocity"] > 1e-3 and without["position"] > 1e-9


def test_the_walls_rolling_springs_on_the_gpu_agree_with_the_cpu_and_matter(measured):
    """The walls' rolling and twisting springs (pendular.gpu.wall_rolling) come back as the
    CPU's, also when handed over halfway; without them the run differs."""
    for case in ("agreement", "handed_over"):
        agreement = measured["rolling"][case]
        cpu, gpu = agreement["rolling_on_walls"]
        assert cpu == gpu > 5, case
        assert agreement["wall_rolling_moment"] < 1e-10, case
        assert agreement["wall_twisting_moment"] < 1e-10, case
    without = measured["rolling"]["without_rolling"]
    assert without["angular_velocity"] > 1e-3 and without["position"] > 1e-9


def test_the_walls_material_matters(measured):
    """What the comparison would miss if the device took the grains' rigid walls instead of
    the walls' own material."""
    rigid = measured["hertz"]["rigid_wall"]
    assert rigid["wall_force"] > 1e-3 and rigid["velocity"] > 1e-6


def test_two_wall_operations_are_refused(measured):
    assert "at most one walls operation" in (measured["refusal"] or "")

