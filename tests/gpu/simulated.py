"""The GPU path against the CPU path under Numba's CUDA simulator, run as a script in its own
process (``NUMBA_ENABLE_CUDASIM=1 python tests/gpu/simulated.py dry wet``) so that the
simulator never reaches the process of the other tests; prints one JSON object of
measurements (simulator.run_checks), which test_gpu_dem.py judges.

The scene: 27 spheres of radii within 5 % of 1 mm on a jittered cubic lattice, slightly
overlapping, with random velocities, in six walls; friction 30 deg, damping 0.2, a stress servo
on x and y and a constant strain rate on z (a triaxial's shear in miniature; several
neighbour-list rebuilds in 200 steps), dry or wet (suction-controlled bridges at contact).
"""

import math

import numpy as np

from pendular.capillary.bridge_state import BridgeState
from pendular.capillary.bridges import CapillaryBridges
from pendular.capillary.table import lookup_suction
from pendular.dem.contact_law import ContactForces, normal_stiffness
from pendular.dem.integrate import Integrator
from pendular.dem.neighbors import NeighborList
from pendular.dem.record import HistoryRecorder
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.walls import ConstantStrainRate, StressServo, WallForces
from pendular.gpu import GpuSimulation
from pendular.gpu.cuda import cuda, device_twin
from simulator import counted_copies, relative, run_checks

RADIUS = 1e-3
YOUNG = 1e7
STEPS = 200
RECORD_PERIOD = 50

#: The CPU's table lookup compiled for the device (the function the bridges' twins call).
device_lookup = device_twin(lookup_suction)


def scene(wet=False, side=3, seed=1):
    """A CPU Simulation of the scene (module docstring), with a history recorder."""
    rng = np.random.default_rng(seed)
    nodes = np.arange(side) * 1.95 * RADIUS
    position = np.array(np.meshgrid(nodes, nodes, nodes, indexing="ij")).reshape(3, -1).T
    position += RADIUS + rng.uniform(-0.05, 0.05, position.shape) * RADIUS
    radius = RADIUS * rng.uniform(0.95, 1.05, len(position))
    particles = Particles(position, radius, 2650.0, velocity=rng.normal(0, 0.01, position.shape))
    length = (side - 1) * 1.95 * RADIUS + 2 * RADIUS
    walls = Walls.box([0.02 * RADIUS] * 3, [length - 0.02 * RADIUS] * 3)
    dt = 0.1 * math.sqrt(particles.mass.min() / normal_stiffness(YOUNG, RADIUS, RADIUS))
    forces = [ContactForces(YOUNG, 0.3, 30.0), WallForces(YOUNG)]
    if wet:
        forces.append(CapillaryBridges(30000.0))
    recorder = HistoryRecorder(RECORD_PERIOD, {
        "stress": lambda sim: sim.walls.stress(),
        "mean_height": lambda sim: float(np.mean(sim.particles.position[:, 2])),
        "touching": lambda sim: float(np.count_nonzero(sim.contacts.touching()))})
    return Simulation(particles, walls, dt, neighbors=NeighborList(0.1 * RADIUS), forces=forces,
                      controls=[StressServo("xy", 1e4, 0.01), ConstantStrainRate("z", 1.0,
                                                                                 length)],
                      integrator=Integrator(0.2), writers=[recorder], threads=1)


@cuda.jit
def lookups(radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values, points,
            out):
    """The device's table lookup at each (r, u*, d*) row of ``points``: out (exists, F*, V*,
    delta1, delta2)."""
    b = cuda.grid(1)
    if b < points.shape[0]:
        exists, f, v, d1, d2 = device_lookup(radius_ratios, suction_axis, distance_low,
                                             log_distance_rupture, log_values, points[b, 0],
                                             points[b, 1], points[b, 2])
        out[b, 0] = 1.0 if exists else 0.0
        out[b, 1] = f
        out[b, 2] = v
        out[b, 3] = d1
        out[b, 4] = d2


