"""Sphere–wall bridges in the DEM (pendular.capillary.wall_bridges): the pull of a sphere
touching a wall is the exact sphere–plane bridge's, on the sphere and on the wall; a bridge
breaks when contact is lost, or with persist at the exact rupture distance; its liquid counts
in the water volume, the saturation and the homogenised stresses; checkpoints keep it; bad
input is refused in one line; the GPU refuses it by name."""

import math

import numpy as np
import pytest

from conftest import refused, run_in_process
from pendular.capillary import SURFACE_TENSION, CapillaryBridges
from pendular.capillary.wall_bridge import wall_bridge_at_distance, wall_rupture_distance
from pendular.dem.contact_law import ContactForces
from pendular.dem.neighbors import NeighborList
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.walls import WallForces
from pendular.homogenize.bridge_tensors import wetted_cap_diagonal
from pendular.homogenize.on_the_fly import homogenized

RADIUS = 1e-3
YOUNG = 1e6
SUCTION = 1000.0                               # [Pa]: u = s R / gamma = 13.7
U = SUCTION * RADIUS / SURFACE_TENSION


class Kinematic:
    """Replaces the integrator: the spheres move at their velocities."""

    stateless = True

    def apply(self, sim):
        p = sim.particles
        p.position += p.velocity * sim.dt


def floor_scene(height, velocity=0.0, persist=False, contact_angle=0.0):
    """One sphere with its centre ``height`` [m] above the floor z = 0 of a box [-0.01,
    0.01]^2 x [0, 0.01], moving up at ``velocity`` [m/s], suction-controlled bridges with wall
    bridges."""
    particles = Particles(np.array([[0.0, 0.0, height]]), np.array([RADIUS]), 2650.0,
                          velocity=np.array([[0.0, 0.0, velocity]]))
    walls = Walls.box([-0.01, -0.01, 0.0], [0.01, 0.01, 0.01])
    bridges = CapillaryBridges(SUCTION, contact_angle=contact_angle, persist=persist,
                               wall_bridges=True)
    return Simulation(particles, walls, 1e-4, neighbors=NeighborList(0.5 * RADIUS),
                      forces=[ContactForces(YOUNG), WallForces(YOUNG), bridges],
                      integrator=Kinematic())


@pytest.mark.parametrize("contact_angle", [0.0, 20.0])
def test_a_sphere_on_a_wall_is_pulled_by_the_exact_bridge_at_contact(contact_angle):
    """F = 2 pi gamma R F*(u, D = 0) toward the wall on the sphere, its reaction on the wall:
    the wall carries E R delta - F; the bridge's volume is the exact one."""
    overlap = 1e-6
    sim = floor_scene(RADIUS - overlap, contact_angle=contact_angle)
    sim.evaluate_forces()
    exact = wall_bridge_at_distance(contact_angle, U, 0.0)
    pull = exact.force * 2.0 * math.pi * SURFACE_TENSION * RADIUS
    spring = YOUNG * RADIUS * overlap
    # the table's contact values at u between its nodes: interpolated within 1e-4
    assert spring - sim.particles.force[0, 2] == pytest.approx(pull, rel=1e-4)
    assert sim.walls.force[4] == sim.particles.force[0, 2]
    walls = sim.operation(CapillaryBridges).walls
    assert walls.count() == 1 and walls.exists[0, 4] == 1
    assert walls.force[0, 4] == pytest.approx(spring - sim.particles.force[0, 2], rel=1e-12)
    assert walls.volume[0, 4] == pytest.approx(exact.volume * RADIUS ** 3, rel=1e-4)
    assert walls.filling[0, 4] == pytest.approx(exact.delta1, rel=1e-4)


@pytest.mark.parametrize("persist", [False, True])
def test_a_bridge_breaks_when_contact_is_lost_or_at_the_exact_rupture_distance(persist):
    """Lifted from the wall: without persist the bridge is gone at the first gap; with it, it
    holds to the sphere–plane rupture distance (within the table's interpolation) and breaks
    there."""
    rupture = wall_rupture_distance(0.0, U) * RADIUS
    speed, dt = 1e-3 * rupture / 1e-4, 1e-4          # the gap grows by rupture / 1000 a step
    sim = floor_scene(RADIUS - 1e-7, speed, persist)
    walls = sim.operation(CapillaryBridges).walls
    last_gap = None
    for _ in range(1200):
        sim.run(1)
        gap = sim.particles.position[0, 2] - RADIUS - sim.particles.velocity[0, 2] * dt
        if walls.count() == 0:
            break
        last_gap = gap
    assert walls.count() == 0
    if persist:
        assert last_gap == pytest.approx(rupture, rel=3e-3)
    else:
        assert last_gap is None or last_gap <= 0.0


