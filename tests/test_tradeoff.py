"""The trade-off study (pendular.tradeoff) through scenarios/tradeoff.py: the quick grid runs and
its table is consistent with its runs."""

import json
import math
import os
import subprocess
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENARIO = os.path.join(ROOT, "scenarios", "tradeoff.py")


@pytest.fixture(scope="module")
def tradeoff(tmp_path_factory):
    out = tmp_path_factory.mktemp("tradeoff")
    subprocess.run([sys.executable, SCENARIO, "--out", str(out), "--quick", "--particles", "200",
                    "--max-strain", "0.01"], check=True, capture_output=True, text=True,
                   timeout=600)
    with open(out / "tradeoff.json") as handle:
        return out, json.load(handle)


def test_rows_cover_the_quick_knobs(tradeoff):
    _, data = tradeoff
    from pendular.tradeoff import QUICK_KNOBS, USES

    assert [(r["knob"], r["value"]) for r in data["rows"]] == [
        (knob, value) for knob, values in QUICK_KNOBS.items() for value in values] + [
        ("combined", use) for use in USES]
    for row in data["rows"]:
        assert row["wall_time_s"] > 0 and row["cpu_time_s"] > 0
        for key in ("peak_q_error", "saturation_error", "stress_ratio_error"):
            assert math.isfinite(row[key]) and row[key] >= 0.0
        assert row["error"] == max(row["peak_q_error"], row["saturation_error"],
                                   row["stress_ratio_error"])


def test_errors_are_measured_against_the_reference(tradeoff):
    _, data = tradeoff
    reference = data["reference"]
    assert reference["settings"]["timestep_safety"] == 0.35
    for row in data["rows"]:
        expected = abs(row["peak_q"] - reference["peak_q"]) / reference["peak_q"]
        assert row["peak_q_error"] == pytest.approx(expected, rel=1e-12)
        assert 0.0 < row["saturation_at_peak"] < 1.0


def test_default_run_is_shared_between_knobs(tradeoff):
    _, data = tradeoff
    defaults = [r for r in data["rows"] if (r["knob"], r["value"]) in
                (("timestep_safety", 0.7), ("inertial_number", 3e-4),
                 ("table_resolution", "350,80"))]
    assert len(defaults) == 3
    assert len({(r["peak_q"], r["cpu_time_s"]) for r in defaults}) == 1   # one run, reused


def test_combined_rows_take_each_knobs_cheapest_setting_within_the_bound(tradeoff):
    """Each knob's setting in a combined row is within the bound, and no setting within it is
    both cheaper (beyond the tie factor) or as cheap and more accurate."""
    _, data = tradeoff
    from pendular.tradeoff import TIME_TIE, USES

    knobs = [r for r in data["rows"] if r["knob"] != "combined"]
    for use, bound in USES.items():
        combined = next(r for r in data["rows"] if r["knob"] == "combined" and r["value"] == use)
        for knob, setting in combined["settings"].items():
            rows = [r for r in knobs if r["knob"] == knob and r["error"] <= bound]
            if not rows:
                continue
            chosen = next(r for r in rows if r["value"] == setting)
            cheapest = min(r["cpu_time_s"] for r in rows)
            assert chosen["cpu_time_s"] <= TIME_TIE * cheapest, knob
            assert all(r["error"] >= chosen["error"] for r in rows
                       if r["cpu_time_s"] <= TIME_TIE * cheapest), knob


def test_report_and_plot(tradeoff):
    out, data = tradeoff
    text = (out / "tradeoff.md").read_text()
    assert "Paper figure" in text and "Quick look" in text
    assert (out / "tradeoff.png").stat().st_size > 0


def test_runs_are_configured_with_dataclasses_not_option_strings(tmp_path):
    from pendular.tradeoff import DEFAULTS, REFERENCE, Study, configure

    study = Study(out=str(tmp_path), particles=300)
    reference = configure(study, REFERENCE, 300)
    assert reference.sample.timestep_safety == 0.35 and reference.shear.inertial_number == 1e-4
    assert reference.bridges.table_resolution == (700, 160) and reference.bridges.suction == 3e4
    default = configure(study, DEFAULTS, 300)
    assert default.sample.particles == 300 and default.shear.max_strain == 0.15
