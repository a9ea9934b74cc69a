"""Tests of the Hertz–Mindlin law and of the restitution's damping
(pendular.dem.hertz_mindlin, pendular.dem.restitution): impacts of the engine's own simulation
(pendular.procedures.impact) against Hertz's closed form, restitution out equal to
restitution in, an oblique impact in gross sliding against its impulse solution, Mindlin's
tangential stiffness on loading and unloading, the damped law's geometry against the linear
law's, and bad input."""

import math

import numpy as np
import pytest

from conftest import refused, run_in_process
from pendular.dem.contact_law import pair_forces
from pendular.dem.hertz_mindlin import (DampedLinearForces, HertzMindlinForces,
    ViscoelasticWallForces, effective_modulus, effective_shear_modulus,
    viscoelastic_pair_forces, viscoelastic_wall_forces)
from pendular.dem.material import rigid_wall
from pendular.dem.neighbors import build_contacts
from pendular.dem.restitution import damping_ratio
from pendular.dem.timestep import rayleigh_timestep
from pendular.procedures import impact
from pendular.utils.parameters import option_values

#: Steel (the issue's check): radius [m], E [Pa], nu, density [kg/m^3], speed [m/s].
STEEL = {"radius": 0.01, "young": 2e11, "poisson": 0.3, "density": 7800.0, "velocity": 1.0}


def impact_of(**given):
    """(summary, history) of the impact of the steel sphere with ``given`` options."""
    values, _ = option_values(impact.OPTIONS, {**STEEL, "contact": "hertz-mindlin", **given})
    return impact.run_impact(values)


def hertz(target):
    """Hertz's peak force [N], peak overlap [m] and contact time [s] of the steel impact
    (Johnson 1985, Eqs. 11.23-11.24): m*, R*, E* and the approach speed of the pair."""
    radius, young, poisson, density, speed = STEEL.values()
    mass = density * 4.0 / 3.0 * math.pi * radius ** 3
    pair = target == "sphere"
    mass_star, radius_star = (mass / 2, radius / 2) if pair else (mass, radius)
    modulus = young / ((2.0 if pair else 1.0) * (1.0 - poisson ** 2))
    approach = 2.0 * speed if pair else speed
    overlap = (15.0 * mass_star * approach ** 2 / (16.0 * modulus * math.sqrt(radius_star))) ** 0.4
    force = 4.0 / 3.0 * modulus * math.sqrt(radius_star) * overlap ** 1.5
    duration = 2.868 * (mass_star ** 2 / (radius_star * modulus ** 2 * approach)) ** 0.2
    return force, overlap, duration


@pytest.mark.parametrize("target", ["wall", "sphere"])
def test_an_elastic_impact_has_hertzs_peak_force_overlap_and_duration(target):
    summary, history = impact_of(target=target)
    force, overlap, duration = hertz(target)
    assert summary["max_normal_force"] == pytest.approx(force, rel=1e-3)
    assert summary["max_overlap"] == pytest.approx(overlap, rel=1e-3)
    assert summary["contact_duration"] == pytest.approx(duration, rel=2e-3)
    assert summary["normal_restitution"] == pytest.approx(1.0, abs=1e-6)
    # Hertz's force along the way: F = (4/3) E* sqrt(R*) delta^(3/2)
    touching = history["overlap"] > 0.0
    law = force * (history["overlap"][touching] / overlap) ** 1.5
    assert np.allclose(history["normal_force"][touching], law, rtol=1e-2, atol=1e-3 * force)


@pytest.mark.parametrize("contact", ["hertz-mindlin", "linear"])
@pytest.mark.parametrize("restitution", [0.1, 0.3, 0.5, 0.7, 0.9, 1.0])
def test_an_impact_rebounds_at_the_restitution_asked(contact, restitution, monkeypatch):
    monkeypatch.setattr(impact, "STEPS_PER_CONTACT", 500)
    summary, _ = impact_of(contact=contact, restitution=restitution)
    assert summary["normal_restitution"] == pytest.approx(restitution, abs=0.01)


