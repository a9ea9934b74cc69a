"""Suction-controlled bridges that persist across gaps and a suction path on the GPU against
the CPU under Numba's CUDA simulator (the scene of persist_checks.py, whose check runs in a
process of its own so that no other test meets the simulator), then the triaxial command with
persisting bridges on both devices. The differences are the CPU's contracted multiply-adds
against the simulator's plain ones, grown over the run (a bridge across a gap is looked up at
its gap): the tests hold them to 1e-12 (positions, walls), 1e-10 (the rest). Bridges across
gaps make the command's sample sensitive: on the CPU alone, one coordinate moved by one ulp
changes its history by more than the bounds the command's test holds (docs/gpu.md).
"""

import numpy as np
import pytest

from conftest import requires
from simulator import (WALLED_SAMPLE, assert_same_records, command_runs_fixture, histories_on_both,
                       on_the_gpu, simulated)

#: The sample that the command test loads, and the folder of its runs.
command_runs = command_runs_fixture(WALLED_SAMPLE)


@pytest.fixture(scope="module")
def measured(command_runs):
    """The checks' measurements, in one process, after the command test's GPU run there."""
    sample, folder = command_runs
    return simulated("persist_checks.py", "path",
                     commands=[on_the_gpu("triaxial", sample, TRIAXIAL, folder)])["path"]


@requires("numba_cuda")
def test_persisting_bridges_and_a_suction_path_agree_with_the_cpu(measured):
    formed, stretched, ruptured = measured["events"]
    assert formed > 5 and stretched > 5 and ruptured > 2      # the physics is exercised
    for stage in measured["stages"]:
        assert stage["same_bridges"], stage
        assert stage["reach"][0] == stage["reach"][1] > 0.0
        assert stage["position"] < 1e-12 and stage["walls"] < 1e-12
        assert stage["stress"] < 1e-10
        assert stage["velocity"] < 1e-10
        for name in ("volume", "bridge_force", "filling", "pair_force"):
            assert stage[name] < 1e-10, name
    assert measured["stages"][-1]["reach"][0] > measured["stages"][0]["reach"][0]


@requires("numba_cuda")
def test_a_farther_reach_needs_a_new_device_run(measured):
    assert "reach" in measured["refused"] and "new GpuSimulation" in measured["refused"]


#: The wet triaxial of test_gpu_command.py with persisting bridges (its sample added).
TRIAXIAL = ["--particles", "60", "--suction", "30000", "--persist-bridges", "--max-strain",
            "0.002", "--inertial-number", "1e-3", "--quiet"]


@requires("numba_cuda")
def test_the_triaxial_command_with_persisting_bridges_records_the_cpu_history(command_runs,
                                                                             measured):
    """``pendular triaxial --sample S --suction 30000 --persist-bridges --device gpu`` (S
    prepared on the CPU; the wetting on the CPU, the loading on the device) records the CPU's
    history: the same rows, bridge and contact counts, the other columns to round-off grown
    over the steps (module docstring)."""
    sample, folder = command_runs
    cpu, gpu = histories_on_both("triaxial", sample, TRIAXIAL, folder)
    assert_same_records(cpu, gpu, 100, ("bridges", "coordination"))
    worst = {}
    for name, values in cpu.items():
        if values.dtype == object:
            continue
        scale = np.max(np.abs(values))
        worst[name] = float(np.max(np.abs(gpu[name] - values)) / scale) if scale else 0.0
    for name, difference in worst.items():
        assert difference <= (2e-6 if name == "unbalanced_force" else 2e-8), (name, difference)


def test_the_swcc_takes_the_device(capsys):
    """``pendular swcc --device gpu`` runs the path on the device (its stages: the tests
    above; in a periodic cell, tests/gpu/test_gpu_persist_cell.py)."""
    from pendular.cli import run_command

    try:
        run_command("swcc", ["--help"])
    except SystemExit:
        pass
    assert "--device {cpu,gpu}" in capsys.readouterr().out
