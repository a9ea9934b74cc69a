"""Graded samples (issue 13): size distributions from a spread or a grading curve, the grading of
a sample against closed forms, preparation with unequal spheres, and the command's options."""

import json

import numba
import numpy as np
import pytest

from conftest import refused, run_in_process

from pendular.dem.grading import (MAX_RADIUS_SPREAD, grading, passing, read_grading_curve,
    sample_radii, size_at_passing)
from pendular.dem.cloud import random_cloud
from pendular.procedures.preparation import PrepareConfig, prepare_sample
from pendular.cli import run_command
from pendular.io.history import read_history
from pendular.procedures.triaxial import TriaxialConfig
from pendular.procedures.config import config_from_dict, config_json, config_to_dict
from pendular.procedures.triaxial import TriaxialTest

CURVE = ((30e-6, 0.0), (40e-6, 20.0), (50e-6, 60.0), (80e-6, 100.0))


def refused_triaxial(capsys, argv, *words):
    return refused(*run_in_process("triaxial", argv, capsys, prog="triaxial.py"), *words)


def test_grading_of_a_uniform_distribution_matches_its_closed_form():
    """Radii uniform on [a, b]: mass passing F(r) = (r^4 - a^4) / (b^4 - a^4)."""
    a, b = 1.0e-5, 3.0e-5
    radii = sample_radii(20000, 2.0e-5, spread=0.5)
    assert radii.min() == pytest.approx(a, rel=1e-4) and radii.max() == pytest.approx(b, rel=1e-4)
    for percent in (10.0, 30.0, 50.0, 60.0):
        r = (a ** 4 + percent / 100.0 * (b ** 4 - a ** 4)) ** 0.25
        assert size_at_passing(radii, percent) == pytest.approx(2.0 * r, rel=2e-3)
    result = grading(radii)
    assert result["Cu"] == pytest.approx(result["D60"] / result["D10"])
    assert result["radius_mean"] == pytest.approx(2.0e-5, rel=1e-12)


def test_passing_of_two_sizes_is_their_mass_fraction():
    radii = np.array([1.0, 1.0, 1.0, 2.0]) * 1e-5         # masses 1, 1, 1, 8
    assert passing(radii, [1e-5, 2e-5, 4e-5]).tolist() == pytest.approx([0.0, 300 / 11, 100.0])


def test_a_prepared_graded_sample_follows_its_grading_curve():
    config = PrepareConfig(particles=400, psd=CURVE, confining=750.0, seed=1, unload_steps=400)
    sim, report = prepare_sample(config, progress=False)
    radius = sim.particles.radius
    sieves = [d for d, _ in CURVE]
    assert passing(radius, sieves) == pytest.approx([p for _, p in CURVE], abs=1.5)
    assert report["grading"]["radius_mean"] == pytest.approx(config.radius, rel=1e-9)
    assert 0.3 < report["porosity"] < 0.45


def test_a_spread_gives_radii_in_r_one_plus_minus_s_about_the_mean():
    config = PrepareConfig(particles=300, radius_spread=0.3, confining=750.0, seed=2,
                           unload_steps=400, timestep_rule="pwave")
    sim, report = prepare_sample(config, progress=False)
    radius = sim.particles.radius
    assert radius.mean() == pytest.approx(config.radius, rel=1e-9)
    assert radius.min() >= 0.7 * config.radius * (1 - 1e-9)
    assert radius.max() <= 1.3 * config.radius * (1 + 1e-9)
    assert radius.max() / radius.min() > 1.8
    # the P-wave rule reads the smallest sphere
    assert sim.dt == pytest.approx(config.timestep_safety * radius.min()
                                   / np.sqrt(config.young / config.density))


