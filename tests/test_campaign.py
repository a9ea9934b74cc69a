"""Campaigns (pendular.campaign): a TOML sweep through `pendular campaign` (runs, campaign.csv,
reuse), the library API (runs built with dataclasses.replace, a failing run), refusals."""

import csv
import dataclasses
import os
import subprocess
import sys
import time

import pytest

from pendular.dem.preparation import PrepareConfig
from pendular.campaign import (Campaign, Run, options_argv, run_name, run_progress,
                               sweep_from_table, table_rows, write_campaign_csv)
from pendular.config import ShearConfig, TensionConfig, TriaxialConfig, config_to_dict

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
    assert "4 triaxial runs (0 reused, 0 failed)" in first.stdout
    with open(out / "campaign.csv") as handle:
        rows = list(csv.DictReader(handle))
    assert sorted((float(r["suction"]), float(r["confining"])) for r in rows) == [
        (0, 250), (0, 750), (30000, 250), (30000, 750)]
    for row in rows:
        assert row["status"] == "run" and float(row["peak_q"]) > 0 and row["particles"] == "150"
        folder = out / "runs" / row["run"]
        assert (folder / "history.h5").exists()
        assert "shear: 100%" in (folder / "log.txt").read_text()     # the run's own progress
    assert {r["run"] for r in rows} == {"suction0_confining250", "suction0_confining750",
                                        "suction30000_confining250",
                                        "suction30000_confining750"}
    wet = [r for r in rows if float(r["suction"]) > 0]
    assert all(0 < float(r["saturation_at_peak"]) < 1 for r in wet)

    stamps = {p: p.stat().st_mtime_ns for p in (out / "runs").glob("*/*")}
    started = time.perf_counter()
    again = pendular("campaign", str(table), "--out", str(out), "--quiet")
    assert time.perf_counter() - started < 60
    assert "4 triaxial runs (4 reused, 0 failed)" in again.stdout
    assert {p: p.stat().st_mtime_ns for p in stamps} == stamps          # no run touched
    with open(out / "campaign.csv") as handle:
        reread = list(csv.DictReader(handle))
    assert [r["status"] for r in reread] == ["reused"] * 4
    assert [r["peak_q"] for r in reread] == [r["peak_q"] for r in rows]


def test_library_campaign_of_replaced_configs_keeps_going_past_a_failed_run(tmp_path):
    base = TriaxialConfig(sample=PrepareConfig(particles=100, confining=500.0),
                          shear=ShearConfig(max_strain=0.005, inertial_number=3e-3),
                          vtk_frames=0)
    runs = [("dry", base),
            Run("broken", dataclasses.replace(base, sample_path=str(tmp_path / "nothing.h5")))]
    result = Campaign(runs).run(tmp_path / "c", quiet=True)
    assert result.reused == [] and list(result.summaries) == ["dry"]
    assert "nothing.h5" in result.failed["broken"] and "log.txt" in result.failed["broken"]
    assert "Traceback" in (tmp_path / "c" / "runs" / "broken" / "log.txt").read_text()
    with pytest.raises(ValueError, match="1 of 2 runs failed: broken"):
        result.check()
    write_campaign_csv(str(tmp_path / "c" / "campaign.csv"), result)
    with open(tmp_path / "c" / "campaign.csv") as handle:
        rows = {r["run"]: r for r in csv.DictReader(handle)}
    assert rows["dry"]["status"] == "run" and rows["broken"]["status"] == "failed"
    assert "nothing.h5" in rows["broken"]["error"] and rows["broken"]["peak_q"] == ""

    # again: the finished run is reused (equal configuration), a changed one runs again
    again = Campaign([("dry", base)]).run(tmp_path / "c", quiet=True)
    assert again.reused == ["dry"]
    assert again.summaries["dry"]["peak_q"] == result.summaries["dry"]["peak_q"]
    changed = dataclasses.replace(base, shear=dataclasses.replace(base.shear, records=50))
    assert Campaign([("dry", changed)]).run(tmp_path / "c", quiet=True).reused == []


def test_a_tension_run_in_a_campaign_is_summarised_and_reused(tmp_path):
    config = TensionConfig(cases=[(0.72, 0.01)], particles=100, max_strain=0.02, vtk_frames=0)
    result = Campaign([("w1", config)]).run(tmp_path / "t", quiet=True)
    assert not result.failed
    summary = result.summaries["w1"]
    assert summary["case"] == "e0.72_w1.00" and summary["tensile_strength_pa"] > 0
    assert (tmp_path / "t" / "runs" / "w1" / "tension.json").exists()
    again = Campaign([("w1", config)]).run(tmp_path / "t", quiet=True)
    assert again.reused == ["w1"] and again.summaries["w1"] == summary


def test_campaign_refuses_bad_runs_before_running(tmp_path):
    config = TriaxialConfig(sample=PrepareConfig(particles=100))
    with pytest.raises(ValueError, match="must be unique: a"):
        Campaign([("a", config), ("a", config)])
    with pytest.raises(ValueError, match="not a folder name"):
        Run("../up", config)
    with pytest.raises(TypeError, match="TriaxialConfig or TensionConfig"):
        Run("a", config_to_dict(config))
    fast = dataclasses.replace(config, shear=ShearConfig(inertial_number=0.5))
    with pytest.raises(ValueError, match="run fast: strain rate .* quasi-static"):
        Campaign([("fast", fast)]).run(tmp_path / "c", quiet=True)
    assert not (tmp_path / "c" / "runs").exists()


