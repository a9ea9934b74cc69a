"""pendular cyclic as a user runs it: a small stress-controlled run, its outputs and summary,
a resumed run, and bad input refused in one line."""

import subprocess
import sys

import numpy as np
import pytest

from conftest import assert_drawn, history_of, refused, run_in_process, summary_of

SMALL = ["--particles", "200", "--confining", "500", "--seed", "2", "--quiet",
         "--amplitude-q", "100", "--cycles", "2", "--vtk-every", "0"]
CYCLE_KEYS = {"cycle", "secant_modulus", "damping_ratio", "axial_strain_max", "axial_strain_min",
              "axial_strain_accumulated", "volumetric_strain"}


@pytest.fixture(scope="module")
def cyclic_run(tmp_path_factory):
    """A run with checkpoints: the uninterrupted run the resume test stops and resumes."""
    out = tmp_path_factory.mktemp("cyclic") / "run"
    subprocess.run([sys.executable, "-m", "pendular.cli", "cyclic", *SMALL,
                    "--checkpoint-every", "500", "--out", str(out)],
                   check=True, capture_output=True, text=True, timeout=600)
    return out


def test_a_stress_controlled_run_gives_its_loops_modulus_and_damping(cyclic_run):
    summary, history = summary_of(cyclic_run), history_of(cyclic_run)
    assert summary["completed"] is True and summary["cycles_completed"] == 2
    rows = summary["cycles"]
    assert [row["cycle"] for row in rows] == [1, 2]
    for row in rows:
        assert CYCLE_KEYS <= set(row)
        assert row["secant_modulus"] > 0.0 and 0.0 <= row["damping_ratio"] < 1.0
        assert row["axial_strain_min"] < 0.0 < row["axial_strain_max"]
        # q held between +-A: the stages end as the axial stress crosses 500 +- 100 Pa
        assert row["q_max"] == pytest.approx(100.0, rel=0.03)
        assert row["q_min"] == pytest.approx(-100.0, rel=0.03)
    assert summary["secant_modulus_first"] == rows[0]["secant_modulus"]
    assert summary["damping_ratio_last"] == rows[1]["damping_ratio"]
    assert summary["axial_strain_accumulated"] == rows[1]["axial_strain_accumulated"]
    assert "phi_peak_deg" not in summary                  # no failure at q = +-0.2 sigma_c
    assert summary["units"]["secant_modulus_first"] == "Pa"
    assert summary["units"]["cycles"]["damping_ratio"] == "1"
    assert np.array_equal(history["cycle"], (history["stage"] + 1) // 2)
    assert list(np.unique(history["stage"])) == list(range(5))
    lateral = history["sigma_wall"][:, :2]
    assert np.abs(lateral / 500.0 - 1.0).max() < 0.02      # the lateral walls servoed
    assert_drawn(cyclic_run / "cyclic.png")
    assert_drawn(cyclic_run / "plots" / "stress_path.png")


def test_a_resumed_cyclic_run_has_the_history_of_an_uninterrupted_one(cyclic_run, tmp_path,
                                                                      capsys):
    """Stopped and resumed, the run of the module's cyclic run (the same options and
    checkpoints) gives its history."""
    whole, out = cyclic_run, tmp_path / "stopped"
    argv = [*SMALL, "--checkpoint-every", "500"]
    steps = summary_of(whole)["steps"]
    status, _ = run_in_process("cyclic", [*argv, "--out", out,
                                          "--stop-after", str(int(0.6 * steps))], capsys)
    assert status == 130 and summary_of(out)["completed"] is False
    assert summary_of(out)["cycles_completed"] < 2        # the cycle cut short is left out
    status, err = run_in_process("cyclic", ["--resume", out, "--quiet"], capsys)
    assert status == 0, err
    expected, got = history_of(whole), history_of(out)
    for name in expected:
        assert np.array_equal(got[name], expected[name], equal_nan=True), name
    assert summary_of(out)["cycles"] == summary_of(whole)["cycles"]


@pytest.mark.parametrize("arguments, words", [
    (["--amplitude-q", "100", "--amplitude-strain", "1e-3"],
     ("--amplitude-strain", "not allowed with", "--amplitude-q")),
    (["--amplitude-q", "500"], ("--amplitude-q = 500", "(0, 500) Pa", "walls cannot pull")),
    (["--amplitude-q", "800"], ("--amplitude-q = 800", "(0, 500) Pa")),
    (["--amplitude-q", "100", "--cycles", "0"], ("--cycles = 0", "[1, 10000]")),
    (["--amplitude-strain", "0.2"], ("--amplitude-strain = 0.2", "[1e-06, 0.05]")),
    ([], ("--amplitude-q", "--amplitude-strain")),
])
def test_bad_cyclic_input_is_refused_in_one_line(arguments, words, tmp_path, capsys):
    status, err = run_in_process("cyclic", ["--particles", "100", "--confining", "500",
                                            *arguments, "--out", tmp_path / "x"], capsys)
    refused(status, err, *words)
    assert not (tmp_path / "x").exists()