def snapshot(sim):
    """The state a comparison reads: particles, walls, per-pair springs keyed by (i, j)."""
    sim.fetch()                         # a device run's state, all of it
    c = sim.contacts
    return {"position": sim.particles.position.copy(), "velocity": sim.particles.velocity.copy(),
            "angular_velocity": sim.particles.angular_velocity.copy(),
            "force": sim.particles.force.copy(), "torque": sim.particles.torque.copy(),
            "wall_position": sim.walls.position.copy(), "wall_force": sim.walls.force.copy(),
            "wall_stress": sim.walls.stress(),
            "springs": {(int(i), int(j)): c.shear_force[k].copy()
                        for k, (i, j) in enumerate(zip(c.pair_i, c.pair_j)) if c.overlap[k] > 0}}


def compare(cpu, gpu):
    """Largest relative difference of each quantity of two snapshots; the springs of the pairs
    touching in both, matched by pair identity."""
    out = {name: relative(cpu[name], gpu[name]) for name in cpu if name != "springs"}
    shared = sorted(set(cpu["springs"]) & set(gpu["springs"]))
    out["springs"] = relative([cpu["springs"][key] for key in shared],
                              [gpu["springs"][key] for key in shared])
    out["touching_cpu"] = len(cpu["springs"])
    out["touching_gpu"] = len(gpu["springs"])
    out["touching_both"] = len(shared)
    return out


def identical(a, b):
    """Whether two snapshots are equal bit for bit."""
    return all(np.array_equal(a[name], b[name]) for name in a if name != "springs") and \
        a["springs"].keys() == b["springs"].keys() and \
        all(np.array_equal(a["springs"][key], b["springs"][key]) for key in a["springs"])


def history_difference(cpu_sim, gpu_sim):
    """Largest relative difference of each recorded column, and the record counts."""
    cpu = cpu_sim.writers[0].arrays()
    gpu = gpu_sim.writers[0].arrays()
    out = {name: relative(cpu[name], gpu[name]) for name in cpu}
    out["records"] = [len(cpu_sim.writers[0]), len(gpu_sim.writers[0])]
    return out


