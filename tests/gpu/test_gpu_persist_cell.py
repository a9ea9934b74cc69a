"""Bridges across gaps in a periodic cell on the GPU against the CPU under Numba's CUDA
simulator: the 64 spheres of periodic_checks.py in their periodic cell, pulled apart along z
(a constant strain rate of negative rate) under the cell's stress servo on x and y, wet with
suction-controlled bridges that persist across gaps (SuctionBridges ``persist``, 30 kPa) or
volume-controlled ones (VolumeBridges, formed at contact at 30 kPa from a reservoir). Bridges
form at contact, stretch across the gaps that open (through the faces too) and rupture at
their rupture distance; their forces enter the cell's stress through the faces (the CPU's
gather_pair_forces_virial). The simulator runs in a process of its own, every check in one
(tests/gpu/persist_cell_checks.py), so that no other test meets it.

Checked too: persisting bridges in shear_checks.py's simple shear (a sheared cell), and
the periodic tension's phases (pendular.procedures.tension: the wetting to a water content,
volume-controlled bridges at contacts and across gaps, and the pull).

At the end of each stage the same pairs hold bridges in the same states as on the CPU and
the cell's faces are equal; the tests hold 1e-12 (positions, faces), 1e-10 (the rest), and the
tension's columns 1e-11 (the unbalanced force 1e-10). Without the bridges' face terms the
stress would differ by far more (docs/gpu.md).
"""

import pytest

from conftest import requires
from simulator import simulated

pytestmark = requires("numba_cuda")

#: The checks, each a test below.
CHECKS = ("suction", "volume", "sheared", "tension")


@pytest.fixture(scope="module")
def measured():
    """Every check's measurements, in one process."""
    return simulated("persist_cell_checks.py", *CHECKS)


def assert_agrees(measured):
    assert measured["rebuilds"][0] == measured["rebuilds"][1] > 1
    formed, stretched, ruptured = measured["events"]
    assert formed > 5 and stretched > 5 and ruptured > 2     # the physics is exercised
    for stage in measured["stages"]:
        assert stage["same_bridges"], stage
        assert stage["through_faces"] > 0
        assert stage["reach"][0] == stage["reach"][1] > 0.0
        assert stage["position"] < 1e-12 and stage["walls"] < 1e-12
        assert stage["stress"] < 1e-10 and stage["velocity"] < 1e-10
        for name in ("volume", "bridge_force", "filling", "pair_force"):
            assert stage[name] < 1e-10, name


def test_persisting_bridges_and_a_suction_path_in_a_periodic_cell_agree_with_the_cpu(measured):
    measured = measured["suction"]
    assert_agrees(measured)
    assert measured["stages"][0]["strain"] < 0.0                 # pulled apart
    assert measured["stages"][-1]["reach"][0] > measured["stages"][0]["reach"][0]


def test_volume_bridges_in_a_periodic_cell_agree_with_the_cpu(measured):
    measured = measured["volume"]
    assert_agrees(measured)
    assert measured["stages"][0]["strain"] < 0.0


def test_persisting_bridges_in_a_sheared_cell_agree_with_the_cpu(measured):
    measured = measured["sheared"]
    assert_agrees(measured)
    assert measured["stages"][0]["gamma"] > 0.4


def test_the_periodic_tension_wets_and_pulls_as_on_the_cpu(measured):
    """pendular.procedures.tension in a periodic cell (``pendular tension --periodic``'s
    phases): the wetting to a water content and the pull record the CPU's history."""
    measured = measured["tension"]
    assert measured["reports"][0] == measured["reports"][1]
    assert measured["reports"][0][2] > 50                       # bridges formed
    assert measured["position"] < 1e-12
    assert measured["rows"][0] == measured["rows"][1] > 100
    for name, difference in measured["differences"].items():
        assert difference <= (1e-10 if name == "unbalanced_force" else 1e-11), name
