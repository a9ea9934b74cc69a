"""Materials of the grains and the walls (pendular.dem.material): the mixing rules of an
unlike pair against Johnson's and Mindlin's, a sphere's impact on a wall of its own material
against Hertz's closed form with the pair's E*, its rebound at the mixed restitution and its
friction the wall's, the rigid wall (the default) unchanged bit for bit, the configuration's
round trip, and bad input refused in one line."""

import math

import numpy as np
import pytest

from conftest import refused, run_in_process
from pendular.dem.contact_law import ContactForces
from pendular.dem.hertz_mindlin import (DampedLinearForces, HertzMindlinForces,
    ViscoelasticWallForces, viscoelastic_wall_forces)
from pendular.dem.material import (Material, effective_modulus, effective_shear_modulus,
    pair_restitution)
from pendular.dem.restitution import damping_ratio
from pendular.dem.state import Particles, Walls
from pendular.dem.wall_friction import FrictionalWallForces, wall_law
from pendular.dem.walls import WallForces
from pendular.procedures import impact
from pendular.procedures.config import config_from_dict, config_to_dict
from pendular.procedures.preparation import PrepareConfig, dry_simulation
from pendular.procedures.registry import config_from_options
from pendular.utils.parameters import flat_options, option_values

#: A steel sphere: radius [m], E [Pa], nu, density [kg/m^3], speed [m/s].
STEEL = {"radius": 0.01, "young": 2e11, "poisson": 0.3, "density": 7800.0, "velocity": 1.0}
#: A glass wall: E [Pa], nu.
GLASS = {"wall_young": 7e10, "wall_poisson": 0.22}


def impact_of(**given):
    """The summary of the steel sphere's Hertz–Mindlin impact on a wall with ``given``."""
    values, _ = option_values(impact.OPTIONS, {**STEEL, "contact": "hertz-mindlin", **given})
    return impact.run_impact(values)[0]


def test_the_pair_moduli_are_johnsons_and_mindlins():
    """1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2, 1/G* = (2 - nu1)/G1 + (2 - nu2)/G2, either
    order; a rigid body adds nothing."""
    steel, glass = (2e11, 0.3), (7e10, 0.22)
    modulus = 1.0 / (0.91 / 2e11 + (1.0 - 0.22 ** 2) / 7e10)
    g_steel, g_glass = 2e11 / 2.6, 7e10 / 2.44
    shear = 1.0 / (1.7 / g_steel + 1.78 / g_glass)
    for a, b in ((steel, glass), (glass, steel)):
        assert effective_modulus(*a, *b) == pytest.approx(modulus, rel=1e-14)
        assert effective_shear_modulus(*a, *b) == pytest.approx(shear, rel=1e-14)
    assert effective_modulus(*steel, math.inf, 0.25) == pytest.approx(2e11 / 0.91, rel=1e-15)
    assert effective_shear_modulus(*steel, math.inf, 0.25) == pytest.approx(g_steel / 1.7,
                                                                            rel=1e-15)


def test_the_restitution_of_an_unlike_pair_is_the_mean_and_of_a_like_pair_its_own():
    assert pair_restitution(0.4, 0.8) == pytest.approx(0.6, rel=1e-15)
    for e in np.random.default_rng(3).uniform(0.01, 1.0, 100):
        assert pair_restitution(e, e) == e


@pytest.mark.parametrize("law", ["hertz-mindlin", "linear"])
def test_a_rigid_wall_of_the_grains_restitution_is_the_former_wall_bit_for_bit(law):
    """The default wall, and a rigid one given with another Poisson ratio, take the
    contact's own E* / G* (or E and ks / kn), damping and friction, equal to the last bit."""
    contact = (HertzMindlinForces(2e11, 0.3, 0.6, 20.0) if law == "hertz-mindlin"
               else DampedLinearForces(1e7, 0.3, 0.6, 20.0))
    default = ViscoelasticWallForces(contact)
    given = ViscoelasticWallForces(contact, Material(math.inf, 0.25, math.inf, 12.0, 0.0, 0.6))
    if law == "hertz-mindlin":
        modulus = 1.0 / ((1.0 - 0.3 ** 2) / 2e11 + 1.0 / math.inf)
        tangential = 1.0 / ((2.0 - 0.3) / (2e11 / (2.0 * 1.3)) + 2.0 / math.inf)
    else:
        modulus, tangential = 1e7, 0.3
    for wall in (default, given):
        assert (wall.modulus, wall.tangential) == (modulus, tangential)
        assert wall.damping == contact.damping == damping_ratio(0.6, law)
    assert default.friction_deg == 0.0 and given.friction_deg == 12.0
    assert given._tan_friction == float(np.tan(np.radians(12.0)))