def test_a_graded_cloud_has_no_overlap_up_to_a_ratio_of_ten():
    radii = sample_radii(1500, 1.0, spread=MAX_RADIUS_SPREAD, seed=4)
    assert radii.max() / radii.min() == pytest.approx(10.0, rel=1e-2)
    edge = (4.0 / 3.0 * np.pi * np.sum(radii ** 3) / 0.15) ** (1.0 / 3.0)
    position = random_cloud(len(radii), radii, np.zeros(3), np.full(3, edge), seed=4)
    assert np.all(position - radii[:, None] >= 0.0) and np.all(position + radii[:, None] <= edge)
    gap = np.linalg.norm(position[:, None] - position[None], axis=2) - (radii[:, None] + radii)
    np.fill_diagonal(gap, 1.0)
    assert gap.min() >= 0.0


@pytest.mark.parametrize("options, words", [
    ({"radius_spread": 0.85}, ["radius_spread", "0.818"]),
    ({"radius_spread": -0.1}, ["radius_spread"]),
    ({"psd": ((1e-5, 0.0), (2e-4, 100.0))}, ["psd", "ratio of 20"]),
    ({"psd": ((2e-5, 0.0), (1e-5, 100.0))}, ["psd", "increasing"]),
    ({"psd": ((1e-5, 0.0), (2e-5, 60.0), (3e-5, 50.0), (4e-5, 100.0))}, ["psd", "decrease"]),
    ({"psd": ((1e-5, 10.0), (2e-5, 100.0))}, ["psd", "from 0"]),
    ({"psd": CURVE, "radius_spread": 0.2}, ["radius_spread", "psd"]),
])
def test_distributions_out_of_range_are_refused_naming_the_parameter(options, words):
    with pytest.raises(ValueError) as error:
        PrepareConfig(particles=100, **options)
    for word in words:
        assert word in str(error.value)


def test_same_seed_same_graded_sample_for_any_thread_count():
    config = PrepareConfig(particles=150, radius_spread=0.4, confining=750.0, seed=7,
                           unload_steps=400)
    first, _ = prepare_sample(config, progress=False, threads=1)
    again, _ = prepare_sample(config, progress=False,
                              threads=numba.config.NUMBA_NUM_THREADS)
    assert np.array_equal(first.particles.position, again.particles.position)
    assert np.array_equal(first.particles.radius, again.particles.radius)
    other, _ = prepare_sample(PrepareConfig(particles=150, radius_spread=0.4, confining=750.0,
                                            seed=8, unload_steps=400), progress=False)
    assert not np.array_equal(first.particles.radius, other.particles.radius)


def test_a_graded_configuration_round_trips_through_json():
    config = PrepareConfig(particles=200, psd=CURVE, seed=3)
    again = config_from_dict(json.loads(json.dumps(config_to_dict(config))))
    assert config_json(again) == config_json(config)
    assert again.radius == config.radius and again.psd == CURVE


def test_a_grading_curve_is_read_from_a_sieve_table(tmp_path):
    path = tmp_path / "psd.csv"
    path.write_text("# F-like sand\ndiameter_m,passing_percent\n"
                    + "".join(f"{d},{p}\n" for d, p in CURVE))
    assert read_grading_curve(str(path)) == CURVE


def test_bad_grading_options_end_in_one_error_line(tmp_path, capsys):
    out = ["--out", str(tmp_path / "out"), "--particles", "100"]
    (tmp_path / "wide.csv").write_text("1e-5,0\n2e-4,100\n")
    (tmp_path / "words.csv").write_text("1e-5,0\nfine,sand\n")
    (tmp_path / "down.csv").write_text("1e-5,0\n3e-5,80\n2e-5,100\n")
    refused_triaxial(capsys, out + ["--psd", str(tmp_path / "missing.csv")], "missing.csv")
    refused_triaxial(capsys, out + ["--psd", str(tmp_path / "wide.csv")], "wide.csv", "[1, 10]")
    refused_triaxial(capsys, out + ["--psd", str(tmp_path / "words.csv")], "words.csv", "row 2")
    refused_triaxial(capsys, out + ["--psd", str(tmp_path / "down.csv")], "down.csv", "increasing")
    refused_triaxial(capsys, out + ["--psd", str(tmp_path / "down.csv"), "--radius", "1e-5"],
            "--radius", "--psd")
    refused_triaxial(capsys, out + ["--radius-spread", "0.9"], "--radius-spread = 0.9")


