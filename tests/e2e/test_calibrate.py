"""`pendular calibrate` end to end on a tiny triaxial (50 spheres to 0.6 % strain, two
iterations of four samples): its outputs, and a calibration started again after a lost run
reusing every other finished run and giving the same posterior; on a tiny oedometer, the curve
of a run of its own recovered exactly."""

import csv
import json
import os
import shutil

import numpy as np
import pytest

from conftest import assert_drawn, requires, run_in_process

from pendular.io.schema import undeclared_keys
from pendular.studies.calibration import (DATA_COLUMNS, SEED_REPLICATES, read_curve,
                                          write_curve)

pytestmark = requires("grainlearning")

CURVE = "axial_strain,q,volumetric_strain\n0.002,450,0.0008\n0.004,650,0.0010\n0.006,700,0.0007\n"


def test_calibrate_writes_its_posterior_and_resumes(tmp_path, capsys):
    data = tmp_path / "curve.csv"
    data.write_text(CURVE)
    out = tmp_path / "calibration"
    argv = ["--data", data, "--test", "triaxial", "--particles", "50", "--max-strain", "0.006",
            "--inertial-number", "0.003", "--records", "60", "--fit", "friction=5:40",
            "--iterations", "2", "--samples", "4", "--quiet", "--out", out]
    status, err = run_in_process("calibrate", argv, capsys)
    assert status == 0, err
    summary = json.loads((out / "summary.json").read_text())
    friction = summary["parameters"]["friction"]
    assert set(friction) >= {"mean", "std", "best", "unit"} and friction["unit"] == "deg"
    assert 5.0 <= friction["mean"] <= 40.0 and 0.0 < friction["std"] < 35.0 / 2
    with open(out / "posterior.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [row["iteration"] for row in rows] == ["0"] * 4 + ["1"] * 4
    assert set(rows[0]) == {"iteration", "sample", "run", "friction", "weight", "error"}
    # every iteration's samples together: one distribution
    assert sum(float(row["weight"]) for row in rows) == pytest.approx(1.0)
    best = min(rows, key=lambda row: float(row["error"]))
    assert summary["best_run"] == os.path.join("runs", best["run"])
    assert summary["best_error"] == pytest.approx(float(best["error"]))
    assert friction["best"] == pytest.approx(float(best["friction"]))
    assert not undeclared_keys(summary, "calibrate")
    assert (out / summary["best_run"] / "history.h5").is_file()
    runs = sorted(os.listdir(out / "runs"))
    assert len(runs) == 8 + SEED_REPLICATES == summary["runs"]
    for name in ("calibration.png", "posterior.png", "errors.png"):
        assert_drawn(out / name)

    # a run lost (as when a calibration is interrupted): started again, the calibration
    # draws the same samples, runs that one again and reuses the others
    lost = out / "runs" / rows[-1]["run"]
    shutil.rmtree(lost)
    kept = {name: os.path.getmtime(out / "runs" / name / "history.h5") for name in runs
            if name != rows[-1]["run"]}
    status, err = run_in_process("calibrate", argv, capsys)
    assert status == 0, err
    assert json.loads((out / "summary.json").read_text())["parameters"] == summary["parameters"]
    assert (lost / "history.h5").is_file()
    assert kept == {name: os.path.getmtime(out / "runs" / name / "history.h5") for name in kept}


def test_calibrate_fits_an_oedometer_to_a_curve_of_its_own(tmp_path, capsys):
    """An oedometer's curve (axial stress, void ratio) made by a run at friction 22.5 deg and
    written by write_curve: the calibration's sample at 22.5 deg, the same sample seed,
    reproduces it exactly."""
    test = ["--particles", "50", "--confining", "500", "--axial-stress", "2000",
            "--inertial-number", "0.003", "--quiet"]
    status, err = run_in_process("oedometer", [*test, "--friction", "22.5",
                                               "--out", tmp_path / "data"], capsys)
    assert status == 0, err
    branch = DATA_COLUMNS["oedometer"].read(tmp_path / "data")
    order = np.argsort(branch["axial_stress"], kind="stable")     # as calibrate reads a run
    stress = np.linspace(700.0, 1900.0, 4)
    data = tmp_path / "curve.csv"
    write_curve(data, tmp_path / "data", "oedometer", stress)
    curve = read_curve(data, "oedometer")
    np.testing.assert_array_equal(curve.control, stress)
    np.testing.assert_array_equal(curve.observed["void_ratio"], np.interp(
        stress, branch["axial_stress"][order], branch["void_ratio"][order]))
    with pytest.raises(ValueError, match="within the run's axial_stress"):
        write_curve(tmp_path / "beyond.csv", tmp_path / "data", "oedometer", [700.0, 1e6])
    out = tmp_path / "calibration"
    status, err = run_in_process("calibrate", ["--data", data, "--test", "oedometer", *test,
                                               "--fit", "friction=5:40", "--iterations", "1",
                                               "--samples", "4", "--out", out], capsys)
    assert status == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert not undeclared_keys(summary, "calibrate")
    assert summary["columns"] == ["void_ratio"]
    with open(out / "posterior.csv", newline="") as handle:
        rows = {float(row["friction"]): float(row["error"]) for row in csv.DictReader(handle)}
    assert rows[22.5] == pytest.approx(0.0, abs=1e-12)
    assert min(error for friction, error in rows.items() if friction != 22.5) > 0.01
    assert summary["best_error"] == pytest.approx(0.0, abs=1e-12)
