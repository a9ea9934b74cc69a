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
simulator, every check in one process of its own (``NUMBA_ENABLE_CUDASIM=1 python
tests/gpu/test_gpu_records.py CHECK ...``, simulator.run_checks). The columns are the CPU's
history's to round-off (docs/gpu.md).
"""

import os

import numpy as np
import pytest

from conftest import requires
from simulator import counted_copies, relative, run_checks, simulated

pytestmark = requires("numba_cuda")

STEPS = 30
RECORD_PERIOD = 10
#: Unbalanced forces of the equilibrium's test: the jittered, moving walled scene passes the
#: first at its first check (0.68 at step 10), the second not within the run (0.68-1.6).
UNBALANCED = (1.0, 0.5)
#: The scenes: inside walls and in a periodic cell, dry and wet.
WALLED = ("dry", "wet")
#: The scene of persist_checks.py (persisting bridges, walls pulled apart), run for
#: PERSIST_STEPS: bridges across gaps at its later records.
PERSIST_STEPS = 80
CHECKS = (*WALLED, "periodic-dry", "periodic-wet", "persist-wet")


def measure(check):
    """The copies back in order, the records, {column: largest relative difference from the
    CPU} of ``check`` (CHECKS); inside walls the equilibrium's test too."""
    from periodic_checks import scene as periodic_scene
    from persist_checks import scene as persist_scene
    from simulated import scene as walled_scene

    from pendular.capillary.bridge_state import ACROSS_GAP, BridgeState
    from pendular.capillary.bridges import CapillaryBridges
    from pendular.dem.record import HistoryRecorder
    from pendular.procedures.guards import SampleGuard
    from pendular.procedures.loading import AxisStrain
    from pendular.procedures.columns import history_columns
    from pendular.procedures.preparation import static

    wet = check.endswith("wet")
    periodic = check.startswith("periodic")
    persist = check.startswith("persist")
    steps = PERSIST_STEPS if persist else STEPS

    def build(device):
        if persist:
            sim = persist_scene()[0]
        else:
            sim = periodic_scene(wet) if periodic else walled_scene(wet=wet, side=4)
        bridges = sim.operation(CapillaryBridges) if wet else None
        columns = history_columns(sim, AxisStrain(2, sim.walls.lengths()[2]),
                                  sim.walls.volume(), bridges)
        sim.writers = [HistoryRecorder(RECORD_PERIOD, columns, reads=("walls",)),
                       SampleGuard(RECORD_PERIOD)]
        sim.device = device
        return sim

    cpu, gpu = build("cpu"), build("gpu")
    cpu.run(steps)
    with counted_copies() as recorded:
        gpu.run(steps)
    a, b = cpu.writers[0].arrays(), gpu.writers[0].arrays()
    out = {"copies": recorded, "records": len(a["step"]), "steps": steps, "columns": sorted(a),
           "difference": {name: relative(a[name], b[name]) for name in a},
           "across_gaps": (int(np.count_nonzero(BridgeState.of(gpu.contacts).state
                                                == ACROSS_GAP)) if wet else 0)}
    if check == "dry":
        out["fetch"] = fetched(build("gpu"))
    if periodic or persist:
        return out
    # an equilibrium's test (pendular.procedures.preparation.static, its unbalanced force
    # alone: the servos' tolerance wide open) on the device stops the run at the CPU's check,
    # reading the walls alone until then
    with counted_copies() as copies:
        stopped = [[build(device).run(STEPS, until=static(unbalanced, tolerance=1e9),
                                      check_every=RECORD_PERIOD) for device in ("cpu", "gpu")]
                   for unbalanced in UNBALANCED]
    return {**out, "static": {"stopped": stopped, "copies": copies}}


def fetched(sim):
    """What reading the state of ``sim`` held by a GpuSimulation run directly (one step)
    gives: the StaleState's message unfetched, then the copies of fetch("walls") (twice) and
    fetch(), and whether the particles were still held between them."""
    from pendular.dem.simulation import StaleState
    from pendular.gpu import GpuSimulation

    gpu = GpuSimulation(sim)
    gpu.run(1)
    try:
        sim.particles
        message = None
    except StaleState as error:
        message = str(error)
    with counted_copies() as copies:
        sim.fetch("walls").fetch("walls")
        held = "particles" not in sim.__dict__
        sim.fetch()
    return {"message": message, "copies": copies, "held_after_walls": held,
            "released": sim.holder is None}


@pytest.fixture(scope="module")
def measured():
    """Every check's measurements, in one process."""
    return simulated(os.path.basename(__file__), *CHECKS)


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


if __name__ == "__main__":
    run_checks({check: lambda check=check: measure(check) for check in CHECKS})
