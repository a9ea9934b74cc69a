"""The radius growth of a preparation (pendular.dem.growth) on the GPU against the CPU, the
checks of tests/gpu/test_gpu_growth.py run under Numba's CUDA simulator in a process of their
own (``NUMBA_ENABLE_CUDASIM=1 python growth_checks.py growth`` prints one JSON object of
measurements, simulator.run_checks).

The scene: 27 spheres of radii within 5 % of 1 mm on a jittered cubic lattice 2.2 mm apart
(solid fraction 0.39), with random velocities, in six fixed walls, friction 0.5 deg; radii grown
at up to 1e-3 per step towards a mean wall stress of TARGET, the time step set at every
neighbour-list rebuild (GrowthTimeStep), skin 0.1 mm: the spheres touch after about 100 steps,
the walls' stress passes the target and the growth turns to shrinking within the run, and the
list is rebuilt for the radii's growth as well as for the motion. A whole preparation takes
thousands of growth steps, beyond the simulator: ``prepare_sample(device="gpu")`` is checked
cut short, against the CPU's message.
"""

import math

from simulator import relative, run_checks

RADIUS = 1e-3
STEPS = 300
TARGET = 5000.0


def scene(timestep=True, seed=3):
    """The CPU Simulation of the module docstring (its growth time step with ``timestep``)."""
    import numpy as np

    from pendular.dem.contact_law import ContactForces
    from pendular.dem.growth import GrowthTimeStep, RadiusGrowth
    from pendular.dem.integrate import Integrator
    from pendular.dem.neighbors import NeighborList
    from pendular.dem.simulation import Simulation
    from pendular.dem.state import Particles, Walls
    from pendular.dem.walls import WallForces

    rng = np.random.default_rng(seed)
    side, spacing = 3, 2.2 * RADIUS
    nodes = np.arange(side) * spacing
    position = np.array(np.meshgrid(nodes, nodes, nodes, indexing="ij")).reshape(3, -1).T
    position += spacing / 2 + rng.uniform(-0.05, 0.05, position.shape) * RADIUS
    radius = RADIUS * rng.uniform(0.95, 1.05, len(position))
    particles = Particles(position, radius, 2650.0, velocity=rng.normal(0, 0.005,
                                                                          position.shape))
    walls = Walls.box([0.0] * 3, [side * spacing] * 3)
    young = 1e6
    controls = [RadiusGrowth(TARGET, 1e-3)]
    if timestep:
        controls.append(GrowthTimeStep(0.7, young, 2650.0))
    dt = 0.7 * float(radius.min()) / math.sqrt(young / 2650.0)
    return Simulation(particles, walls, dt, neighbors=NeighborList(0.1 * RADIUS),
                      forces=[ContactForces(young, 0.3, 0.5), WallForces(young)],
                      controls=controls, integrator=Integrator(0.2))


def growth_run():
    """The scene on the CPU and on the GPU (GpuSimulation driven directly), STEPS steps."""
    import numpy as np

    from pendular.gpu import GpuSimulation

    cpu = scene()
    start_radius = cpu.particles.radius.copy()
    start_dt = cpu.dt
    peak = 0.0
    growth_only = 0
    for _ in range(STEPS):
        before = cpu.neighbors.rebuilds
        moved = np.max(np.linalg.norm(cpu.particles.position - cpu.neighbors._reference_position,
                                      axis=1)) if cpu.neighbors._reference_position is not None \
            else np.inf
        cpu.run(1)
        # rebuilt while no particle had moved half the skin: the radii's growth asked for it
        growth_only += cpu.neighbors.rebuilds > before and moved <= 0.5 * cpu.neighbors.skin
        peak = max(peak, float(np.mean(cpu.walls.stress())))
    sim = scene()
    gpu = GpuSimulation(sim)
    gpu.run(STEPS)
    gpu_rebuilds = gpu.fetch_rebuilds()
    gpu.to_host()
    # the same steps in two GpuSimulations, the state back on the host between them
    split = scene()
    for _ in range(2):
        half = GpuSimulation(split)
        half.run(STEPS // 2)
        half.to_host()
    p, q = sim.particles, cpu.particles
    return {
        "split": {"position": relative(split.particles.position, q.position),
                  "radius": relative(split.particles.radius, q.radius),
                  "dt": abs(split.dt - cpu.dt) / cpu.dt},
        "agreement": {
            "radius": relative(p.radius, q.radius),
            "mass": relative(p.mass, q.mass),
            "inertia": relative(p.inertia, q.inertia),
            "position": relative(p.position, q.position),
            "velocity": relative(p.velocity, q.velocity),
            "wall_position": relative(sim.walls.position, cpu.walls.position),
            "wall_stress": relative(sim.walls.stress(), cpu.walls.stress()),
            "dt": abs(sim.dt - cpu.dt) / cpu.dt},
        "touching": {"cpu": int(np.count_nonzero(cpu.contacts.touching())),
                     "gpu": int(np.count_nonzero(sim.contacts.touching()))},
        "radius_growth": float(np.min(q.radius / start_radius)),
        "peak_stress": peak,
        "rebuilds": {"cpu": int(cpu.neighbors.rebuilds), "gpu": gpu_rebuilds,
                     "growth_only": int(growth_only)},
        "dt_change": abs(cpu.dt / start_dt - 1.0),
    }


def prepare_run(particles=20, periodic=False, max_steps=60):
    """A preparation of ``particles`` spheres (in a periodic cell with ``periodic``) cut short
    at ``max_steps`` on each device (prepare_sample): its message, and the steps the device's
    growth took."""
    from pendular.gpu.growth import DeviceGrowth
    from pendular.procedures.preparation import PrepareConfig, prepare_sample

    config = PrepareConfig(particles=particles, seed=1, periodic=periodic)
    messages = {}
    device_steps = []
    advance = DeviceGrowth.advance

    def counted(self, gpu, launches):
        device_steps.append(gpu.sim.step)
        advance(self, gpu, launches)

    DeviceGrowth.advance = counted
    try:
        for device in ("cpu", "gpu"):
            try:
                prepare_sample(config, progress=False, max_steps=max_steps, device=device)
            except ValueError as error:
                messages[device] = str(error)
    finally:
        DeviceGrowth.advance = advance
    return {**messages, "max_steps": max_steps, "device_steps": len(device_steps)}


def refusals():
    """The messages of the scenes test_a_growth_the_gpu_cannot_follow_is_refused_by_name
    builds."""
    from pendular.gpu import GpuSimulation

    messages = {}
    for name, change in (("two", lambda controls: controls + controls[:1]),
                         ("order", lambda controls: controls[::-1])):
        sim = scene()
        sim.controls = change(sim.controls)
        try:
            GpuSimulation(sim)
        except ValueError as error:
            messages[name] = str(error)
    return messages



def growth():
    """Every measurement the tests judge."""
    result = growth_run()
    result["refused"] = refusals()
    result["prepare"] = prepare_run()
    return result


if __name__ == "__main__":
    run_checks({"growth": growth})
