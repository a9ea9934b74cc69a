"""A loading path's history recorded from a GPU run without bringing the state back: every
column a record needs (pendular.procedures.columns.history_columns, with the bridges' for a wet
scene) and the crushed-sample guard read the device's homogenisation
(pendular.homogenize.on_the_fly.homogenized, pendular.gpu.homogenize), so that a record step
fetches the walls (a periodic cell's faces, rate, stress and stiffness) alone and the whole
state comes back once, as the run returns. An equilibrium's test (static) reads the device's
unbalanced force the same way.

The 64-sphere walled scene of tests/gpu/simulated.py and the periodic one of
tests/gpu/periodic_checks.py (pairs through the faces; the homogenisation over the branch
vectors through them, the cell's volume, no walls), dry and wet at 30 kPa, 30 steps recorded
every 10, and the scene of tests/gpu/persist_checks.py (27 spheres, persisting bridges, walls
pulled apart for PERSIST_STEPS, bridges across gaps at its later records), under Numba's CUDA
simulator, every check in one process of its own (tests/gpu/records_checks.py). The columns
are the CPU's history's to round-off (docs/gpu.md).
"""

import pytest

from conftest import requires
from records_checks import CHECKS, PERSIST_STEPS, RECORD_PERIOD, STEPS, WALLED
from simulator import simulated

pytestmark = requires("numba_cuda")


@pytest.fixture(scope="module")
def measured():
    """Every check's measurements, in one process."""
    return simulated("records_checks.py", *CHECKS)


@pytest.fixture(scope="module")
def recorded(request, measured):
    return request.param.endswith("wet"), measured[request.param]


@pytest.mark.parametrize("recorded", CHECKS, indirect=True)
def test_record_steps_copy_the_walls_alone(recorded):
    _, measured = recorded
    if measured["steps"] == PERSIST_STEPS:      # the persisting bridges: some across gaps
        assert measured["across_gaps"] > 0
    assert measured["records"] == measured["steps"] // RECORD_PERIOD
    *during, last = measured["copies"]
    assert last == "all"                        # once, as the run returns
    assert during and set(during) == {"walls"}


@pytest.mark.parametrize("recorded", CHECKS, indirect=True)
def test_the_recorded_columns_are_the_cpus(recorded):
    wet, measured = recorded
    assert {"sigma_contact", "fabric", "porosity", "coordination"} <= set(measured["columns"])
    if wet:
        assert {"chi", "psi", "saturation", "bridges"} <= set(measured["columns"])
    for name, difference in measured["difference"].items():
        assert difference < 1e-12, name


@pytest.mark.parametrize("recorded", ["dry"], indirect=True)
def test_held_state_is_read_through_an_explicit_fetch(recorded):
    """Unfetched, the state of a device run is refused by name; fetch("walls") copies the walls
    once and leaves the particles on the device; fetch() brings the rest and ends the hold."""
    _, measured = recorded
    fetch = measured["fetch"]
    assert "sim.fetch('particles')" in fetch["message"]
    assert fetch["copies"] == ["walls", "all"]
    assert fetch["held_after_walls"] and fetch["released"]


@pytest.mark.parametrize("recorded", WALLED, indirect=True)
def test_an_equilibrium_test_reads_the_walls_alone_and_stops_where_the_cpu_does(recorded):
    _, measured = recorded
    passed, held = measured["static"]["stopped"]
    assert passed == [RECORD_PERIOD, RECORD_PERIOD] and held == [STEPS, STEPS]
    copies = measured["static"]["copies"]
    assert copies.count("all") == 2 and set(copies) == {"walls", "all"}   # once a run
