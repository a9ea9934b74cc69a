"""The periodic cell's checks of tests/gpu/test_gpu_periodic.py, run under Numba's CUDA simulator
in a process of their own (``NUMBA_ENABLE_CUDASIM=1 python periodic_checks.py dry wet hertz``
prints one JSON object of measurements, simulator.run_checks): 64 spheres of radii within 5 %
of 1 mm on a jittered cubic lattice, slightly overlapping, with random velocities, in a
periodic cell; friction 30 deg, damping 0.2, the cell's stress servo on x and y and a constant
strain rate on z (the particles wrapped through the faces and the pairs found through them at
the device's rebuilds), dry and wet (suction-controlled bridges at contact), and dry with
Hertz–Mindlin contacts damped to a restitution of 0.5 (``hertz``). The scene serves the other
cell checks too (shear_checks.py, rolling_checks.py, persist_cell, homogenize, records).
"""

import math

import numpy as np

from simulator import relative, run_checks

RADIUS = 1e-3
YOUNG = 1e7
SIDE = 4
SPACING = 1.95 * RADIUS
#: Steps of the dry and the wet comparison (seven rebuilds, particles wrapped through each
#: face), and of the GPU part of a run the CPU continues (several rebuilds on the device).
STEPS = {"dry": 100, "wet": 100}
HANDOVER = 50
CONTINUED = 100


def servo_and_strain_rate(length):
    """The scene's controls in a cell of edge ``length`` [m]: the stress servo on x and y, a
    constant strain rate on z."""
    from pendular.dem.walls import ConstantStrainRate, StressServo

    return [StressServo("xy", 2e4, 0.02), ConstantStrainRate("z", 2.0, length)]


def scene(wet=False, seed=3, controls=servo_and_strain_rate, offset=0.0):
    """A CPU Simulation of the module docstring's scene: ``controls(edge)`` its controls, the
    cell's image above in z offset by ``offset`` of its width along x (a sheared cell's)."""
    from pendular.capillary.bridges import CapillaryBridges
    from pendular.dem.cell import PeriodicCell
    from pendular.dem.contact_law import ContactForces, normal_stiffness
    from pendular.dem.integrate import Integrator
    from pendular.dem.neighbors import NeighborList
    from pendular.dem.simulation import Simulation
    from pendular.dem.state import Particles

    rng = np.random.default_rng(seed)
    nodes = np.arange(SIDE) * SPACING + 0.01 * RADIUS      # the first layers across faces
    position = np.array(np.meshgrid(nodes, nodes, nodes, indexing="ij")).reshape(3, -1).T
    position += rng.uniform(-0.05, 0.05, position.shape) * RADIUS
    radius = RADIUS * rng.uniform(0.95, 1.05, len(position))
    particles = Particles(position, radius, 2650.0,
                          velocity=rng.normal(0, 0.05, position.shape))
    length = SIDE * SPACING
    cell = PeriodicCell.box([0.0] * 3, [length] * 3)
    cell.shear_offset = offset * length
    dt = 0.1 * math.sqrt(particles.mass.min() / normal_stiffness(YOUNG, RADIUS, RADIUS))
    forces = [ContactForces(YOUNG, 0.3, 30.0)]
    if wet:
        forces.append(CapillaryBridges(30000.0))
    return Simulation(particles, cell, dt, neighbors=NeighborList(0.1 * RADIUS), forces=forces,
                      controls=controls(length), integrator=Integrator(0.2), threads=1)


#: Steps of the Hertz–Mindlin comparison, and of its GPU part continued on the CPU: with the
#: contacts damped this scene's runs part from round-off within a hundred steps on the CPU
#: alone, and the servo, reading the springs' secant stiffness (the per-pair normal force
#: without the dashpot), takes the device's round-off soonest, so the comparison stops
#: before (docs/gpu.md).
HERTZ_STEPS = 40


def hertz_scene(wet=False):
    """The dry scene with Hertz–Mindlin contacts damped to a restitution of 0.5
    (pendular.dem.hertz_mindlin) instead of linear springs."""
    from pendular.dem.hertz_mindlin import HertzMindlinForces

    sim = scene(wet)
    sim.forces[0] = HertzMindlinForces(YOUNG, 0.3, 0.5, 30.0)
    return sim


def snapshot(sim):
    """The state a comparison reads (positions unwrapped: the runs may wrap at other steps)."""
    sim.fetch()                         # a device run's state, all of it
    cell = sim.walls
    return {"position": cell.unwrapped(sim.particles),
            "velocity": sim.particles.velocity.copy(),
            "angular_velocity": sim.particles.angular_velocity.copy(),
            "cell": cell.position.copy(), "rate": cell.rate.copy(),
            "stress": cell.stress_tensor.copy(), "shear_stress": cell.shear_stress(),
            "stiffness": cell.stiffness.copy(),
            "offset": cell.shear_offset, "shear_rate": cell.shear_rate,
            "shear_strain": cell.shear_strain,
            "touching": int(np.count_nonzero(sim.contacts.touching()))}


def compare(cpu, gpu):
    """Largest relative difference of each quantity of two snapshots; the touching counts."""
    out = {name: relative(cpu[name], gpu[name]) for name in cpu if name != "touching"}
    out["touching"] = [cpu["touching"], gpu["touching"]]
    return out


def agreement(wet, build=scene, steps=None, handover=HANDOVER, continued=CONTINUED):
    """The CPU's and the GPU's runs of ``steps`` (STEPS) steps of ``build(wet)`` compared; the
    GPU's wraps (particles wrapped, per axis), the CPU's and the GPU's rebuilds, the axial
    strain, the cell's offset (a fraction of its width), shear strain and shear stress; a GPU
    run of ``handover`` steps continued ``continued`` steps on the CPU against the CPU
    alone."""
    from pendular.gpu import GpuSimulation

    steps = STEPS["wet" if wet else "dry"] if steps is None else steps
    cpu = build(wet)
    cpu.run(steps)
    gpu_sim = build(wet)
    gpu = GpuSimulation(gpu_sim)
    gpu.run(steps)
    rebuilds = gpu.fetch_rebuilds()
    gpu.to_host()
    out = compare(snapshot(cpu), snapshot(gpu_sim))
    cell = gpu_sim.walls
    out["wrapped"] = np.count_nonzero(cell.wraps, axis=0).tolist()
    out["rebuilds"] = [cpu.neighbors.rebuilds, rebuilds]
    out["strain"] = 1.0 - cell.position[5] / (SIDE * SPACING)
    out["offset_fraction"] = cell.shear_offset / cell.position[1]
    out["gamma"] = cell.shear_strain
    out["tau"] = cell.shear_stress()
    handed = build(wet)
    GpuSimulation(handed).run(handover)
    handed.run(continued)           # the state back on the host, then the CPU
    alone = build(wet)
    alone.run(handover + continued)
    out["continued"] = compare(snapshot(alone), snapshot(handed))
    return out


if __name__ == "__main__":
    run_checks({"dry": lambda: agreement(False), "wet": lambda: agreement(True),
                "hertz": lambda: agreement(False, hertz_scene, HERTZ_STEPS, HERTZ_STEPS // 2,
                                           HERTZ_STEPS // 2)})