def dry():
    """Agreement with the CPU over STEPS steps, history included; determinism (two runs of
    STEPS / 2 steps equal bit for bit); per-pair state carried across rebuilds (a run forced to
    rebuild its list every 10 steps equals the plain run bit for bit, and the CPU)."""
    cpu = scene()
    cpu.run(STEPS)
    plain = GpuSimulation(scene())
    plain.run(STEPS // 2)
    plain.to_host()
    half = snapshot(plain.sim)
    plain.run(STEPS - STEPS // 2)
    plain.to_host()
    again = GpuSimulation(scene())
    again.run(STEPS // 2)
    again.to_host()
    forced = GpuSimulation(scene())
    for _ in range(STEPS // 10):
        forced.run(10)
        forced.state.flags[0:1].copy_to_device(np.ones(1, np.int32))
    forced.to_host()
    return {"steps": STEPS, "particles": len(cpu.particles),
            "agreement": compare(snapshot(cpu), snapshot(plain.sim)),
            "history": history_difference(cpu, plain.sim),
            "rebuilds_cpu": cpu.neighbors.rebuilds, "rebuilds_gpu": plain.fetch_rebuilds(),
            "rebuilds_forced": forced.fetch_rebuilds(),
            "deterministic": identical(half, snapshot(again.sim)),
            "forced_equals_plain": identical(snapshot(plain.sim), snapshot(forced.sim)),
            "step": [cpu.step, plain.sim.step], "time": [cpu.time, plain.sim.time],
            "refusals": refusals(), "diverged": diverged(), "device": device_run()}


def device_run():
    """``Simulation(device="gpu").run`` with ``until`` against the CPU: the steps taken, the
    state and the history, and the device's copies back (GpuSimulation.copy_back) by part: an
    ``until`` that fetches the walls brings back the walls alone, the recorder everything."""
    cpu, gpu = scene(), scene()
    gpu.device = "gpu"
    length = cpu.walls.lengths()[2]

    def until(sim):                 # the axial walls closer by 110 steps of the strain rate
        return sim.fetch("walls").walls.lengths()[2] < length * (1.0 - 110 * sim.dt * 1.0)

    with counted_copies() as copies:
        taken = [sim.run(STEPS, until=until, check_every=25) for sim in (cpu, gpu)]
    return {"taken": taken, "step": [cpu.step, gpu.step], "copies": copies,
            "agreement": compare(snapshot(cpu), snapshot(gpu)),
            "history": history_difference(cpu, gpu),
            "released": sorted(set(gpu.__dict__) & {"particles", "walls", "contacts",
                                                    "controls", "_held", "_holder"})}


def refusals():
    """The messages with which the GPU path refuses what it does not run yet."""
    messages = []
    persisting = scene()        # bridges across gaps gathered before the walls' springs
    persisting.forces.insert(1, CapillaryBridges(30000.0, persist=True))
    unknown = scene()
    unknown.controls.append(Integrator(0.1))
    for sim in (persisting, unknown):
        try:
            GpuSimulation(sim)
        except ValueError as error:
            messages.append(str(error))
    return messages


def diverged():
    """The error of a run whose particles fly off (a time step far too long)."""
    sim = scene()
    sim.dt *= 1e6
    try:
        GpuSimulation(sim).run(60)
    except FloatingPointError as error:
        return str(error)
    return None


def wet():
    """Agreement with the CPU over STEPS steps with bridges at contact, and the device's table
    lookup against the CPU's at random (r, u*, d*) points of the same table."""
    cpu = scene(wet=True)
    cpu.run(STEPS)
    gpu = GpuSimulation(scene(wet=True))
    gpu.run(STEPS)
    gpu.to_host()
    cpu_bridges = BridgeState.of(cpu.contacts)
    gpu_bridges = BridgeState.of(gpu.sim.contacts)
    pairs = {(int(i), int(j)): k for k, (i, j) in enumerate(zip(cpu.contacts.pair_i,
                                                               cpu.contacts.pair_j))}
    matched = [(pairs[(int(i), int(j))], k) for k, (i, j) in enumerate(zip(
        gpu.sim.contacts.pair_i, gpu.sim.contacts.pair_j)) if (int(i), int(j)) in pairs]
    cpu_index, gpu_index = (np.array(index) for index in zip(*matched))
    bridge_fields = {name: relative(getattr(cpu_bridges, name)[cpu_index],
                                    getattr(gpu_bridges, name)[gpu_index])
                     for name in ("state", "volume", "force", "filling_i", "filling_j")}

    bridges = cpu.operation(CapillaryBridges)
    arrays = bridges.suction_table.arrays()
    rng = np.random.default_rng(2)
    points = np.column_stack([rng.uniform(arrays[0][0], arrays[0][-1], 64),
                              10.0 ** rng.uniform(-2.0, 2.0, 64), rng.uniform(-0.02, 0.3, 64)])

    device_out = np.zeros((len(points), 5))
    lookups[1, len(points)](*arrays, points, device_out)
    host_out = np.array([[float(e), f, v, d1, d2] for e, f, v, d1, d2 in
                         (lookup_suction(*arrays, *point) for point in points)])
    return {"steps": STEPS, "particles": len(cpu.particles),
            "agreement": compare(snapshot(cpu), snapshot(gpu.sim)),
            "history": history_difference(cpu, gpu.sim),
            "bridges": [cpu_bridges.count(), gpu_bridges.count()],
            "bridge_fields": bridge_fields,
            "lookup": relative(host_out, device_out),
            "lookups_existing": int(host_out[:, 0].sum())}


if __name__ == "__main__":
    run_checks({"dry": dry, "wet": wet})
