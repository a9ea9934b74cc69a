"""The GPU side of tests/gpu/test_gpu_records.py, run under Numba's CUDA simulator in a
process of its own (``NUMBA_ENABLE_CUDASIM=1 python tests/gpu/records_checks.py CHECK ...``,
simulator.run_checks): a loading path's history recorded on the CPU and on the device, and
the copies back the device's records make."""

import numpy as np

from simulator import counted_copies, relative, run_checks

STEPS = 30
RECORD_PERIOD = 10
#: Unbalanced forces of the equilibrium's test: the jittered, moving walled scene passes the
#: first at its first check, the second not within the run.
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
    from pendular.procedures.columns import history_columns
    from pendular.procedures.guards import SampleGuard
    from pendular.procedures.loading import AxisStrain
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


if __name__ == "__main__":
    run_checks({check: lambda check=check: measure(check) for check in CHECKS})
