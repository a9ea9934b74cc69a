"""The GPU side of tests/gpu/test_gpu_tension.py, run under Numba's CUDA simulator in a
process of its own (``NUMBA_ENABLE_CUDASIM=1 python tests/gpu/tension_checks.py pull``,
simulator.run_checks): the tension's wetting and pull from simulated.py's 27 spheres on
the CPU and on the device, and what the tests compare."""

import numpy as np

from simulator import counted_copies, relative, run_checks

#: Steps of the wetting's settling (the tension's WET_STEPS, a bound on its run: the wetting
#: takes one try at the CPU's formation suction within it), and the pull's extension [-]
#: (contacts opening all along it).
WET_STEPS = 100
PULL_STRAIN = 0.005


def wetted_and_pulled(device, folder):
    """(wetting report, wetted positions, pull steps, history, Pull) of the tension's phases
    (module docstring) on ``device``; the copies back of the pull (counted_copies)."""
    from dataclasses import replace

    from pendular.dem.walls import StressServo
    from pendular.procedures import tension_pull
    from pendular.procedures.tension import TensionConfig, tension_sample
    from simulated import RADIUS, scene

    tension_pull.WET_STEPS = WET_STEPS
    dry = scene(side=3)
    dry.writers.clear()
    dry.controls = [StressServo("xyz", 1e4, 0.01)]
    dry.evaluate_forces()           # the contacts of the state the wetting starts from
    dry.device = device
    sample = replace(tension_sample(), radius=RADIUS, density=2650.0, confining=1e4)
    config = TensionConfig(sample=sample, cases=[(0.7, 0.01)], inertial_number=1e-2,
                           max_strain=PULL_STRAIN, grip_depth=0.1, vtk_frames=0)
    sim, bridges, report = tension_pull.wet(dry, config, 0.01, progress=False)
    position = sim.particles.position.copy()
    with counted_copies() as copies:
        pull = tension_pull.Pull(sim, bridges, config, folder, progress=False)
        steps, history = pull.run(None)
    return report, position, steps, history, pull, copies


def pull():
    """The wetting's reports and the pull's rows, columns and copies on both devices."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        cpu_report, cpu_position, steps, cpu, _, _ = wetted_and_pulled("cpu", folder)
        gpu_report, gpu_position, _, gpu, pull, copies = wetted_and_pulled("gpu", folder)
    wetting = {"position": relative(cpu_position, gpu_position)}
    for name, report in (("cpu", cpu_report), ("gpu", gpu_report)):
        wetting[name] = {"tries": len(report["wetting_attempts"]),
                         **{key: report[key] for key in ("formation_suction_pa",
                                                         "water_content", "saturation",
                                                         "bridges")}}
    counts = ("step", "bridges", "coordination")
    return {"wetting": wetting, "pull": {
        "steps": steps, "rows": [len(cpu["step"]), len(gpu["step"])],
        "equal": [name for name in counts if np.array_equal(cpu[name], gpu[name])],
        "differences": {name: relative(cpu[name], gpu[name]) for name in cpu
                        if name not in counts},
        "copies": copies, "members": [len(grip.members) for grip in pull.grips]}}



if __name__ == "__main__":
    run_checks({"pull": pull})
