"""Summaries that never mislead, as a user runs the commands: a wet extension that stops when
the axial walls leave the sample, the critical state of a real run judged by its stated rule,
and --quiet's stdout read whole by json.loads."""

import json
import subprocess
import sys

import numpy as np
import pytest

from conftest import assert_drawn, history_of, summary_of
from pendular.cli import run_command
from pendular.homogenize.invariants import deviator_stress
from pendular.io.columns import HISTORY_COLUMNS
from pendular.io.schema import undeclared_keys
from pendular.procedures.critical_state import CRITICAL_STATE_KEYS, critical_state

pytestmark = pytest.mark.slow


def pendular(*argv):
    """(stdout, stderr) of ``pendular ARGV`` run as a user runs it; exit status 0."""
    done = subprocess.run([sys.executable, "-m", "pendular", *map(str, argv)],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return done.stdout, done.stderr


def test_a_wet_extension_stops_when_the_axial_walls_leave_the_sample(tmp_path):
    """At 30 kPa suction and 750 Pa confining the bridges hold the sample together and the
    axial walls, which cannot pull, leave it near 1 % extension: the shear ends there, and no
    friction angle is made of the walls' release (it read 90 degrees)."""
    out = tmp_path / "extension"
    stdout, stderr = pendular("triaxial", "--particles", "300", "--suction", "30000",
                              "--direction", "extension", "--vtk-frames", "0", "--quiet",
                              "--out", out)
    printed = json.loads(stdout)                     # stdout: the JSON alone
    summary, history = summary_of(out), history_of(out)
    assert printed["axial_contact_lost"] is True and f"outputs in {out}" in stderr
    assert summary["axial_contact_lost"] is True and summary["completed"] is True
    assert "axial stress fell to 0" in summary["stopped"]
    assert history["sigma_wall"][-1, 2] <= 0.0 < history["sigma_wall"][-2, 2]
    assert -0.05 < history["axial_strain"][-1] < 0.0          # not on to -25 %
    assert summary["phi_peak_deg"] is None and summary["phi_peak_effective_deg"] is None
    assert summary["phi_peak_note"].startswith("not measured: the axial stress fell to 0")
    assert summary["peak_reached"] is False
    # one sign of q: the summary's is the history's sigma_z - sigma_lateral, negative here
    q = deviator_stress(history["sigma_wall"])
    assert summary["peak_q"] == pytest.approx(q.min()) and summary["peak_q"] < 0.0
    assert all(summary[key] is None for key in CRITICAL_STATE_KEYS)
    assert summary["porosity_before_wetting"] == summary["initial_porosity"]
    assert summary["porosity_after_wetting"] == summary["wet_porosity"]
    n = summary["porosity_after_wetting"]
    assert summary["void_ratio_after_wetting"] == pytest.approx(n / (1.0 - n))
    assert not undeclared_keys(summary, "triaxial")
    assert_drawn(out / "triaxial.png")


def test_a_real_run_reports_its_critical_state_by_the_stated_rule(tmp_path, capsys):
    """``pendular triaxial`` run in-process (pendular.cli.run_command; its own interpreter in
    the test above)."""
    out = tmp_path / "compression"
    capsys.readouterr()
    assert run_command("triaxial", ["--particles", "300", "--max-strain", "0.15",
                                    "--vtk-frames", "0", "--quiet", "--out", str(out)]) == 0
    assert set(CRITICAL_STATE_KEYS) <= set(json.loads(capsys.readouterr().out))
    summary, history = summary_of(out), history_of(out)
    expected = critical_state(history["axial_strain"], history["volumetric_strain"],
                              history["sigma_wall"], deviator_stress(history["sigma_wall"]),
                              history["porosity"])
    for key in (*CRITICAL_STATE_KEYS, "critical_state_note"):
        assert summary[key] == expected[key]
    reached = summary["M_cs"] is not None
    assert summary["critical_state_note"].startswith("reached" if reached else "not reached")
    assert "over the last 5 % of axial strain" in summary["critical_state_note"]
    if reached:
        assert 0.5 < summary["M_cs"] < 1.5 and summary["void_ratio_cs"] > 0.5
    assert summary["units"]["phi_cs_deg"] == "deg"
    assert all(type(value) in (float, int, bool, str, list, dict, type(None))
               for value in summary.values())
    assert not undeclared_keys(summary, "triaxial")
    assert all("triaxial" in HISTORY_COLUMNS[name].commands for name in history)
    assert np.isfinite(summary["principal_difference_at_peak"])
