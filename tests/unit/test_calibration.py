"""Calibration (pendular.studies.calibration): the measured curve's CSV and each of its
refusals (file, line, column), the --fit specifications, and `pendular calibrate` refusing bad
input in one error line before anything runs."""

import json
import os

import numpy as np
import pytest

from conftest import refused, requires, run_in_process

from pendular.studies.calibration import (MIN_POINTS, SEED_REPLICATES, Calibration, Fit,
                                          parse_fit, read_curve)

TRIAXIAL = "axial_strain,q,volumetric_strain\n0.01,300,0.001\n0.02,450,-0.001\n0.04,500,-0.004\n"


def write(tmp_path, text, name="curve.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_a_triaxial_curve_is_read_column_by_column(tmp_path):
    curve = read_curve(write(tmp_path, " axial_strain , q\n\n0.01,300\n0.02,450\n0.04,500\n"),
                       "triaxial")
    assert curve.columns == ["q"]
    np.testing.assert_array_equal(curve.control, [0.01, 0.02, 0.04])
    np.testing.assert_array_equal(curve.observed["q"], [300.0, 450.0, 500.0])
    both = read_curve(write(tmp_path, TRIAXIAL), "triaxial")
    assert both.columns == ["q", "volumetric_strain"]
    # each column from its least value in the data, in units of its range there
    np.testing.assert_allclose(both.scaled("q", both.observed["q"]), [0.0, 0.75, 1.0])
    np.testing.assert_allclose(both.scaled("volumetric_strain", [0.001, -0.004]), [1.0, 0.0])


@pytest.mark.parametrize("text, words", [
    ("axial_strain,q,pressure\n0.01,1,2\n0.02,2,3\n0.03,3,4\n",
     ["line 1, column 3", "unknown column 'pressure'", "axial_strain, q, volumetric_strain"]),
    ("axial_stress,void_ratio\n1000,0.7\n2000,0.69\n4000,0.68\n",
     ["line 1", "curve of oedometer, not of triaxial"]),
    ("axial_strain,volumetric_strain\n0.01,0\n0.02,0\n0.03,0\n", ["line 1", "'q' missing"]),
    ("axial_strain,q\n0.01,300\n0.02,nan\n0.03,500\n",
     ["line 3, column 2", "'nan' is not a finite number"]),
    ("axial_strain,q\n0.01,300\n0.02,abc\n0.03,500\n", ["line 3, column 2", "not a number"]),
    ("axial_strain,q\n0.01,300\n0.03,450\n0.02,500\n",
     ["line 4, column 1", "axial_strain = 0.02 does not rise", "0.03"]),
    ("axial_strain,q\n0.01,300\n0.01,450\n0.02,500\n", ["line 3, column 1", "does not rise"]),
    ("axial_strain,q\n0.01,300\n0.02,450\n", ["2 points", f"at least {MIN_POINTS}"]),
    ("axial_strain,q\n0.01,300\n0.02\n0.03,500\n", ["line 3", "1 values, 2 columns"]),
    ("axial_strain,q,q\n0.01,1,1\n0.02,2,2\n0.03,3,3\n", ["line 1", "'q' given twice"]),
    ("", ["is empty", "axial_strain, q"]),
])
def test_a_bad_curve_is_refused_naming_the_file_line_and_column(tmp_path, text, words):
    path = write(tmp_path, text)
    with pytest.raises(ValueError) as error:
        read_curve(path, "triaxial")
    assert str(path) in str(error.value)
    for word in words:
        assert word in str(error.value), (word, str(error.value))


def test_a_missing_file_is_refused(tmp_path):
    with pytest.raises(ValueError, match="no such file"):
        read_curve(tmp_path / "absent.csv", "triaxial")


def test_fit_names_a_numeric_option_of_the_test_in_its_units():
    fit = parse_fit("friction=10:50", "triaxial")
    assert fit == Fit("friction", 10.0, 50.0, "deg")
    assert parse_fit("contact-angle=0:60", "triaxial").key == "contact_angle"
    assert parse_fit("particles=100:200", "triaxial").integer
    assert parse_fit("particles=100:200", "triaxial").value(149.6) == 150


def test_the_contact_laws_numbers_are_fitted_and_their_choices_fixed(tmp_path):
    """Hertz–Mindlin's Poisson ratio and restitution, rolling resistance and gravity are
    numbers --fit names; --contact and --drainage, choices, are fixed options of the runs."""
    fits = [parse_fit(text, "triaxial") for text in
            ("poisson=0.1:0.4", "restitution=0.3:0.9", "rolling-friction=0:0.2",
             "gravity=0:9.81")]
    assert [fit.unit for fit in fits] == ["1", "1", "1", "m/s^2"]
    for text in ("contact=0:1", "drainage=0:1"):
        with pytest.raises(ValueError, match="not a numeric option"):
            parse_fit(text, "triaxial")
    calibration = Calibration("triaxial", {"particles": 60, "max_strain": 0.05,
                                           "contact": "hertz-mindlin", "drainage": "undrained"},
                              fits, read_curve(write(tmp_path, TRIAXIAL), "triaxial"))
    config = calibration.config(calibration.sample_values([0.25, 0.6, 0.1, 9.81]))
    assert (config.sample.contact, config.shear.drainage) == ("hertz-mindlin", "undrained")
    assert (config.sample.poisson, config.sample.restitution, config.sample.rolling_friction,
            config.sample.gravity) == (0.25, 0.6, 0.1, 9.81)


@pytest.mark.parametrize("text, words", [
    ("frictio=10:50", ["'frictio' is not a numeric option of triaxial", "friction"]),
    ("periodic=0:1", ["'periodic' is not a numeric option"]),          # a flag
    ("vtk-every=0:10", ["not a numeric option"]),                      # set by calibrate
    ("seed=0:10", ["not a numeric option"]),                           # varied by calibrate
    ("friction=50:10", ["range [50, 10] is empty", "LOW < HIGH"]),
    ("friction=10:10", ["is empty"]),
    ("friction=10", ["NAME=LOW:HIGH"]),
    ("friction:10:50", ["NAME=LOW:HIGH"]),
    ("friction=a:50", ["must be numbers"]),
    ("friction=10:inf", ["finite"]),
])
def test_a_bad_fit_is_refused_naming_it(text, words):
    with pytest.raises(ValueError) as error:
        parse_fit(text, "triaxial")
    assert f"--fit {text!r}" in str(error.value)
    for word in words:
        assert word in str(error.value), (word, str(error.value))


def test_a_list_option_cannot_be_fitted():
    with pytest.raises(ValueError, match="'stresses' is not a numeric option of isotropic"):
        parse_fit("stresses=1:2", "isotropic")


def test_calibration_checks_the_prior_against_the_options_declaration(tmp_path):
    curve = read_curve(write(tmp_path, TRIAXIAL), "triaxial")
    options = {"particles": 60, "max_strain": 0.05}
    with pytest.raises(ValueError, match=r"--fit friction=5:95: --friction = 95.0 deg is "
                                         r"outside the valid range \[0, 90\)"):
        Calibration("triaxial", options, [parse_fit("friction=5:95", "triaxial")], curve)
    with pytest.raises(ValueError, match="--friction: fitted"):
        Calibration("triaxial", {**options, "friction": 20}, [parse_fit("friction=5:40",
                                                                        "triaxial")], curve)
    with pytest.raises(ValueError, match="--fit friction given twice"):
        Calibration("triaxial", options, [parse_fit("friction=5:40", "triaxial")] * 2, curve)
    with pytest.raises(ValueError, match="--max-strain 0.03 is below the data's last "
                                         "axial_strain 0.04"):
        Calibration("triaxial", {**options, "max_strain": 0.03},
                    [parse_fit("friction=5:40", "triaxial")], curve)
    with pytest.raises(ValueError, match=r"--samples 3: valid range \[4, inf\)"):
        Calibration("triaxial", options, [parse_fit("friction=5:40", "triaxial")], curve,
                    samples=3)
    calibration = Calibration("triaxial", options, [parse_fit("friction=5:40", "triaxial")],
                              curve)
    seeds = calibration.seed_runs({"friction": 17.0})
    assert [run.config.sample.seed for run in seeds] == list(range(1, SEED_REPLICATES + 1))
    assert {run.config.sample.friction_deg for run in seeds} == {17.0}


def test_the_seed_noise_is_counted_once_per_curve(tmp_path):
    curve = read_curve(write(tmp_path, TRIAXIAL), "triaxial")
    calibration = Calibration("triaxial", {"particles": 60, "max_strain": 0.05},
                              [parse_fit("friction=5:40", "triaxial")], curve)
    base = np.zeros((2, 3))
    scatter = np.array([[0.1], [0.2]])
    curves = [base + scatter, base - scatter]  # variances 0.02 and 0.08 at each of 3 points
    # the data and a run: two samples, whose difference has twice that variance, per column
    assert calibration.seed_noise(curves) == pytest.approx([2 * 0.02 * 3, 2 * 0.08 * 3])
    assert np.all(calibration.seed_noise([base, base]) > 0.0)  # a positive bound for the filter


@pytest.mark.parametrize("argv, words", [
    (["--fit", "frictio=5:40"], ["--fit 'frictio=5:40'", "not a numeric option"]),
    (["--fit", "friction=40:5"], ["--fit 'friction=40:5'", "is empty"]),
    (["--fit", "friction=5:40", "--test", "cyclic"],
     ["--test cyclic", "calibrate compares curves of triaxial, oedometer"]),
    (["--fit", "friction=5:40", "--amplitude-q", "100"],
     ["--amplitude-q is not an option of triaxial"]),
    (["--fit", "friction=5:40", "--particles", "10"], ["--particles", "[50, "]),
    (["--fit", "friction=5:40", "--max-strain", "0.01"], ["--max-strain 0.01 is below"]),
])
def test_calibrate_refuses_bad_input_in_one_line_before_anything_runs(tmp_path, capsys, argv,
                                                                    words):
    data = write(tmp_path, TRIAXIAL)
    out = tmp_path / "out"
    command = ["--data", data, "--test", "triaxial", "--particles", "60", "--max-strain",
               "0.05", "--out", out, *argv]
    refused(*run_in_process("calibrate", command, capsys), *words)
    assert not out.exists()


def test_calibrate_refuses_a_curve_of_another_test(tmp_path, capsys):
    data = write(tmp_path, "axial_stress,void_ratio\n1000,0.7\n2000,0.69\n4000,0.68\n")
    out = tmp_path / "out"
    refused(*run_in_process("calibrate", ["--data", data, "--test", "triaxial", "--fit",
                                          "friction=5:40", "--out", out], capsys),
            str(data), "curve of oedometer, not of triaxial")
    assert not out.exists()


@requires("grainlearning")
def test_the_inference_recovers_a_parameter_and_reports_one_it_cannot_see(tmp_path, monkeypatch):
    """A stand-in for the runs (a closed-form curve of the contact friction, in which Young's
    modulus plays no part, with a scatter of 2 % between seeds) in place of the campaign: the
    friction is recovered within its reported std, Young's modulus reported unconstrained."""
    import pendular.studies.calibration as calibration_module
    from pendular.studies.calibration import CurveKind, MeasuredCurve
    from pendular.studies.campaign import CampaignResult

    strain = np.linspace(0.0, 0.05, 101)

    def curve(friction, seed):
        scatter = 1.0 + 0.02 * np.random.default_rng(seed).standard_normal()
        return (1e3 * np.tan(np.radians(friction)) * (1.0 - np.exp(-strain / 0.01))
                * scatter)

    configs = {}

    class StandIn:
        def __init__(self, runs):
            self.runs = runs

        def run(self, out, options=None, **settings):
            for run in self.runs:
                configs[os.path.join(out, "runs", run.name)] = run.config
            return CampaignResult(self.runs, summaries={run.name: {} for run in self.runs})

    def read(folder):
        sample = configs[folder].sample
        return {"axial_strain": strain, "q": curve(sample.friction_deg, sample.seed)}

    monkeypatch.setattr(calibration_module, "Campaign", StandIn)
    kind = CurveKind("axial_strain", ("q",), {}, read, lambda config: ("max_strain", 0.05))
    control = np.linspace(0.005, 0.05, 10)
    data = MeasuredCurve("stand-in", kind, control,
                         {"q": np.interp(control, strain, curve(20.0, 7))})
    fits = [parse_fit("friction=5:40", "triaxial"), parse_fit("young=5e5:5e6", "triaxial")]
    calibration = Calibration("triaxial", {"particles": 60, "max_strain": 0.05}, fits, data,
                              iterations=3, samples=16)
    summary = calibration.run(str(tmp_path), log=lambda message: None)
    friction, young = summary["parameters"]["friction"], summary["parameters"]["young"]
    assert abs(friction["mean"] - 20.0) < max(2.0 * friction["std"], 0.5), friction
    assert friction["constrained"] and friction["std"] < 0.3 * friction["prior_std"]
    assert not young["constrained"], young
    assert set(summary["seed_noise"]) == {"q"} and summary["seed_noise"]["q"] > 0.0
    assert len(summary["rows"]) == 3 * 16


def test_a_tension_curve_runs_one_specimen_per_water_content_of_the_data(tmp_path):
    data = write(tmp_path, "water_content,tensile_strength\n0.005,400\n0.01,600\n0.02,700\n")
    curve = read_curve(data, "tension")
    fits = [parse_fit("contact-angle=0:30", "tension")]
    calibration = Calibration("tension", {"particles": 100, "void_ratio": 0.7}, fits, curve)
    config = calibration.config({"contact_angle": 10.0})
    np.testing.assert_allclose(config.cases, [(0.7, 0.005), (0.7, 0.01), (0.7, 0.02)])
    with pytest.raises(ValueError, match="--water-content: set by calibrate from the data's "
                                         "water_content column"):
        Calibration("tension", {"particles": 100, "void_ratio": 0.7, "water_content": 1.0},
                    fits, curve)
    with pytest.raises(ValueError, match="--void-ratio 0.58,0.72: give one void ratio"):
        Calibration("tension", {"particles": 100}, fits, curve)
    # the run's tension.json read back as the data's columns, by water content
    (tmp_path / "tension.json").write_text(json.dumps({"cases": [
        {"water_content_target": 0.01, "tensile_strength_pa": 610.0},
        {"water_content_target": 0.005, "tensile_strength_pa": 390.0},
        {"water_content_target": 0.02, "tensile_strength_pa": 720.0}]}))
    run = curve.kind.read(str(tmp_path))
    np.testing.assert_array_equal(run["water_content"], [0.005, 0.01, 0.02])
    np.testing.assert_array_equal(run["tensile_strength"], [390.0, 610.0, 720.0])


def test_an_swcc_curve_is_its_drying_branch(tmp_path):
    (tmp_path / "swcc.json").write_text(json.dumps({
        "drying": [{"suction": 5000.0, "saturation": 0.1}, {"suction": 10000.0,
                                                             "saturation": 0.05}],
        "wetting": [{"suction": 10000.0, "saturation": 0.05}, {"suction": 5000.0,
                                                               "saturation": 0.07}]}))
    run = read_curve(write(tmp_path, "suction,saturation\n5000,0.1\n7000,0.08\n10000,0.05\n"),
                     "swcc").kind.read(str(tmp_path))
    np.testing.assert_array_equal(run["suction"], [5000.0, 10000.0])
    np.testing.assert_array_equal(run["saturation"], [0.1, 0.05])
