"""Campaigns (pendular.studies.campaign): a TOML sweep through `pendular campaign` (runs, campaign.csv,
reuse), the library API (runs built with dataclasses.replace, a failing run), refusals (bad or
empty tables, --jobs, a folder in use, damaged results of an earlier campaign)."""

import csv
import dataclasses
import json
import os
import re
import subprocess
import sys
import time

import h5py
import pytest

from conftest import refused, run_in_process, summary_of

import pendular.studies.campaign as campaign_module
from pendular.procedures.preparation import PrepareConfig
from pendular.studies.campaign import (MAX_RUNS, Campaign, CampaignResult, Run, check_jobs,
                                       executor, finished_summary, max_jobs, run_name,
                                       run_progress, sweep_from_table, table_rows,
                                       write_campaign_csv)
from pendular.procedures.config import ShearConfig, config_to_dict
from pendular.procedures.tension import TensionConfig, tension_sample
from pendular.procedures.triaxial import TriaxialConfig
from pendular.io.outputs import OutputFolder
from pendular.studies.run_kinds import PROCEDURES

TABLE = """
command = "triaxial"
[fixed]
particles = 100
max_strain = 0.005
inertial_number = 3e-3
vtk_every = 0
[sweep]
suction = [0, 30000]
confining = [250, 750]
"""


def pendular(*arguments, check=True):
    return subprocess.run([sys.executable, "-m", "pendular.cli", *arguments],
                          capture_output=True, text=True, check=check, timeout=600)


def test_two_by_two_sweep_runs_writes_its_table_and_reuses_its_runs(tmp_path, capsys):
    """``pendular campaign`` in its own interpreter, then again in-process
    (pendular.cli.run_command) over the finished runs."""
    table = tmp_path / "sweep.toml"
    table.write_text(TABLE)
    out = tmp_path / "out"
    first = pendular("campaign", str(table), "--out", str(out), "--jobs", "2", "--quiet")
    assert "4 triaxial runs (0 reused, 0 failed)" in first.stderr      # --quiet: JSON alone
    assert json.loads(first.stdout) == {"command": "triaxial", "runs": 4, "reused": 0,
                                        "failed": 0, "out": str(out)}
    with open(out / "campaign.csv") as handle:
        rows = list(csv.DictReader(handle))
    assert sorted((float(r["suction"]), float(r["confining"])) for r in rows) == [
        (0, 250), (0, 750), (30000, 250), (30000, 750)]
    peak = {}
    for row in rows:
        assert row["status"] == "run" and row["particles"] == "100"
        folder = out / "runs" / row["run"]
        assert float(row["peak_q"]) == pytest.approx(summary_of(folder)["peak_q"], rel=1e-6)
        peak[float(row["suction"]), float(row["confining"])] = float(row["peak_q"])
        assert (folder / "history.h5").exists()
        assert "shear: 100%" in (folder / "log.txt").read_text()     # the run's own progress
    for suction in (0, 30000):               # a higher confining stress carries more
        assert peak[suction, 750] > peak[suction, 250]
    for confining in (250, 750):             # the bridges' cohesion adds strength
        assert peak[30000, confining] > peak[0, confining]
    assert {r["run"] for r in rows} == {"suction0_confining250", "suction0_confining750",
                                        "suction30000_confining250",
                                        "suction30000_confining750"}
    wet = [r for r in rows if float(r["suction"]) > 0]
    assert all(0 < float(r["saturation_at_peak"]) < 1 for r in wet)

    stamps = {p: p.stat().st_mtime_ns for p in (out / "runs").glob("*/*")}
    started = time.perf_counter()
    status, err = run_in_process("campaign", [table, "--out", out, "--quiet"], capsys)
    assert time.perf_counter() - started < 60
    assert status == 0, err
    assert "4 triaxial runs (4 reused, 0 failed)" in err
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
    result = Campaign(runs).run(tmp_path / "c", progress=False)
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
    again = Campaign([("dry", base)]).run(tmp_path / "c", progress=False)
    assert again.reused == ["dry"]
    assert again.summaries["dry"]["peak_q"] == result.summaries["dry"]["peak_q"]
    changed = dataclasses.replace(base, shear=dataclasses.replace(base.shear, records=50))
    assert Campaign([("dry", changed)]).run(tmp_path / "c", progress=False).reused == []


