"""Undrained triaxial and water stages as a user runs them: ``pendular triaxial --drainage
undrained`` dry and wet (the volume held within 1e-6, the excess pore pressure its
definition, the wet sample's water held), a path table with a ramped and a stepped suction
stage and one with a water-content stage and a constant-volume stage, the shipped collapse
table (examples/paths/wetting_collapse.toml), and bad stage entries refused in one line naming
the table, the stage and the key with its range."""

import os

import numpy as np
import pytest

from pendular.cli import run_command
from pendular.homogenize.invariants import deviator_stress, mean_stress
from pendular.io.schema import undeclared_keys

from conftest import ROOT, history_of, refused, run_in_process, summary_of

SMALL = ["--particles", "60", "--confining", "750", "--seed", "1", "--quiet", "--vtk-every",
         "0", "--no-plots"]
SHEAR = ["--drainage", "undrained", "--max-strain", "0.01", "--inertial-number", "2e-3"]


@pytest.fixture(scope="module", params=[[], ["--suction", "30000"]], ids=["dry", "wet"])
def undrained(request, tmp_path_factory):
    """(wetting options, all options, folder) of an undrained shear with checkpoints: the
    uninterrupted run the resume test stops and resumes."""
    options = [*SMALL, *SHEAR, *request.param, "--checkpoint-every", "200"]
    out = tmp_path_factory.mktemp("undrained") / "whole"
    assert run_command("triaxial", [*options, "--out", str(out)]) == 0
    return request.param, options, out


def test_an_undrained_triaxial_holds_its_volume_and_gives_the_excess_pore_pressure(undrained):
    wet, _, out = undrained
    history, summary = history_of(out), summary_of(out)
    assert np.abs(history["volumetric_strain"]).max() < 1e-6
    assert summary["max_volume_change"] < 1e-6 and summary["drainage"] == "undrained"
    sigma = history["sigma_wall"]
    q, p = deviator_stress(sigma), mean_stress(sigma)
    expected = (q - q[0]) / 3.0 - (p - p[0])        # Delta p_total - Delta p', sigma_3 held
    assert history["excess_pore_pressure"] == pytest.approx(expected, abs=1e-9)
    peak = summary["peak_index"]
    assert summary["excess_pore_pressure_at_peak"] == pytest.approx(expected[peak], abs=1e-9)
    path = summary["effective_stress_path"]
    assert path["p"][0] == pytest.approx(p[0]) and path["q"][-1] == pytest.approx(q[-1])
    assert summary["units"]["excess_pore_pressure_at_peak"] == "Pa"
    assert not undeclared_keys(summary, "triaxial")
    if wet:     # the water held: closed liquid, its balance, suction and Sr recorded
        assert summary["liquid_balance_error"] < 1e-9
        assert {"suction", "saturation", "liquid_bridges"} <= set(history)
        assert "suction" in path and summary["suction_final"] > 0.0


def test_suction_and_water_content_stages_run_from_tables(tmp_path, capsys):
    table = tmp_path / "suction.toml"
    table.write_text("""
[[stage]]                       # wetting, ramped
stress = {x = "confining", y = "confining", z = "confining"}
suction = 10000
suction_rate = 2e6
until = "static"

[[stage]]                       # drying back, stepped
stress = {x = "confining", y = "confining", z = "confining"}
suction = 30000
""")
    out = tmp_path / "suction"
    status, err = run_in_process("path", [table, *SMALL, "--suction", "30000", "--out", out],
                                 capsys)
    assert status == 0, err
    history, summary = history_of(out), summary_of(out)
    ends = [row["suction"] for row in summary["stages"]]
    assert ends == [10000.0, 30000.0]
    steps = np.diff(history["suction"][history["stage"] == 0])
    assert np.all(steps <= 0.0)                     # the ramp only goes down
    first, second = summary["water_stages"]
    assert (first["suction_before"], first["suction_after"]) == (30000.0, 10000.0)
    assert summary["collapse_strain"] == first["volumetric_strain_change"]
    assert summary["stages"][0]["saturation"] > summary["stages"][1]["saturation"]
    assert not undeclared_keys(summary, "path")

    table = tmp_path / "water.toml"
    table.write_text("""
[[stage]]                       # wetting to 1 % at the confining stress
stress = {x = "confining", y = "confining", z = "confining"}
water_content = 1.0

[[stage]]                       # then an undrained compression
strain_rate = {z = "quasi-static"}
volume = "constant"
until = {strain = 0.005}
""")
    out = tmp_path / "water"
    status, err = run_in_process("path", [table, *SMALL, "--water-content", "0.5",
                                          "--out", out], capsys)
    assert status == 0, err
    history, summary = history_of(out), summary_of(out)
    assert [row["water_content"] for row in summary["stages"]] == pytest.approx([0.01, 0.01])
    shear = history["stage"] == 1
    volume = history["volumetric_strain"][shear]
    assert np.abs(volume - volume[0]).max() < 1e-6
    assert summary["liquid_balance_error"] < 1e-9
    assert not undeclared_keys(summary, "path")


