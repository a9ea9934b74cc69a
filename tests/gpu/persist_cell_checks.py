"""The GPU side of tests/gpu/test_gpu_persist_cell.py, run under Numba's CUDA simulator in a
process of its own (``NUMBA_ENABLE_CUDASIM=1 python tests/gpu/persist_cell_checks.py CHECK
...``, simulator.run_checks): bridges across gaps in a periodic cell (persisting,
volume-controlled, in a sheared cell) and the periodic tension, on the CPU and on the device."""

import numpy as np

from periodic_checks import RADIUS, SIDE, SPACING, scene as periodic_scene
from persist_checks import bridge_events, compare, snapshot as persist_snapshot
from shear_checks import scene as shear_scene
from simulator import relative, run_checks

#: Steps of each control's comparison (the volume-controlled bridges' third rupture across a
#: gap comes after 260 steps, the sheared cell's shear strain passes 0.4 after 260; the
#: suction path's later stages add their own events); (suction [Pa], steps) of the suction
#: path's later stages ("suction": a higher suction in the same device run, a lower one,
#: which reaches farther, in a new one).
STEPS = {"suction": 100, "volume": 300, "sheared": 300}
PATH = ((90000.0, 100), (10000.0, 80))
#: The periodic tension's water content [-] (its bridges' reach fits the 64 spheres' cell),
#: steps of its wetting's settling (the tension's WET_STEPS, a bound on its run: each of the
#: wetting's two tries reaches it) and its pull's extension [-] (bridges rupture from about
#: a third of it on).
WATER_CONTENT = 0.005
WET_STEPS = 100
PULL_STRAIN = 0.005


def pulled_apart(length):
    """The controls in a cell of edge ``length`` [m]: the stress servo on x and y, z pulled
    apart at a strain rate of -20 /s."""
    from pendular.dem.walls import ConstantStrainRate, StressServo

    return [StressServo("xy", 1e4, 0.01), ConstantStrainRate("z", -20.0, length)]


def scene(control):
    """The module docstring's scene on the CPU with bridges of ``control`` ("suction":
    persisting, "volume"; "sheared": persisting, in shear_checks.py's sheared cell), and its
    bridges."""
    from pendular.capillary.bridges import CapillaryBridges

    if control == "sheared":
        sim = shear_scene(wet=True)
    else:
        sim = periodic_scene(wet=True, controls=pulled_apart)
    bridges = (CapillaryBridges(30000.0, control="volume") if control == "volume" else
               CapillaryBridges(30000.0, persist=True))
    sim.forces[-1] = bridges        # in place of the bridges at contact
    return sim, bridges


def snapshot(sim, bridges):
    """test_gpu_persist.py's snapshot (each bridge per pair (i, j)) with the positions
    unwrapped (the runs may wrap at other steps) and the cell's faces and stress tensor."""
    sim.fetch()                         # a device run's state, all of it
    cell = sim.walls
    return {**persist_snapshot(sim, bridges), "position": cell.unwrapped(sim.particles),
            "walls": cell.position.copy(), "stress": cell.stress_tensor.copy()}


def agreement(control):
    """STEPS[control] steps of the scene with bridges of ``control`` on the CPU (one at a
    time, counting the bridges' events) and on the GPU, compared, then ("suction") each stage
    of PATH; the CPU's and the GPU's rebuilds, the particles wrapped through the faces (per
    axis), the axial and shear strains and the bridges held through a face, at the end of
    each stage."""
    from pendular.gpu import GpuSimulation

    cpu, cpu_bridges = scene(control)
    gpu_sim, gpu_bridges = scene(control)
    gpu = GpuSimulation(gpu_sim)
    out = {"stages": [], "events": [0, 0, 0]}
    stages = ((None, STEPS[control]), *(PATH if control == "suction" else ()))
    for stage, (suction, steps) in enumerate(stages):
        if suction is not None:
            cpu_bridges.set_suction(suction)
            gpu_bridges.set_suction(suction)
        events = bridge_events(cpu, cpu_bridges, steps)
        out["events"] = [a + b for a, b in zip(out["events"], events)]
        if stage < 2:
            gpu.run(steps)
        else:               # a farther reach: Simulation.run's new device run
            gpu_sim.device = "gpu"
            gpu_sim.run(steps)
        if stage == 0:      # the device run's own count
            out["rebuilds"] = [cpu.neighbors.rebuilds, gpu.fetch_rebuilds()]
        held = snapshot(cpu, cpu_bridges)
        result = compare(held, snapshot(gpu_sim, gpu_bridges))
        c = cpu.contacts
        through = {(int(i), int(j)) for i, j, image in zip(c.pair_i, c.pair_j, c.image)
                   if image.any()}
        result["through_faces"] = len(through.intersection(held["pairs"]))
        result["wrapped"] = [int(n) for n in (gpu_sim.walls.wraps != 0).sum(axis=0)]
        result["strain"] = 1.0 - gpu_sim.walls.position[5] / (SIDE * SPACING)
        result["gamma"] = gpu_sim.walls.shear_strain
        result["reach"] = [cpu.neighbors.interaction_range,
                           gpu_sim.neighbors.interaction_range]
        out["stages"].append(result)
    return out


def wetted_and_pulled(device, folder):
    """(wetting report, wetted positions unwrapped, pull steps, history) of the periodic
    tension's phases on ``device``: the scene dry under a stress servo at 10 kPa, wetted to a
    water content of 0.5 % (volume-controlled bridges at contacts and across gaps, WET_STEPS
    steps of settling), then pulled along z (the cell stretched, x and y servoed at zero) by
    PULL_STRAIN."""
    from dataclasses import replace

    from pendular.dem.walls import StressServo
    from pendular.procedures import tension_pull
    from pendular.procedures.tension import TensionConfig, tension_sample

    tension_pull.WET_STEPS = WET_STEPS
    dry = periodic_scene()
    dry.writers.clear()
    dry.controls = [StressServo("xyz", 1e4, 0.01)]
    dry.evaluate_forces()           # the contacts of the state the wetting starts from
    dry.device = device
    sample = replace(tension_sample(), radius=RADIUS, density=2650.0, confining=1e4,
                     periodic=True)
    config = TensionConfig(sample=sample, cases=[(0.7, WATER_CONTENT)], inertial_number=1e-2,
                           max_strain=PULL_STRAIN, vtk_frames=0)
    sim, bridges, report = tension_pull.wet(dry, config, WATER_CONTENT, progress=False)
    position = sim.walls.unwrapped(sim.particles)
    steps, history = tension_pull.Pull(sim, bridges, config, folder, progress=False).run(None)
    return report, position, steps, history


def tension_agreement():
    """The periodic tension's wetting and pull (wetted_and_pulled) on the CPU and on the GPU:
    the wettings' reports, the wetted positions' and each history column's largest relative
    difference."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        cpu_report, cpu_position, steps, cpu = wetted_and_pulled("cpu", folder)
        gpu_report, gpu_position, _, gpu = wetted_and_pulled("gpu", folder)
    reported = ("formation_suction_pa", "water_content", "bridges")
    return {"steps": steps, "position": relative(cpu_position, gpu_position),
            "reports": [[report[key] for key in reported] for report in (cpu_report,
                                                                         gpu_report)],
            "rows": [len(cpu["step"]), len(gpu["step"])],
            "differences": {name: relative(cpu[name], gpu[name]) for name in cpu
                            if np.asarray(cpu[name]).dtype != object}}


if __name__ == "__main__":
    run_checks({"suction": lambda: agreement("suction"), "volume": lambda: agreement("volume"),
                "sheared": lambda: agreement("sheared"), "tension": tension_agreement})