def test_a_tension_run_in_a_campaign_is_summarised_and_reused(tmp_path):
    config = TensionConfig(cases=[(0.72, 0.01)], sample=tension_sample(particles=100),
                           max_strain=0.02, vtk_frames=0)
    result = Campaign([("w1", config)]).run(tmp_path / "t", progress=False)
    assert not result.failed
    summary = result.summaries["w1"]
    assert summary["case"] == "e0.72_w1.00" and summary["tensile_strength_pa"] > 0
    assert (tmp_path / "t" / "runs" / "w1" / "tension.json").exists()
    again = Campaign([("w1", config)]).run(tmp_path / "t", progress=False)
    assert again.reused == ["w1"] and again.summaries["w1"] == summary


OEDOMETER = """
command = "oedometer"
[fixed]
particles = 60
confining = 500
vtk_every = 0
[sweep]
axial_stress = [1500, 2000]
"""

SWCC = """
command = "swcc"
[fixed]
particles = 60
confining = 750
suctions = [3000, 30000]
"""


def rows_of(out):
    with open(out / "campaign.csv") as handle:
        return list(csv.DictReader(handle))


def test_an_oedometer_table_runs_writes_its_table_and_reuses_its_runs(tmp_path, capsys):
    table = tmp_path / "oedometer.toml"
    table.write_text(OEDOMETER)
    out = tmp_path / "out"
    status, err = run_in_process("campaign", [table, "--out", out, "--quiet"], capsys)
    assert status == 0, err
    rows = rows_of(out)
    assert [(r["run"], r["status"]) for r in rows] == [("axial_stress1500", "run"),
                                                       ("axial_stress2000", "run")]
    for row in rows:
        summary = summary_of(out / "runs" / row["run"])
        assert float(row["axial_stress"]) == summary["axial_stress_target"]
        assert float(row["k0"]) == pytest.approx(summary["k0"], rel=1e-12)
        assert 0.0 < summary["k0"] < 1.0 and row["particles"] == "60"
        assert (out / "runs" / row["run"] / "oedometer.png").exists()
    status, err = run_in_process("campaign", [table, "--out", out, "--quiet"], capsys)
    assert status == 0, err
    assert [r["status"] for r in rows_of(out)] == ["reused", "reused"]
    assert [r["k0"] for r in rows_of(out)] == [r["k0"] for r in rows]


def test_an_swcc_table_runs_writes_its_key_figures_and_reuses_its_run(tmp_path, capsys):
    table = tmp_path / "swcc.toml"
    table.write_text(SWCC)
    out = tmp_path / "out"
    status, err = run_in_process("campaign", [table, "--out", out, "--quiet"], capsys)
    assert status == 0, err
    [row] = rows_of(out)
    assert row["run"] == "run" and row["status"] == "run" and row["suctions"] == "[3000.0, 30000.0]"
    result = json.loads((out / "runs" / "run" / "swcc.json").read_text())
    for branch in ("drying", "wetting"):
        for stage in result[branch]:
            suction = f"{stage['suction']:g}"
            assert float(row[f"saturation_{branch}_{suction}"]) == stage["saturation"]
            assert float(row[f"chi_{branch}_{suction}"]) == stage["chi"]
    assert float(row["initial_porosity"]) == result["preparation"]["porosity"]
    status, err = run_in_process("campaign", [table, "--out", out, "--quiet"], capsys)
    assert status == 0, err
    assert rows_of(out)[0]["status"] == "reused"


#: The least options of each command in a table (runs are built, not run).
LEAST = {"triaxial": {"particles": 60}, "oedometer": {"axial_stress": 2000},
         "isotropic": {"stresses": "1000,2000"}, "cyclic": {"amplitude_q": 100},
         "simple-shear": {"particles": 100}, "path": {"table": "path.toml"},
         "tension": {"particles": 100}, "swcc": {"particles": 60}}


