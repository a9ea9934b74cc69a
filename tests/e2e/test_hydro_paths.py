"""Hydro-mechanical paths (issue 14): the SWCC of a sample (drying then wetting), the triaxial at
constant water content (liquid conserved, suction an output) and the wetting protocols, run as
a user runs them (scenarios/swcc.py in a process of its own; the other runs in-process,
pendular.cli.run_command, as the scenarios run it: scenarios/triaxial.py's own process is
tested in test_triaxial.py and test_faults.py), and their bad input refused in one line. The
triaxials whose test is not about the preparation start from the SWCC's sample
(--sample)."""

import contextlib
import io
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from pendular import read_history
from pendular.cli import run_command
from pendular.io.schema import undeclared_keys

from conftest import ROOT, assert_drawn, run_in_process

SMALL = ["--particles", "150", "--quiet"]
RATE = ["--inertial-number", "2e-3", "--vtk-frames", "0"]
SHEAR = ["--max-strain", "0.01", *RATE]


def scenario(name, *argv):
    subprocess.run([sys.executable, os.path.join(ROOT, "scenarios", name), *argv],
                   check=True, capture_output=True, text=True, timeout=600)


def in_process(capsys, name, *argv):
    """Scenario ``name``'s command run in-process, as the scenario runs it."""
    status, err = run_in_process(name.removesuffix(".py"), argv, capsys, prog=name)
    assert status == 0, err


@pytest.fixture(scope="module")
def swcc_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("swcc") / "swcc"
    scenario("swcc.py", *SMALL, "--confining", "750", "--suctions", "3000,30000,300000",
             "--out", str(out))
    return out, json.loads((out / "swcc.json").read_text())


def test_swcc_has_both_branches_and_their_hysteresis(swcc_run):
    out, result = swcc_run
    assert not undeclared_keys(result, "swcc")
    for branch in ("drying", "wetting"):
        rows = result[branch]
        assert [r["suction"] for r in rows] == ([3000.0, 30000.0, 300000.0] if branch == "drying"
                                                else [300000.0, 30000.0, 3000.0])
        for row in rows:
            for key in ("saturation", "bridges", "porosity", "volumetric_strain", "chi"):
                assert np.isfinite(row[key]), (branch, key)
            assert 0.0 < row["saturation"] < 1.0 and 0.0 < row["chi"] < 1.0
    drying = [r["saturation"] for r in result["drying"]]
    assert drying[0] > drying[1] > drying[2]              # drier at higher suction
    # bridges across gaps break on drying and do not form again on wetting: less water
    assert result["bridges_formed_across_gaps"] > 0
    for entry in result["hysteresis"][:-1]:
        assert entry["saturation_difference"] > 0.0 and entry["bridges_difference"] > 0
    assert result["hysteresis"][-1]["saturation_difference"] == 0.0      # the turning point
    assert result["units"]["suction"] == "Pa" and result["units"]["saturation"] == "1"
    assert set(result["regular_packings"]) == {"scp", "bcc", "fcp"}
    assert_drawn(out / "swcc.png")
    history = read_history(out / "history.h5")
    assert history["suction"].attrs["units"] == "Pa"
    assert sorted(set(history["suction"].values)) == [3000.0, 30000.0, 300000.0]


def test_swcc_at_contacts_only_has_no_broken_gap_bridges(tmp_path, capsys):
    """--form-gap 0: every bridge formed at a contact, so the wetting branch differs from the
    drying one only by the contacts the path opened."""
    in_process(capsys, "swcc.py", *SMALL, "--suctions", "10000,100000", "--form-gap", "0",
               "--out", str(tmp_path))
    result = json.loads((tmp_path / "swcc.json").read_text())
    assert result["bridges_formed_across_gaps"] == 0
    first = result["hysteresis"][0]
    assert abs(first["saturation_difference"]) < 0.1 * result["drying"][0]["saturation"]


