"""The trade-off study (pendular.studies.tradeoff): its runs are configurations built with
dataclasses.replace, reused only when their stored configuration is equal; and the quick grid
through scenarios/tradeoff.py, whose table is consistent with its runs."""

import dataclasses
import json
import math
import os
import subprocess
import sys

import pytest

from pendular.studies import tradeoff
from pendular.procedures.config import config_to_dict

from conftest import ROOT, assert_drawn, run_in_process

SCENARIO = os.path.join(ROOT, "scenarios", "tradeoff.py")


def _plain(value):
    """``value`` as it reads back from JSON (tuples as lists)."""
    return json.loads(json.dumps(value))


# ---------------------------------------------------------------- configurations (no run)

def test_knobs_set_their_field_of_the_default_configuration(tmp_path):
    study = tradeoff.Study(out=str(tmp_path), particles=300, max_strain=0.02, seed=4)
    default = study.default()
    assert default.sample.particles == 300 and default.sample.seed == 4
    assert default.shear.max_strain == 0.02 and default.bridges.suction == tradeoff.SUCTION
    assert default.bridges.table_resolution == tradeoff.DEFAULT_TABLE
    assert default.sample_path == tradeoff.sample_file(tmp_path, 300, 4)
    reference = study.reference()
    assert reference.sample.timestep_safety == 0.35 and reference.shear.inertial_number == 1e-4
    assert reference.bridges.table_resolution == (700, 160)
    for knob, values in tradeoff.KNOBS.items():
        for value in values:
            config, shown = study.variant(knob, value)
            assert tradeoff.setting(config, knob) == shown
            # nothing else changed: setting the knob back gives the default
            assert tradeoff.with_setting(config, knob, tradeoff.setting(default, knob)) == \
                dataclasses.replace(default, sample_path=config.sample_path)
    assert study.variant("particles", 0.5)[0].sample_path == tradeoff.sample_file(tmp_path, 150, 4)
    assert study.variant("bridges", "toroidal")[0].bridges.model == "toroidal"


def test_bad_study_settings_are_refused_naming_them(tmp_path):
    with pytest.raises(ValueError, match="particles = 10 is outside the valid range"):
        tradeoff.Study(out=str(tmp_path), particles=10)
    with pytest.raises(ValueError, match="max_strain = 0.6 is outside the valid range"):
        tradeoff.Study(out=str(tmp_path), max_strain=0.6)
    with pytest.raises(ValueError, match="table_resolution"):
        tradeoff.with_setting(tradeoff.Study(out=str(tmp_path)).default(), "table_resolution",
                              (2, 80))


def test_a_finished_run_is_reused_only_with_an_equal_configuration(tmp_path, monkeypatch):
    study = tradeoff.Study(out=str(tmp_path), particles=300)
    config = study.default()
    folder = tmp_path / "runs" / "default"
    folder.mkdir(parents=True)
    stored = {"settings": tradeoff.settings(config), "particles": 300, "peak_q": 123.0}
    (folder / "timing.json").write_text(json.dumps({**stored, "config": config_to_dict(config)}))
    assert tradeoff.run_variant(config, str(folder), study.sample(300)) == stored

    ran = []

    class FakeTest:
        def __init__(self, config):
            self.config = config

        def run(self, out, progress, threads, plots):
            assert plots is False       # the study times physics, not figures
            ran.append((self.config, threads))
            return {"steps": 10, "particle_steps_per_s": 1.0, "peak_q": 99.0,
                    "saturation_at_peak": 0.01, "peak_q_effective": 2.0,
                    "p_effective_at_peak": 4.0, "axial_strain_at_peak": 0.01}

    monkeypatch.setattr(tradeoff, "TriaxialTest", FakeTest)
    monkeypatch.setattr(tradeoff, "sample_made_with", lambda path, sample: True)
    other = dataclasses.replace(config, shear=dataclasses.replace(config.shear, max_strain=0.1))
    result = tradeoff.run_variant(other, str(folder), study.sample(300))
    assert ran == [(other, 1)] and result["peak_q"] == 99.0
    assert result["stress_ratio_at_peak"] == 0.5
    saved = json.loads((folder / "timing.json").read_text())
    assert saved["config"] == _plain(config_to_dict(other))
    assert tradeoff.run_variant(other, str(folder), study.sample(300)) == _plain(result)
    assert len(ran) == 1


# ---------------------------------------------------------------- the quick grid

@pytest.fixture(scope="module")
def quick_grid(tmp_path_factory):
    out = tmp_path_factory.mktemp("tradeoff")
    subprocess.run([sys.executable, SCENARIO, "--out", str(out), "--quick", "--particles", "60",
                    "--max-strain", "0.005"], check=True, capture_output=True, text=True,
                   timeout=900)
    with open(out / "tradeoff.json") as handle:
        return out, json.load(handle)