def test_the_restitution_does_not_depend_on_the_impact_speed(monkeypatch):
    """Damping 2 gamma sqrt(m* k(delta)) makes e a function of gamma alone
    (pendular.dem.restitution)."""
    monkeypatch.setattr(impact, "STEPS_PER_CONTACT", 500)
    slow, _ = impact_of(restitution=0.5, velocity=0.01)
    fast, _ = impact_of(restitution=0.5, velocity=10.0)
    assert slow["normal_restitution"] == pytest.approx(fast["normal_restitution"], abs=2e-3)


def test_the_linear_springs_textbook_damping_misses_without_tension():
    """gamma = -ln e / sqrt(ln^2 e + pi^2) holds only for a force that may pull; the
    no-tension mapping needs more damping (Schwager & Pöschel 2007)."""
    e = 0.5
    textbook = -math.log(e) / math.sqrt(math.log(e) ** 2 + math.pi ** 2)
    assert damping_ratio(e, "linear") > 1.1 * textbook
    assert damping_ratio(1.0, "linear") == damping_ratio(1.0) == 0.0


@pytest.mark.parametrize("restitution", [1.0, 0.6])
def test_an_oblique_impact_in_gross_sliding_has_the_impulse_solution(restitution):
    """Sliding throughout: the friction impulse is mu times the normal one, m (1 + e_n) v_n:
    e_t = 1 - mu (1 + e_n) / tan(theta), omega = 2.5 mu (1 + e_n) v_n / R (sphere on a wall,
    Thornton et al. 2013)."""
    angle, friction = 60.0, 10.0
    summary, _ = impact_of(angle=angle, friction=friction, restitution=restitution)
    mu = math.tan(math.radians(friction))
    normal = summary["normal_restitution"]
    assert normal == pytest.approx(restitution, abs=0.01)
    speed_n = STEEL["velocity"] * math.cos(math.radians(angle))
    assert summary["tangential_restitution"] == pytest.approx(
        1.0 - mu * (1.0 + normal) / math.tan(math.radians(angle)), rel=1e-4)
    assert summary["rebound_angular_velocity"] == pytest.approx(
        2.5 * mu * (1.0 + normal) * speed_n / STEEL["radius"], rel=2e-3)


def test_a_normal_impact_of_a_spinning_sphere_keeps_its_rebound_on_the_tangent():
    """A spinning sphere at normal incidence leaves along a tilted path, its spin slowed by
    the friction: the tangential impulse and the loss of spin match, I dw = -R m dv_t."""
    spin = 100.0
    summary, _ = impact_of(spin=spin, friction=20.0)
    mass = STEEL["density"] * 4.0 / 3.0 * math.pi * STEEL["radius"] ** 3
    inertia = 0.4 * mass * STEEL["radius"] ** 2
    tangential = STEEL["velocity"] * math.tan(math.radians(summary["rebound_angle_deg"]))
    assert tangential * summary["normal_restitution"] > 0.0  # thrown forward
    assert inertia * (spin - summary["rebound_angular_velocity"]) == pytest.approx(
        STEEL["radius"] * mass * tangential * summary["normal_restitution"], rel=2e-3)


def pressed_pair(overlap):
    """Two steel spheres (radius R) overlapping by ``overlap`` [m] along x, at rest."""
    radius = STEEL["radius"]
    position = np.array([[0.0, 0.0, 0.0], [2.0 * radius - overlap, 0.0, 0.0]])
    return position, np.full(2, radius), build_contacts(position, np.full(2, radius), 0.0)


