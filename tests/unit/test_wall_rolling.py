"""Rolling and twisting resistance on the walls (pendular.dem.wall_rolling) against closed forms:
a sphere held on a wall and spinning slowly turns on an elastic spring, M = -k_r theta,
k_r = 2.25 k_n mu_r^2 R^2, and oscillates at sqrt(k_r / I); spinning fast, the moments sit on
mu_r R F_n and mu_t R F_n and its spin decays at those over I; rolling without slip on a
frictional floor under gravity it slows at a = -mu_r R F_n R / (I + m R l) (l the lever of the
friction force, R - delta/2); the springs survive a checkpoint; a configuration's walls take
the moments only when asked; ``pendular impact --target wall`` spins down at the EPSD rate."""

import math

import numpy as np
import pytest

from conftest import RADIUS, refused, run_in_process
from pendular.dem.checkpoint import load_checkpoint, save_checkpoint
from pendular.dem.contact_law import ContactForces
from pendular.dem.gravity import Gravity
from pendular.dem.hertz_mindlin import HertzMindlinForces, ViscoelasticWallForces
from pendular.dem.integrate import Integrator
from pendular.dem.material import Material, rigid_wall
from pendular.dem.neighbors import NeighborList
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.wall_friction import FrictionalWallForces
from pendular.dem.wall_rolling import WallRollingResistance
from pendular.dem.walls import WallForces
from pendular.procedures import impact
from pendular.utils.parameters import option_values

YOUNG = 1e8                 # [Pa]: kn = E R = 1e5 N/m
SHEAR_RATIO = 0.3
DENSITY = 2650.0
G = 9.81
MASS = DENSITY * 4.0 / 3.0 * math.pi * RADIUS ** 3
INERTIA = 0.4 * MASS * RADIUS ** 2


class Spinning:
    """Replaces the integrator: the sphere stays where it is, its spin follows its torque
    (w += T / I dt)."""

    stateless = True

    def apply(self, sim):
        p = sim.particles
        p.angular_velocity += p.torque / p.inertia[:, None] * sim.dt


def floor_scene(overlap, spin, wall, integrator, contact=None, wall_forces=None, extra=(),
                velocity=(0.0, 0.0, 0.0), dt=5e-7, damping_ratio=0.0):
    """One sphere of RADIUS on the floor z = 0 of a box [-1, 1]^2 x [0, 1] at ``overlap`` [m],
    spinning at ``spin`` (3,) [rad/s] and moving at ``velocity``: ``contact`` (the linear
    law by default), ``wall_forces`` (its frictionless walls by default), the walls' rolling
    resistance of the Material ``wall`` (its dashpots' ``damping_ratio``), then ``extra``
    forces."""
    contact = ContactForces(YOUNG, SHEAR_RATIO, 30.0) if contact is None else contact
    particles = Particles(np.array([[0.0, 0.0, RADIUS - overlap]]), np.array([RADIUS]),
                          DENSITY, velocity=np.array([velocity], float),
                          angular_velocity=np.array([spin], float))
    walls = Walls.box([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0])
    wall_forces = WallForces(YOUNG) if wall_forces is None else wall_forces
    return Simulation(particles, walls, dt, neighbors=NeighborList(0.2 * RADIUS),
                      forces=[contact, wall_forces,
                              WallRollingResistance(contact, wall, damping_ratio), *extra],
                      integrator=integrator)


def rolling_wall(rolling, twisting=0.0):
    return Material(math.inf, rolling_friction=rolling, twisting_friction=twisting)


def test_below_the_limit_the_moment_is_an_elastic_spring():
    """Slow spin w0 about x: M = -k_r theta, theta the angle turned, k_r = 2.25 kn mu_r^2 R^2
    (kn = E R); w(t) = w0 cos(Omega t), Omega = sqrt(k_r / I), so the spin first vanishes at
    pi / (2 Omega) and the peak moment is w0 sqrt(k_r I), below mu_r R Fn."""
    mu, overlap, w0 = 0.3, 1e-5, 0.05
    sim = floor_scene(overlap, [w0, 0.0, 0.0], rolling_wall(mu), Spinning())
    kn = YOUNG * RADIUS
    stiffness = 2.25 * kn * mu ** 2 * RADIUS ** 2
    omega = math.sqrt(stiffness / INERTIA)
    quarter = int(0.5 * math.pi / omega / sim.dt)
    angle, spins, moments = 0.0, [], []
    for _ in range(2 * quarter):
        angle += sim.particles.angular_velocity[0, 0] * sim.dt      # the spin the step reads
        sim.run(1)
        spins.append(sim.particles.angular_velocity[0, 0])
        moments.append(sim.particles.torque[0, 0])
        assert moments[-1] == pytest.approx(-stiffness * angle, rel=1e-9)
    spins, moments = np.array(spins), np.array(moments)
    assert abs(int(np.argmax(spins < 0.0)) - quarter) <= 1
    peak = w0 * math.sqrt(stiffness * INERTIA)
    assert np.abs(moments).max() == pytest.approx(peak, rel=1e-3)
    assert peak < mu * RADIUS * kn * overlap
    np.testing.assert_array_equal(sim.particles.torque[0, 1:], 0.0)