def test_the_laboratory_walls_by_default_are_the_former_walls():
    """PrepareConfig's wall material by default: WallForces for the elastic linear law,
    FrictionalWallForces with wall friction, the contact's damping for the damped laws."""
    assert type(wall_law(ContactForces(1e6), 1e6, PrepareConfig().wall_material())) \
        is WallForces
    frictional = PrepareConfig(wall_friction=20.0).wall_material()
    wall = wall_law(ContactForces(1e6), 1e6, frictional)
    assert type(wall) is FrictionalWallForces and wall.damping == 0.0
    config = PrepareConfig(contact="hertz-mindlin", young=7e10, restitution=0.7)
    contact = HertzMindlinForces(7e10, 0.3, 0.7)
    wall = wall_law(contact, 7e10, config.wall_material())
    assert (wall.modulus, wall.damping) == (effective_modulus(7e10, 0.3), contact.damping)


def test_a_laboratory_scene_walls_take_the_configurations_wall_material():
    """dry_simulation's walls: the pair's E*, G*, mean restitution and the wall's friction;
    elastic linear grains on walls of restitution 0.6 get a dashpot of e = 0.8."""
    particles = Particles(np.array([[0.5, 0.5, 0.5]]), np.array([0.1]), 2650.0)
    walls = Walls.box((0, 0, 0), (1, 1, 1))
    config = PrepareConfig(contact="hertz-mindlin", young=7e10, poisson=0.3, restitution=0.5,
                           wall_young=2e11, wall_poisson=0.25, wall_restitution=0.9,
                           wall_friction=10.0)
    wall = dry_simulation(particles, walls, config, 1e-6, 0.01, 18.0, []).forces[1]
    assert wall.modulus == effective_modulus(7e10, 0.3, 2e11, 0.25)
    assert wall.tangential == effective_shear_modulus(7e10, 0.3, 2e11, 0.25)
    assert wall.restitution == pytest.approx(0.7, rel=1e-15)
    assert wall.damping == damping_ratio(wall.restitution, "hertz-mindlin")
    assert wall.friction_deg == 10.0
    linear = dry_simulation(particles, walls, PrepareConfig(wall_restitution=0.6), 1e-6, 0.01,
                            18.0, []).forces[1]
    assert type(linear) is FrictionalWallForces and linear.friction_deg == 0.0
    assert linear.damping == damping_ratio(0.8, "linear") > 0.0


def test_an_impact_on_a_rigid_wall_given_as_the_spheres_material_is_the_default_bit_for_bit():
    default = impact_of(angle=30.0, friction=10.0, restitution=0.6)
    given = impact_of(angle=30.0, friction=10.0, restitution=0.6, wall_friction=10.0,
                      wall_restitution=0.6)
    assert given == default


def test_an_impact_on_a_wall_of_its_own_modulus_has_hertzs_force_overlap_and_duration():
    """Steel on glass: Hertz's closed form (Johnson 1985, Eqs. 11.23-11.24) with the pair's
    E*, m* = m (the wall does not move), R* = R."""
    summary = impact_of(**GLASS)
    radius, speed = STEEL["radius"], STEEL["velocity"]
    mass = STEEL["density"] * 4.0 / 3.0 * math.pi * radius ** 3
    modulus = 1.0 / ((1.0 - 0.3 ** 2) / 2e11 + (1.0 - 0.22 ** 2) / 7e10)
    overlap = (15.0 * mass * speed ** 2 / (16.0 * modulus * math.sqrt(radius))) ** 0.4
    force = 4.0 / 3.0 * modulus * math.sqrt(radius) * overlap ** 1.5
    duration = 2.868 * (mass ** 2 / (radius * modulus ** 2 * speed)) ** 0.2
    assert summary["effective_modulus"] == pytest.approx(modulus, rel=1e-14)
    assert summary["max_normal_force"] == pytest.approx(force, rel=1e-3)
    assert summary["max_overlap"] == pytest.approx(overlap, rel=1e-3)
    assert summary["contact_duration"] == pytest.approx(duration, rel=2e-3)
    assert summary["normal_restitution"] == pytest.approx(1.0, abs=1e-6)
    # the rigid wall's force is (E*_rigid / E*)^(2/5) = 1.74 times higher: the wall matters
    assert impact_of()["max_normal_force"] > 1.7 * summary["max_normal_force"]


@pytest.mark.parametrize("contact", ["hertz-mindlin", "linear"])
def test_an_impact_on_a_wall_rebounds_at_the_mixed_restitution(contact):
    """A sphere of e = 0.9 on a wall of e = 0.5 rebounds at their mean, 0.7."""
    given = GLASS if contact == "hertz-mindlin" else {}
    summary = impact_of(contact=contact, restitution=0.9, wall_restitution=0.5, **given)
    assert summary["contact_restitution"] == pytest.approx(0.7, rel=1e-15)
    assert summary["normal_restitution"] == pytest.approx(0.7, abs=1e-3)


