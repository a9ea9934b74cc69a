"""The GPU side of tests/gpu/test_gpu_crosscheck.py, run under Numba's CUDA simulator in a
process of its own (``NUMBA_ENABLE_CUDASIM=1 python tests/gpu/crosscheck_checks.py shear``,
simulator.run_checks): the cross-check's shear on the CPU and on the device, pendular on the
CPU standing in for YADE."""

import os
import tempfile

import numpy as np

from simulator import run_checks

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
    cpu = crosscheck.CrossCheck(config).run(os.path.join(folder, "cpu"), progress=False)
    packing = os.path.join(folder, "cpu", "packing.txt")
    gpu = crosscheck.CrossCheck(config, packing=packing).run(os.path.join(folder, "gpu"),
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



def shear():
    """measure() in a temporary folder."""
    with tempfile.TemporaryDirectory() as folder:
        return measure(folder)


if __name__ == "__main__":
    run_checks({"shear": shear})