def test_mindlin_tangential_loading_and_unloading_follow_8_g_a_capped_by_coulomb():
    """At a fixed overlap, a tangential displacement s loads the force at 8 G* a s up to
    mu Fn (Mindlin 1949, without microslip), and unloading from the cap goes back at the same
    stiffness (Mindlin & Deresiewicz 1953's initial unloading slope) to -mu Fn."""
    radius, young, poisson, density = (STEEL[k] for k in ("radius", "young", "poisson",
                                                          "density"))
    overlap = 1e-6
    position, radii, contacts = pressed_pair(overlap)
    law = HertzMindlinForces(young, poisson, friction_deg=20.0)
    mass = np.full(2, density * 4.0 / 3.0 * math.pi * radius ** 3)
    contact_radius = math.sqrt(radius / 2.0 * overlap)
    kt = 8.0 * law.tangential * contact_radius
    fn = 4.0 / 3.0 * law.modulus * math.sqrt(radius / 2.0) * overlap ** 1.5
    cap = fn * math.tan(math.radians(20.0))
    arrays = [np.zeros((1, 3)), np.zeros((1, 3)), np.zeros(1), np.zeros(1), np.zeros((1, 3))]
    dt = 1e-7
    step = cap / kt / 50.0              # a fiftieth of the displacement to the cap, each step
    velocity = np.zeros((2, 3))

    def move(speed, steps):
        velocity[1, 1] = speed / dt
        forces = []
        for _ in range(steps):
            viscoelastic_pair_forces(position, velocity, np.zeros((2, 3)), radii, mass,
                                     contacts.pair_i, contacts.pair_j, contacts.image,
                                     np.zeros(3), np.zeros(3), *arrays, True, law.modulus,
                                     law.tangential, 0.0, law._tan_friction, dt)
            forces.append(arrays[4][0, 1])
        return np.array(forces)

    loading = move(step, 100)
    assert arrays[3][0] == pytest.approx(fn, rel=1e-9)
    assert law.tangential == pytest.approx(effective_shear_modulus(young, poisson, young,
                                                                   poisson))
    assert loading[:50] == pytest.approx(-kt * step * np.arange(1, 51), rel=1e-9)
    assert loading[60:] == pytest.approx(-cap, rel=1e-9)
    unloading = move(-step, 150)
    assert unloading[:100] == pytest.approx(-cap + kt * step * np.arange(1, 101), rel=1e-9,
                                            abs=1e-9 * cap)
    assert unloading[110:] == pytest.approx(cap, rel=1e-9)


def test_the_wall_has_mindlins_stiffness_of_a_rigid_body():
    """A sphere on a rigid wall: Fn = (4/3) E/(1-nu^2) sqrt(R) delta^(3/2), kt = 8 G/(2-nu) a."""
    radius, young, poisson, density = (STEEL[k] for k in ("radius", "young", "poisson",
                                                          "density"))
    overlap = 1e-6
    wall = ViscoelasticWallForces(HertzMindlinForces(young, poisson),
                                  rigid_wall(friction_deg=30.0))
    position = np.array([[0.0, 0.0, radius - overlap]])
    velocity = np.array([[1e-3, 0.0, 0.0]])
    mass = np.array([density * 4.0 / 3.0 * math.pi * radius ** 3])
    shear = np.zeros((1, 6, 3))
    force, torque, totals = np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((3, 6))
    dt = 1e-9
    viscoelastic_wall_forces(position, velocity, np.zeros((1, 3)), np.full(1, radius), mass,
                             np.array([0]), np.array([-1.0, 1.0, -1.0, 1.0, 0.0, 1.0]),
                             np.zeros(6), True, wall.modulus, wall.tangential, 0.0,
                             wall._tan_friction, dt, shear, force, torque, *totals)
    modulus = effective_modulus(young, poisson)
    assert modulus == pytest.approx(young / (1 - poisson ** 2))
    assert force[0, 2] == pytest.approx(4 / 3 * modulus * math.sqrt(radius) * overlap ** 1.5)
    kt = 8.0 * young / (2.0 * (1.0 + poisson)) / (2.0 - poisson) * math.sqrt(radius * overlap)
    assert force[0, 0] == pytest.approx(-kt * 1e-3 * dt)
    assert torque[0, 1] == pytest.approx(-(radius - overlap / 2) * force[0, 0])  # (-R n) x F
    assert totals[0][4] == pytest.approx(force[0, 2])