def test_an_oblique_impact_slides_with_the_walls_friction():
    """Gross sliding on the wall: e_t = 1 - mu_w (1 + e_n) / tan(theta) with the wall's
    friction mu_w, not the sphere's (Thornton et al. 2013)."""
    angle = 60.0
    summary = impact_of(angle=angle, friction=40.0, wall_friction=10.0, **GLASS)
    mu = math.tan(math.radians(10.0))
    normal = summary["normal_restitution"]
    assert summary["tangential_restitution"] == pytest.approx(
        1.0 - mu * (1.0 + normal) / math.tan(math.radians(angle)), rel=1e-4)


def test_a_wall_of_its_own_material_has_mindlins_stiffness_of_the_pair():
    """Fn = (4/3) E* sqrt(R) delta^(3/2) and kt = 8 G* a with the pair's E* and G*, and the
    wall's stiffness total 2 E* a."""
    radius, overlap, dt = 0.01, 1e-6, 1e-9
    wall = ViscoelasticWallForces(HertzMindlinForces(2e11, 0.3),
                                  Material(7e10, 0.22, math.inf, 30.0))
    position = np.array([[0.0, 0.0, radius - overlap]])
    mass = np.array([7800 * 4.0 / 3.0 * math.pi * radius ** 3])
    force, torque, totals = np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((3, 6))
    viscoelastic_wall_forces(position, np.array([[1e-3, 0.0, 0.0]]), np.zeros((1, 3)),
                             np.full(1, radius), mass, np.array([0]),
                             np.array([-1.0, 1.0, -1.0, 1.0, 0.0, 1.0]), np.zeros(6), True,
                             wall.modulus, wall.tangential, wall.damping, wall._tan_friction,
                             dt, np.zeros((1, 6, 3)), force, torque, *totals)
    modulus = effective_modulus(2e11, 0.3, 7e10, 0.22)
    contact_radius = math.sqrt(radius * overlap)
    assert force[0, 2] == pytest.approx(4 / 3 * modulus * math.sqrt(radius) * overlap ** 1.5,
                                        rel=1e-9)
    kt = 8.0 * effective_shear_modulus(2e11, 0.3, 7e10, 0.22) * contact_radius
    assert force[0, 0] == pytest.approx(-kt * 1e-3 * dt, rel=1e-9)
    assert totals[1][4] == pytest.approx(2.0 * modulus * contact_radius, rel=1e-9)


def test_a_tests_wall_material_round_trips_through_its_configuration():
    config = config_from_options("triaxial", {
        "particles": 60, "contact": "hertz-mindlin", "young": 1e8, "restitution": 0.8,
        "wall_young": 2e11, "wall_poisson": 0.25, "wall_restitution": 0.5,
        "wall_friction": 15.0})
    assert config.sample.wall_material() == Material(2e11, 0.25, math.inf, 15.0, 0.0, 0.5)
    assert config_from_dict(config_to_dict(config)) == config
    flat = flat_options(config.sample)
    assert (flat["wall_young"], flat["wall_poisson"], flat["wall_restitution"]) == \
        (2e11, 0.25, 0.5)
    assert PrepareConfig().wall_material() == Material(math.inf, 0.3, math.inf, 0.0, 0.0, 1.0)


@pytest.mark.parametrize("argv, words", [
    (["--wall-young", "2e11"], ("--wall-young", "Hertz-Mindlin")),
    (["--contact", "hertz-mindlin", "--young", "1e8", "--wall-young", "1e7"],
     ("--wall-young", "[1e+08, inf) Pa")),
    (["--wall-young", "-1"], ("--wall-young", "(0, inf) Pa")),
    (["--wall-poisson", "0.2"], ("--wall-poisson", "wall_young")),
    (["--contact", "hertz-mindlin", "--wall-young", "1e9", "--wall-poisson", "0.5"],
     ("--wall-poisson", "(-1, 0.5)")),
    (["--wall-restitution", "0"], ("--wall-restitution", "(0, 1]")),
    (["--periodic", "--wall-restitution", "0.5"], ("--wall-restitution", "periodic")),
])
def test_a_laboratory_test_refuses_a_bad_wall_material_in_one_line(argv, words, capsys):
    refused(*run_in_process("triaxial", ["--particles", "60", *argv], capsys), *words)


@pytest.mark.parametrize("argv, words", [
    (["--target", "sphere", "--contact", "hertz-mindlin", "--wall-restitution", "0.5"],
     ("--wall-restitution", "--target")),
    (["--wall-young", "7e10"], ("--wall-young", "--contact")),
    (["--contact", "hertz-mindlin", "--wall-young", "1e3"],
     ("--velocity", "--wall-young", "at most 0.1")),
    (["--wall-friction", "90"], ("--wall-friction", "[0, 90)")),
])
def test_the_impact_command_refuses_a_bad_wall_in_one_line(argv, words, tmp_path, capsys):
    refused(*run_in_process("impact", [*argv, "--out", tmp_path / "impact"], capsys), *words)