def test_rows_cover_the_quick_knobs(quick_grid):
    _, data = quick_grid
    assert [[r["knob"], r["value"]] for r in data["rows"]] == _plain([
        (knob, value) for knob, values in tradeoff.QUICK_KNOBS.items() for value in values] + [
        ("combined", use) for use in tradeoff.USES])
    assert set(data["arguments"]) == {"out", "particles", "max_strain", "seed", "quick", "docs"}
    for row in data["rows"]:
        assert row["wall_time_s"] > 0 and row["cpu_time_s"] > 0
        for key in ("peak_q_error", "saturation_error", "stress_ratio_error"):
            assert math.isfinite(row[key]) and row[key] >= 0.0
        assert row["error"] == max(row["peak_q_error"], row["saturation_error"],
                                   row["stress_ratio_error"])


def test_errors_are_measured_against_the_reference(quick_grid):
    _, data = quick_grid
    reference = data["reference"]
    assert reference["settings"]["timestep_safety"] == 0.35
    for row in data["rows"]:
        expected = abs(row["peak_q"] - reference["peak_q"]) / reference["peak_q"]
        assert row["peak_q_error"] == pytest.approx(expected, rel=1e-12)
        assert 0.0 < row["saturation_at_peak"] < 1.0


def test_default_run_is_shared_between_knobs(quick_grid):
    _, data = quick_grid
    defaults = [r for r in data["rows"] if (r["knob"], r["value"]) in
                (("timestep_safety", 0.7), ("inertial_number", 3e-4),
                 ("table_resolution", [350, 80]))]
    assert len(defaults) == 3
    assert len({(r["peak_q"], r["cpu_time_s"]) for r in defaults}) == 1   # one run, reused


def test_combined_rows_take_each_knobs_cheapest_setting_within_the_bound(quick_grid):
    """Each knob's setting in a combined row is within the bound, and no setting within it is
    both cheaper (beyond the tie factor) or as cheap and more accurate."""
    _, data = quick_grid
    knobs = [r for r in data["rows"] if r["knob"] != "combined"]
    for use, bound in tradeoff.USES.items():
        combined = next(r for r in data["rows"] if r["knob"] == "combined" and r["value"] == use)
        for knob, setting in combined["settings"].items():
            rows = [r for r in knobs if r["knob"] == knob and r["error"] <= bound]
            if not rows:
                continue
            chosen = next(r for r in rows if r["value"] == setting)
            cheapest = min(r["cpu_time_s"] for r in rows)
            assert chosen["cpu_time_s"] <= tradeoff.TIME_TIE * cheapest, knob
            assert all(r["error"] >= chosen["error"] for r in rows
                       if r["cpu_time_s"] <= tradeoff.TIME_TIE * cheapest), knob


def test_report_and_plot(quick_grid):
    out, data = quick_grid
    text = (out / "tradeoff.md").read_text()
    assert "Paper figure" in text and "Quick look" in text
    assert "| table_resolution | 350,80 |" in text
    assert_drawn(out / "tradeoff.png")
    # each run keeps its configuration beside its timing
    timing = json.loads((out / "runs" / "reference" / "timing.json").read_text())
    run = out / "runs" / "reference"        # its history and summary, no figures (untimed)
    assert (run / "history.h5").is_file() and (run / "summary.json").is_file()
    assert not (run / "triaxial.png").exists() and not (run / "plots").exists()
    assert timing["config"]["fields"]["shear"]["fields"]["inertial_number"] == 1e-4


def test_the_noise_floor_is_the_reference_on_other_samples(quick_grid):
    """NOISE_SEEDS more samples at the reference settings; the floor is their largest error."""
    _, data = quick_grid
    noise, reference = data["noise"], data["reference"]
    assert [r["seed"] for r in noise] == list(range(1, 1 + tradeoff.NOISE_SEEDS))
    for row in noise:
        assert row["settings"] == reference["settings"]
        assert row["peak_q_error"] == pytest.approx(
            abs(row["peak_q"] - reference["peak_q"]) / reference["peak_q"], rel=1e-12)
        assert row["peak_q"] != reference["peak_q"]        # another sample, another peak
    assert data["noise_floor"]["error"] == max(r["error"] for r in noise)


# ---------------------------------------------------------------- one knob across samples

