"""The direct-tension test (pendular.procedures.tension, pendular.procedures.grips, pendular.capillary.wetting): wetting to a
water content, grips, strength, and its command line."""

import copy
import dataclasses
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from pendular.capillary import BridgeTable, formation_suction
from pendular.dem.measure import unbalanced_force
from pendular.procedures.preparation import prepare_sample
from pendular.dem.state import Particles, Walls
from pendular.dem.grips import Grip
from pendular.procedures.grips import grip_members
from pendular.procedures import tension_pull as direct_tension
from pendular.procedures.water_content import WATER_TOLERANCE
from pendular.cli import command_parser
from pendular.procedures.config import CONFIG_TYPES, config_from_dict, config_to_dict
from pendular.procedures.tension import TensionConfig, tension_sample
from pendular.procedures.preparation import PrepareConfig

from conftest import ROOT, run_in_process
from pendular.io.schema import undeclared_keys

GAMMA = 0.074
WATER = 0.0104       # Kim's middle water content (fraction)
TINY = ["--particles", "200", "--max-strain", "0.03", "--vtk-frames", "0", "--quiet"]


@pytest.fixture(scope="module")
def table():
    return BridgeTable.cached(0.0, radius_ratios=(1.0,))


@pytest.fixture(scope="module")
def args():
    return TensionConfig(sample=tension_sample(particles=200), max_strain=0.03, vtk_frames=0)


@pytest.fixture(scope="module")
def dry(args):
    """200 spheres of R = 0.11 mm held at 100 Pa (growth friction 10 deg)."""
    sim, _ = prepare_sample(direct_tension.prepare_config(args, 10.0), progress=False)
    return sim


@pytest.fixture(scope="module")
def wetted(dry, args):
    return direct_tension.wet(dry, args, WATER, progress=False)


def test_formation_suction_holds_the_target_volume(table):
    """Bisection against an independent sum of table volumes, over two sphere sizes."""
    radius_i = np.array([1e-4] * 30 + [2e-4] * 10)
    radius_j = radius_i.copy()

    def held(suction):
        return sum(table.lookup(1.0, suction * r / GAMMA, 0.0)[2] * r ** 3 for r in radius_i)

    for target in (0.02 * 30 * 1e-12 + 0.02 * 10 * 8e-12, 0.1 * 40 * 1e-12):
        suction = formation_suction(table, radius_i, radius_j, target, GAMMA)
        assert held(suction) == pytest.approx(target, rel=1e-5)
    # more water than bridges at vanishing suction can hold, or none
    with pytest.raises(ValueError, match="water volume"):
        formation_suction(table, radius_i, radius_j, 1.0 * 40 * 8e-12, GAMMA)
    with pytest.raises(ValueError, match="water volume"):
        formation_suction(table, radius_i, radius_j, 0.0, GAMMA)


def test_wetting_reaches_the_water_content(wetted, dry, args):
    """w = water mass / grain mass, the grains' mass from the simulated spheres' density."""
    sim, bridges, report = wetted
    water = (1000.0 * bridges.water_volume(sim.contacts)
             / (sim.particles.density * sim.particles.solid_volume()))
    assert water == pytest.approx(WATER, rel=WATER_TOLERANCE)
    assert report["water_content"] == pytest.approx(water)
    # the bridges outnumber the dry contacts: the settling under the bridges made new ones
    assert bridges.count(sim) >= np.count_nonzero(dry.contacts.overlap > 0.0)


def _force_on_upper_part(sim, bridges, height):
    """z force on the particles above ``height`` from those below: contact + capillary forces
    of the pairs that cross the plane (pair arrays hold the force on j from i)."""
    contacts = sim.contacts
    position = sim.particles.position
    below_i = position[contacts.pair_i, 2] < height
    below_j = position[contacts.pair_j, 2] < height
    across = below_i != below_j
    force_z = (contacts.force + bridges.pair_forces(sim))[across, 2]
    return float(np.sum(np.where(below_i[across], force_z, -force_z)))


def test_grip_pull_equals_the_force_across_a_plane(wetted, args, tmp_path):
    """Pull 1 %, hold the grips still until static: both grips' pull equals the tension
    carried across the mid-height plane by contact and capillary forces."""
    sim = copy.deepcopy(wetted[0])
    bridges = sim.operation(type(wetted[1]))
    pull = direct_tension.Pull(sim, bridges, args, str(tmp_path), progress=False)
    sim.run(int(0.01 / (pull.rate * sim.dt)))
    pull.extension.rate = 0.0
    sim.run(20000, until=lambda s: unbalanced_force(s.particles, s.contacts)
            < 1e-3, check_every=200)
    walls = sim.walls
    tension = -_force_on_upper_part(sim, bridges, 0.5 * (walls.lo[2] + walls.hi[2]))
    assert tension > 0.0
    for grip in pull.grips:
        assert grip.pull == pytest.approx(tension, rel=0.02)