@pytest.mark.parametrize("command", sorted(PROCEDURES))
def test_a_table_of_every_laboratory_command_builds_its_runs(tmp_path, command):
    (tmp_path / "path.toml").write_text('[[stage]]\nstrain_rate = {x = 0, y = 0, z = '
                                        '"quasi-static"}\nuntil = {strain = 0.01, axis = "z"}\n')
    table = tmp_path / "t.toml"
    fixed = "".join(f"{key} = {json.dumps(value)}\n" for key, value in LEAST[command].items())
    table.write_text(f'command = "{command}"\n[fixed]\n{fixed}[sweep]\nseed = [1, 2]\n')
    found, runs = sweep_from_table(table)
    assert found == command and [r.name for r in runs] == ["seed1", "seed2"]
    assert all(type(r.config) is PROCEDURES[command].config for r in runs)
    assert [r.config.sample.seed for r in runs] == [1, 2]
    if command == "path":                           # relative to the table's folder
        assert runs[0].config.source == str(tmp_path / "path.toml")


@pytest.mark.parametrize("command, text, message", [
    ("swcc", "max_strain = 0.1\n", "max_strain ([fixed]): not an option of swcc in a table"),
    ("swcc", "force = true\n", "force ([fixed]): not an option of swcc"),
    ("oedometer", "force = \"yes\"\n", "force = 'yes': a flag, true or false expected"),
    ("oedometer", "axial_stress = -5\n", "axial_stress = -5 ([fixed])"),
    ("swcc", "suctions = [30000, 3000]\n", "suctions = [30000, 3000] ([fixed]): suctions = "
                                            "30000,3000: at least two suctions"),
    ("cyclic", "cycles = 2\n", "give amplitude_q PA (stress control) or amplitude_strain"),
    ("path", "particles = 60\n", "PATH.toml is missing"),
])
def test_bad_tables_of_other_commands_are_refused_naming_the_key(tmp_path, capsys, command,
                                                                  text, message):
    table = tmp_path / "bad.toml"
    table.write_text(f'command = "{command}"\n[fixed]\n{text}')
    with pytest.raises(ValueError, match=re.escape(message)):
        sweep_from_table(table)
    status, err = run_in_process("campaign", [table, "--out", tmp_path / "o"], capsys)
    refused(status, err, f"pendular campaign: error: table = {str(table)!r}", message)
    assert not (tmp_path / "o").exists()


def test_an_oedometer_refused_before_running_names_its_run(tmp_path, capsys):
    table = tmp_path / "fast.toml"
    table.write_text('command = "oedometer"\n[fixed]\nparticles = 60\n'
                     '[sweep]\ninertial_number = [0.5]\n')
    status, err = run_in_process("campaign", [table, "--out", tmp_path / "o", "--quiet"], capsys)
    refused(status, err, f"table = {str(table)!r}: run inertial_number0.5: strain rate",
            "quasi-static")
    assert not (tmp_path / "o" / "runs").exists()


def test_campaign_refuses_bad_runs_before_running(tmp_path):
    config = TriaxialConfig(sample=PrepareConfig(particles=100))
    with pytest.raises(ValueError, match="must be unique: a"):
        Campaign([("a", config), ("a", config)])
    with pytest.raises(ValueError, match="not a folder name"):
        Run("../up", config)
    with pytest.raises(TypeError, match="the configuration of a laboratory command .*"
                                        "SwccConfig.*, got dict"):
        Run("a", config_to_dict(config))
    fast = dataclasses.replace(config, shear=ShearConfig(inertial_number=0.5))
    with pytest.raises(ValueError, match="run fast: strain rate .* quasi-static"):
        Campaign([("fast", fast)]).run(tmp_path / "c", progress=False)
    assert not (tmp_path / "c" / "runs").exists()


def test_a_run_of_a_table_refused_before_running_names_the_table(tmp_path, capsys):
    table = tmp_path / "fast.toml"
    table.write_text('[fixed]\nparticles = 60\n[sweep]\ninertial_number = [0.5]\n')
    status, err = run_in_process("campaign", [table, "--out", tmp_path / "o", "--quiet"], capsys)
    refused(status, err, f"table = {str(table)!r}: run inertial_number0.5: strain rate",
            "quasi-static")
    assert not (tmp_path / "o" / "runs").exists()