def test_a_seed_study_runs_every_setting_against_its_own_samples_reference(tmp_path):
    study = tradeoff.SeedStudy(out=str(tmp_path), knob="timestep_rule", seeds=3,
                               particles=300, seed=2)
    runs = {name: (config, sample) for name, config, sample in study.runs()}
    default_rule = tradeoff.Study(str(tmp_path)).default().sample.timestep_rule
    other_rule = next(v for v in tradeoff.KNOBS["timestep_rule"] if v != default_rule)
    for seed in (2, 3, 4):
        reference, sample = runs[f"seed{seed}_reference"]
        assert reference == tradeoff.Study(str(tmp_path), 300, seed=seed).reference()
        for rule in tradeoff.KNOBS["timestep_rule"]:
            config, on = runs[f"seed{seed}_timestep_rule={rule}"]
            assert config.sample.timestep_rule == rule and config.sample.seed == seed
            assert config.sample_path == reference.sample_path and on == sample   # paired
        # the other rule also on a sample prepared with it
        config, on = runs[f"seed{seed}_timestep_rule={other_rule}_prepared"]
        assert on.timestep_rule == other_rule and on.seed == seed
        assert config.sample_path != reference.sample_path
    assert len(runs) == 3 * 4
    # a knob of the shear alone: no samples of its own
    shear = tradeoff.SeedStudy(out=str(tmp_path), knob="inertial_number", seeds=2)
    assert not any(name.endswith("_prepared") for name, _, _ in shear.runs())


def test_bad_seed_study_settings_are_refused_naming_them(tmp_path):
    with pytest.raises(ValueError, match="knob = 'particles'"):
        tradeoff.SeedStudy(out=str(tmp_path), knob="particles")
    with pytest.raises(ValueError, match="seeds = 1 is outside the valid range"):
        tradeoff.SeedStudy(out=str(tmp_path), knob="damping", seeds=1)
    with pytest.raises(ValueError, match="--jobs 0 is outside the valid range"):
        tradeoff.SeedStudy(out=str(tmp_path), knob="damping", jobs=0)


def test_seed_rows_read_each_run_against_its_own_samples_reference(tmp_path):
    """Hand-made results: paired errors against the same seed's reference, the references'
    scatter, the samples prepared with a setting against the references' mean."""
    study = tradeoff.SeedStudy(out=str(tmp_path), knob="damping", seeds=2, seed=0)

    def result(q, sr, ratio, cpu=1.0):
        return {"peak_q": q, "saturation_at_peak": sr, "stress_ratio_at_peak": ratio,
                "cpu_time_s": cpu, "steps": 10, "wetting_steps": 0, "porosity": 0.4,
                "coordination": 4.0}

    results = {"seed0_reference": result(100.0, 0.02, 1.0),
               "seed1_reference": result(110.0, 0.02, 1.0)}
    for value in tradeoff.KNOBS["damping"]:
        results[f"seed0_damping={value}"] = result(101.0, 0.02, 1.0)     # +1 %
        results[f"seed1_damping={value}"] = result(110.0, 0.02, 1.0)     # 0 %
        results[f"seed0_damping={value}_prepared"] = result(126.0, 0.02, 1.0)
        results[f"seed1_damping={value}_prepared"] = result(126.0, 0.02, 1.0)
    rows, scatter = tradeoff.seed_rows(study, results)
    assert scatter["peak_q"]["mean"] == 105.0
    assert scatter["peak_q"]["relative_sd"] == pytest.approx(math.sqrt(50.0) / 105.0)
    paired = [r for r in rows if not r["prepared_with_it"]]
    assert [r["value"] for r in paired] == tradeoff.KNOBS["damping"]
    assert paired[0]["peak_q"]["paired"]["mean"] == pytest.approx(0.005)
    assert paired[0]["peak_q"]["paired"]["largest"] == pytest.approx(0.01)
    assert all(r["within_scatter"] for r in paired)
    prepared = [r for r in rows if r["prepared_with_it"]]
    assert prepared[0]["peak_q"]["against_references"]["mean"] == pytest.approx(0.2)
    assert not any(r["within_scatter"] for r in prepared)    # 20 % off, sd 6.7 %


def test_a_seed_study_from_the_command_line(tmp_path, capsys):
    """scenarios/tradeoff.py's command run in-process (the quick grid runs the scenario in its
    own interpreter)."""
    out = tmp_path / "seeds"
    status, err = run_in_process("tradeoff", ["--out", out, "--knob", "timestep_rule",
                                              "--seeds", "2", "--particles", "60",
                                              "--max-strain", "0.005"], capsys,
                                 prog="tradeoff.py")
    assert status == 0, err
    data = json.loads((out / "seeds_timestep_rule.json").read_text())
    assert len(data["runs"]) == 2 * 4 and len(data["rows"]) == 3
    for row in data["rows"]:
        assert 0.3 < row["porosity"] < 0.5 and row["cpu_time_s"] > 0
    text = (out / "seeds_timestep_rule.md").read_text()
    assert "Scatter between samples" in text and "prepared with it" in text
    status, err = run_in_process("tradeoff", ["--out", out, "--seeds", "3"], capsys,
                                 prog="tradeoff.py")
    assert status != 0
    assert "error: --seeds" in err.strip().splitlines()[-1]
