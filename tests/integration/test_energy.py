"""Energy conservation of an undamped, frictionless packing with walls."""

import numpy as np

from pendular.dem.measure import kinetic_energy
from pendular.dem.cloud import random_cloud
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.contact_law import ContactForces, normal_stiffness
from pendular.dem.integrate import Integrator
from pendular.dem.neighbors import NeighborList
from pendular.dem.walls import WallForces

from conftest import SpringEnergyProbe


def energy_error(timestep_factor, steps):
    """Largest relative deviation of the total energy of an undamped frictionless packing."""
    radius, young, density = 1e-3, 1e6, 2650.0
    edge = 0.02
    position = random_cloud(500, radius, np.zeros(3), np.full(3, edge), seed=2)
    rng = np.random.default_rng(5)
    # radii 10 % larger than placed: the packing starts overlapped and loaded
    particles = Particles(position, np.full(500, 1.1 * radius), density,
                          velocity=rng.normal(scale=0.05, size=(500, 3)))
    walls = Walls.box(np.zeros(3), np.full(3, edge))
    dt = timestep_factor * np.sqrt(particles.mass[0] / normal_stiffness(young, radius, radius))
    probe = SpringEnergyProbe(young)
    sim = Simulation(particles, walls, dt, neighbors=NeighborList(0.3 * radius),
                     forces=[ContactForces(young, 0.3, 0.0), WallForces(young)],
                     controls=[probe], integrator=Integrator(damping=0.0))

    def total():
        # leapfrog: springs at x(t), velocities at t -/+ dt/2; v(t) is their mean
        on_step = 0.5 * (probe.velocity_before + sim.particles.velocity)
        return 0.5 * np.sum(sim.particles.mass * np.sum(on_step ** 2, axis=1)) + probe.energy

    sim.run(1)
    start = total()
    energies = []
    for _ in range(20):
        sim.run(steps // 20)
        energies.append(total())
    assert np.count_nonzero(sim.contacts.overlap > 0) > 100
    assert probe.energy > 0.1 * start
    return np.abs(np.array(energies) / start - 1.0).max()


def test_total_energy_is_conserved_without_damping():
    """Leapfrog with no damping and no friction conserves kinetic + spring energy: the error is
    bounded (no drift) and second order in dt. Both runs cover the same time, 2,000 steps of
    the coarse step (about 45 contact durations pi sqrt(m / 2 kn)): enough for the error's
    order; tests/integration/test_threads.py follows a packing over 5,000 steps for drift."""
    coarse = energy_error(0.05, steps=2000)
    fine = energy_error(0.025, steps=4000)
    assert coarse < 1e-3
    assert coarse / fine > 3.0


def test_damping_dissipates_energy():
    radius, young = 1e-3, 1e6
    position = random_cloud(200, radius, np.zeros(3), np.full(3, 0.02), seed=3)
    rng = np.random.default_rng(6)
    particles = Particles(position, np.full(200, radius), 2650.0,
                          velocity=rng.normal(scale=0.05, size=(200, 3)))
    walls = Walls.box(np.zeros(3), np.full(3, 0.02))
    dt = 0.05 * np.sqrt(particles.mass[0] / normal_stiffness(young, radius, radius))
    sim = Simulation(particles, walls, dt,
                     neighbors=NeighborList(0.3 * radius),
                     forces=[ContactForces(young, 0.3, 20.0), WallForces(young)],
                     integrator=Integrator(damping=0.2))
    start = kinetic_energy(sim.particles)
    sim.run(5000)
    assert kinetic_energy(sim.particles) < 0.8 * start