@pytest.fixture(scope="module")
def water_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("water") / "w"
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        status = run_command("triaxial", [*SMALL, *SHEAR, "--water-content", "0.5",
                                          "--out", str(out)], prog="triaxial.py")
    assert status == 0, err.getvalue()
    return out, json.loads((out / "summary.json").read_text())


def test_constant_water_content_conserves_the_liquid(water_run):
    out, summary = water_run
    assert summary["water_content"] == pytest.approx(0.005, rel=0.01)
    assert summary["liquid_balance_error"] < 1e-9
    assert summary["liquid_lost_fraction"] == 0.0             # shared, not lost
    assert summary["suction_at_peak"] > 0.0
    assert summary["units"]["suction_at_peak"] == "Pa"
    history = read_history(out / "history.h5")
    total = (history["liquid_bridges"] + history["liquid_film"] + history["liquid_lost"]).values
    assert np.allclose(total, summary["liquid_initial"], rtol=1e-9, atol=0)
    assert history["liquid_bridges"].attrs["units"] == "m^3"
    # the suction is an output: each bridge's own, averaged
    assert np.all(np.isfinite(history["suction"].values)) and history["suction"].values.std() > 0


def test_wetting_protocols_run_and_report(swcc_run, tmp_path, capsys):
    """The wetting before the shear, its steps and wall stresses: a shear to 0.5 %."""
    summaries = {}
    for protocol in ("at-shear", "constant-volume"):
        in_process(capsys, "triaxial.py", *SMALL, "--max-strain", "0.005", *RATE, "--suction",
                   "30000", "--wetting", protocol, "--sample", swcc_run[0] / "sample.h5",
                   "--out", str(tmp_path / protocol))
        summaries[protocol] = json.loads((tmp_path / protocol / "summary.json").read_text())
    assert summaries["at-shear"]["wetting_steps"] == 0
    assert summaries["at-shear"]["initial_bridges"] > 0
    constant = summaries["constant-volume"]
    assert constant["wetting_steps"] > 0
    # bridges pulling the grains together at fixed walls unload the walls
    assert np.mean(constant["sigma_wall_at_constant_volume"]) < 750.0
    config = json.loads(json.dumps(read_history(tmp_path / "at-shear" / "history.h5").attrs))
    assert "at-shear" in str(config)


@pytest.mark.parametrize("argv, words", [
    (["--suction", "30000", "--water-content", "0.5"], ["--suction", "--water-content"]),
    (["--rupture-liquid", "lost"], ["--rupture-liquid needs --water-content"]),
    (["--wetting", "at-shear"], ["--wetting", "--suction > 0"]),
    (["--water-content", "-1"], ["--water-content", "valid range"]),
    (["--water-content", "0.5", "--persist-bridges"], ["--water-content", "--persist-bridges"]),
])
def test_bad_hydraulic_options_are_refused(argv, words, capsys):
    with pytest.raises(SystemExit) as stop:
        run_command("triaxial", [*SMALL, *argv], prog="triaxial.py")
    err = capsys.readouterr().err
    assert stop.value.code == 2 and "Traceback" not in err
    for word in words:
        assert word in err, err


@pytest.mark.parametrize("argv, words", [
    (["--suctions", "30000,3000"], ["--suctions", "ascending"]),
    (["--suctions", "3000"], ["--suctions", "at least two"]),
    (["--suctions", "a,b"], ["--suctions", "comma-separated"]),
    (["--suctions", "10,30000"], ["suction = 10 Pa", "pendular"]),
    (["--form-gap", "3"], ["--form-gap", "valid range"]),
])
def test_bad_swcc_options_are_refused(argv, words, capsys):
    with pytest.raises(SystemExit) as stop:
        run_command("swcc", [*SMALL, *argv], prog="swcc.py")
    err = capsys.readouterr().err
    assert stop.value.code == 2 and "Traceback" not in err
    for word in words:
        assert word in err, err
