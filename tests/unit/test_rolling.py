"""Rolling and twisting resistance (pendular.dem.rolling, Ai et al. 2011's EPSD model) against
its closed forms: the elastic spring k θ, the plastic limit μ R* F_n, the deceleration of a
sphere spinning on a fixed one in full rolling and full twisting, the viscous part; the springs
turning with the contact, carried across a neighbour-list rebuild, the same on 1 and 2 threads;
the options' errors."""

import numpy as np
import pytest

from conftest import RADIUS, YOUNG, refused, requires, run_in_process, two_body_scene
from pendular.capillary import CapillaryBridges
from pendular.dem.contact_law import normal_stiffness
from pendular.dem.integrate import Integrator
from pendular.dem.neighbors import NeighborList
from pendular.dem.protocols import pair_key
from pendular.dem.rolling import FIELDS, OWNER, RollingResistance
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.walls import WallForces
from pendular.dem.contact_law import ContactForces
from pendular.dem.gravity import Gravity
from pendular.dem.cloud import random_cloud
from pendular.procedures.preparation import PrepareConfig, servoed_simulation

OVERLAP = 1e-5                                  # [m], 0.01 R
REDUCED = 0.5 * RADIUS                          # R* of two equal spheres [m]
NORMAL_FORCE = normal_stiffness(YOUNG, RADIUS, RADIUS) * OVERLAP        # [N]


def rolling_stiffness(mu):
    """k_r = 2.25 k_n mu^2 R*^2 [N m/rad] of the pressed pair."""
    return 2.25 * normal_stiffness(YOUNG, RADIUS, RADIUS) * mu ** 2 * REDUCED ** 2


class Spin:
    """Replaces the integrator: nothing moves but sphere 0's rotation, which follows its
    torque (``free``) or keeps its angular velocity."""

    stateless = True

    def __init__(self, free):
        self.free = free

    def apply(self, sim):
        p = sim.particles
        p.velocity[:] = 0.0
        p.angular_velocity[1] = 0.0
        if self.free:
            p.angular_velocity[0] += p.torque[0] / p.inertia[0] * sim.dt


def pressed_pair(spin, rolling=0.0, twisting=0.0, damping_ratio=0.0, free=False):
    """Sphere 0 at the origin spinning at ``spin`` (3,) [rad/s], pressed (OVERLAP) on sphere 1
    along +x, which holds still; frictionless contacts (the shear force adds no torque)."""
    sim = two_body_scene([[0, 0, 0], [2 * RADIUS - OVERLAP, 0, 0]], [[0, 0, 0], [0, 0, 0]],
                         extra=[RollingResistance(rolling, twisting, damping_ratio)])
    sim.particles.angular_velocity[0] = spin
    sim.integrator = Spin(free)
    return sim


def moments(sim):
    """name -> the per-pair array of the rolling resistance (pendular.dem.rolling.FIELDS)."""
    return {field.name: sim.contacts.extra[pair_key(OWNER, field)] for field in FIELDS}


@pytest.mark.parametrize("axis, mu_r, mu_t", [(2, 0.2, 0.0), (0, 0.0, 0.3)],
                         ids=["rolling", "twisting"])
def test_a_small_relative_rotation_is_held_by_the_spring(axis, mu_r, mu_t):
    """Below the limit the moment on the spinning sphere is -k theta, its opposite on the other."""
    speed = 0.5
    sim = pressed_pair(np.eye(3)[axis] * speed, mu_r, mu_t)
    steps = 100
    sim.run(steps)
    theta = speed * steps * sim.dt                              # [rad]
    moment = -rolling_stiffness(max(mu_r, mu_t)) * theta
    assert abs(moment) < 0.5 * max(mu_r, mu_t) * REDUCED * NORMAL_FORCE      # elastic
    assert sim.particles.torque[0] == pytest.approx(np.eye(3)[axis] * moment, rel=1e-12,
                                                    abs=1e-30)
    assert np.array_equal(sim.particles.torque[1], -sim.particles.torque[0])


@pytest.mark.parametrize("axis, mu_r, mu_t", [(2, 0.2, 0.0), (1, 0.1, 0.3), (0, 0.3, 0.2)],
                         ids=["rolling", "rolling with twisting", "twisting"])