def test_below_the_limit_the_twisting_dashpot_damps_at_its_ratio():
    """Slow spin w0 about the floor's normal, damping ratio eta: the twisting spring and
    dashpot (-eta 2 sqrt(I k_t) w) make a damped oscillator, whose successive spin maxima fall
    by exp(-2 pi eta / sqrt(1 - eta^2))."""
    mu, overlap, w0, eta = 0.3, 1e-5, 0.05, 0.1
    sim = floor_scene(overlap, [0.0, 0.0, w0], rolling_wall(0.0, mu), Spinning(),
                      damping_ratio=eta)
    spins = []
    for _ in range(800):
        sim.run(1)
        spins.append(sim.particles.angular_velocity[0, 2])
    spins = np.array(spins)
    peaks = [k for k in range(1, len(spins) - 1) if spins[k - 1] < spins[k] >= spins[k + 1]]
    assert len(peaks) >= 3
    decrement = spins[peaks[1]] / spins[peaks[0]]
    expected = math.exp(-2.0 * math.pi * eta / math.sqrt(1.0 - eta ** 2))
    assert decrement == pytest.approx(expected, rel=1e-2)
    assert spins[peaks[2]] / spins[peaks[1]] == pytest.approx(decrement, rel=1e-3)


@pytest.mark.parametrize("contact", ["linear", "hertz-mindlin"])
def test_on_the_limit_the_spin_decays_at_mu_r_fn_r_over_i(contact):
    """Fast spin about x (rolling) and z (twisting) on a frictionless wall: once the springs
    reach their limits the moments are mu_r R Fn and mu_t R Fn against the spin, and each
    step takes mu R Fn dt / I off it (Fn = E R delta, or Hertz's 4/3 E* sqrt(R) delta^3/2
    with E* = E / (1 - nu^2) on a rigid wall)."""
    mu_r, mu_t, overlap, w0 = 0.2, 0.1, 1e-7, 1000.0
    law = (ContactForces(YOUNG, SHEAR_RATIO, 30.0) if contact == "linear"
           else HertzMindlinForces(YOUNG, 0.25, 1.0, 30.0))
    walls = None if contact == "linear" else ViscoelasticWallForces(law, rigid_wall())
    sim = floor_scene(overlap, [w0, 0.0, w0], rolling_wall(mu_r, mu_t), Spinning(), law,
                      walls)
    if contact == "linear":
        normal = YOUNG * RADIUS * overlap
    else:
        normal = 4.0 / 3.0 * YOUNG / (1.0 - 0.25 ** 2) * math.sqrt(RADIUS) * overlap ** 1.5
    sim.run(200)        # past the springs' elastic turn (theta = Fn / (2.25 kn mu R))
    before = sim.particles.angular_velocity[0].copy()
    steps = 1000
    sim.run(steps)
    np.testing.assert_allclose(sim.particles.torque[0], [-mu_r * RADIUS * normal, 0.0,
                                                         -mu_t * RADIUS * normal], rtol=1e-12)
    drop = (before - sim.particles.angular_velocity[0]) * INERTIA / (steps * sim.dt)
    np.testing.assert_allclose(drop, [mu_r * RADIUS * normal, 0.0, mu_t * RADIUS * normal],
                               rtol=1e-9)


def rolling_scene(v0, mu_r, restitution=0.3):
    """A sphere resting on a frictional (tan 30 deg), damped (``restitution``) linear floor
    under gravity at its static overlap, rolling along x at ``v0`` [m/s] (w_y = v0 / R)."""
    overlap = MASS * G / (YOUNG * RADIUS)
    contact = ContactForces(YOUNG, SHEAR_RATIO, 30.0)
    return floor_scene(overlap, [0.0, v0 / RADIUS, 0.0], rolling_wall(mu_r), Integrator(0.0),
                       contact, FrictionalWallForces(YOUNG, SHEAR_RATIO, 30.0, restitution),
                       [Gravity(G)], velocity=(v0, 0.0, 0.0)), overlap


