"""Suction-controlled bridges that persist across gaps (SuctionBridges ``persist``) and a
suction path (SuctionBridges.set_suction between runs) on the GPU against the CPU, the check of
tests/gpu/test_gpu_persist.py run under Numba's CUDA simulator in a process of its own
(``NUMBA_ENABLE_CUDASIM=1 python persist_checks.py path`` prints one JSON object of
measurements, simulator.run_checks): 27 spheres of radii within 5 % of 1 mm on a jittered
cubic lattice, slightly overlapping, with random velocities, in six walls pulled apart along z
(a constant strain rate) under a stress servo on x and y; friction 30 deg, damping 0.2.
Bridges form at contact, stretch across the gaps that open and rupture at their rupture
distance; the suction goes 30 kPa -> 90 kPa (bridges at contact looked up again, bridges
across gaps ruptured where the rupture distance fell below their gap; the same GpuSimulation)
-> 10 kPa (a farther reach: a new device run, as Simulation.run makes).
"""

import math

import numpy as np

from simulator import relative, run_checks

RADIUS = 1e-3
YOUNG = 1e7
SIDE = 3
#: (suction [Pa], steps) of the path's three stages.
PATH = ((30000.0, 120), (90000.0, 100), (10000.0, 80))


def scene(seed=4):
    """A CPU Simulation of the module docstring's scene, and its bridges."""
    from pendular.capillary.bridges import CapillaryBridges
    from pendular.dem.contact_law import ContactForces, normal_stiffness
    from pendular.dem.integrate import Integrator
    from pendular.dem.neighbors import NeighborList
    from pendular.dem.simulation import Simulation
    from pendular.dem.state import Particles, Walls
    from pendular.dem.walls import ConstantStrainRate, StressServo, WallForces

    rng = np.random.default_rng(seed)
    nodes = np.arange(SIDE) * 1.95 * RADIUS
    position = np.array(np.meshgrid(nodes, nodes, nodes, indexing="ij")).reshape(3, -1).T
    position += RADIUS + rng.uniform(-0.05, 0.05, position.shape) * RADIUS
    radius = RADIUS * rng.uniform(0.95, 1.05, len(position))
    particles = Particles(position, radius, 2650.0,
                          velocity=rng.normal(0, 0.05, position.shape))
    length = (SIDE - 1) * 1.95 * RADIUS + 2 * RADIUS
    walls = Walls.box([0.02 * RADIUS] * 3, [length - 0.02 * RADIUS] * 3)
    dt = 0.1 * math.sqrt(particles.mass.min() / normal_stiffness(YOUNG, RADIUS, RADIUS))
    bridges = CapillaryBridges(PATH[0][0], persist=True)
    forces = [ContactForces(YOUNG, 0.3, 30.0), WallForces(YOUNG), bridges]
    sim = Simulation(particles, walls, dt, neighbors=NeighborList(0.1 * RADIUS), forces=forces,
                     controls=[StressServo("xy", 1e4, 0.01),
                               ConstantStrainRate("z", -20.0, length)],
                     integrator=Integrator(0.2), threads=1)
    return sim, bridges


def snapshot(sim, bridges):
    """The state a comparison reads: particles, walls, and per pair (i, j) of the list the
    bridges' state, volume, force, filling angles, suction (0 under suction control) and force
    on j from i."""
    sim.fetch()                         # a device run's state, all of it
    from pendular.capillary.bridge_state import BridgeState

    c = sim.contacts
    state = BridgeState.of(c)
    pair_force = bridges.pair_forces(sim)
    held = state.state != 0
    pairs = {(int(i), int(j)): k for k, (i, j) in enumerate(zip(c.pair_i, c.pair_j))
             if held[k]}
    keys = sorted(pairs)
    rows = [pairs[key] for key in keys]
    return {"position": sim.particles.position.copy(),
            "velocity": sim.particles.velocity.copy(),
            "walls": sim.walls.position.copy(), "stress": sim.walls.stress(),
            "pairs": keys, "state": state.state[rows].astype(int).tolist(),
            "volume": state.volume[rows], "bridge_force": state.force[rows],
            "filling": np.stack([state.filling_i[rows], state.filling_j[rows]], axis=1),
            "suction": state.suction[rows], "pair_force": pair_force[rows]}


def compare(cpu, gpu):
    """Largest relative difference of each array of two snapshots; whether the bridges are
    the same pairs in the same states; the CPU's bridges across gaps."""
    same = cpu["pairs"] == gpu["pairs"] and cpu["state"] == gpu["state"]
    out = {"same_bridges": same, "bridges": len(cpu["pairs"]),
           "across_gaps": int(sum(s == 2 for s in cpu["state"]))}
    for name in cpu:
        if name not in ("pairs", "state"):
            out[name] = (relative(cpu[name], gpu[name]) if same or name not in
                         ("volume", "bridge_force", "filling", "suction", "pair_force")
                         else None)
    return out


def bridge_events(sim, bridges, steps):
    """Run the CPU ``steps`` steps one at a time: (bridges formed, bridges that went across a
    gap, bridges across a gap that ruptured) over them."""
    from pendular.capillary.bridge_state import BridgeState

    def states():
        c = sim.contacts
        if c is None:
            return {}
        state = BridgeState.of(c).state
        return {(int(i), int(j)): int(s) for i, j, s in zip(c.pair_i, c.pair_j, state) if s}

    formed = stretched = ruptured = 0
    before = states()
    for _ in range(steps):
        sim.run(1)
        now = states()
        formed += sum(key not in before for key in now)
        stretched += sum(s == 2 and before.get(key) != 2 for key, s in now.items())
        ruptured += sum(s == 2 and key not in now for key, s in before.items())
        before = now
    return formed, stretched, ruptured


def agreement():
    """The path (PATH) on the CPU and on the GPU, compared at the end of each stage."""
    from pendular.gpu import GpuSimulation

    cpu, cpu_bridges = scene()
    gpu_sim, gpu_bridges = scene()
    gpu = GpuSimulation(gpu_sim)
    out = {"stages": [], "events": [0, 0, 0]}
    for stage, (suction, steps) in enumerate(PATH):
        if stage:
            cpu_bridges.set_suction(suction)
            gpu_bridges.set_suction(suction)
        events = bridge_events(cpu, cpu_bridges, steps)
        out["events"] = [a + b for a, b in zip(out["events"], events)]
        if stage < 2:       # the same device run: a suction change within its reach
            gpu.run(steps)
            if stage == 0:
                out["refused"] = reach_refused(gpu_bridges, gpu)
        else:               # a farther reach: Simulation.run's new device run
            gpu_sim.device = "gpu"
            gpu_sim.run(steps)
        result = compare(snapshot(cpu, cpu_bridges), snapshot(gpu_sim, gpu_bridges))
        result["reach"] = [cpu.neighbors.interaction_range, gpu_sim.neighbors.interaction_range]
        out["stages"].append(result)
    return out


def reach_refused(bridges, gpu):
    """The message of a run of ``gpu`` (a GpuSimulation) asked at a suction that reaches
    farther than its grid (10 kPa), the suction then put back."""
    suction = bridges.suction
    reach = bridges.required_range
    bridges.set_suction(PATH[2][0])
    try:
        gpu.run(0)
    except ValueError as error:
        return str(error)
    finally:
        bridges.suction, bridges.required_range = suction, reach
    return None


if __name__ == "__main__":
    run_checks({"path": agreement})