def test_the_damped_linear_law_without_damping_is_the_linear_law():
    """Same rotation, projection and cap of the shear spring: DampedLinearForces at e = 1
    gives ContactForces' pair forces on a random packing, step after step."""
    rng = np.random.default_rng(4)
    count, radius = 200, 1e-3
    position = rng.random((count, 3)) * 0.012
    radii = np.full(count, radius)
    contacts = build_contacts(position, radii, 1e-4)
    velocity = rng.normal(size=(count, 3)) * 1e-2
    spin = rng.normal(size=(count, 3))
    mass = np.full(count, 1e-5)
    pairs = len(contacts.pair_i)
    ours = [np.zeros((pairs, 3)), np.zeros((pairs, 3)), np.zeros(pairs), np.zeros(pairs),
            np.zeros((pairs, 3))]
    linear = [array.copy() for array in ours]
    law = DampedLinearForces(1e6, 0.3, 1.0, 25.0)
    for _ in range(5):
        viscoelastic_pair_forces(position, velocity, spin, radii, mass, contacts.pair_i,
                                 contacts.pair_j, contacts.image, np.zeros(3), np.zeros(3),
                                 *ours, False, law.modulus, law.tangential, law.damping,
                                 law._tan_friction, 1e-4)
        pair_forces(position, velocity, spin, radii, contacts.pair_i, contacts.pair_j,
                    contacts.image, np.zeros(3), np.zeros(3), *linear, 1e6, 0.3,
                    law._tan_friction, 1e-4, 0)
        position += velocity * 1e-4
    assert np.count_nonzero(linear[3]) > 50
    for got, want in zip(ours, linear):
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-18)


def test_the_rayleigh_step_is_the_rayleigh_wave_crossing():
    young, poisson, density = 7e10, 0.22, 2500.0
    shear = young / (2 * (1 + poisson))
    assert rayleigh_timestep([2e-3, 1e-3], young, poisson, density) == pytest.approx(
        math.pi * 1e-3 * math.sqrt(density / shear) / (0.1631 * poisson + 0.8766))


def test_the_wall_springs_survive_a_checkpoint_and_refuse_a_bad_one():
    wall = ViscoelasticWallForces(HertzMindlinForces(1e9, 0.25, 0.5))
    springs = np.arange(36.0).reshape(2, 6, 3)
    wall.load_state({"wall_shear": springs})
    assert np.array_equal(wall.state_dict()["wall_shear"], springs)
    with pytest.raises(ValueError, match="wall_shear"):
        wall.load_state({"wall_shear": np.zeros((2, 5, 3))})


@pytest.mark.parametrize("given, words", [
    ({"poisson": 0.5}, ("poisson", "(-1, 0.5)")),
    ({"poisson": -1.0}, ("poisson", "(-1, 0.5)")),
    ({"restitution": 0.0}, ("restitution", "(0, 1]")),
    ({"restitution": 1.5}, ("restitution", "(0, 1]")),
])
def test_the_law_refuses_a_material_outside_its_range(given, words):
    settings = {"young": 1e9, "poisson": 0.3, "restitution": 1.0, **given}
    with pytest.raises(ValueError) as error:
        HertzMindlinForces(**settings)
    assert all(word in str(error.value) for word in words)


@pytest.mark.parametrize("argv, words", [
    (["--poisson", "0.5"], ("--poisson", "(-1, 0.5)")),
    (["--poisson", "-1.2"], ("--poisson", "(-1, 0.5)")),
    (["--restitution", "0"], ("--restitution", "(0, 1]")),
    (["--restitution", "1.01"], ("--restitution", "(0, 1]")),
    (["--angle", "90"], ("--angle", "[0, 90)")),
    (["--velocity", "-1"], ("--velocity",)),
    (["--target", "floor"], ("--target",)),
    (["--young", "1e3", "--velocity", "10"], ("--velocity", "--young", "at most 0.1")),
])
def test_the_impact_command_refuses_bad_input_in_one_line(argv, words, tmp_path, capsys):
    status, err = run_in_process("impact", [*argv, "--out", tmp_path / "run"], capsys)
    refused(status, err, *words)
    assert not (tmp_path / "run").exists()


