"""Wall friction (pendular.dem.wall_friction) against closed forms: a sphere pressed on a wall
and pushed sideways sticks on its spring k_t u and then slides at exactly mu N, with the moment
of the force at its contact point; a sphere sliding on a frictional floor under gravity slows
at mu g and starts rolling at 5/7 of its speed; the springs survive a checkpoint; a scene picks
the wall law its configuration names; bad input is refused in one line."""

import math

import numpy as np
import pytest

from conftest import RADIUS, refused, run_in_process
from pendular.dem.checkpoint import load_checkpoint, save_checkpoint
from pendular.dem.contact_law import ContactForces
from pendular.dem.gravity import Gravity
from pendular.dem.hertz_mindlin import HertzMindlinForces, ViscoelasticWallForces
from pendular.dem.integrate import Integrator
from pendular.dem.neighbors import NeighborList
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.wall_friction import FrictionalWallForces, wall_law
from pendular.dem.walls import WallForces

YOUNG = 1e8                 # [Pa]: kn = E R = 1e5 N/m
SHEAR_RATIO = 0.3
FRICTION = 30.0             # [deg]
MU = math.tan(math.radians(FRICTION))
G = 9.81
DENSITY = 2650.0


class Kinematic:
    """Replaces the integrator: sphere 0 moves at its velocity, nothing accelerates."""

    stateless = True

    def apply(self, sim):
        p = sim.particles
        p.position += p.velocity * sim.dt


def floor_scene(position, velocity, integrator, forces=(), dt=5e-7):
    """One sphere of RADIUS above the floor z = 0 of a box [-1, 1]^2 x [0, 1] with a frictional
    linear wall (FrictionalWallForces) and ``forces`` after it."""
    particles = Particles(np.array([position], float), np.array([RADIUS]), DENSITY,
                          velocity=np.array([velocity], float))
    walls = Walls.box([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0])
    return Simulation(particles, walls, dt, neighbors=NeighborList(0.2 * RADIUS),
                      forces=[ContactForces(YOUNG, SHEAR_RATIO, FRICTION),
                              FrictionalWallForces(YOUNG, SHEAR_RATIO, FRICTION), *forces],
                      integrator=integrator)


def test_a_pressed_sphere_pushed_sideways_sticks_then_slides_at_mu_n():
    """Overlap delta held, the sphere moved along x at u: the tangential force is -k_t u t
    (k_t = 0.3 E R) until it reaches mu N, N = E R delta, then stays on mu N exactly; the
    moment is that of the force at R - delta/2 below the centre; the floor's normal force is
    N alone."""
    overlap, speed = 1e-5, 0.05
    sim = floor_scene([0.0, 0.0, RADIUS - overlap], [speed, 0.0, 0.0], Kinematic())
    normal = YOUNG * RADIUS * overlap
    kt = SHEAR_RATIO * YOUNG * RADIUS
    sticking = int(MU * normal / (kt * speed * sim.dt))
    forces, torques = [], []
    for _ in range(2 * sticking):
        sim.run(1)
        forces.append(sim.particles.force[0].copy())
        torques.append(sim.particles.torque[0].copy())
    forces, torques = np.array(forces), np.array(torques)
    # the force of step n is the spring after n increments, the last evaluated before the move
    displacement = speed * sim.dt * np.arange(1, len(forces) + 1)
    stick = slice(0, sticking - 1)
    np.testing.assert_allclose(forces[stick, 0], -kt * displacement[stick], rtol=1e-9)
    np.testing.assert_allclose(forces[sticking + 1:, 0], -MU * normal, rtol=1e-12)
    np.testing.assert_allclose(forces[:, 2], normal, rtol=1e-9)
    assert np.all(forces[:, 1] == 0.0)
    lever = RADIUS - 0.5 * overlap
    np.testing.assert_allclose(torques[:, 1], -lever * forces[:, 0], rtol=1e-12)   # (-l n) x F
    assert sim.walls.force[4] == pytest.approx(normal, rel=1e-9)


def test_without_friction_the_frictional_wall_is_the_frictionless_one():
    """At a friction angle of 0 the springs carry nothing: the forces and the walls'
    totals of WallForces, to round-off."""
    rng = np.random.default_rng(3)
    position = rng.uniform(0.1, 0.9, (20, 3))
    near = rng.uniform(0.9 * RADIUS, 1.1 * RADIUS, 20)        # each sphere on one wall
    position[np.arange(20), np.arange(20) % 3] = np.where(np.arange(20) < 10, near, 1.0 - near)
    velocity = rng.normal(0, 0.01, (20, 3))
    spin = rng.normal(0, 10.0, (20, 3))
    sims = []
    for wall in (WallForces(YOUNG), FrictionalWallForces(YOUNG, SHEAR_RATIO, 0.0)):
        particles = Particles(position.copy(), np.full(20, RADIUS), DENSITY,
                              velocity=velocity.copy())
        particles.angular_velocity[:] = spin
        sim = Simulation(particles, Walls.box([0.0] * 3, [1.0] * 3), 1e-7,
                         neighbors=NeighborList(0.2 * RADIUS),
                         forces=[ContactForces(YOUNG, SHEAR_RATIO, FRICTION), wall],
                         integrator=Integrator(0.0))
        sim.evaluate_forces()
        sims.append(sim)
    plain, frictional = sims
    assert np.count_nonzero(plain.walls.force) == 6
    np.testing.assert_allclose(frictional.particles.force, plain.particles.force, rtol=1e-14,
                               atol=1e-30)
    assert np.all(frictional.particles.torque == 0.0)
    for name in ("force", "stiffness", "moment"):
        np.testing.assert_allclose(getattr(frictional.walls, name), getattr(plain.walls, name),
                                   rtol=1e-14)