def test_the_moment_is_capped_at_mu_r_times_r_star_times_the_normal_force(axis, mu_r, mu_t):
    """Past the limit the moment stays on it, mu R* F_n, against the relative rotation."""
    speed = 1000.0
    sim = pressed_pair(np.eye(3)[axis] * speed, mu_r, mu_t)
    sim.run(300)
    mu = mu_t if axis == 0 else mu_r
    assert speed * 300 * sim.dt > 2 * mu * REDUCED * NORMAL_FORCE / rolling_stiffness(mu)
    expected = -mu * REDUCED * NORMAL_FORCE * np.eye(3)[axis]
    assert sim.particles.torque[0] == pytest.approx(expected, rel=1e-12, abs=1e-30)
    state = moments(sim)
    assert np.linalg.norm(state["rolling_moment"][0]) == pytest.approx(
        0.0 if axis == 0 else mu_r * REDUCED * NORMAL_FORCE, rel=1e-12, abs=1e-30)


@pytest.mark.parametrize("axis, mu_r, mu_t", [(2, 0.2, 0.0), (0, 0.0, 0.2)],
                         ids=["rolling", "twisting"])
def test_a_spinning_sphere_on_a_fixed_one_slows_at_the_limit_moment(axis, mu_r, mu_t):
    """Full rolling (twisting): omega(t) = omega0 - M_max t / I once the spring has reached
    its limit, after an elastic rotation M_max / k that takes t_e = M_max / (k omega0)."""
    omega0 = 2000.0
    sim = pressed_pair(np.eye(3)[axis] * omega0, mu_r, mu_t, free=True)
    mu = max(mu_r, mu_t)
    limit = mu * REDUCED * NORMAL_FORCE
    inertia = sim.particles.inertia[0]
    elastic = limit / (rolling_stiffness(mu) * omega0)          # t_e [s]
    sim.run(2000)
    early = sim.particles.angular_velocity[0, axis]
    sim.run(2000)
    late = sim.particles.angular_velocity[0, axis]
    assert late > 0.3 * omega0                                   # still spinning
    assert late - early == pytest.approx(-limit / inertia * 2000 * sim.dt, rel=1e-9)
    assert late == pytest.approx(omega0 - limit / inertia * sim.time,
                                 abs=limit / inertia * elastic)
    assert np.count_nonzero(sim.particles.angular_velocity[0]) == 1     # about its own axis


def test_the_viscous_part_damps_the_relative_rotation_below_the_limit():
    """Ai et al.'s dashpot: -eta 2 sqrt(I_r k_r) omega on top of the spring, I_r the pair's
    inertia about the contact point, [2 / (I + m R^2)]^-1 for equal spheres."""
    speed, eta, mu = 0.5, 0.3, 0.2
    sim = pressed_pair([0, 0, speed], mu, damping_ratio=eta)
    sim.run(100)
    p = sim.particles
    equivalent = 0.5 * (p.inertia[0] + p.mass[0] * RADIUS ** 2)
    viscous = eta * 2.0 * np.sqrt(equivalent * rolling_stiffness(mu)) * speed
    spring = rolling_stiffness(mu) * speed * 100 * sim.dt
    assert p.torque[0, 2] == pytest.approx(-spring - viscous, rel=1e-12)
    assert moments(sim)["rolling_moment"][0, 2] == pytest.approx(-spring, rel=1e-12)


def test_the_rolling_moment_turns_with_a_pair_orbiting_as_a_rigid_body():
    """A loaded spring kept as the pair turns rigidly about z by a quarter turn: the moment
    turns with the normal, its size kept (relative rotation zero: no increment)."""
    sim = pressed_pair([0, 0.5, 0], 0.2)
    sim.run(50)
    before = moments(sim)["rolling_moment"][0].copy()
    assert before[1] < 0.0 and before[0] == before[2] == 0.0
    steps = 2000
    rate = 0.5 * np.pi / (steps * sim.dt)                        # [rad/s]
    centre = 0.5 * sim.particles.position[1]
    offset = sim.particles.position - centre
    start = sim.step

    class Orbit:
        stateless = True

        def apply(self, s):
            angle = rate * (s.step + 1 - start) * s.dt
            turn = np.array([[np.cos(angle), -np.sin(angle), 0],
                             [np.sin(angle), np.cos(angle), 0], [0, 0, 1]])
            s.particles.position[:] = centre + offset @ turn.T
            s.particles.angular_velocity[:] = [0, 0, rate]

    sim.particles.angular_velocity[:] = [0, 0, rate]
    sim.integrator = Orbit()
    sim.run(steps)
    sim.evaluate_forces()                       # at the quarter turn
    after = moments(sim)["rolling_moment"][0]
    assert np.linalg.norm(after) == pytest.approx(np.linalg.norm(before), rel=1e-3)
    assert after == pytest.approx([-before[1], 0, 0], abs=1e-3 * np.linalg.norm(before))