def test_dry_sample_has_no_strength_and_wet_one_a_rumpf_order_strength(dry, wetted, args,
                                                                        table, tmp_path):
    """Rumpf (1962): sigma_t = (1 - n) k F / (pi d^2), k bridges per particle, F the force of
    a bridge at contact, its menisci args.roughness R apart (computed here from the table, not
    by the scenario)."""
    _, dry_history = direct_tension.Pull(copy.deepcopy(dry), None, args, str(tmp_path / "dry"),
                                  progress=False).run(None)
    sim = copy.deepcopy(wetted[0])
    bridges = sim.operation(type(wetted[1]))
    count = bridges.count(sim)
    particles = sim.particles
    radius = float(particles.radius[0])
    porosity = 1.0 - particles.solid_volume() / sim.walls.volume()
    force = (table.lookup(1.0, bridges.suction * radius / GAMMA, args.roughness)[1]
             * 2.0 * math.pi * GAMMA * radius)
    rumpf = (1.0 - porosity) * (2.0 * count / len(particles)) * force / (math.pi * 4 * radius ** 2)
    _, history = direct_tension.Pull(sim, bridges, args, str(tmp_path / "wet"),
                              progress=False).run(None)
    wet_strength = float(np.max(history["tensile_stress"]))
    dry_strength = float(np.max(dry_history["tensile_stress"]))
    assert dry_strength < 0.01 * rumpf
    assert 0.2 * rumpf < wet_strength < 1.0 * rumpf
    # quasi-static: the thesis's criterion on the unbalanced force, on average up to the peak
    peak = int(np.argmax(history["tensile_stress"]))
    assert np.mean(history["unbalanced_force"][1:peak + 1]) < 0.02


@pytest.mark.parametrize("arguments, message", [
    (["--void-ratio", "0.3"], "--void-ratio = 0.3 is outside the valid range"),
    (["--water-content", "9"], "--water-content = 9 % is outside the valid range (0, 5.28] %"),
    (["--water-content", "0,1"], "--water-content = 0 % is outside"),
    (["--contact-angle", "95"], "--contact-angle = 95.0 deg is outside"),
    (["--particles", "10"], "--particles = 10 is outside"),
    (["--residual", "1.5"], "--residual = 1.5 is outside"),
    (["--specific-gravity", "11"], "--specific-gravity = 11.0 is outside the valid range [1, 10]"),
    (["--friction", "95"], "--friction = 95.0 deg is outside"),
    (["--void-ratio", "0.7,x"], "--void-ratio = '0.7,x' is not a comma-separated list"),
])
def test_bad_inputs_are_refused_by_name(arguments, message, capsys):
    """scenarios/direct_tension.py's command, run in-process (its own interpreter in
    test_command_runs_one_case_and_writes_its_outputs)."""
    status, err = run_in_process("tension", [*TINY, *arguments, "--out", os.devnull], capsys,
                                 prog="direct_tension.py")
    assert status == 2
    assert message in err and "Traceback" not in err
    assert err.count("error:") == 1


def test_config_is_validated_and_saved_as_json(args):
    """Variants by dataclasses.replace are validated again; the JSON form (the sample nested
    as a PrepareConfig) reads back equal."""
    assert CONFIG_TYPES["TensionConfig"] is TensionConfig
    variant = dataclasses.replace(args, cases=[(0.65, 0.01), (0.65, 0.02)], vtk_every=50,
                                  sample=dataclasses.replace(args.sample, radius_spread=0.1))
    data = json.loads(json.dumps(config_to_dict(variant)))
    assert data["fields"]["sample"]["type"] == "PrepareConfig"
    assert "specific_gravity" not in data["fields"] and "particles" not in data["fields"]
    assert config_from_dict(data) == variant
    assert TensionConfig().cases == [(e, w) for e, w, _ in direct_tension.KIM_2001]
    with pytest.raises(ValueError, match="^friction_deg = 95.0 deg is outside"):
        tension_sample(friction_deg=95.0)
    # the tension's own ranges, narrower than PrepareConfig's, name the fields
    with pytest.raises(ValueError, match=r"^young = 2000000000000.0 Pa is outside"):
        dataclasses.replace(args, sample=dataclasses.replace(args.sample, young=2e12))
    with pytest.raises(ValueError, match=r"^specific_gravity = 0.5 is outside"):
        dataclasses.replace(args, sample=PrepareConfig(particles=200, density=500.0))
    with pytest.raises(ValueError, match="^void_ratio = 1.5 is outside"):
        dataclasses.replace(args, cases=[(1.5, 0.01)])
    with pytest.raises(ValueError, match="empty"):
        dataclasses.replace(args, cases=[])