def sliding_scene(speed):
    """A sphere resting on the floor (overlap m g / (E R)) under gravity, sliding along x at
    ``speed`` [m/s] without spin, no damping."""
    mass = DENSITY * 4.0 / 3.0 * math.pi * RADIUS ** 3
    overlap = mass * G / (YOUNG * RADIUS)
    return floor_scene([0.0, 0.0, RADIUS - overlap], [speed, 0.0, 0.0], Integrator(0.0),
                       [Gravity(G)])


def test_a_sliding_sphere_slows_at_mu_g_and_rolls_at_five_sevenths_of_its_speed():
    """Sliding, v = v0 - mu g t and omega = 5 mu g t / (2 R); slip ends at t* = 2 v0 / (7 mu g)
    at v = 5/7 v0, after which the sphere rolls (omega R = v)."""
    v0 = 0.05
    sim = sliding_scene(v0)
    t_star = 2.0 * v0 / (7.0 * MU * G)
    half = int(0.5 * t_star / sim.dt)
    sim.run(half)
    p = sim.particles
    assert p.velocity[0, 0] == pytest.approx(v0 - MU * G * sim.time, rel=1e-7)
    assert p.angular_velocity[0, 1] * RADIUS == pytest.approx(2.5 * MU * G * sim.time, rel=1e-5)
    sim.run(3 * half)
    # rolling: the tangential spring's oscillation about rolling is of order mu g / omega_t
    assert p.velocity[0, 0] == pytest.approx(5.0 / 7.0 * v0, rel=2e-3)
    assert p.angular_velocity[0, 1] * RADIUS == pytest.approx(p.velocity[0, 0], rel=5e-3)
    assert abs(p.velocity[0, 2]) < 1e-9


def test_the_wall_springs_survive_a_checkpoint(tmp_path):
    """A sliding sphere saved mid-slide and resumed is the uninterrupted run, bit for bit."""
    saved = sliding_scene(0.05)
    saved.run(300)
    assert np.any(saved.operation(FrictionalWallForces).wall_shear != 0.0)
    save_checkpoint(tmp_path / "slide.h5", saved)
    resumed = sliding_scene(0.05)
    load_checkpoint(tmp_path / "slide.h5", resumed)
    np.testing.assert_array_equal(resumed.operation(FrictionalWallForces).wall_shear,
                                  saved.operation(FrictionalWallForces).wall_shear)
    for sim in (saved, resumed):
        sim.run(300)
    assert np.array_equal(resumed.particles.velocity, saved.particles.velocity)
    assert np.array_equal(resumed.particles.angular_velocity, saved.particles.angular_velocity)


def test_a_scene_takes_the_wall_law_its_configuration_names():
    from pendular.procedures.preparation import PrepareConfig, dry_simulation

    particles = Particles(np.array([[0.5, 0.5, 0.5]]), np.array([0.1]), DENSITY)
    walls = Walls.box((0, 0, 0), (1, 1, 1))
    for settings, kind, friction in (({}, WallForces, None),
                                     ({"wall_friction": 20.0}, FrictionalWallForces, 20.0),
                                     ({"contact": "hertz-mindlin", "young": 7e10,
                                       "wall_friction": 25.0}, ViscoelasticWallForces, 25.0)):
        config = PrepareConfig(**settings)
        sim = dry_simulation(particles, walls, config, 1e-6, 0.01, 18.0, [])
        wall = sim.forces[1]
        assert type(wall) is kind
        if friction is not None:
            assert wall.friction_deg == friction
    assert type(wall_law(HertzMindlinForces(7e10, 0.2), 7e10)) is ViscoelasticWallForces


@pytest.mark.parametrize("value", [-1.0, 90.0, 120.0])
def test_a_wall_friction_out_of_range_is_refused_naming_it(value):
    with pytest.raises(ValueError, match=r"wall_friction = .* valid range \[0, 90\) deg"):
        FrictionalWallForces(YOUNG, SHEAR_RATIO, value)


@pytest.mark.parametrize("value", ["-5", "90"])
def test_the_command_refuses_a_wall_friction_out_of_range_in_one_line(value, capsys):
    refused(*run_in_process("triaxial", ["--particles", "60", "--wall-friction", value],
                            capsys), "--wall-friction", "[0, 90)")


def test_wall_friction_in_a_periodic_cell_is_refused(capsys):
    refused(*run_in_process("triaxial", ["--particles", "60", "--wall-friction", "20",
                                         "--periodic"], capsys), "--wall-friction", "--periodic")