def test_the_springs_are_carried_to_the_same_pairs_across_a_rebuild():
    """A new pair listed before two loaded ones moves them in the list; their springs follow."""
    sim = two_body_scene([[0, 0, 0], [2 * RADIUS - OVERLAP, 0, 0], [0, 5 * RADIUS, 0],
                          [2 * RADIUS - OVERLAP, 5 * RADIUS, 0], [0, -10 * RADIUS, 0]],
                         np.zeros((5, 3)), extra=[RollingResistance(0.2, 0.1)])
    sim.particles.angular_velocity[[0, 2]] = [[0.3, 0, 0.5], [0.2, 0.4, 0]]
    sim.integrator = Spin(False)
    sim.run(20)

    def springs(s):
        state = moments(s)
        return {(int(i), int(j)): (state["rolling_moment"][k].copy(),
                                   state["twisting_moment"][k])
                for k, (i, j) in enumerate(zip(s.contacts.pair_i, s.contacts.pair_j))
                if s.contacts.overlap[k] > 0.0}

    before = springs(sim)
    assert set(before) == {(0, 1), (2, 3)}
    sim.particles.position[4] = [0, -2.05 * RADIUS, 0]            # within the skin of sphere 0
    sim.operation(NeighborList).rebuild(sim)
    pairs = list(zip(sim.contacts.pair_i.tolist(), sim.contacts.pair_j.tolist()))
    assert pairs.index((2, 3)) > pairs.index((0, 4))
    state = moments(sim)
    for (i, j), (rolling, twisting) in before.items():
        k = pairs.index((i, j))
        assert np.array_equal(state["rolling_moment"][k], rolling)
        assert state["twisting_moment"][k] == twisting != 0.0
    assert not state["rolling_moment"][pairs.index((0, 4))].any()


@requires("threads")
def test_one_and_two_threads_give_identical_trajectories():
    runs = []
    for threads in (1, 2):
        count, edge = 80, 0.012
        position = random_cloud(count, RADIUS, np.zeros(3), np.full(3, edge), seed=5)
        velocity = np.random.default_rng(2).normal(scale=0.05, size=(count, 3))
        particles = Particles(position, np.full(count, 1.3 * RADIUS), 2650.0,
                              velocity=velocity)
        dt = 0.05 * np.sqrt(particles.mass[0] / normal_stiffness(YOUNG, RADIUS, RADIUS))
        sim = Simulation(particles, Walls.box(np.zeros(3), np.full(3, edge)), dt,
                         neighbors=NeighborList(0.3 * RADIUS),
                         forces=[ContactForces(YOUNG, 0.3, 20.0), WallForces(YOUNG),
                                 RollingResistance(0.3, 0.1, damping_ratio=0.3)],
                         integrator=Integrator(0.2), threads=threads)
        sim.run(150)
        runs.append(sim)
    one, two = runs
    assert one.operation(NeighborList).rebuilds > 1
    assert np.count_nonzero(moments(one)["twisting_moment"]) > 20
    for name in ("position", "angular_velocity", "torque"):
        assert np.array_equal(getattr(one.particles, name), getattr(two.particles, name)), name
    for name, array in moments(one).items():
        assert np.array_equal(array, moments(two)[name]), name


@pytest.mark.parametrize("option, value, valid", [
    ("--rolling-friction", "-0.1", "[0, 0.5]"),
    ("--twisting-friction", "0.6", "[0, 0.5]"),
    ("--gravity", "-9.81", "[0, 1000]"),
])
def test_a_coefficient_out_of_range_is_refused_naming_the_option(option, value, valid, capsys):
    refused(*run_in_process("triaxial", ["--particles", "60", option, value], capsys), option,
            valid)


