"""Suction-controlled bridges that persist across gaps (SuctionBridges ``persist``) and a
suction path (SuctionBridges.set_suction between runs) on the GPU against the CPU under Numba's
CUDA simulator: 27 spheres of radii within 5 % of 1 mm on a jittered cubic lattice, slightly
overlapping, with random velocities, in six walls pulled apart along z (a constant strain
rate) under a stress servo on x and y; friction 30 deg, damping 0.2. Bridges form at contact,
stretch across the gaps that open and rupture at their rupture distance; the suction goes
30 kPa -> 90 kPa (bridges at contact looked up again, bridges across gaps ruptured where the
rupture distance fell below their gap; the same GpuSimulation) -> 10 kPa (a farther reach:
a new device run, as Simulation.run makes). The simulator runs in a process of its own (this
file as a script: ``NUMBA_ENABLE_CUDASIM=1 python test_gpu_persist.py CHECK`` prints one JSON
object of measurements), so that no other test meets it.

Measured (simulator, 27 spheres, 120 + 100 + 80 steps; 95 bridges formed, 65 stretched
across a gap, 49 of those ruptured; the reach 4.6 um, then 12.6 um at 10 kPa): at the end of
each stage the same pairs hold bridges in the same states as on the CPU, and the largest
relative differences are 1.3e-14 in positions, 2.8e-12 in velocities, 7.2e-14 in wall
stresses, none in wall positions, 5.0e-12 in bridge volumes, 3.5e-12 in bridge forces (and
forces on j from i), 3.4e-12 in filling angles: the CPU's contracted multiply-adds against the
simulator's plain ones, grown over the run (a bridge across a gap is looked up at its gap).
The tests hold them to 1e-12 (positions, walls), 1e-10 (the rest).

The command (``pendular triaxial --sample S --particles 60 --suction 30000 --persist-bridges
--max-strain 0.002 --inertial-number 1e-3``, 162 steps of shear, a record each step): the rows,
bridge and contact counts are the CPU's; the other columns agree within 2.1e-9 of their largest
value (volumetric strain; sigma_wall 8.2e-10) and the unbalanced force within 2.3e-7. Bridges
across gaps make this sample sensitive: on the CPU alone, one coordinate of the sample moved by
one ulp changes the volumetric strain by 6.0e-8 and the unbalanced force by 6.9e-6. The test
holds 2e-8 and 2e-6.
"""

import json
import math
import os

import numpy as np
import pytest

from simulator import assert_same_records, histories_on_both, relative, simulated

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


# ---------------------------------------------------------------- the tests (pytest)
@pytest.fixture(scope="module")
def measured():
    pytest.importorskip("numba_cuda")
    return simulated(os.path.basename(__file__), "path")


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


def test_a_farther_reach_needs_a_new_device_run(measured):
    assert "reach" in measured["refused"] and "new GpuSimulation" in measured["refused"]


#: The wet triaxial of test_gpu_command.py with persisting bridges (its sample added).
TRIAXIAL = ["--particles", "60", "--suction", "30000", "--persist-bridges", "--max-strain",
            "0.002", "--inertial-number", "1e-3", "--quiet"]


def test_the_triaxial_command_with_persisting_bridges_records_the_cpu_history(tmp_path):
    """``pendular triaxial --sample S --suction 30000 --persist-bridges --device gpu`` (S
    prepared on the CPU; the wetting on the CPU, the loading on the device) records the CPU's
    history: the same rows, bridge and contact counts, the other columns to round-off grown
    over 162 steps (module docstring)."""
    pytest.importorskip("numba_cuda")
    cpu, gpu = histories_on_both("triaxial", ["--particles", 60, "--max-strain", 1e-4,
                                              "--quiet"], TRIAXIAL, tmp_path)
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


if __name__ == "__main__":
    print(json.dumps(agreement()))
