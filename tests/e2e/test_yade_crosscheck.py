"""YADE cross-check (pendular.studies.crosscheck, scenarios/yade_crosscheck.py).

With a ``yade`` executable on PATH: 300 spheres, wet, 1 % axial strain. Both codes start the
shear from the same exported packing, so the wall stresses and the degree of saturation at the
start must agree to round-off and table interpolation; the shear then follows the same law in
both (mimic_yade), and the peak deviator stress and Sr at peak must agree within a few per cent
(measured: 0.1 % and 0.04 %). Takes about 10 s (plus the 300-sphere preparation, cached, the
first time). And 300 spheres dry in a periodic cell (YADE: PeriTriaxController) to 3 %: the
cell's stress at the start agrees to 2e-5, both servos hold the lateral stress within 1 %, and
the peak q agrees within 5 % (measured 0.2 %; docs/yade_crosscheck.md, "Periodic cell").

Without YADE: the pendular half runs against a stand-in that shears the same packing with
pendular and writes YADE's history layout (every difference must then be zero), and the command
line says that YADE is missing.
"""

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from pendular.interop.yade.formats import read_spheres, write_spheres
from pendular.studies import crosscheck
from pendular.procedures.config import YADE_CHOICES
from pendular.io.history import read_history

from conftest import ROOT, assert_drawn, requires
from support.yade_stand_in import pendular_as_yade

SCENARIO = os.path.join(ROOT, "scenarios", "yade_crosscheck.py")
#: Tolerances of the agreement checks [-]: start of the shear (same packing), peak (same law).
START_TOLERANCE = 1e-3
PEAK_TOLERANCE = 0.05
SUMMARY_KEYS = ("peak_q", "p_at_peak", "axial_strain_at_peak", "volumetric_strain_at_peak",
                "saturation_at_peak", "bridges_at_peak", "porosity_at_peak", "seconds_per_step",
                "particle_steps_per_s")
DIFFERENCES = ("peak_q_rel_diff", "saturation_rel_diff", "volumetric_strain_at_peak_diff",
               "start_sigma_rel_diff", "start_saturation_rel_diff")


def check_result(result, max_strain, tolerance=0.01):
    """Finite differences and summaries (those of the bridges only in a wet result); both codes
    reach ``max_strain`` within ``tolerance`` (relative; the last record period may overshoot
    it)."""
    def measured(keys):
        return [key for key in keys if result["suction"] > 0.0 or not
                any(word in key for word in ("saturation", "bridges"))]

    for key in measured(DIFFERENCES):
        assert math.isfinite(result[key]), key
    for code in ("pendular", "yade"):
        summary = result[code]
        for key in measured(SUMMARY_KEYS):
            assert math.isfinite(summary[key]), (code, key)
            assert summary[key] >= 0.0 or key == "volumetric_strain_at_peak", (code, key)
        assert summary["final_axial_strain"] == pytest.approx(max_strain, rel=tolerance)
        assert summary["peak_q"] > 0.0


@requires("yade")
def test_wet_crosscheck_agrees(tmp_path):
    config = crosscheck.crosscheck_config(particles=300, suction=30000.0, max_strain=0.01,
                                          records=50, mimic_yade=True)
    result = crosscheck.CrossCheck(config).run(tmp_path, progress=False)
    assert json.loads((tmp_path / "crosscheck.json").read_text())["peak_q_rel_diff"] == \
        result["peak_q_rel_diff"]
    assert_drawn(tmp_path / "crosscheck.png")
    check_result(result, 0.01)
    # same packing, same bridges: the start of the shear is the same state in both codes
    assert result["start_sigma_rel_diff"] < START_TOLERANCE
    assert abs(result["start_saturation_rel_diff"]) < START_TOLERANCE
    assert result["pendular"]["start"]["bridges"] == result["yade"]["start"]["bridges"] > 0
    # the same shear law: the peak agrees
    assert abs(result["peak_q_rel_diff"]) < PEAK_TOLERANCE
    assert abs(result["saturation_rel_diff"]) < PEAK_TOLERANCE
    assert abs(result["volumetric_strain_at_peak_diff"]) < 1e-3