def test_a_sphere_rolling_without_slip_slows_at_the_epsd_rate():
    """Rolling without slip (v = w R), m a = F, I dw/dt = -l F - M with M = mu_r R Fn,
    Fn = m g, l = R - delta/2 the friction force's lever: a = -M R / (I + m R l), about
    -(5/7) mu_r g for delta << R."""
    v0, mu_r = 0.02, 0.1
    sim, overlap = rolling_scene(v0, mu_r)
    sim.run(2000)              # the tangential spring settles (its dashpot)
    p = sim.particles
    t0, v1 = sim.time, p.velocity[0, 0]
    sim.run(4000)
    rate = (p.velocity[0, 0] - v1) / (sim.time - t0)
    lever = RADIUS - 0.5 * overlap
    expected = -mu_r * RADIUS * MASS * G * RADIUS / (INERTIA + MASS * RADIUS * lever)
    assert rate == pytest.approx(expected, rel=1e-6)
    assert expected == pytest.approx(-5.0 / 7.0 * mu_r * G, rel=1e-3)
    assert p.angular_velocity[0, 1] * RADIUS == pytest.approx(p.velocity[0, 0], rel=1e-4)


def test_the_wall_springs_survive_a_checkpoint(tmp_path):
    """A rolling sphere saved mid-roll and resumed is the uninterrupted run, bit for bit."""
    saved, _ = rolling_scene(0.02, 0.1)
    saved.run(300)
    springs = saved.operation(WallRollingResistance)
    assert np.any(springs.wall_rolling_moment != 0.0)
    save_checkpoint(tmp_path / "roll.h5", saved)
    resumed, _ = rolling_scene(0.02, 0.1)
    load_checkpoint(tmp_path / "roll.h5", resumed)
    np.testing.assert_array_equal(resumed.operation(WallRollingResistance).wall_rolling_moment,
                                  springs.wall_rolling_moment)
    for sim in (saved, resumed):
        sim.run(300)
    assert np.array_equal(resumed.particles.velocity, saved.particles.velocity)
    assert np.array_equal(resumed.particles.angular_velocity, saved.particles.angular_velocity)


def test_a_configuration_puts_moments_on_its_walls_only_when_asked():
    from pendular.procedures.preparation import PrepareConfig, dry_simulation

    particles = Particles(np.array([[0.5, 0.5, 0.5]]), np.array([0.1]), DENSITY)
    walls = Walls.box((0, 0, 0), (1, 1, 1))
    kinds = {}
    for name, settings in (("plain", {"rolling_friction": 0.2}),
                           ("walls", {"wall_rolling_friction": 0.2}),
                           ("twist", {"wall_twisting_friction": 0.1, "contact": "hertz-mindlin",
                                      "young": 7e10})):
        sim = dry_simulation(particles, walls, PrepareConfig(**settings), 1e-6, 0.01, 18.0, [])
        kinds[name] = [type(op).__name__ for op in sim.forces]
        growing = dry_simulation(particles, walls, PrepareConfig(**settings), 1e-6, 0.01, 18.0,
                                 [], resistance=False)
        assert not any(isinstance(op, WallRollingResistance) for op in growing.forces)
    assert "WallRollingResistance" not in kinds["plain"]
    assert kinds["walls"] == ["ContactForces", "WallForces", "WallRollingResistance"]
    assert kinds["twist"][-1] == "WallRollingResistance"


def test_wall_rolling_friction_out_of_range_or_in_a_periodic_cell_is_refused(capsys):
    refused(*run_in_process("triaxial", ["--particles", "60", "--wall-rolling-friction",
                                         "0.6"], capsys), "--wall-rolling-friction", "0.5")
    refused(*run_in_process("triaxial", ["--particles", "60", "--wall-twisting-friction",
                                         "0.1", "--periodic"], capsys),
            "--wall-twisting-friction", "periodic")


def test_an_impact_on_the_wall_spins_down_at_the_epsd_rate():
    """``pendular impact --target wall`` with --rolling-friction (the wall's, unless
    --wall-rolling-friction) on a frictionless wall: a sphere spinning fast enough that its
    spring sits on the limit through the contact loses mu_r R J / I of its spin, J = 2 m v
    the elastic contact's normal impulse (its springs' elastic turn, theta = Fn / (2.25 kn mu_r
    R), shortens the lever on J little)."""
    values, _ = option_values(impact.OPTIONS, {
        "target": "wall", "contact": "linear", "velocity": 0.05, "spin": 2000.0,
        "friction": 0.0, "rolling_friction": 0.2})
    summary = impact.run_impact(values)[0]
    radius, mass = values["radius"], values["density"] * 4.0 / 3.0 * math.pi * 0.01 ** 3
    lost = 0.2 * radius * 2.0 * mass * 0.05 / (0.4 * mass * radius ** 2)
    assert 2000.0 - summary["rebound_angular_velocity"] == pytest.approx(lost, rel=1e-6)
    assert summary["normal_restitution"] == pytest.approx(1.0, rel=1e-3)
    quiet, _ = option_values(impact.OPTIONS, {**values, "wall_rolling_friction": 0.0})
    assert impact.run_impact(quiet)[0]["rebound_angular_velocity"] == 2000.0