@pytest.mark.parametrize("command", ["campaign", "chapter5"])
def test_a_campaign_on_a_device_that_cannot_run_here_is_refused_before_running(
        tmp_path, capsys, monkeypatch, command):
    """Without a GPU (and not in Numba's CUDA simulator), --device gpu is refused in one line
    naming it before anything is made."""
    monkeypatch.delenv("NUMBA_ENABLE_CUDASIM", raising=False)
    table = tmp_path / "t.toml"
    table.write_text('[fixed]\nparticles = 60\nmax_strain = 0.01\n')
    argv = ([table] if command == "campaign" else
            ["--particles", 60, "--suctions", 0, "--confining", 750])
    status, err = run_in_process(command, [*argv, "--out", tmp_path / "o", "--device", "gpu"],
                                 capsys)
    refused(status, err, f"pendular {command}: error: --device gpu cannot run here")
    assert not (tmp_path / "o").exists()


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


def test_tables_build_validated_configs(tmp_path):
    table = tmp_path / "t.toml"
    table.write_text('[fixed]\nparticles = 200\nsample = "s.h5"\nbridges = "toroidal"\n'
                     'persist_bridges = true\n[sweep]\nsuction = [1000, 2000]\n')
    command, runs = sweep_from_table(table)
    assert command == "triaxial" and [r.name for r in runs] == ["suction1000", "suction2000"]
    assert runs[1].config.bridges.suction == 2000.0 and runs[1].config.bridges.persist
    assert runs[0].config.bridges.model == "toroidal" and runs[0].config.sample.particles == 200
    assert runs[0].config.sample_path == str(tmp_path / "s.h5")      # relative to the table
    table.write_text('[fixed]\nparticles = 200\nsample = "-s.h5"\n')   # a value, not an option
    assert sweep_from_table(table)[1][0].config.sample_path == str(tmp_path / "-s.h5")
    table.write_text('[fixed]\nparticles = 200\nforce = true\nsuction = 1000\n'
                     'table_resolution = [100, 40]\n')
    run = sweep_from_table(table)[1][0]
    assert run.force and run.config.bridges.table_resolution == (100, 40)
    table.write_text('command = "tension"\n[fixed]\nparticles = 300\n'
                     '[sweep]\nwater_content = [0.5, 1.0]\n')
    command, runs = sweep_from_table(table)
    assert command == "tension" and all(isinstance(r.config, TensionConfig) for r in runs)
    assert [r.config.cases for r in runs] == [[(0.72, 0.005), (0.58, 0.005)],
                                               [(0.72, 0.01), (0.58, 0.01)]]


