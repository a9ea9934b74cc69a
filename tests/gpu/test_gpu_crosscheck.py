"""The YADE cross-check with pendular's shear on the GPU (``run_crosscheck(device="gpu")``,
``pendular crosscheck --device gpu``), under Numba's CUDA simulator in a process of its own
(this file as a script prints one JSON object of measurements).

YADE is replaced by pendular on the CPU (as tests/e2e/test_yade_crosscheck.py does without
YADE): a 60-sphere wet packing (30 kPa) settled and exported by a CPU cross-check is sheared
again from that packing on the device, to 5e-4 axial strain (about 140 steps). The device's
pendular history equals the CPU's to round-off and the comparison with the stand-in is zero
to round-off.
"""

import json
import os
import tempfile

import numpy as np
import pytest

from conftest import requires
from simulator import simulated

#: Axial strain of the shear (about 140 steps at the cross-check's inertial number).
MAX_STRAIN = 5e-4


def measure(folder):
    """The CPU cross-check and the device's from its packing, both against pendular on the
    CPU standing in for YADE: {device, differences of the histories, the comparison's}."""
    import h5py

    from pendular.studies import crosscheck

    config = crosscheck.crosscheck_config(particles=60, suction=30000.0, max_strain=MAX_STRAIN,
                                          records=5, mimic_yade=True)

    from support.yade_stand_in import pendular_as_yade      # tests/ is on the path

    stand_in = pendular_as_yade(config)

    crosscheck.find_yade = lambda: "yade"
    crosscheck.yade_capillary_files = lambda contact_angle: folder
    crosscheck.run_yade_triaxial = stand_in
    cpu = crosscheck.run_crosscheck(config, os.path.join(folder, "cpu"), progress=False)
    packing = os.path.join(folder, "cpu", "packing.txt")
    gpu = crosscheck.run_crosscheck(config, os.path.join(folder, "gpu"), packing=packing,
                                    progress=False, device="gpu")

    def history(run):
        path = os.path.join(folder, run, "pendular_history.h5")
        with h5py.File(path) as handle:
            return {name: data[()] for name, data in handle["history"].items()
                    if data.dtype != object}

    a, b = history("cpu"), history("gpu")
    differences = {}
    for name in a:
        scale = float(np.max(np.abs(a[name])))
        difference = float(np.max(np.abs(a[name] - b[name])))
        differences[name] = difference / scale if scale > 0 else difference
    return {"device": [cpu["device"], gpu["device"]], "rows": [len(a["step"]), len(b["step"])],
            "differences": differences,
            "peak_q": [cpu["pendular"]["peak_q"], gpu["pendular"]["peak_q"],
                       gpu["yade"]["peak_q"]]}


pytestmark = requires("numba_cuda")


@pytest.fixture(scope="module")
def measured():
    return simulated(os.path.basename(__file__))


def test_the_crosschecks_pendular_shear_runs_on_the_gpu_as_on_the_cpu(measured):
    assert measured["device"] == ["cpu", "gpu"]
    assert measured["rows"][0] == measured["rows"][1] >= 5
    for name, difference in measured["differences"].items():
        assert difference < (1e-8 if name == "unbalanced_force" else 1e-11), name
    cpu, gpu, stand_in = measured["peak_q"]
    assert gpu == pytest.approx(cpu, rel=1e-11) and gpu == pytest.approx(stand_in, rel=1e-11)


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as folder:
        print(json.dumps(measure(folder)))