def test_an_oblique_impact_resumes_from_a_checkpoint_bit_for_bit(tmp_path):
    """The wall's springs and the pairs' go through a checkpoint: a resumed impact is the
    uninterrupted one."""
    from pendular.dem.checkpoint import load_checkpoint, save_checkpoint

    values, _ = option_values(impact.OPTIONS, {**STEEL, "contact": "hertz-mindlin",
                                               "angle": 20.0, "restitution": 0.7})
    saved, _ = impact.impact_scene(values)
    saved.run(600)
    assert np.any(saved.operation(ViscoelasticWallForces).wall_shear != 0.0)
    save_checkpoint(tmp_path / "impact.h5", saved)
    resumed, _ = impact.impact_scene(values)
    load_checkpoint(tmp_path / "impact.h5", resumed)
    for sim in (saved, resumed):
        sim.run(600)
    assert np.array_equal(resumed.particles.velocity, saved.particles.velocity)
    assert np.array_equal(resumed.particles.angular_velocity, saved.particles.angular_velocity)


def test_a_laboratory_scene_takes_the_law_its_configuration_names():
    from pendular.dem.contact_law import ContactForces
    from pendular.dem.state import Particles, Walls
    from pendular.dem.walls import WallForces
    from pendular.procedures.preparation import (RAYLEIGH_SHARE, PrepareConfig, dry_simulation,
        pwave_step)

    particles = Particles(np.array([[0.5, 0.5, 0.5]]), np.array([0.1]), 2650.0)
    walls = Walls.box((0, 0, 0), (1, 1, 1))
    for settings, kinds in (({}, (ContactForces, WallForces)),
                            ({"restitution": 0.5}, (DampedLinearForces, ViscoelasticWallForces)),
                            ({"contact": "hertz-mindlin", "young": 7e10, "poisson": 0.22},
                             (HertzMindlinForces, ViscoelasticWallForces))):
        config = PrepareConfig(**settings)
        sim = dry_simulation(particles, walls, config, 1e-6, 0.01, 18.0, [])
        assert tuple(type(op) for op in sim.forces) == kinds
    assert pwave_step([1e-3], config) == pytest.approx(
        config.timestep_safety * RAYLEIGH_SHARE * rayleigh_timestep(1e-3, 7e10, 0.22, 2650.0))


@pytest.mark.parametrize("law", [HertzMindlinForces(2e11, 0.3, 0.3),
                                 DampedLinearForces(2e11, 0.3, 0.3)])
def test_the_per_pair_normal_force_is_the_springs_whatever_the_damping(law):
    """A damped pair closing or opening: its force on the particles carries the dashpot, its
    per-pair normal force the spring's alone, so that the rolling resistance's k_n = F_n /
    delta (pendular.dem.rolling) is the secant stiffness, 4/3 E* sqrt(R* delta) or the
    linear kn, and not one that swings with the normal velocity."""
    from pendular.dem.contact_law import normal_stiffness

    overlap, radius = 1e-6, STEEL["radius"]
    position, radii, contacts = pressed_pair(overlap)
    mass = np.full(2, STEEL["density"] * 4.0 / 3.0 * math.pi * radius ** 3)
    stiffness = (4.0 / 3.0 * law.modulus * math.sqrt(0.5 * radius * overlap) if law.hertz
                 else normal_stiffness(law.modulus, radius, radius))
    for speed in (-0.1, 0.1):                   # closing, then opening
        velocity = np.array([[0.0, 0.0, 0.0], [speed, 0.0, 0.0]])
        arrays = [np.zeros((1, 3)), np.zeros((1, 3)), np.zeros(1), np.zeros(1),
                  np.zeros((1, 3))]
        viscoelastic_pair_forces(position, velocity, np.zeros((2, 3)), radii, mass,
                                 contacts.pair_i, contacts.pair_j, contacts.image,
                                 np.zeros(3), np.zeros(3), *arrays, law.hertz, law.modulus,
                                 law.tangential, law.damping, law._tan_friction, 1e-9)
        _, _, overlaps, normal_force, force = arrays
        assert normal_force[0] / overlaps[0] == pytest.approx(stiffness, rel=1e-9)
        assert (force[0, 0] > normal_force[0]) == (speed < 0.0)     # the dashpot's sign


