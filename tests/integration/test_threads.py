"""Thread counts: a dry and a wet scene give bit-identical trajectories with 1 and 2 Numba
threads, and an undamped frictionless dense packing conserves its energy on both.

(tests/integration/test_energy.py checks the energy error's order in dt on one thread; here the
multi-body packing runs on both thread counts, and the wet scene adds capillary bridges.)
"""

import numpy as np
import pytest

from pendular.capillary import CapillaryBridges
from pendular.dem.contact_law import ContactForces, normal_stiffness
from pendular.dem.integrate import Integrator
from pendular.dem.neighbors import NeighborList
from pendular.dem.cloud import random_cloud
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.walls import WallForces

from conftest import SpringEnergyProbe, requires

RADIUS, YOUNG, DENSITY, EDGE = 1e-3, 1e6, 2650.0, 0.016
#: Steps run on two threads (each costs ~10-30 ms on a loaded 2-core machine).
TWO_THREAD_STEPS = 200
#: Radius / placement radius: the overlaps that load the packing.
INFLATION = 1.3

pytestmark = requires("threads")


def dense_packing(threads, friction_deg=0.0, damping=0.0, suction=None, count=200):
    """``count`` spheres placed without overlap then inflated by INFLATION: a dense, loaded packing
    with random velocities, frictionless and undamped unless asked; ``suction`` adds bridges."""
    position = random_cloud(count, RADIUS, np.zeros(3), np.full(3, EDGE), seed=4)
    velocity = np.random.default_rng(9).normal(scale=0.05, size=(count, 3))
    particles = Particles(position, np.full(count, INFLATION * RADIUS), DENSITY, velocity=velocity)
    dt = 0.05 * np.sqrt(particles.mass[0] / normal_stiffness(YOUNG, RADIUS, RADIUS))
    probe = SpringEnergyProbe(YOUNG)
    forces = [ContactForces(YOUNG, 0.3, friction_deg), WallForces(YOUNG)]
    if suction is not None:
        forces.append(CapillaryBridges(suction, 0.073))
    sim = Simulation(particles, Walls.box(np.zeros(3), np.full(3, EDGE)), dt,
                     neighbors=NeighborList(0.3 * RADIUS), forces=forces, controls=[probe],
                     integrator=Integrator(damping), threads=threads)
    return sim, probe


def total_energy(sim, probe):
    """Kinetic energy at the on-step velocity (mean of v(t -/+ dt/2)) plus spring energy [J]."""
    on_step = 0.5 * (probe.velocity_before + sim.particles.velocity)
    return 0.5 * np.sum(sim.particles.mass * np.sum(on_step ** 2, axis=1)) + probe.energy


@pytest.mark.parametrize("scene", [
    {"friction_deg": 20.0, "damping": 0.2},
    {"friction_deg": 20.0, "damping": 0.2, "suction": 2000.0},
], ids=["dry", "wet"])
def test_one_and_two_threads_give_identical_trajectories(scene):
    runs = []
    for threads in (1, 2):
        sim, _ = dense_packing(threads, **scene)
        sim.run(TWO_THREAD_STEPS)
        runs.append(sim)
    one, two = runs
    assert one.threads == 1 and two.threads == 2
    assert one.operation(NeighborList).rebuilds > 1          # lists were rebuilt on the way
    if "suction" in scene:
        bridges = one.operation(CapillaryBridges).count(one)
        assert bridges > 5 and bridges == two.operation(CapillaryBridges).count(two)
    for name in ("position", "velocity", "angular_velocity", "force"):
        assert np.array_equal(getattr(one.particles, name), getattr(two.particles, name)), name
    assert np.array_equal(one.walls.force, two.walls.force)
    assert np.array_equal(one.contacts.shear_force, two.contacts.shear_force)


def energy_history(threads, steps, every=200):
    """Total energy every ``every`` steps of the undamped frictionless packing; (start, array)."""
    sim, probe = dense_packing(threads)
    sim.run(1)
    start = total_energy(sim, probe)
    energies = []
    for _ in range(steps // every):
        sim.run(every)
        energies.append(total_energy(sim, probe))
    assert np.count_nonzero(sim.contacts.overlap > 0.0) > len(sim.particles)   # dense: Z > 2
    assert probe.energy > 0.1 * start                            # springs hold a fair share
    return start, np.array(energies)


def test_undamped_frictionless_packing_conserves_energy_on_both_thread_counts():
    """5,000 steps on one thread: bounded drift; the two-thread run (shorter: a second thread
    is slow on a loaded machine) follows the same energies bit for bit."""
    start, one = energy_history(1, 5000)
    assert np.abs(one / start - 1.0).max() < 1e-3
    start_two, two = energy_history(2, TWO_THREAD_STEPS)
    assert start_two == start and np.array_equal(two, one[:len(two)])