def test_the_liquid_and_the_stresses_count_the_wall_bridges():
    """The water volume and the saturation hold the wall bridge's liquid; chi gains
    (V_b I + A(R, delta1)) / V with A along the wall's normal, psi = chi s + B with B
    along it too: axisymmetric about z."""
    sim = floor_scene(RADIUS - 1e-6)
    sim.evaluate_forces()
    bridges = sim.operation(CapillaryBridges)
    walls = bridges.walls
    liquid = walls.water_volume()
    assert liquid > 0.0 and bridges.water_volume(sim.contacts) == liquid
    voids = sim.walls.volume() - sim.particles.solid_volume()
    assert bridges.saturation(sim) == pytest.approx(liquid / voids, rel=1e-14)
    measured = homogenized(sim)
    assert measured["water_volume"] == liquid
    lateral, axial = wetted_cap_diagonal(RADIUS, walls.filling[0, 4])
    volume = sim.walls.volume()
    np.testing.assert_allclose(np.diag(measured["chi"]),
                               (liquid + np.array([lateral, lateral, axial])) / volume,
                               rtol=1e-12)
    psi = measured["psi"]
    assert psi[0, 0] == pytest.approx(psi[1, 1], rel=1e-12) and psi[2, 2] != psi[0, 0]
    assert np.all(psi[~np.eye(3, dtype=bool)] == 0.0)
    assert measured["psi_interface"][2, 2] > 0.0


def test_the_wall_bridges_survive_a_checkpoint(tmp_path):
    from pendular.dem.checkpoint import load_checkpoint, save_checkpoint

    saved = floor_scene(RADIUS - 1e-7, 1e-3, persist=True)
    saved.run(3)
    assert saved.operation(CapillaryBridges).walls.count() == 1
    save_checkpoint(tmp_path / "wet.h5", saved)
    resumed = floor_scene(RADIUS - 1e-7, 1e-3, persist=True)
    load_checkpoint(tmp_path / "wet.h5", resumed)
    for name in ("exists", "volume", "force", "filling"):
        assert np.array_equal(getattr(resumed.operation(CapillaryBridges).walls, name),
                              getattr(saved.operation(CapillaryBridges).walls, name)), name
    for sim in (saved, resumed):
        sim.run(5)
    assert np.array_equal(saved.particles.force, resumed.particles.force)


def test_wall_bridges_need_suction_controlled_exact_bridges():
    with pytest.raises(ValueError, match="wall_bridges needs control='suction'"):
        CapillaryBridges(SUCTION, control="volume", wall_bridges=True)
    with pytest.raises(ValueError, match="wall_bridges needs model='exact'"):
        CapillaryBridges(SUCTION, model="toroidal", wall_bridges=True)


@pytest.mark.parametrize("argv, words", [
    (["--wall-bridges"], ("--wall-bridges", "--suction")),
    (["--wall-bridges", "--water-content", "5"], ("--wall-bridges",)),
])
def test_the_command_refuses_wall_bridges_it_cannot_run_in_one_line(argv, words, capsys):
    refused(*run_in_process("triaxial", ["--particles", "60", *argv], capsys), *words)


def test_the_walls_stress_is_the_contacts_and_the_bridges_in_equilibrium():
    """A sphere between the floor and the ceiling, pressed on both and wetting both: the wall
    stress is sigma_contact + sigma_capillary, the bridges' l f on the capillary side."""
    overlap = 2e-6
    particles = Particles(np.array([[0.0, 0.0, RADIUS - overlap]]), np.array([RADIUS]), 2650.0)
    walls = Walls.box([-0.01, -0.01, 0.0], [0.01, 0.01, 2.0 * (RADIUS - overlap)])
    sim = Simulation(particles, walls, 1e-4, neighbors=NeighborList(0.5 * RADIUS),
                     forces=[ContactForces(YOUNG), WallForces(YOUNG),
                             CapillaryBridges(SUCTION, wall_bridges=True)],
                     integrator=Kinematic())
    sim.evaluate_forces()
    assert sim.operation(CapillaryBridges).walls.count() == 2
    assert abs(sim.particles.force[0, 2]) < 1e-12 * sim.walls.force[4]
    measured = homogenized(sim)
    total = measured["sigma_contact"] + measured["sigma_capillary"]
    assert measured["sigma_capillary"][2, 2] < 0.0 < measured["sigma_contact"][2, 2]
    assert total[2, 2] == pytest.approx(sim.walls.stress()[2], rel=1e-12)