@pytest.mark.parametrize("law", [HertzMindlinForces(1e6, 0.3), HertzMindlinForces(1e6, 0.3, 0.4),
                                 DampedLinearForces(1e6, 0.3, 0.4)])
def test_the_one_thread_kernels_give_the_parallel_kernels_forces_bit_for_bit(law):
    """Row by row (serial_viscoelastic_pair_forces) and scattered to the particles as the
    pairs are evaluated (scattered_viscoelastic_pair_forces): the per-pair arrays and the
    particles' sums of viscoelastic_pair_forces and the gather, step after step."""
    from pendular.dem.contact_law import gather_contact_forces
    from pendular.dem.hertz_mindlin import (scattered_viscoelastic_pair_forces,
        serial_viscoelastic_pair_forces)

    rng = np.random.default_rng(7)
    count, radius = 200, 1e-3
    position = rng.random((count, 3)) * 0.012
    radii = np.full(count, radius) * rng.uniform(0.8, 1.2, count)
    contacts = build_contacts(position, radii, 1e-4)
    velocity = rng.normal(size=(count, 3)) * 1e-2
    spin = rng.normal(size=(count, 3))
    mass = 2650.0 * 4.0 / 3.0 * math.pi * radii ** 3
    pairs = len(contacts.pair_i)
    runs = {name: [np.zeros((pairs, 3)), np.zeros((pairs, 3)), np.zeros(pairs), np.zeros(pairs),
                   np.zeros((pairs, 3))] for name in ("parallel", "serial", "scattered")}
    sums = {name: (np.zeros((count, 3)), np.zeros((count, 3))) for name in ("parallel",
                                                                            "scattered")}
    material = (law.hertz, law.modulus, law.tangential, law.damping, law._tan_friction, 1e-6)
    box = (contacts.image, np.zeros(3), np.zeros(3))
    kinematics = (position, velocity, spin, radii, mass)
    for _ in range(5):
        for force, torque in sums.values():
            force[:] = 0.0
            torque[:] = 0.0
        viscoelastic_pair_forces(*kinematics, contacts.pair_i, contacts.pair_j, *box,
                                 *runs["parallel"], *material)
        gather_contact_forces(runs["parallel"][4], None, runs["parallel"][1],
                              runs["parallel"][2], radii, contacts.row_start,
                              contacts.second_start, contacts.second_pair, *sums["parallel"])
        serial_viscoelastic_pair_forces(*kinematics, contacts.row_start, contacts.pair_j,
                                        *box, *runs["serial"], *material, 4)
        scattered_viscoelastic_pair_forces(*kinematics, contacts.row_start, contacts.pair_j,
                                           *box, *runs["scattered"], *material, 0,
                                           *sums["scattered"])
        position += velocity * 1e-6
    assert np.count_nonzero(runs["parallel"][3]) > 50
    for name in ("serial", "scattered"):
        for got, want in zip(runs[name], runs["parallel"]):
            np.testing.assert_array_equal(got, want)
    for got, want in zip(sums["scattered"], sums["parallel"]):
        np.testing.assert_array_equal(got, want)
    assert np.abs(sums["parallel"][1]).max() > 0.0