def test_table_rows_cartesian_and_explicit():
    command, rows, varied = table_rows({"fixed": {"particles": 10},
                                        "sweep": {"suction": [0, 1], "seed": [1, 2, 3]}}, "t")
    assert command == "triaxial" and len(rows) == 6 and rows[0] == {
        "particles": 10, "suction": 0, "seed": 1}
    assert run_name(rows[-1], varied[-1]) == "suction1_seed3"
    _, rows, varied = table_rows({"command": "tension", "fixed": {"particles": 100},
                                  "runs": [{"void_ratio": 0.7}, {"name": "x", "particles": 200}]},
                                 "t")
    assert rows == [{"particles": 100, "void_ratio": 0.7}, {"particles": 200, "name": "x"}]
    assert [run_name(r, v) for r, v in zip(rows, varied)] == ["void_ratio0.7", "x"]
    assert options_argv({"max_strain": 0.02, "persist_bridges": True, "quiet": False,
                         "table_resolution": [350, 80]}) == [
        "--max-strain", "0.02", "--persist-bridges", "--table-resolution", "350,80"]


def test_tables_build_validated_configs(tmp_path):
    table = tmp_path / "t.toml"
    table.write_text('[fixed]\nparticles = 200\nsample = "s.h5"\nbridges = "toroidal"\n'
                     'persist_bridges = true\n[sweep]\nsuction = [1000, 2000]\n')
    command, runs = sweep_from_table(table)
    assert command == "triaxial" and [r.name for r in runs] == ["suction1000", "suction2000"]
    assert runs[1].config.bridges.suction == 2000.0 and runs[1].config.bridges.persist
    assert runs[0].config.bridges.model == "toroidal" and runs[0].config.sample.particles == 200
    assert runs[0].config.sample_path == str(tmp_path / "s.h5")      # relative to the table
    table.write_text('command = "tension"\n[fixed]\nparticles = 300\n'
                     '[sweep]\nwater_content = [0.5, 1.0]\n')
    command, runs = sweep_from_table(table)
    assert command == "tension" and all(isinstance(r.config, TensionConfig) for r in runs)
    assert [r.config.cases for r in runs] == [[(0.72, 0.005), (0.58, 0.005)],
                                               [(0.72, 0.01), (0.58, 0.01)]]


@pytest.mark.parametrize("text, message", [
    ('[fixed]\nbogus_option = 1\n', "triaxial has no option(s) --bogus-option"),
    ('[sweep]\nout = ["a", "b"]\n', "no option(s) --out in a table (out: set by the campaign)"),
    ('command = "dance"\n', "command = 'dance' is not one of"),
    ('[sweep]\nsuction = 5\n', "sweep.suction = 5 is not a non-empty list"),
    ('[fixed]\nparticles = -3\n', "run run: particles"),
    ('[fixed]\nparticles = "many"\n', "argument --particles: invalid int value: 'many'"),
    ('[fixed]\nseed = 1\n[sweep]\nseed = [1, 2]\n', "seed both in [fixed] and in [sweep]"),
    ('[[runs]]\nseed = 1\n[[runs]]\nseed = 1\n', "runs seed1 repeat a folder name"),
    ('[[runs]]\nsuction = 1\n[sweep]\nseed = [1]\n', "not both"),
    ('colour = "red"\n', "unknown table key(s) colour"),
    ('this is not toml', "not a readable TOML table"),
])
def test_bad_tables_are_refused_naming_what_is_wrong(tmp_path, text, message):
    table = tmp_path / "bad.toml"
    table.write_text(text)
    with pytest.raises(ValueError) as error:
        sweep_from_table(table)
    assert message in str(error.value)
    result = pendular("campaign", str(table), "--out", str(tmp_path / "o"), check=False)
    assert result.returncode == 2 and result.stderr.count("error:") == 1, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr
    assert not (tmp_path / "o").exists()


def test_run_progress_reads_the_last_bar_of_a_log(tmp_path):
    folder = tmp_path / "run"
    folder.mkdir()
    assert run_progress(folder) == ""
    (folder / "log.txt").write_text(
        "\rgrow radii: 0step [00:00, ?step/s]\rgrow radii: 5800step [00:01, 3604.62step/s, "
        "sigma=4922/5000Pa, n=0.428, unbal=0.005/0.01]\n")
    assert run_progress(folder) == "grow radii 5800step sigma=4922/5000Pa n=0.428"
    with open(folder / "log.txt", "a") as handle:
        handle.write("\rshear:  57%|#####     | 200/348 [00:01<00:00, 164.56step/s]")
    assert run_progress(folder) == "shear 57%"


def test_the_chapter5_grid_is_a_shipped_table():
    import pendular.chapter5 as chapter5

    assert os.path.isfile(chapter5.TABLE)
    command, runs = sweep_from_table(chapter5.TABLE)
    assert command == "triaxial" and len(runs) == 16
    assert {r.config.sample.particles for r in runs} == {10000}
    grid = chapter5.Chapter5Grid.from_table()
    assert grid.suctions == [0, 15000, 30000, 300000] and grid.particles == 10000


def test_a_run_stored_before_a_defaulted_field_existed_is_the_same_run():
    """Reuse across versions: a configuration stored before ``wetting`` existed equals one with
    its default (the former behaviour), not one with another value."""
    from pendular.campaign import same_config
    from pendular.config import BridgeConfig, TriaxialConfig, config_to_dict

    config = TriaxialConfig(bridges=BridgeConfig(30000.0))
    stored = config_to_dict(config)
    del stored["fields"]["wetting"]
    del stored["fields"]["bridges"]["fields"]["liquid"]
    assert same_config(stored, config)
    assert not same_config(stored, dataclasses.replace(config, wetting="at-shear"))
    assert not same_config({"no": "config"}, config) and not same_config(None, config)