@pytest.mark.parametrize("text, message", [
    # empty: each would run the command's default test (10,000 spheres to 25 %)
    ("", "bad.toml' is empty; valid: [fixed] options with [sweep] lists or [[runs]] rows"),
    ('[sweep]\n', "[sweep] is empty; valid: a non-empty list per swept option"),
    ('runs = []\n', "runs = [] holds no run; valid: one [[runs]] table per run"),
    ('[fixed]\n', "bad.toml' sets no option, so each run would be the triaxial command's "
                  "default test"),
    ('command = "tension"\n', "sets no option, so each run would be the tension command's"),
    ('[[runs]]\nname = "a"\n', "sets no option"),
    # unreadable
    (b'[fixed]\nparticles = 300\nname = "\xff"\n', "bad.toml' is not a TOML table: byte 0xff at "
                                                    "line 3, column 9 is not UTF-8 text"),
    ('this is not toml', "bad.toml' is not a valid TOML table: "),
    ('[fixed]\nparticles = 3 4\n', "(at line 2, column 15)"),
    # the table's layout
    ('command = "dance"\n', "command = 'dance' is not one of"),
    ('colour = "red"\n', "unknown table key(s) colour"),
    ('[sweep]\nsuction = 5\n', "sweep.suction = 5 is not a non-empty list"),
    ('[fixed]\nseed = 1\n[sweep]\nseed = [1, 2]\n', "seed both in [fixed] and in [sweep]"),
    ('[[runs]]\nseed = 1\n[[runs]]\nseed = 1\n', "runs seed1 repeat a folder name"),
    ('[[runs]]\nsuction = 1\n[sweep]\nseed = [1]\n', "not both"),
    ("[sweep]\n" + "".join(f"k{i} = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n" for i in range(5)),
     f"100000 runs (10 k0 x 10 k1 x 10 k2 x 10 k3 x 10 k4); valid: at most {MAX_RUNS} runs"),
    # keys: each named with its section
    ('[fixed]\nbogus_option = 1\n', "bogus_option ([fixed]): not an option of triaxial in a "
                                     "table; see 'pendular triaxial --help'"),
    ('[sweep]\nout = ["a", "b"]\n', "out ([sweep]: set by the campaign): not an option"),
    ('[fixed]\nmax-strain = 0.1\n', "max-strain ([fixed]: write max_strain)"),
    ('[fixed]\nparticles = -3\n', "run run: particles = -3 ([fixed]): particles = -3 is "
                                   "outside the valid range"),
    ('[fixed]\nparticles = "many"\n', 'run run: particles = "many" ([fixed]): particles = '
                                       "'many': an integer expected"),
    ('[fixed]\nparticles = false\n', "particles = false ([fixed]): particles = False: a value "
                                      "expected, not true or false"),
    ('[fixed]\npersist_bridges = 1\n', "persist_bridges = 1 ([fixed]): persist_bridges = 1: a "
                                        "flag, true or false expected"),
    ('[fixed]\nforce = "yes"\n', "force = \"yes\" ([fixed]): force = 'yes': a flag, true or "
                                  "false expected"),
    ('[fixed]\nparticles = 300\n[sweep]\nsuction = [1000, -5]\n',
     "run suction-5: suction = -5 ([sweep]): suction = -5.0 Pa is outside the valid range"),
    ('[fixed]\nwater_content = 5\n[sweep]\nsuction = [0, 1000]\n',
     "run suction1000: water_content = 5 ([fixed]), suction = 1000 ([sweep]): suction and "
     "water_content: give one"),
    ('[[runs]]\nseed = 1\n[[runs]]\nvtk_every = 5\nvtk_frames = 3\n',
     "vtk_every = 5 (row 2 of [[runs]]), vtk_frames = 3 (row 2 of [[runs]]): vtk_every and "
     "vtk_frames: give one"),
    ('[fixed]\nparticles = 300\nsuction = 1000\ntable_resolution = [3, 40]\n',
     "table_resolution = [3, 40] ([fixed]): table_resolution [3, 40]: two integers NS,ND"),
    ('command = "tension"\n[fixed]\nparticles = 200\nperiodic = true\ngrip_depth = 2\n',
     "periodic = true ([fixed]), grip_depth = 2 ([fixed]): grip_depth = 2 does not apply to "
     "periodic: a periodic cell has no walls"),
    ('[[runs]]\nname = "a/b"\nseed = 1\n', 'name = "a/b" (row 1 of [[runs]]): run name '
                                            "'a/b' is not a folder name"),
    ('[[runs]]\nname = [1]\nseed = 1\n', "name = [1] (row 1 of [[runs]]): a folder name"),
])
def test_bad_tables_are_refused_naming_what_is_wrong(tmp_path, capsys, text, message):
    table = tmp_path / "bad.toml"
    if isinstance(text, bytes):
        table.write_bytes(text)
    else:
        table.write_text(text)
    with pytest.raises(ValueError) as error:
        sweep_from_table(table)
    assert str(error.value).startswith(f"table = {str(table)!r}")
    assert message in str(error.value)
    status, err = run_in_process("campaign", [table, "--out", tmp_path / "o"], capsys)
    refused(status, err, f"pendular campaign: error: table = {str(table)!r}", message)
    assert not (tmp_path / "o").exists()


def test_a_table_path_that_is_not_a_file_is_refused(tmp_path, capsys):
    for path, message in ((tmp_path / "none.toml", "cannot be read: No such file or directory"),
                          (tmp_path, "is not a file; valid: a TOML file"),
                          ("/dev/zero", "is not a file; valid: a TOML file")):
        status, err = run_in_process("campaign", [path, "--out", tmp_path / "o"], capsys)
        refused(status, err, f"table = {str(path)!r} {message}")