@requires("yade")
def test_periodic_crosscheck_agrees(tmp_path):
    config = crosscheck.crosscheck_config(particles=300, max_strain=0.03, records=30,
                                          periodic=True)
    result = crosscheck.CrossCheck(config).run(tmp_path, progress=False)
    check_result(result, 0.03)
    assert result["periodic"] and result["yade"]["controller"]["controller"] == \
        "PeriTriaxController"
    # same packing in the same cell: the Love-Weber stress at the start is the same
    assert result["start_sigma_rel_diff"] < START_TOLERANCE
    # both cell servos hold the confining stress (YADE's with pendular's gain) ...
    for code in ("pendular", "yade"):
        assert result[code]["lateral_stress_max_rel_error"] < 0.01, code
    # ... so the same contact law gives the same peak: a 300-sphere sample scatters by about
    # 2 % between two codes once past the peak (walled measurements), PEAK_TOLERANCE is 5 %
    assert abs(result["peak_q_rel_diff"]) < PEAK_TOLERANCE
    assert abs(result["volumetric_strain_at_peak_diff"]) < 2e-3


# ---------------------------------------------------------------- without YADE

def test_pendular_half_against_itself(tmp_path, monkeypatch):
    """The whole cross-check (settle, export, shear, compare, write) with pendular on both
    sides: the differences are zero, the outputs complete, the driver's settings those of the
    scene."""
    config = crosscheck.crosscheck_config(particles=60, suction=30000.0, max_strain=0.004,
                                          records=8, mimic_yade=True)
    seen = {}

    def fake_files(contact_angle):
        seen["contact_angle"] = contact_angle
        return str(tmp_path)

    def fake_run(settings, threads=1, env=None):
        seen["settings"] = settings
        return pendular_as_yade(config)(settings, threads, env)

    monkeypatch.setattr(crosscheck, "find_yade", lambda: "yade")
    monkeypatch.setattr(crosscheck, "yade_capillary_files", fake_files)
    monkeypatch.setattr(crosscheck, "run_yade_triaxial", fake_run)
    out = tmp_path / "out"
    result = crosscheck.CrossCheck(config).run(out, progress=False)

    check_result(result, 0.004, tolerance=1.0 / 8 + 0.01)
    for key in DIFFERENCES:
        assert result[key] == 0.0, key
    assert result["pendular"]["start"]["bridges"] == result["settle"]["bridges"] > 0
    assert result["mimic_yade"] and result["suction"] == 30000.0 and result["particles"] == 60
    stored = json.loads((out / "crosscheck.json").read_text())
    assert set(stored) >= {"shear_config", "servo", "settle", "packing", "config",
                           "cost_ratio_yade_over_pendular", "axial_strain_at_peak_diff"}
    assert stored["shear_config"]["servo_stiffness_every"] == 10
    assert (out / "crosscheck.png").stat().st_size > 0 and (out / "packing.txt").exists()
    history = read_history(out / "pendular_history.h5", index="record")
    assert history.sizes["record"] >= 8 and "sigma_effective" in history
    # the driver is given the scene's settings
    settings = seen["settings"]
    assert seen["contact_angle"] == 0.0
    assert settings["capillary"] == {"suction": 30000.0, "files": str(tmp_path),
                                     "surface_tension": 0.073, "persist": False}
    assert settings["dt"] == result["dt"] and settings["strain_rate"] == result["strain_rate"]
    assert settings["stress_damping"] == pytest.approx(1.0 - result["servo"]["gain"])
    assert settings["max_vel"] == result["servo"]["max_velocity"]
    # a second cross-check shears the exported packing again without settling
    again = crosscheck.CrossCheck(config, packing=out / "packing.txt").run(tmp_path / "again",
                                                                          progress=False)
    assert again["settle"] == {"from": str(out / "packing.txt")}
    assert again["pendular"]["peak_q"] == result["pendular"]["peak_q"]