def test_command_options_build_the_config():
    parser, module = command_parser("tension")
    config = module.config_from(parser.parse_args(
        ["--void-ratio", "0.65,0.6", "--water-content", "1", "--vtk-every", "100"]))
    assert config.cases == [(0.65, 0.01), (0.6, 0.01)] and config.vtk_every == 100
    assert module.config_from(parser.parse_args([])) == TensionConfig()
    # one grain density: --specific-gravity sets the spheres' density, Gs = rho_s / rho_w
    assert TensionConfig().sample.density == 2650.0 and TensionConfig().specific_gravity == 2.65
    heavy = module.config_from(parser.parse_args(["--specific-gravity", "2.7",
                                                  "--friction", "25", "--confining", "200"]))
    assert heavy.sample.density == 2700.0 and heavy.specific_gravity == 2.7
    assert heavy.sample.friction_deg == 25.0 and heavy.sample.confining == 200.0
    assert heavy.options()["specific_gravity"] == 2.7 and heavy.options()["friction"] == 25.0
    with pytest.raises(SystemExit):           # one of --vtk-every, --vtk-frames
        parser.parse_args(["--vtk-every", "100", "--vtk-frames", "5"])


def test_unreachable_void_ratio_is_refused_with_the_reachable_range(args):
    dense = dataclasses.replace(args, sample=dataclasses.replace(args.sample, particles=100))
    with pytest.raises(ValueError, match=r"--void-ratio = 0.52 is outside the valid range"):
        direct_tension.prepare_void_ratio(dense, 0.52, progress=False)


def test_command_runs_one_case_and_writes_its_outputs(tmp_path):
    out = tmp_path / "tension"
    done = subprocess.run([sys.executable, os.path.join(ROOT, "scenarios", "direct_tension.py"),
                           "--particles", "100", "--void-ratio", "0.72", "--water-content", "1",
                           "--max-strain", "0.01", "--vtk-every", "2000", "--quiet", "--out",
                           str(out)], check=True, capture_output=True, text=True)
    assert json.loads(done.stdout)["cases"][0]["case"] == "e0.72_w1.00"   # --quiet: JSON alone
    result = json.loads((out / "tension.json").read_text())
    (case,) = result["cases"]
    assert not undeclared_keys(case, "tension")
    assert case["tensile_strength_pa"] > 0.0 and case["water_content"] == pytest.approx(
        0.01, rel=WATER_TOLERANCE)
    folder = out / "cases" / case["case"]
    assert (out / "report.md").exists() and (folder / "history.h5").exists()
    assert list((folder / "vtk").glob("*.pvd"))
    # the command line as given, and the configuration it built
    assert result["arguments"]["void_ratio"] == "0.72" and result["arguments"]["quiet"] is True
    config = config_from_dict(result["config"])
    assert config.vtk_every == 2000 and config.sample.particles == 100


def test_prediction_is_chapter4s_kim_comparison(args):
    """pendular.procedures.tension's prediction of Kim's cases is Table 4.5's exact, theta = 0 column of
    pendular.studies.chapter4 (same reference data, same packing choice)."""
    from pendular.homogenize import regular_packing
    from pendular.studies import chapter4
    from pendular.procedures.reference import (KIM_2001, KIM_RADIUS, KIM_SEPARATION,
        comparison_packing)

    for e, w, _ in KIM_2001:
        packing = regular_packing(comparison_packing(e)[0], separation=KIM_SEPARATION)
        expected = chapter4.state(packing, KIM_RADIUS, 0.0, "exact", water_content=w).psi[0, 0]
        assert direct_tension.prediction(args, e, w)[0] == pytest.approx(expected, rel=1e-12)


def test_grips_take_every_particle_touching_their_wall():
    particles = Particles(np.array([[0.5, 0.5, 0.1], [0.5, 0.5, 0.25], [0.5, 0.5, 0.9]]),
                          np.full(3, 0.1), 2650.0)
    walls = Walls.box([0, 0, 0], [1, 1, 1])
    assert grip_members(particles.position, particles.radius, walls, 4, 0.3).tolist() == [0, 1]
    assert grip_members(particles.position, particles.radius, walls, 5, 0.3).tolist() == [2]
    with pytest.raises(ValueError, match="grip depth"):
        grip_members(particles.position, particles.radius, walls, 4, 0.05)
    with pytest.raises(ValueError, match="no particles"):
        Grip(4, [])