def test_a_graded_wet_triaxial_reports_its_grading(tmp_path):
    out = tmp_path / "out"
    status = run_command("triaxial", ["--particles", "300", "--radius-spread", "0.3",
                                      "--suction", "30000", "--max-strain", "0.01",
                                      "--inertial-number", "1e-3", "--vtk-frames", "0",
                                      "--no-plots", "--quiet", "--out", str(out)])
    assert status == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["grading"]["radius_mean"] == pytest.approx(2.4e-5, rel=1e-9)
    assert 0.7 * 2.4e-5 <= summary["grading"]["radius_min"] < 0.8 * 2.4e-5
    assert summary["grading"]["Cu"] > 1.2 and summary["units"]["grading"]["D50"] == "m"
    assert summary["stress_balance_flagged"] == []
    assert summary["saturation_at_peak"] > 0.0


@pytest.fixture(scope="module")
def graded_run(tmp_path_factory):
    """Output folder of a short triaxial of 120 spheres of radius spread 0.3 (seed 3), whose
    sample.h5 the tests below load; made once for the module, read only."""
    out = tmp_path_factory.mktemp("graded") / "graded"
    assert run_command("triaxial", ["--particles", "120", "--radius-spread", "0.3",
                                    "--seed", "3", "--max-strain", "0.002",
                                    "--inertial-number", "2e-3", "--vtk-frames", "0",
                                    "--no-plots", "--quiet", "--out", str(out)]) == 0
    return out


def test_a_sample_of_another_spread_is_refused_naming_the_sizes(graded_run, tmp_path, capsys):
    sample = str(graded_run / "sample.h5")
    again = ["--particles", "120", "--max-strain", "0.002", "--inertial-number", "2e-3",
             "--vtk-frames", "0", "--no-plots", "--quiet", "--sample", sample]
    assert run_command("triaxial", again + ["--radius-spread", "0.3",
                                            "--out", str(tmp_path / "same")]) == 0
    capsys.readouterr()
    refused_triaxial(capsys, again + ["--radius-spread", "0.2", "--out", str(tmp_path / "other")],
            "radius_spread = 0.2", sample.rsplit("/", 1)[0])


def test_a_sample_gives_its_count_and_sizes_and_refuses_only_a_contradiction(graded_run,
                                                                             tmp_path, capsys):
    """--sample takes the particle count and the radii from the sample (no --particles
    repeated, on the command line or in the API); a count that contradicts it is refused."""
    out = graded_run
    sample = str(out / "sample.h5")
    loaded = tmp_path / "loaded"
    assert run_command("triaxial", ["--sample", sample, "--max-strain", "0.002",
                                    "--inertial-number", "2e-3", "--vtk-frames", "0",
                                    "--no-plots", "--quiet", "--out", str(loaded)]) == 0
    config = config_from_dict(json.loads(read_history(loaded).attrs["config"]))
    assert (config.sample.particles, config.sample.radius_spread, config.sample.seed) == \
        (120, 0.3, 3)
    made = json.loads((out / "summary.json").read_text())["grading"]
    assert json.loads((loaded / "summary.json").read_text())["grading"] == made
    test = TriaxialTest(TriaxialConfig(sample_path=sample))          # the API alike
    assert (test.config.sample.particles, test.config.sample.radius_spread) == (120, 0.3)
    capsys.readouterr()
    refused_triaxial(capsys, ["--sample", sample, "--particles", "100", "--max-strain", "0.002",
                              "--out", str(tmp_path / "other")],
                     "has 120 particles; the run asks for particles = 100")