def test_periodic_pendular_half_against_itself(tmp_path, monkeypatch):
    """The periodic cross-check with pendular on both sides: the packing is the cell's, the
    driver is asked for a periodic cell with its stress evaluated every step and pendular's
    servo gain (growDamping below 0 at micrometre spheres), the differences are zero."""
    config = crosscheck.crosscheck_config(particles=100, max_strain=0.004, records=8,
                                          periodic=True)
    seen = {}

    def fake_run(settings, threads=1, env=None):
        seen["settings"] = settings
        return pendular_as_yade(config)(settings, threads, env)

    monkeypatch.setattr(crosscheck, "find_yade", lambda: "yade")
    monkeypatch.setattr(crosscheck, "run_yade_triaxial", fake_run)
    out = tmp_path / "out"
    result = crosscheck.CrossCheck(config).run(out, progress=False)
    check_result(result, 0.004, tolerance=1.0 / 8 + 0.01)
    assert result["peak_q_rel_diff"] == result["start_sigma_rel_diff"] == 0.0
    assert result["periodic"] and result["pendular"]["lateral_stress_max_rel_error"] < 0.05
    settings = seen["settings"]
    assert settings["periodic"] and settings["glob_update"] == 1
    assert settings["stress_damping"] < 0.0
    position, _, lo, hi = read_spheres(out / "packing.txt")
    assert np.all(lo == 0.0) and np.all((position >= 0.0) & (position < hi))
    # a walled cross-check's packing is not a cell
    walled = tmp_path / "walled.txt"
    write_spheres(walled, position + 1e-6, np.full(len(position), 2.4e-5), lo + 1e-6,
                  hi + 1e-6)
    with pytest.raises(ValueError, match="packing = .*box_lo"):
        crosscheck.CrossCheck(config, packing=walled)


@requires("yade")
def test_hertz_mindlin_crosscheck_agrees(tmp_path):
    """YADE's Ip2_FrictMat_FrictMat_MindlinPhys / Law2_ScGeom_MindlinPhys_Mindlin against
    pendular's Hertz–Mindlin law on the same packing: the walls' Hertz contacts made alike
    (yade_wall_poisson), the wall stresses at the start agree to round-off (YADE's own wall
    contacts, a sphere on a twin sphere, would be 2 sqrt(2) times softer), and the peak
    within 5 %."""
    config = crosscheck.crosscheck_config(particles=300, max_strain=0.01, records=30,
                                          contact="hertz-mindlin", mimic_yade=True)
    result = crosscheck.CrossCheck(config).run(tmp_path, progress=False)
    check_result(result, 0.01)
    assert json.loads((tmp_path / "yade_result.json").read_text())["contact"] == "hertz-mindlin"
    assert result["start_sigma_rel_diff"] < START_TOLERANCE
    assert abs(result["peak_q_rel_diff"]) < PEAK_TOLERANCE


def test_yades_wall_contact_is_made_pendulars_rigid_plane():
    """Ip2_FrictMat_FrictMat_MindlinPhys's mixing (E* = Ea Eb / ((1 - va^2) Eb + (1 - vb^2) Ea),
    R* = Ra Rb / (Ra + Rb), a box taking the sphere's radius) with the wall material's
    Poisson ratio of yade_wall_poisson gives Hertz's coefficient 4/3 E* sqrt(R*) of a sphere on
    pendular's rigid plane, E / (1 - nu^2) with R* = R."""
    from pendular.dem.hertz_mindlin import effective_modulus

    for young, poisson, radius in ((1e6, 0.3, 2.4e-5), (7e10, 0.22, 1e-3), (1e9, 0.0, 1e-4)):
        wall = crosscheck.yade_wall_poisson(poisson)
        mixed = young * young / ((1.0 - poisson ** 2) * young + (1.0 - wall ** 2) * young)
        yade = 4.0 / 3.0 * mixed * math.sqrt(radius * radius / (2.0 * radius))
        rigid = 4.0 / 3.0 * effective_modulus(young, poisson) * math.sqrt(radius)
        assert yade == pytest.approx(rigid, rel=1e-12)


