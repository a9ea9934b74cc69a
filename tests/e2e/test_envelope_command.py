"""``pendular envelope`` as a user runs it (pendular.studies.envelope): triaxials at three
confining stresses as one campaign, the Mohr–Coulomb fits with their standard errors, the
figures, the finished tests reused, and bad input refused in one line."""

import pytest

from conftest import assert_drawn, refused, run_in_process, summary_of

from pendular.io.schema import undeclared_keys
from pendular.studies.envelope import mohr_coulomb_envelope

TINY = ["--particles", "60", "--max-strain", "0.01", "--inertial-number", "2e-3",
        "--vtk-every", "0", "--seed", "1"]


def test_an_envelope_of_three_tests_is_fitted_drawn_and_its_tests_reused(tmp_path, capsys):
    out = tmp_path / "envelope"
    argv = ["--confining", "500,1000,2000", *TINY, "--out", out, "--quiet"]
    status, err = run_in_process("envelope", argv, capsys)
    assert status == 0, err
    summary = summary_of(out)
    tests = summary["tests"]
    assert [t["confining"] for t in tests] == [500.0, 1000.0, 2000.0] == summary["confining"]
    for test in tests:
        run = summary_of(out / test["run"])                 # each triaxial's own summary
        assert test["run"] == f"runs/confining{test['confining']:g}" and not test["reused"]
        assert test["peak_q"] == run["peak_q"] and test["p_at_peak"] == run["p_at_peak"]
        # dry: the effective stress is the net one; sigma_3 at the peak is the lateral stress
        assert test["peak_q_effective"] == test["peak_q"]
        assert test["sigma_1_at_peak"] - test["sigma_3_at_peak"] == pytest.approx(
            test["peak_q"])
        assert test["sigma_3_at_peak"] == pytest.approx(test["confining"], rel=0.05)
    fit = mohr_coulomb_envelope([t["p_at_peak"] for t in tests], [t["peak_q"] for t in tests])
    assert summary["phi_deg"] == fit.phi_deg and summary["cohesion"] == fit.cohesion
    assert summary["phi_error_deg"] == fit.phi_error_deg > 0
    assert summary["cohesion_error"] == fit.cohesion_error > 0
    assert summary["phi_effective_deg"] == summary["phi_deg"] and "effective_note" in summary
    assert summary["degrees_of_freedom"] == 1 and summary["units"]["cohesion"] == "Pa"
    assert not undeclared_keys(summary, "envelope")
    for name in ("mohr_circles.png", "peaks_pq.png"):
        assert_drawn(out / name)
    assert (out / "campaign.csv").read_text().count("confining") >= 4

    status, err = run_in_process("envelope", argv, capsys)        # again: reused
    assert status == 0, err
    again = summary_of(out)
    assert all(t["reused"] for t in again["tests"]) and again["phi_deg"] == summary["phi_deg"]


@pytest.mark.parametrize("argv, words", [
    (["--confining", "500"], ("--confining = '500': at least 2 confining stresses",)),
    (["--confining", "500,500"], ("--confining = '500,500' repeats 500",)),
    (["--confining", "0,500"], ("--confining = 0.0 Pa is outside the valid range (0",)),
    (["--confining=-1,500"], ("--confining = -1.0 Pa",)),
    ([], ("--confining is missing",)),
    (["--confining", "500,1000", "--b", "0.5"], ("unrecognized arguments: --b",)),
    (["--confining", "500,1000", "--particles", "3"], ("--particles = 3 is outside",)),
])
def test_bad_envelopes_are_refused_in_one_line(tmp_path, capsys, argv, words):
    status, err = run_in_process("envelope", [*argv, "--out", tmp_path / "o"], capsys)
    refused(status, err, "pendular envelope: error: ", *words)
    assert not (tmp_path / "o").exists()