@pytest.mark.parametrize("stage, wetting, words", [
    ("suction = 1000", ["--suction", "30000"],
     ("path.toml: stage 1: suction = 1000 Pa is outside the valid range [", "pendular regime")),
    ("suction = -5", ["--suction", "30000"],
     ("path.toml: stage 1: suction = -5 Pa is outside the valid range (0, 1e+09] Pa",)),
    ("suction_rate = 10", ["--suction", "30000"],
     ("path.toml: stage 1: suction_rate = 10 needs a suction",)),
    ("suction = 10000", [], ("path.toml: stage 1: suction = 10000 Pa needs a sample wetted at "
                             "a suction",)),
    ("water_content = 150", ["--water-content", "0.5"],
     ("path.toml: stage 1: water_content = 150 % is outside the valid range (0, 100] %",)),
    ("water_content = 2", ["--suction", "30000"],
     ("path.toml: stage 1: water_content = 2 % needs a sample wetted at a water content",
      "give suction")),
    ("volume = 'held'", [], ("path.toml: stage 1: volume = 'held'; valid: 'constant'",)),
])
def test_bad_water_and_volume_entries_are_refused_in_one_line(stage, wetting, words, tmp_path,
                                                              capsys):
    table = tmp_path / "path.toml"
    table.write_text(f"[[stage]]\nstress = {{x = 750, y = 750, z = 750}}\n{stage}\n")
    out = tmp_path / "out"
    status, err = run_in_process("path", [table, "--particles", "100", *wetting, "--out", out],
                                 capsys)
    refused(status, err, *words)
    assert not out.exists()


def test_undrained_refuses_b_in_one_line(tmp_path, capsys):
    status, err = run_in_process("triaxial", ["--drainage", "undrained", "--b", "0.5",
                                              "--out", tmp_path / "out"], capsys)
    refused(status, err, "drainage = 'undrained' holds the volume", "--b")


def test_the_shipped_collapse_table_runs_and_gives_the_strain_of_its_wetting(tmp_path, capsys):
    out = tmp_path / "collapse"
    status, err = run_in_process("path", [os.path.join(ROOT, "examples", "paths",
                                                       "wetting_collapse.toml"),
                                          *SMALL, "--suction", "30000", "--radius", "0.0001",
                                          "--inertial-number", "2e-3", "--out", out], capsys)
    assert status == 0, err
    summary = summary_of(out)
    (wetting,) = summary["water_stages"]
    assert (wetting["stage"], wetting["suction_before"], wetting["suction_after"]) == (
        2, 30000.0, 1000.0)
    assert summary["collapse_strain"] == wetting["volumetric_strain_change"]
    # oedometric: the lateral walls held, so the volumetric strain is the axial one
    assert summary["collapse_axial_strain"] == pytest.approx(summary["collapse_strain"],
                                                             abs=1e-12)
    axial = [row["sigma_wall"][2] for row in summary["stages"]]
    assert axial == pytest.approx([10000.0] * 3, rel=0.01)


def test_an_interrupted_undrained_shear_resumes_to_the_same_history(undrained, tmp_path,
                                                                     capsys):
    _, options, whole = undrained
    stopped = tmp_path / "stopped"
    steps = summary_of(whole)["steps"]
    status, _ = run_in_process("triaxial", [*options, "--out", stopped,
                                            "--stop-after", str(steps // 2)], capsys)
    assert status == 130
    status, err = run_in_process("triaxial", ["--resume", stopped, "--quiet"], capsys)
    assert status == 0, err
    expected, got = history_of(whole), history_of(stopped)
    for name in expected:
        assert np.array_equal(got[name], expected[name], equal_nan=True), name
