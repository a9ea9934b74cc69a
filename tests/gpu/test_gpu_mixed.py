"""Mixed stress conditions (pendular.dem.mixed_stress.MixedStress) on the GPU against the CPU,
under Numba's CUDA simulator in a process of its own (this file run as a script, as
tests/gpu/simulated.py is): the 27-sphere scene of simulated.py sheared at a constant mean
stress p (one servo for x and y) and at a constant b (sigma_3 given on x, y set), the servos'
targets set on the device each step from the walls' stresses. A condition that needs walls to
pull raises the CPU's StageFailed, at the same step, with the same message. The differences
from the CPU are round-off, as in tests/gpu/test_gpu_dem.py.
"""

import json
import os

import pytest

from conftest import requires
from simulator import simulated

pytestmark = requires("numba_cuda")

STEPS = 300
#: The mean stress held [Pa] (the scene's stresses are 3e4-1e5 Pa), and that of the failing
#: run: 3 p falls below the axial stress within its first 25 steps.
MEAN_STRESS = 5e4
FAILING_MEAN_STRESS = 2.5e4


@pytest.fixture(scope="module")
def mixed():
    return simulated(os.path.basename(__file__))


@pytest.mark.parametrize("condition", ["constant_p", "constant_b"])
def test_a_mixed_condition_on_the_gpu_agrees_with_the_cpu_to_round_off(mixed, condition):
    run = mixed[condition]
    agreement, history = run["agreement"], run["history"]
    assert agreement["touching_cpu"] == agreement["touching_gpu"] == agreement["touching_both"]
    assert agreement["position"] < 1e-13 and agreement["wall_position"] < 1e-13
    assert agreement["wall_stress"] < 1e-12
    for name in ("velocity", "force", "springs"):
        assert agreement[name] < 1e-10, name
    assert history["records"] == [STEPS // 50] * 2
    assert history["targets"] < 1e-12
    # the condition moved the targets away from the servos' first ones
    assert run["target_change"] > 0.05


def test_the_targets_set_on_the_device_come_back_to_the_servos(mixed):
    """After the run the host's servos hold the device's targets (a checkpoint saves them)."""
    for condition in ("constant_p", "constant_b"):
        targets = mixed[condition]["final_targets"]
        assert targets["gpu"] == pytest.approx(targets["cpu"], rel=1e-12)


def test_runs_in_a_row_copy_nothing_and_equal_one_run(mixed):
    """A GpuSimulation driven directly, two runs in a row: no copy back between them (the
    second run's set-up reads the scene, not its state), and the state after them equals one
    run of the same steps bit for bit; the next run's set-up keeps the targets the device set
    (the host's are stale while the device holds the state)."""
    assert mixed["in_a_row"]["copies"] == ["all"]
    assert mixed["in_a_row"]["targets_kept"]
    assert mixed["in_a_row"]["equals_one_run"]


def test_a_condition_that_needs_walls_to_pull_fails_on_the_gpu_as_on_the_cpu(mixed):
    """Simulation(device="gpu").run: StageFailed with the CPU's message (its step included),
    the history ends where the CPU's does, and the host holds the state afterwards."""
    cpu, gpu = mixed["failing"]["cpu"], mixed["failing"]["gpu"]
    assert cpu["error"] == "StageFailed" and gpu["error"] == "StageFailed"
    assert "walls cannot pull" in cpu["message"]
    assert gpu["message"] == cpu["message"]
    assert 2 < cpu["failed_at"] < STEPS
    assert gpu["records"] == cpu["records"] == list(range(2, cpu["failed_at"] + 1, 2))
    assert gpu["released"] == []
    # with nothing reading the state, the check after the failure raises it
    checked = mixed["failing"]["checked"]
    assert checked["error"] == "StageFailed" and checked["message"] == cpu["message"]
    assert checked["step"] == 25


# ---------------------------------------------------------------- the script, in the simulator

def _scenes(condition, mean_stress=MEAN_STRESS, period=50):
    """A CPU scene and its twin for the GPU, under ``condition`` ("constant_p" at
    ``mean_stress`` [Pa], "constant_b" at b = 0.5), recording the wall stresses and the
    servos' targets every ``period`` steps."""
    from pendular.dem.mixed_stress import MixedStress
    from pendular.dem.record import HistoryRecorder
    from pendular.dem.walls import ConstantStrainRate, StressServo
    from pendular.procedures.loading import MixedStress as StageMixedStress
    from pendular.procedures.loading import Stage, Strain
    from simulated import scene

    sims = []
    for _ in range(2):
        sim = scene()
        axial = sim.controls[1]
        if condition == "constant_p":
            lateral = StressServo("xy", 1e4, 0.01)
            stage = Stage(strain_rate={"z": 1.0}, mean_stress=mean_stress, until=Strain(0.1))
            servos = [lateral]
            control = StageMixedStress(stage, {0: lateral, 1: lateral})
        else:
            servos = [StressServo("x", 1e4, 0.01), StressServo("y", 1e4, 0.01)]
            control = MixedStress({0: servos[0], 1: servos[1]}, "y", b=0.5,
                                  stress={"x": 1e4})
        assert isinstance(axial, ConstantStrainRate)
        sim.controls = [control, *servos, axial]
        sim.writers = [HistoryRecorder(period, {
            "step": lambda s: s.step, "stress": lambda s: s.walls.stress(),
            "targets": lambda s: [op.target for op in s.controls if hasattr(op, "target")]})]
        sims.append(sim)
    return sims


def _failure(sim):
    """{error, message, failed_at, records, released} of a run expected to fail."""
    out = {"error": None, "message": None, "records": None}
    try:
        sim.run(STEPS)
    except Exception as error:   # the class is what is compared
        out.update(error=type(error).__name__, message=str(error))
    out["failed_at"] = sim.step
    out["records"] = sim.writers[0].arrays()["step"].tolist()
    out["released"] = sorted(set(sim.__dict__) & {"_held", "_holder"})
    return out


def main():
    import numpy as np

    from pendular.gpu import GpuSimulation
    from simulated import compare, identical, relative, snapshot

    out = {}
    for condition in ("constant_p", "constant_b"):
        cpu, gpu = _scenes(condition)
        first = [op.target for op in cpu.controls if hasattr(op, "target")]
        cpu.run(STEPS)
        gpu.device = "gpu"
        gpu.run(STEPS)
        cpu_history, gpu_history = cpu.writers[0].arrays(), gpu.writers[0].arrays()
        targets = [op.target for op in cpu.controls if hasattr(op, "target")]
        out[condition] = {
            "agreement": compare(snapshot(cpu), snapshot(gpu)),
            "history": {"records": [len(cpu_history["step"]), len(gpu_history["step"])],
                        "targets": relative(cpu_history["targets"], gpu_history["targets"]),
                        "stress": relative(cpu_history["stress"], gpu_history["stress"])},
            "final_targets": {"cpu": targets,
                              "gpu": [op.target for op in gpu.controls
                                      if hasattr(op, "target")]},
            "target_change": float(np.max(np.abs(np.subtract(targets, first))) / 1e4)}

    # two runs in a row, held on the device between them, against one run
    copies = []
    copy_back = GpuSimulation.copy_back

    def counted(self, part=None):
        copies.append(part or "all")
        return copy_back(self, part)

    one = GpuSimulation(_scenes("constant_p")[1])
    one.sim.writers.clear()
    one.run(STEPS)
    one.to_host()
    GpuSimulation.copy_back = counted
    row = GpuSimulation(_scenes("constant_p")[1])
    row.sim.writers.clear()
    row.run(STEPS // 2)
    device_parameters = row.state.parameters.copy_to_host()
    row.configure()                         # the set-up of the next run
    kept = np.array_equal(row.state.parameters.copy_to_host(), device_parameters,
                          equal_nan=True)         # NaN: what a MixedStress does not hold
    row.run(STEPS - STEPS // 2)
    row.to_host()
    GpuSimulation.copy_back = copy_back
    out["in_a_row"] = {"copies": copies, "targets_kept": kept,
                       "equals_one_run": identical(snapshot(one.sim), snapshot(row.sim))}

    cpu, gpu = _scenes("constant_p", FAILING_MEAN_STRESS, period=2)
    gpu.device = "gpu"
    out["failing"] = {"cpu": _failure(cpu), "gpu": _failure(gpu)}
    unwatched = GpuSimulation(_scenes("constant_p", FAILING_MEAN_STRESS)[1])
    unwatched.sim.writers.clear()
    try:
        unwatched.run(STEPS, check_every=25)
    except Exception as error:
        out["failing"]["checked"] = {"error": type(error).__name__, "message": str(error),
                                     "step": unwatched.sim.step}
    print(json.dumps(out))


if __name__ == "__main__":
    main()