def test_relative_psd_and_sample_paths_are_the_tables(tmp_path, monkeypatch):
    (tmp_path / "elsewhere").mkdir()
    monkeypatch.chdir(tmp_path / "elsewhere")
    table = tmp_path / "t.toml"
    table.write_text('[fixed]\nparticles = 300\npsd = "grading.csv"\n')
    with pytest.raises(ValueError, match="psd = \"grading.csv\" \\(\\[fixed\\]\\): psd file "
                                         + repr(str(tmp_path / "grading.csv"))):
        sweep_from_table(table)


TINY = '[fixed]\nparticles = 60\nmax_strain = 0.002\ninertial_number = 2e-3\nvtk_every = 0\n'


def test_jobs_beyond_the_machine_are_refused_naming_jobs(tmp_path, capsys):
    high = max_jobs()
    assert high == campaign_module.JOBS_PER_CPU * (os.cpu_count() or 1)
    assert check_jobs(1) == 1 and check_jobs(high) == high
    for jobs in (0, high + 1, 10**20, 1.5, True):
        with pytest.raises(ValueError, match=r"--jobs .* valid range \[1, " + str(high) + r"\]"):
            check_jobs(jobs)
    with pytest.raises(ValueError, match="--jobs 100000000000000000000 is outside"):
        with executor(10**20):
            pass
    table = tmp_path / "t.toml"
    table.write_text(TINY)
    big = "99999999999999999999"
    status, err = run_in_process("campaign", [table, "--out", tmp_path / "o", "--jobs", big], capsys)
    refused(status, err, f"--jobs {big} is outside the valid range [1, {high}] "
                         f"({campaign_module.JOBS_PER_CPU} processes per CPU of this machine")
    assert not (tmp_path / "o").exists()
    status, err = run_in_process("campaign", [table, "--out", tmp_path / "o", "--jobs", high + 1],
                          capsys)
    refused(status, err, f"--jobs {high + 1} is outside the valid range [1, {high}]")
    # the other commands with --jobs reach the same check before anything runs
    for name, argv in (("chapter5", ["--particles", "60", "--suctions", "0", "--confining",
                                     "500", "--max-strain", "0.001", "--quiet"]),
                       ("tradeoff", ["--knob", "damping", "--seeds", "2", "--particles", "60"])):
        status, err = run_in_process(name, [*argv, "--out", tmp_path / name, "--jobs", big], capsys)
        refused(status, err, f"pendular {name}: error: --jobs", f"valid range [1, {high}]")


def test_a_campaign_into_a_folder_in_use_is_refused(tmp_path, capsys, monkeypatch):
    table = tmp_path / "t.toml"
    table.write_text(TINY)
    out = tmp_path / "o"
    with OutputFolder(out, "another campaign"):
        status, err = run_in_process("campaign", [table, "--out", out, "--quiet"], capsys)
    refused(status, err, f"out = {str(out)!r}: the folder is in use by another pendular run",
            "another campaign")
    assert not (out / "campaign.csv").exists() and not (out / "runs").exists()

    # a campaign holds its folder while its runs go (no run needed to see it)
    def run(self, where, options=None, **settings):
        with pytest.raises(ValueError, match="in use by another pendular run .*campaign"):
            with OutputFolder(out, "a second campaign"):
                pass
        return CampaignResult(self.runs, summaries={r.name: {"peak_q": 1.5} for r in self.runs})

    monkeypatch.setattr(Campaign, "run", run)
    assert run_in_process("campaign", [table, "--out", out, "--quiet"], capsys)[0] == 0
    with open(out / "campaign.csv") as handle:
        rows = list(csv.DictReader(handle))
    assert [(r["run"], r["status"], r["peak_q"]) for r in rows] == [("run", "run", "1.5")]
    with open(out / ".pendular-outputs.json") as handle:
        manifest = json.load(handle)
    assert manifest["command"] == ["campaign", str(table)] and "campaign.csv" in manifest["files"]
    with OutputFolder(out, "after it"):          # released at the end
        pass


