"""Gravity (pendular.dem.gravity) against closed forms: free fall undamped and under Cundall's
local damping, a sphere resting on the floor wall carrying its weight; refused in a periodic
cell."""

import numpy as np
import pytest

from conftest import RADIUS, YOUNG, two_body_scene
from pendular.dem.cell import PeriodicCell
from pendular.dem.contact_law import ContactForces
from pendular.dem.gravity import Gravity
from pendular.dem.integrate import Integrator
from pendular.dem.neighbors import NeighborList
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles

G = 9.81


@pytest.mark.parametrize("damping", [0.0, 0.2])
def test_a_free_particle_falls_as_the_closed_form(damping):
    """Leapfrog under a constant force: v = -a n dt and z = z0 - a dt^2 n (n + 1) / 2 after n
    steps, exactly: the closed form z0 - a t^2 / 2 lagged by a t dt / 2; a = g undamped, (1 - λ) g
    under local damping (it acts on the weight of a particle that is not in equilibrium)."""
    sim = two_body_scene([[0, 0, 0]], [[0, 0, 0]], damping=damping, extra=[Gravity(G)])
    steps = 500
    sim.run(steps)
    acceleration = (1.0 - damping) * G
    p = sim.particles
    assert p.velocity[0] == pytest.approx([0, 0, -acceleration * steps * sim.dt], rel=1e-12)
    drop = -p.position[0, 2]
    assert drop == pytest.approx(acceleration * sim.dt ** 2 * steps * (steps + 1) / 2, rel=1e-12)
    assert drop - 0.5 * acceleration * sim.time ** 2 == pytest.approx(
        0.5 * acceleration * sim.time * sim.dt, rel=1e-6)


def test_a_sphere_resting_on_the_floor_carries_its_weight():
    """At rest on the z- wall (k_n = E R) the wall carries m g at the overlap m g / (E R): local
    damping brings it there and leaves the weight whole."""
    sim = two_body_scene([[0, 0, -1.0 + RADIUS]], [[0, 0, 0]], damping=0.5, extra=[Gravity(G)])
    sim.run(10000)
    weight = sim.particles.mass[0] * G
    assert sim.walls.force[4] == pytest.approx(weight, rel=1e-6)
    overlap = RADIUS - (sim.particles.position[0, 2] + 1.0)
    assert overlap == pytest.approx(weight / (YOUNG * RADIUS), rel=1e-6)


def test_gravity_is_refused_in_a_periodic_cell():
    particles = Particles(np.array([[0.5, 0.5, 0.5]]) * 1e-2, np.array([RADIUS]), 2650.0)
    sim = Simulation(particles, PeriodicCell.box(np.zeros(3), np.full(3, 1e-2)), 1e-6,
                     neighbors=NeighborList(0.1 * RADIUS),
                     forces=[ContactForces(YOUNG), Gravity(G)], integrator=Integrator())
    with pytest.raises(ValueError, match="periodic cell"):
        sim.run(1)


@pytest.mark.parametrize("value", [0.0, -1.0, 2000.0, float("nan")])
def test_a_gravity_out_of_range_is_refused_naming_it(value):
    with pytest.raises(ValueError, match=r"gravity = .* valid range \(0, 1000\] m/s\^2"):
        Gravity(value)
