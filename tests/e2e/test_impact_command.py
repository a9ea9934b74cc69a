"""`pendular impact` as a user runs it: the issue's steel check (Hertz's peak force, overlap
and contact time within 1 %, a rebound at the restitution asked), its outputs with their units
and keys."""

import json
import math
import subprocess
import sys

import pytest

from conftest import assert_drawn, history_of, summary_of
from pendular.cli import run_command

STEEL = ["--target", "wall", "--contact", "hertz-mindlin", "--radius", "0.01", "--young", "2e11",
         "--poisson", "0.3", "--density", "7800", "--velocity", "1"]
KEYS = ("max_normal_force", "max_overlap", "contact_duration", "normal_restitution",
        "tangential_restitution", "rebound_angular_velocity", "rebound_angle_deg")


def impact(tmp_path, *options, capsys=None):
    """(summary, run folder) of ``pendular impact`` with the steel sphere and ``options``: in
    its own interpreter, or with ``capsys`` in-process (pendular.cli.run_command)."""
    out = tmp_path / "impact"
    argv = [*STEEL, *options, "--quiet", "--out", str(out)]
    if capsys is None:
        stdout = subprocess.run([sys.executable, "-m", "pendular", "impact", *argv], check=True,
                                capture_output=True, text=True, timeout=300).stdout
    else:
        capsys.readouterr()
        assert run_command("impact", argv) == 0
        stdout = capsys.readouterr().out
    assert json.loads(stdout)["max_overlap"] == summary_of(out)["max_overlap"]
    return summary_of(out), out


def test_a_steel_sphere_on_a_wall_has_hertzs_peak_force_overlap_and_duration(tmp_path):
    summary, out = impact(tmp_path)
    mass = 7800 * 4 / 3 * math.pi * 0.01 ** 3
    modulus = 2e11 / (1 - 0.3 ** 2)
    overlap = (15 * mass / (16 * modulus * math.sqrt(0.01))) ** 0.4
    assert summary["max_overlap"] == pytest.approx(overlap, rel=0.01)
    assert summary["max_normal_force"] == pytest.approx(
        4 / 3 * modulus * math.sqrt(0.01) * overlap ** 1.5, rel=0.01)
    assert summary["contact_duration"] == pytest.approx(
        2.868 * (mass ** 2 / (0.01 * modulus ** 2)) ** 0.2, rel=0.01)
    assert set(KEYS) <= set(summary) and summary["tangential_restitution"] is None
    history, units = history_of(out, units=True)
    assert units == {"record": None, "time": "s", "overlap": "m", "normal_force": "N",
                     "tangential_force": "N", "angular_velocity": "rad/s"}
    assert max(history["normal_force"]) == summary["max_normal_force"]
    assert_drawn(out / "impact.png")


def test_a_steel_sphere_rebounds_at_the_restitution_asked(tmp_path, capsys):
    summary, _ = impact(tmp_path, "--restitution", "0.5", "--angle", "30", capsys=capsys)
    assert summary["normal_restitution"] == pytest.approx(0.5, abs=0.01)
    assert -1.0 < summary["tangential_restitution"] < 1.0
