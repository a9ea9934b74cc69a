"""Sphere–wall bridges (pendular.gpu.wall_bridges) on the GPU against the CPU, the checks of
tests/gpu/test_gpu_wall_bridges.py run under Numba's CUDA simulator in a process of their own
(``NUMBA_ENABLE_CUDASIM=1 python wall_bridges_checks.py agreement persist refusal order``
prints one JSON object of measurements, simulator.run_checks):

- "agreement": the 27-sphere scene of simulated.py (a triaxial's shear in miniature) wet,
  its suction-controlled bridges at contact with sphere–wall bridges, over STEPS: the plain
  run, one handed from the CPU to the device halfway (the wall bridges' state goes up and
  comes back), and the CPU's run without wall bridges (what the comparison would miss);
- "persist": the same with bridges that persist across gaps (``persist``: a wall bridge lives
  on from step to step, and its state goes up to the device when handed over);
- "refusal": the same scene with a radius growth (the wall bridges' table is checked for the
  radii once a run);
- "order": the same scene, its bridges listed before the wall forces (whose sums on the CPU
  then overwrite the pulls).
"""

from simulator import run_checks

STEPS = 200


def scene(wall_bridges=True, persist=False):
    """simulated.py's wet scene, its bridges with sphere–wall bridges (``persist``: across
    gaps)."""
    from pendular.capillary.bridges import CapillaryBridges
    from simulated import scene as plain

    sim = plain(wet=True)
    sim.forces[-1] = CapillaryBridges(30000.0, persist=persist,
                                     wall_bridges=wall_bridges)
    return sim


def snapshot(sim):
    """simulated.py's snapshot with the wall bridges' state and moments."""
    from pendular.capillary.bridges import CapillaryBridges
    from simulated import snapshot as plain

    out = plain(sim)
    walls = sim.operation(CapillaryBridges).walls
    for name in ("exists", "volume", "force", "filling", "moment"):
        out[f"bridges_{name}"] = getattr(walls, name).copy()
    return out


def compare(cpu, gpu):
    """simulated.py's comparison and the count of wall bridges (CPU, GPU)."""
    import numpy as np

    from simulated import compare as plain

    out = plain(cpu, gpu)
    out["wall_bridges"] = [int(np.count_nonzero(s["bridges_exists"])) for s in (cpu, gpu)]
    return out


def agreement(persist=False):
    """The scene on both devices (module docstring)."""
    from pendular.gpu import GpuSimulation
    from simulated import compare as plain_compare, snapshot as plain_snapshot

    cpu = scene(persist=persist)
    cpu.run(STEPS)
    gpu = GpuSimulation(scene(persist=persist))
    gpu.run(STEPS)
    gpu.to_host()
    handed = scene(persist=persist)
    handed.run(STEPS // 2)
    handed_gpu = GpuSimulation(handed)
    handed_gpu.run(STEPS - STEPS // 2)
    handed_gpu.to_host()
    out = {"agreement": compare(snapshot(cpu), snapshot(gpu.sim)),
           "handed_over": compare(snapshot(cpu), snapshot(handed_gpu.sim))}
    if not persist:
        without = scene(wall_bridges=False)
        without.run(STEPS)
        out["without"] = plain_compare(plain_snapshot(cpu), plain_snapshot(without))
    return out


def refusal():
    """The error of the scene with a radius growth."""
    from pendular.dem.growth import RadiusGrowth
    from pendular.gpu import GpuSimulation

    growing = scene()
    growing.controls = [RadiusGrowth(1e4, 1e-3)]
    try:
        GpuSimulation(growing)
    except ValueError as error:
        return str(error)
    return None


def order():
    """The error of the scene with its bridges listed before the wall forces."""
    from pendular.gpu import GpuSimulation

    reordered = scene()
    reordered.forces.insert(1, reordered.forces.pop())
    try:
        GpuSimulation(reordered)
    except ValueError as error:
        return str(error)
    return None


if __name__ == "__main__":
    run_checks({"agreement": agreement, "persist": lambda: agreement(persist=True),
                "refusal": refusal, "order": order})