def test_damaged_results_of_an_earlier_campaign_are_run_again(tmp_path, capsys, monkeypatch):
    triaxial = TriaxialConfig(sample=PrepareConfig(particles=100))
    folder = tmp_path / "triaxial"
    folder.mkdir()
    with h5py.File(folder / "sample.h5", "w") as handle:
        handle.attrs["config"] = json.dumps({"config": config_to_dict(triaxial)})
    whole = {"peak_axial_stress": 3.0, "peak_q": 2.0, "p_at_peak": 1.0,
             "axial_strain_at_peak": 0.1, "completed": True}
    for damaged in ("[1]", '"x"', "{}", "{", "[" * 100000, json.dumps({**whole, "peak_q": "x"}),
                    json.dumps({**whole, "completed": False})):
        (folder / "summary.json").write_text(damaged)
        assert finished_summary(triaxial, str(folder)) is None, damaged
    (folder / "summary.json").write_text(json.dumps(whole))
    assert finished_summary(triaxial, str(folder)) == whole
    with h5py.File(folder / "sample.h5", "w") as handle:
        handle.attrs["config"] = 5                  # not JSON text
    assert finished_summary(triaxial, str(folder)) is None

    tension = TensionConfig(cases=[(0.72, 0.01)], sample=tension_sample(particles=100))
    stored = config_to_dict(tension)
    folder = tmp_path / "tension"
    folder.mkdir()
    for damaged in ('"x"', "[1]", json.dumps({"config": stored}),
                    json.dumps({"config": stored, "cases": [5]}),
                    json.dumps({"config": stored, "cases": "x"}),
                    json.dumps({"config": [1], "cases": [{"case": "a"}]})):
        (folder / "tension.json").write_text(damaged)
        assert finished_summary(tension, str(folder)) is None, damaged
    (folder / "tension.json").write_text(json.dumps({"config": stored, "cases": [
        {"case": "a", "tensile_strength_pa": 9.0, "grading": {}}]}))
    assert finished_summary(tension, str(folder)) == {"case": "a", "tensile_strength_pa": 9.0}

    # through the command: the damaged run is run again (here a stand-in), no traceback
    table = tmp_path / "t.toml"
    table.write_text('command = "tension"\n[fixed]\nparticles = 100\nvoid_ratio = 0.72\n'
                     'water_content = 1\n')
    out = tmp_path / "o"
    (out / "runs" / "run").mkdir(parents=True)
    (out / "runs" / "run" / "tension.json").write_text('"damaged"')
    ran = []
    monkeypatch.setattr(campaign_module, "run_one",
                        lambda config, folder, *rest: ran.append(folder) or {"case": "new"})
    assert run_in_process("campaign", [table, "--out", out, "--quiet"], capsys)[0] == 0
    assert ran == [str(out / "runs" / "run")]
    with open(out / "campaign.csv") as handle:
        assert [(r["status"], r["case"]) for r in csv.DictReader(handle)] == [("run", "new")]


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
    import pendular.studies.chapter5 as chapter5

    assert os.path.isfile(chapter5.TABLE)
    command, runs = sweep_from_table(chapter5.TABLE)
    assert command == "triaxial" and len(runs) == 16
    assert {r.config.sample.particles for r in runs} == {10000}
    grid = chapter5.Chapter5Grid.from_table()
    assert grid.suctions == [0, 15000, 30000, 300000] and grid.particles == 10000


def test_a_run_stored_before_a_defaulted_field_existed_is_the_same_run():
    """Reuse across versions: a configuration stored before ``wetting`` existed equals one with
    its default (the former behaviour), not one with another value."""
    from pendular.procedures.config import same_config
    from pendular.procedures.config import BridgeConfig, config_to_dict
    from pendular.procedures.triaxial import TriaxialConfig

    config = TriaxialConfig(bridges=BridgeConfig(30000.0))
    stored = config_to_dict(config)
    del stored["fields"]["wetting"]
    del stored["fields"]["bridges"]["fields"]["liquid"]
    assert same_config(stored, config)
    assert not same_config(stored, dataclasses.replace(config, wetting="at-shear"))
    assert not same_config({"no": "config"}, config) and not same_config(None, config)