def test_command_refuses_a_wet_or_periodic_hertz_mindlin_crosscheck():
    from pendular.cli import UsageError, command_parser
    from pendular.cli.commands.crosscheck import check, config_from

    parser, _ = command_parser("crosscheck")
    config = config_from(parser.parse_args(["--contact", "hertz-mindlin", "--poisson", "0.25"]))
    assert (config.sample.contact, config.sample.poisson) == ("hertz-mindlin", 0.25)
    for extra, flag in ((["--suction", "1e4"], "--suction"), (["--periodic"], "--periodic")):
        with pytest.raises(UsageError, match=f"{flag} with --contact hertz-mindlin"):
            check(parser.parse_args(["--contact", "hertz-mindlin", *extra]))
    with pytest.raises(ValueError, match="contact = 'hertz-mindlin' with bridges"):
        crosscheck.check_mirrored(crosscheck.crosscheck_config(suction=1e4,
                                                               contact="hertz-mindlin"))


def test_configuration_and_refusals():
    assert crosscheck.mimics_yade(crosscheck.crosscheck_config(mimic_yade=True).shear)
    assert not crosscheck.mimics_yade(crosscheck.crosscheck_config().shear)
    assert all(getattr(crosscheck.crosscheck_config(mimic_yade=True).shear, k) == v
               for k, v in YADE_CHOICES.items())
    assert crosscheck.crosscheck_config().bridges is None
    toroidal = crosscheck.crosscheck_config(suction=1e4)
    toroidal.bridges.model = "toroidal"
    with pytest.raises(ValueError, match="model = 'toroidal'"):
        crosscheck.check_mirrored(toroidal)
    assert crosscheck.crosscheck_config(periodic=True).sample.periodic
    with pytest.raises(ValueError, match="suction = 10000 Pa with a periodic cell"):
        crosscheck.check_mirrored(crosscheck.crosscheck_config(suction=1e4, periodic=True))


def test_command_refuses_a_wet_periodic_crosscheck():
    from pendular.cli import UsageError, command_parser
    from pendular.cli.commands.crosscheck import check, config_from

    parser, _ = command_parser("crosscheck")
    assert config_from(parser.parse_args(["--periodic"])).sample.periodic
    with pytest.raises(UsageError, match="--suction 10000.0 Pa with --periodic"):
        check(parser.parse_args(["--periodic", "--suction", "1e4"]))


def test_the_crosscheck_takes_the_grading_options_of_the_triaxial_command(tmp_path):
    from pendular.cli import command_parser
    from pendular.cli.commands.crosscheck import config_from

    curve = tmp_path / "psd.csv"
    curve.write_text("3e-5,0\n5e-5,50\n8e-5,100\n")
    parser, _ = command_parser("crosscheck")
    spread = config_from(parser.parse_args(["--radius", "2.31e-5", "--radius-spread", "0.3",
                                            "--seed", "2"])).sample
    assert (spread.radius, spread.radius_spread, spread.seed) == (2.31e-5, 0.3, 2)
    graded = config_from(parser.parse_args(["--psd", str(curve)])).sample
    assert graded.psd == ((3e-5, 0.0), (5e-5, 50.0), (8e-5, 100.0))


def test_command_line_says_when_yade_is_missing():
    environment = dict(os.environ, PATH="")
    result = subprocess.run([sys.executable, SCENARIO, "--particles", "100", "--quiet"],
                            capture_output=True, text=True, env=environment, timeout=300)
    assert result.returncode == 2
    assert "yade_crosscheck.py: error: no YADE executable" in result.stderr
    assert "Traceback" not in result.stderr
