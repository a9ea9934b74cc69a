"""A loading path's history recorded from a GPU run in a periodic cell without bringing the
state back: every column a record needs (pendular.procedures.loading.history_columns, with the
bridges' for a wet scene) and the crushed-sample guard read the device's homogenisation in the
cell (Simulation.homogenized, pendular.gpu.homogenize: branch vectors through the faces, the
cell's volume, no walls), so that a record step copies the cell alone (its faces, rate, stress
and stiffness) and the whole state comes back once, as the run returns. The columns equal the
CPU's history to round-off (measured, largest relative differences: 9.2e-16 dry and wet, in
sigma_contact, but for B, a deviator whose terms cancel, 3.1e-14, and the anisotropies, from
eigenvalues, 2.5e-14).

The 64-sphere periodic scene of tests/gpu/test_gpu_periodic.py (pairs through the faces, the
cell's servo on x and y, a strain rate on z), dry and wet at 30 kPa, 30 steps recorded every
10, under Numba's CUDA simulator in a process of its own
(``NUMBA_ENABLE_CUDASIM=1 python tests/gpu/test_gpu_periodic_records.py dry|wet``).
"""

import json
import os
import sys

import pytest

from simulator import counted_copies, relative, simulated

STEPS = 30
RECORD_PERIOD = 10


def measure(wet):
    """(copies back in order, records, {column: largest relative difference from the CPU})."""
    from test_gpu_periodic import scene

    from pendular.capillary.bridges import CapillaryBridges
    from pendular.dem.record import HistoryRecorder
    from pendular.procedures.guards import SampleGuard
    from pendular.procedures.loading import AxisStrain, history_columns

    def build(device):
        sim = scene(wet)
        bridges = sim.operation(CapillaryBridges) if wet else None
        columns = history_columns(sim, AxisStrain(2, sim.walls.lengths()[2]),
                                  sim.walls.volume(), bridges)
        sim.writers = [HistoryRecorder(RECORD_PERIOD, columns), SampleGuard(RECORD_PERIOD)]
        sim.device = device
        return sim

    cpu, gpu = build("cpu"), build("gpu")
    cpu.run(STEPS)
    with counted_copies() as recorded:
        gpu.run(STEPS)
    a, b = cpu.writers[0].arrays(), gpu.writers[0].arrays()
    return {"copies": recorded, "records": len(a["step"]), "columns": sorted(a),
            "difference": {name: relative(a[name], b[name]) for name in a}}


@pytest.fixture(scope="module", params=["dry", "wet"])
def recorded(request):
    pytest.importorskip("numba_cuda", reason="numba-cuda is not installed "
                        "(pip install -e '.[gpu]')")
    return request.param == "wet", simulated(os.path.basename(__file__), request.param)


def test_periodic_record_steps_copy_the_cell_alone(recorded):
    _, measured = recorded
    assert measured["records"] == STEPS // RECORD_PERIOD
    *during, last = measured["copies"]
    assert last == "all"                        # once, as the run returns
    assert during and set(during) == {"walls"}


def test_the_recorded_columns_are_the_cpus_in_a_cell(recorded):
    wet, measured = recorded
    assert {"sigma_contact", "fabric", "porosity", "coordination"} <= set(measured["columns"])
    if wet:
        assert {"chi", "psi", "psi_interface", "saturation", "bridges"} <= set(
            measured["columns"])
    for name, difference in measured["difference"].items():
        assert difference < 1e-12, name


if __name__ == "__main__":
    print(json.dumps(measure(sys.argv[1] == "wet")))
