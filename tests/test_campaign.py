"""Sweeps from a TOML parameter table (pendular campaign): runs, campaign.csv, reuse, refusals."""

import csv
import os
import subprocess
import sys

import pytest

from pendular.campaign import options_argv, run_name, sweep_from_table, table_rows

TABLE = """
command = "triaxial"
[fixed]
particles = 150
max_strain = 0.01
inertial_number = 3e-3
vtk_every = 0
[sweep]
suction = [0, 30000]
confining = [250, 750]
"""


def pendular(*arguments, check=True):
    return subprocess.run([sys.executable, "-m", "pendular.cli", *arguments],
                          capture_output=True, text=True, check=check, timeout=600)


def test_two_by_two_sweep_runs_writes_its_table_and_reuses_its_runs(tmp_path):
    table = tmp_path / "sweep.toml"
    table.write_text(TABLE)
    out = tmp_path / "out"
    first = pendular("campaign", str(table), "--out", str(out), "--jobs", "2", "--quiet")
    assert "4 triaxial runs (0 reused)" in first.stdout
    with open(out / "campaign.csv") as handle:
        rows = list(csv.DictReader(handle))
    assert sorted((float(r["suction"]), float(r["confining"])) for r in rows) == [
        (0, 250), (0, 750), (30000, 250), (30000, 750)]
    for row in rows:
        assert float(row["peak_q"]) > 0 and row["particles"] == "150"
        assert (out / "runs" / row["run"] / "history.h5").exists()
    wet = [r for r in rows if float(r["suction"]) > 0]
    assert all(0 < float(r["saturation_at_peak"]) < 1 for r in wet)
    stamps = {p: p.stat().st_mtime_ns for p in (out / "runs").glob("*/history.h5")}
    again = pendular("campaign", str(table), "--out", str(out), "--quiet")
    assert "4 triaxial runs (4 reused)" in again.stdout
    assert {p: p.stat().st_mtime_ns for p in stamps} == stamps


def test_table_rows_cartesian_and_explicit():
    command, rows, varied = table_rows({"fixed": {"particles": 10},
                                        "sweep": {"suction": [0, 1], "seed": [1, 2, 3]}}, "t")
    assert command == "triaxial" and len(rows) == 6 and rows[0] == {
        "particles": 10, "suction": 0, "seed": 1}
    assert run_name(rows[-1], varied[-1]) == "suction1_seed3"
    _, rows, _ = table_rows({"command": "tension", "runs": [{"void_ratio": 0.7}]}, "t")
    assert rows == [{"void_ratio": 0.7}]
    assert options_argv({"max_strain": 0.02, "persist_bridges": True, "quiet": False}) == [
        "--max-strain", "0.02", "--persist-bridges"]


@pytest.mark.parametrize("text, message", [
    ('[fixed]\nbogus_option = 1\n', "triaxial has no option(s) --bogus-option"),
    ('command = "dance"\n', "command = 'dance' is not one of"),
    ('[sweep]\nsuction = 5\n', "sweep.suction = 5 is not a non-empty list"),
    ('[fixed]\nparticles = -3\n', "particles"),
    ('[[runs]]\nsuction = 1\n[sweep]\nseed = [1]\n', "not both"),
    ('this is not toml', "not a readable TOML table"),
])
def test_bad_tables_are_refused_naming_what_is_wrong(tmp_path, text, message):
    table = tmp_path / "bad.toml"
    table.write_text(text)
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        sweep_from_table(table)
    result = pendular("campaign", str(table), "--out", str(tmp_path / "o"), check=False)
    assert result.returncode == 2 and result.stderr.count("error:") == 1
    assert "Traceback" not in result.stderr


def test_the_chapter5_grid_is_a_shipped_table():
    import pendular.chapter5 as chapter5

    assert os.path.isfile(chapter5.TABLE)
    command, runs = sweep_from_table(chapter5.TABLE)
    assert command == "triaxial" and len(runs) == 16
    grid = chapter5.Chapter5Grid.from_table()
    assert grid.suctions == [0, 15000, 30000, 300000] and grid.particles == 10000
