"""The GPU path in a periodic cell (pendular.gpu.cell) against the CPU path under Numba's CUDA
simulator: 64 spheres of radii within 5 % of 1 mm on a jittered cubic lattice, slightly
overlapping, with random velocities, in a periodic cell; friction 30 deg, damping 0.2, the
cell's stress servo on x and y and a constant strain rate on z (the particles wrapped through
the faces and the pairs found through them at the device's rebuilds), dry and wet
(suction-controlled bridges at contact). The simulator runs in a process of its own (this file
as a script: ``NUMBA_ENABLE_CUDASIM=1 python test_gpu_periodic.py CHECK`` prints one JSON
object of measurements), so that no other test meets it.

Measured (simulator, 64 spheres; dry 300 steps, 8 rebuilds; wet 200 steps, 7 rebuilds):
largest relative differences from the CPU 2.5e-15 (wet 1.7e-15) in unwrapped positions,
3.4e-12 (1.2e-12) in velocities, 3.3e-12 (8.3e-13) in angular velocities, 3.6e-15 (3.0e-15)
in the cell's stress tensor, 3.7e-16 (5.5e-16) in its stiffness, none in its faces and rates;
a GPU run of 150 steps continued 100 on the CPU against the CPU's 250: 4.3e-15 (3.3e-15) in
positions, 3.5e-12 (3.1e-12) in velocities. The CPU's hot kernels contract multiply-adds and
take reciprocals; the simulator computes each operation as written.
"""

import json
import math
import os
import sys

import numpy as np
import pytest

from simulator import assert_same_records, histories_on_both, relative, simulated

RADIUS = 1e-3
YOUNG = 1e7
SIDE = 4
SPACING = 1.95 * RADIUS
#: Steps of the dry and the wet comparison, and of the GPU part of a run the CPU continues.
STEPS = {"dry": 300, "wet": 200}
HANDOVER = 150
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


def agreement(wet, build=scene):
    """The CPU's and the GPU's runs of STEPS steps of ``build(wet)`` compared; the GPU's wraps
    (particles wrapped, per axis), the CPU's and the GPU's rebuilds, the axial strain, the
    cell's offset (a fraction of its width), shear strain and shear stress; a GPU run of
    HANDOVER steps continued CONTINUED steps on the CPU against the CPU alone."""
    from pendular.gpu import GpuSimulation

    steps = STEPS["wet" if wet else "dry"]
    cpu = build(wet)
    cpu.run(steps)
    gpu_sim = build(wet)
    gpu = GpuSimulation(gpu_sim)
    gpu.run(steps)
    rebuilds = gpu.rebuilds
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
    GpuSimulation(handed).run(HANDOVER)
    handed.run(CONTINUED)           # the state back on the host, then the CPU
    alone = build(wet)
    alone.run(HANDOVER + CONTINUED)
    out["continued"] = compare(snapshot(alone), snapshot(handed))
    return out


# ---------------------------------------------------------------- the tests (pytest)
def measured(check, script=os.path.basename(__file__)):
    """The measurements of ``script``'s ``check`` (this file's by default), run under the
    simulator."""
    pytest.importorskip("numba_cuda")
    return simulated(script, check)


@pytest.fixture(scope="module")
def dry():
    return measured("dry")


@pytest.fixture(scope="module")
def wet():
    return measured("wet")


def assert_agrees(measured):
    assert measured["touching"][0] == measured["touching"][1] > 100    # a packing, not a gas
    assert measured["position"] < 1e-13
    assert measured["cell"] < 1e-13 and measured["rate"] < 1e-13
    assert measured["stress"] < 1e-13 and measured["stiffness"] < 1e-13
    for name in ("velocity", "angular_velocity"):
        assert measured[name] < 1e-10, name


def test_a_periodic_cell_agrees_with_the_cpu_to_round_off_dry(dry):
    assert sum(dry["wrapped"]) > 0                        # through the faces
    assert dry["rebuilds"][0] == dry["rebuilds"][1] > 2   # several lists
    assert dry["strain"] > 0.0
    assert_agrees(dry)


def test_a_periodic_cell_agrees_with_the_cpu_to_round_off_wet(wet):
    assert wet["rebuilds"][0] == wet["rebuilds"][1] > 1
    assert_agrees(wet)


def test_a_gpu_run_continued_on_the_cpu_equals_the_cpu_run(dry, wet):
    assert_agrees(dry["continued"])
    assert_agrees(wet["continued"])


#: The periodic triaxial command on both devices (its sample, prepared on the CPU, added).
COMMAND = ["--particles", "60", "--periodic", "--max-strain", "0.002", "--inertial-number",
           "1e-3", "--quiet"]


def test_the_periodic_triaxial_command_records_the_cpu_history(tmp_path):
    """``pendular triaxial --periodic --sample S --device gpu`` (S a periodic sample prepared on
    the CPU) runs the sample's equilibrium and the shear on the device and records the CPU's
    history: the same rows and contact counts, the other columns to round-off grown over 340
    steps (measured, dry: 1.2e-10 of the largest volumetric strain, 3.5e-11 of the cell
    stress, 7.8e-9 in the unbalanced force, a residual ratio)."""
    pytest.importorskip("numba_cuda")
    cpu, gpu = histories_on_both("triaxial", ["--particles", 60, "--periodic", "--max-strain",
                                              1e-4, "--quiet"], COMMAND, tmp_path)
    assert_same_records(cpu, gpu, 100)
    for name, values in cpu.items():
        if values.dtype == object:
            continue
        bound = 1e-7 if name == "unbalanced_force" else 1e-9
        assert np.max(np.abs(gpu[name] - values)) <= bound * np.max(np.abs(values)), name


def test_a_radius_growth_in_a_moving_cell_is_refused_by_name():
    """A radius growth runs on the device in a cell whose faces no control moves only (its
    rebuild test does not follow the cell's stretching)."""
    pytest.importorskip("numba_cuda")
    from pendular.dem.growth import RadiusGrowth
    from pendular.gpu.simulation import check_scene

    sim = scene()
    sim.controls = [RadiusGrowth(1e4, 1.0), *sim.controls]
    with pytest.raises(ValueError, match="RadiusGrowth in a periodic cell whose faces no "
                                         "control moves only.*StressServo"):
        check_scene(sim)


if __name__ == "__main__":
    print(json.dumps(agreement(sys.argv[1] == "wet")))
