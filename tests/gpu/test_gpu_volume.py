"""Volume-controlled bridges (VolumeBridges) on the GPU against the CPU under Numba's CUDA
simulator (the scene of volume_checks.py, whose checks run in one process of their own so that
no other test meets the simulator): the same pairs hold bridges in the same states as on the
CPU, the bridges' volumes, the films and the liquid lost equal the CPU's (the same sums in the
same order); the tests hold 1e-12 (positions) and 1e-10 (the rest).

The command (``pendular triaxial --sample S --water-content 5 --device gpu``) records the CPU's
rows, bridge and contact counts; its other columns differ within the sensitivity of the
wetting to a water content, not by an error of the device: on the CPU alone one coordinate of
the sample moved by one ulp changes them by as much (docs/gpu.md).
"""

import numpy as np
import pytest

from conftest import requires
from simulator import (WALLED_SAMPLE, assert_same_records, command_runs_fixture, histories_on_both,
                       on_the_gpu, simulated)

pytestmark = requires("numba_cuda")


#: The sample that the command test loads, and the folder of its runs.
command_runs = command_runs_fixture(WALLED_SAMPLE)


@pytest.fixture(scope="module")
def measured(command_runs):
    """The checks' measurements, in one process, after the command test's GPU run there."""
    sample, folder = command_runs
    return simulated("volume_checks.py", "shared", "lost",
                     commands=[on_the_gpu("triaxial", sample, TRIAXIAL, folder)])


def assert_agrees(stage):
    assert stage["same_bridges"], stage
    assert stage["bridges"] > 20
    assert stage["position"] < 1e-12
    for name in ("velocity", "stress", "volume", "bridge_force", "suction", "pair_force",
                 "film", "lost"):
        assert stage[name] < 1e-10, name


@pytest.mark.parametrize("liquid", ["shared", "lost"])
def test_volume_controlled_bridges_agree_with_the_cpu(liquid, measured):
    result = measured[liquid]
    assert_agrees(result["open"])
    closed = result["closed"]
    assert_agrees(closed)
    assert closed["across_gaps"] > 0 and result["formed_from_films"] > 0
    if liquid == "shared":
        assert closed["liquid"][2] == 0.0
    else:
        assert closed["liquid"][2] > 0.0              # bridges ruptured and lost their liquid
    assert max(closed["balance_error"]) < 1e-12      # bridges + films + lost: the liquid closed


#: The wet triaxial of test_gpu_command.py at a water content (its sample added).
TRIAXIAL = ["--particles", "60", "--water-content", "5", "--max-strain", "0.002",
            "--inertial-number", "1e-3", "--quiet"]


def test_the_triaxial_command_at_a_water_content_records_the_cpu_history(command_runs, measured):
    """``pendular triaxial --sample S --water-content 5 --device gpu`` (S prepared on the CPU)
    records the CPU's rows, bridge and contact counts, and columns within the sensitivity of
    that wetting (module docstring)."""
    sample, folder = command_runs
    cpu, gpu = histories_on_both("triaxial", sample, TRIAXIAL, folder)
    assert_same_records(cpu, gpu, 100, ("bridges", "coordination"))
    for name, values in cpu.items():
        if values.dtype == object:
            continue
        bound = 2e-2 if name == "unbalanced_force" else 2e-4
        assert np.max(np.abs(gpu[name] - values)) <= bound * np.max(np.abs(values)), name
