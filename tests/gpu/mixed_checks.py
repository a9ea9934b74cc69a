"""The GPU side of tests/gpu/test_gpu_mixed.py, run under Numba's CUDA simulator in a
process of its own (``NUMBA_ENABLE_CUDASIM=1 python tests/gpu/mixed_checks.py mixed``,
simulator.run_checks): simulated.py's scene under a constant p and a constant b on the CPU
and on the device."""

import numpy as np

from simulator import run_checks

#: Steps of each comparison (six rebuilds; the targets moved from the servos' first ones
#: from the first records on) and of the runs in a row.
STEPS = 100
#: The mean stress held [Pa] (the scene's stresses are 3e4-1e5 Pa), and that of the failing
#: run: 3 p falls below the axial stress within its first 25 steps.
MEAN_STRESS = 5e4
FAILING_MEAN_STRESS = 2.5e4


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


def mixed():
    """Both conditions on both devices, two runs in a row against one, and the failing run."""
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
    return out



if __name__ == "__main__":
    run_checks({"mixed": mixed})