def test_gravity_in_a_periodic_cell_is_refused(capsys):
    refused(*run_in_process("triaxial", ["--particles", "60", "--gravity", "9.81",
                                         "--periodic"], capsys), "--gravity", "--periodic")


def test_a_loaded_sample_gets_the_resistance_and_the_weight_and_a_plain_one_neither():
    """A sample's scene (preparation.servoed_simulation, as a loaded --sample and a resumed run
    build it) holds the forces its configuration asks for, after the contact law."""
    position = random_cloud(30, RADIUS, np.zeros(3), np.full(3, 0.01), seed=1)
    kinds = {}
    for name, options in (("plain", {}), ("resisting", {"rolling_friction": 0.2,
                                                       "twisting_friction": 0.1,
                                                       "gravity": 9.81})):
        config = PrepareConfig(particles=30, radius=RADIUS, **options)
        sim = servoed_simulation(Particles(position, np.full(30, RADIUS), config.density),
                                 Walls.box(np.zeros(3), np.full(3, 0.01)), config, 750.0)
        kinds[name] = [type(op) for op in sim.forces]
    assert kinds["plain"] == [ContactForces, WallForces]
    assert kinds["resisting"] == [ContactForces, WallForces, Gravity, RollingResistance]


def test_a_capillary_bridge_does_not_raise_the_limit_moment():
    """The limit is mu_r R* F_n of the contact law's normal force alone: the bridge's
    attraction pulls the spheres together but is not part of F_n (as for the Coulomb cap)."""
    sim = pressed_pair([0, 0, 1000.0], 0.2)
    sim.forces.append(CapillaryBridges(2000.0, 0.073))
    sim.run(300)
    assert sim.operation(CapillaryBridges).count(sim) == 1
    assert sim.particles.force[0, 0] != pytest.approx(-NORMAL_FORCE, rel=1e-3)   # attracted
    assert sim.particles.torque[0] == pytest.approx([0, 0, -0.2 * REDUCED * NORMAL_FORCE],
                                                    rel=1e-12)


@pytest.mark.parametrize("contact", ["hertz-mindlin", "linear"])
def test_spheres_rolling_on_each_other_in_an_impact_lose_the_limit_moments_impulse(contact):
    """``pendular impact --target sphere --spin W --rolling-friction MU_R``: at normal incidence
    the two spheres, spinning opposite ways, roll on each other without sliding, and a spring
    that loads faster than its limit grows (2.25 k_n mu_r^2 R*^2 2W against mu_r R* dFn/dt)
    stays on it: the moment mu_r R* Fn takes mu_r R* J / I off the spin, J = m v (1 + e_n) the
    normal impulse of an undamped contact (a damped one's limit follows its spring force, not
    the dashpot's: pendular.dem.rolling); without resistance the spin is kept."""
    from pendular.procedures import impact
    from pendular.utils.parameters import option_values

    radius, density, speed, spin, mu_r = 0.01, 7800.0, 1.0, 2000.0, 0.2
    given = {"target": "sphere", "contact": contact, "radius": radius, "young": 2e11,
             "density": density, "velocity": speed, "spin": spin}
    rolled, _ = impact.run_impact(option_values(impact.OPTIONS,
                                                {**given, "rolling_friction": mu_r})[0])
    free, _ = impact.run_impact(option_values(impact.OPTIONS, given)[0])
    mass = density * 4.0 / 3.0 * np.pi * radius ** 3
    impulse = mass * speed * (1.0 + rolled["normal_restitution"])
    loss = mu_r * 0.5 * radius * impulse / (0.4 * mass * radius ** 2)
    assert spin - rolled["rebound_angular_velocity"] == pytest.approx(loss, rel=1e-6)
    assert free["rebound_angular_velocity"] == pytest.approx(spin, rel=1e-12)
    assert rolled["normal_restitution"] == pytest.approx(free["normal_restitution"], rel=1e-9)


def test_a_walls_rolling_friction_with_a_sphere_target_is_refused_naming_the_option(capsys):
    refused(*run_in_process("impact", ["--target", "sphere", "--wall-rolling-friction", "0.2"],
                            capsys), "--wall-rolling-friction", "--target")
