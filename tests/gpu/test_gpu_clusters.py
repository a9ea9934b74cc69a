"""Liquid clusters (pendular.capillary.liquid_clusters) on the GPU against the CPU under Numba's
CUDA simulator: the scene of clusters_checks.py and the command (``pendular triaxial --sample S
--suction 20000 --liquid clusters --device gpu``), run in one process of their own so that no
other test meets the simulator. The pore units, their filling and their forces are the host's
model; the device adds the clusters' forces and takes off the bridges' shares each step, from
what the host uploads at each step of the model (pendular.gpu.clusters).

The command records the CPU's rows and its bridge, contact and cluster counts; its other
columns differ within the sensitivity of the wetting (on the CPU alone one coordinate of the
sample moved by one ulp changes them by as much: docs/gpu.md).
"""

import numpy as np
import pytest

from conftest import requires
from simulator import (WALLED_SAMPLE, assert_same_records, command_runs_fixture, histories_on_both,
                       on_the_gpu, simulated)

pytestmark = requires("numba_cuda")

#: The smallest command with filled units: the 60-sphere sample wetted at 20 kPa.
TRIAXIAL = ["--particles", "60", "--suction", "20000", "--liquid", "clusters", "--max-strain",
            "0.002", "--inertial-number", "1e-3", "--quiet"]


#: The sample that the command test loads, and the folder of its runs.
command_runs = command_runs_fixture(WALLED_SAMPLE)


@pytest.fixture(scope="module")
def measured(command_runs):
    """The checks' measurements, in one process, after the command test's GPU run there."""
    sample, folder = command_runs
    return simulated("clusters_checks.py", "clusters", "wetter", "refusal",
                     commands=[on_the_gpu("triaxial", sample, TRIAXIAL, folder)])


def test_the_clusters_forces_on_the_gpu_agree_with_the_cpu(measured):
    """The grains' forces after a run whose writer stepped the model between the device's
    steps (forces following the grains, the model at the packing as it stands: new forces
    uploaded), and after a drier suction imposed between two runs: the CPU's, to round-off."""
    result = measured["clusters"]
    cpu_filled, gpu_filled = result["filled"]
    assert cpu_filled == gpu_filled
    first, settled, drier, last = cpu_filled
    assert first > settled > drier > 0 and last > 0          # the filled units changed
    assert result["versions"][0] == result["versions"][1] > 5
    assert result["updates"][0] == result["updates"][1] > 0
    for run in ("first", "second"):
        assert result[run]["position"] < 1e-13, run
        assert result[run]["force"] < 1e-11 and result[run]["cluster_force"] < 1e-11, run
    # what the comparison would miss without them: far above its round-off
    assert min(result["clusters_force"]) > 1e-6 and min(result["absorbed_force"]) > 1e-7


def test_a_lower_suction_during_a_run_uploads_the_state_again(measured):
    """The model stepped at a lower suction halfway through a run (the bridges' reach grows
    beyond what the device's list was sized for): the state goes up again from the host and
    the run goes on as the CPU's."""
    result = measured["wetter"]
    assert result["replaced"] and result["reach"][1] > result["reach"][0]
    assert result["filled"] > 0
    assert result["agreement"]["position"] < 1e-13
    assert result["agreement"]["force"] < 1e-11


def test_clusters_the_gpu_does_not_run_are_refused_by_name(measured):
    before, periodic = measured["refusal"]
    assert "LiquidClusters listed after their bridges only" in before
    assert "inside walls only, not in a periodic cell" in periodic


def test_the_triaxial_command_with_clusters_records_the_cpu_history(command_runs, measured):
    """``pendular triaxial --sample S --suction 20000 --liquid clusters --device gpu`` (S
    prepared on the CPU) records the CPU's rows, bridge, contact and cluster counts, and
    columns within the sensitivity of that wetting (module docstring)."""
    sample, folder = command_runs
    cpu, gpu = histories_on_both("triaxial", sample, TRIAXIAL, folder)
    assert_same_records(cpu, gpu, 100, ("bridges", "coordination", "clusters"))
    assert cpu["clusters"].min() > 0 and cpu["liquid_in_clusters"].min() > 0.1
    for name, values in cpu.items():
        if values.dtype == object:
            continue
        bound = 2e-2 if name == "unbalanced_force" else 2e-4
        assert np.max(np.abs(gpu[name] - values)) <= bound * np.max(np.abs(values)), name
