"""The YADE cross-check with pendular's shear on the GPU (``CrossCheck(config).run(out,
device="gpu")``, ``pendular crosscheck --device gpu``), under Numba's CUDA simulator in a
process of its own (tests/gpu/crosscheck_checks.py).

YADE is replaced by pendular on the CPU (as tests/e2e/test_yade_crosscheck.py does without
YADE): a 60-sphere wet packing (30 kPa) settled and exported by a CPU cross-check is sheared
again from that packing on the device, to 5e-4 axial strain (about 140 steps). The device's
pendular history equals the CPU's to round-off and the comparison with the stand-in is zero
to round-off.
"""

import pytest

from conftest import requires
from simulator import simulated

pytestmark = requires("numba_cuda")


@pytest.fixture(scope="module")
def measured():
    return simulated("crosscheck_checks.py", "shear")["shear"]


def test_the_crosschecks_pendular_shear_runs_on_the_gpu_as_on_the_cpu(measured):
    assert measured["device"] == ["cpu", "gpu"]
    assert measured["rows"][0] == measured["rows"][1] >= 5
    for name, difference in measured["differences"].items():
        assert difference < (1e-8 if name == "unbalanced_force" else 1e-11), name
    cpu, gpu, stand_in = measured["peak_q"]
    assert gpu == pytest.approx(cpu, rel=1e-11) and gpu == pytest.approx(stand_in, rel=1e-11)

