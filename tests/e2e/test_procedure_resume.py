"""An SWCC run stopped mid-path and a direct tension stopped mid-pull, pendular and with liquid
clusters, and laboratory tests with liquid clusters (triaxial, simple shear) stopped
mid-loading (deterministically, --stop-after) and continued with --resume write the
uninterrupted run's files bit for bit (timings aside); a damaged or forged checkpoint, and a
resume that would change the run's configuration, are refused in one line naming the file or
the option."""

import copy
import json
import os
import shutil

import h5py
import numpy as np
import pytest

from conftest import refused, run_in_process, zero_bytes
from pendular.cli import run_command
from pendular.procedures import laboratory, tension as tension_module
from pendular.procedures.tension_clusters import update_period
from pendular.utils.integrity import stamp, verify

pytestmark = pytest.mark.slow

# 50 spheres, two suctions: each stage of the path takes a few hundred steps
RUN = ["--particles", "50", "--confining", "750", "--suctions", "3000,30000", "--threads", "1",
       "--quiet"]
#: Checkpoints every 70 steps, stopped after 350 steps of the path: the last checkpoint falls
#: inside a stage, away from its equilibrium checks (every 200 steps of the stage).
STOP = ["--checkpoint-every", "70", "--stop-after", "350"]
#: Timings, which differ between runs (summaries, a tension's cases, history attributes).
TIMINGS = {"wall_time_s", "wetting_time_s", "pull_time_s", "preparation_time_s",
           "pre_shear_time_s", "shear_time_s", "cluster_update_time_s", "particle_steps_per_s"}
#: HDF5 attributes that hold object references (dimension scales), compared by their targets.
REFERENCES = {"DIMENSION_LIST", "REFERENCE_LIST"}


def swcc(argv, capsys):
    return run_in_process("swcc", argv, capsys)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """(uninterrupted run folder, interrupted run folder before its resume)."""
    root = tmp_path_factory.mktemp("swcc_resume")
    whole, stopped = root / "whole", root / "stopped"
    assert run_command("swcc", RUN + ["--out", str(whole)]) == 0
    assert run_command("swcc", RUN + STOP + ["--out", str(stopped)]) == 130
    return whole, stopped


def contents(path):
    """{object name: (data or None, attributes)} of an HDF5 file, references left out."""
    with h5py.File(path) as handle:
        found = {}

        def visit(name, item):
            data = item[()] if isinstance(item, h5py.Dataset) else None
            found[name] = (data, {k: v for k, v in item.attrs.items()
                                  if k not in REFERENCES and k not in TIMINGS})
        handle.visititems(visit)
        found["/"] = (None, {k: v for k, v in handle.attrs.items() if k not in TIMINGS})
    return found


def without_timings(data):
    """A JSON value with the TIMINGS keys left out at every depth."""
    if isinstance(data, dict):
        return {k: without_timings(v) for k, v in data.items() if k not in TIMINGS}
    if isinstance(data, list):
        return [without_timings(v) for v in data]
    return data


def same(value, other):
    """Whether two attribute values are equal, NaN equal to NaN (the suction of a test at a
    water content)."""
    value, other = np.asarray(value), np.asarray(other)
    numbers = value.dtype.kind in "fc" and other.dtype.kind in "fc"
    return np.array_equal(value, other, equal_nan=numbers)


def assert_same_files(first, second, files=("history.h5", "sample.h5"), summary="swcc.json"):
    for name in files:
        a, b = contents(first / name), contents(second / name)
        assert a.keys() == b.keys(), name
        for key, (data, attributes) in a.items():
            other, other_attributes = b[key]
            if data is not None:
                assert data.dtype == other.dtype and np.array_equal(data, other), (name, key)
            assert attributes.keys() == other_attributes.keys(), (name, key)
            for attribute, value in attributes.items():
                assert same(value, other_attributes[attribute]), (name, key, attribute)
    a, b = (json.loads((folder / summary).read_text()) for folder in (first, second))
    assert without_timings(a) == without_timings(b)


def test_a_stopped_swcc_resumes_bit_for_bit(runs, tmp_path, capsys):
    whole, stopped = runs
    run = tmp_path / "run"
    shutil.copytree(stopped, run)
    assert not (run / "swcc.json").exists() and (run / "checkpoint.h5").exists()
    status, err = swcc(["--resume", str(run), "--threads", "1", "--quiet"], capsys)
    assert status == 0, err
    assert_same_files(whole, run)
    # stopped again after its resume, and resumed once more: still the same files
    again = tmp_path / "again"
    shutil.copytree(stopped, again)
    status, err = swcc(["--resume", str(again), "--stop-after", "150", "--quiet"], capsys)
    assert status == 130 and f"--resume {again}" in err, err
    assert swcc(["--resume", str(again), "--quiet"], capsys)[0] == 0
    assert_same_files(whole, again)


def test_a_stopped_swcc_with_clusters_resumes_bit_for_bit(tmp_path, capsys):
    """Stopped in its second stage: the clusters' state of that stage and the first stage's
    pores/ frame come from the checkpoint."""
    argv = RUN + ["--liquid", "clusters"]
    whole, run = tmp_path / "whole", tmp_path / "run"
    assert swcc(argv + ["--out", whole], capsys)[0] == 0
    assert swcc(argv + STOP + ["--out", run], capsys)[0] == 130
    with h5py.File(run / "checkpoint.h5") as handle:
        assert json.loads(handle.attrs["extra_state"])["stage"] == 1
    status, err = swcc(["--resume", run, "--quiet"], capsys)
    assert status == 0, err
    assert_same_files(whole, run)
    frames = sorted(path.name for path in (whole / "pores").glob("*"))
    assert frames == sorted(path.name for path in (run / "pores").glob("*"))
    for name in frames:
        assert (whole / "pores" / name).read_bytes() == (run / "pores" / name).read_bytes()


def forge(path, change):
    """Edit the checkpoint and stamp it again (a valid checksum over a wrong content)."""
    stored = verify(path, kind="file")
    with h5py.File(path, "r+") as handle:
        change(handle)
    stamp(path, stored)


def edit_extra(key, value):
    def change(handle):
        extra = json.loads(handle.attrs["extra_state"])
        extra[key] = value
        handle.attrs["extra_state"] = json.dumps(extra)
    return change


FAULTS = {
    "zeroed bytes": (lambda p: zero_bytes(p, "particles/position", 32), ["checksum mismatch"]),
    "stage forged": (lambda p: forge(p, edit_extra("stage", 3)), ["stage rows"]),
    "path state forged": (lambda p: forge(p, edit_extra("stages", "none")),
                          ["does not belong"]),
    "missing": (os.remove, ["checkpoint.h5 is missing"]),
}


@pytest.mark.parametrize("name", sorted(FAULTS))
def test_a_damaged_swcc_checkpoint_is_refused_naming_it(name, runs, tmp_path, capsys):
    run = tmp_path / "run"
    shutil.copytree(runs[1], run)
    damage, words = FAULTS[name]
    damage(str(run / "checkpoint.h5"))
    refused(*swcc(["--resume", str(run), "--quiet"], capsys), "checkpoint.h5", *words)
    assert not (run / "swcc.json").exists()


def test_a_resume_that_changes_the_configuration_is_refused(runs, tmp_path, capsys):
    run = tmp_path / "run"
    shutil.copytree(runs[1], run)
    refused(*swcc(["--resume", str(run), "--suctions", "3000,300000", "--quiet"], capsys),
            "--suctions", "cannot be changed")


# ---------------------------------------------------------------- direct tension

#: One void ratio, two water contents: the second case pulled from the sample of the first.
TENSION = ["--particles", "100", "--void-ratio", "0.72", "--water-content", "1,2",
           "--max-strain", "0.01", "--vtk-frames", "0", "--threads", "1", "--quiet"]
#: Stopped in the second case's pull (each pulls about 1,900 steps), checkpoints every 150.
TENSION_STOP = ["--checkpoint-every", "150", "--stop-after", "2500"]
CASES = ("e0.72_w1.00", "e0.72_w2.00")


@pytest.fixture(scope="module")
def tension_runs(tmp_path_factory):
    """(folder holding the uninterrupted run ``run``, folder holding the stopped one): the
    same --out, which tension.json records."""
    whole, stopped = (tmp_path_factory.mktemp(name) for name in ("whole", "stopped"))
    here = os.getcwd()
    try:
        os.chdir(whole)
        assert run_command("tension", TENSION + ["--out", "run"]) == 0
        os.chdir(stopped)
        assert run_command("tension", TENSION + TENSION_STOP + ["--out", "run"]) == 130
    finally:
        os.chdir(here)
    return whole, stopped


def tension(argv, capsys):
    return run_in_process("tension", argv, capsys)


def test_a_stopped_tension_resumes_bit_for_bit(tension_runs, tmp_path, capsys, monkeypatch):
    whole, stopped = tension_runs
    shutil.copytree(stopped / "run", tmp_path / "run")
    monkeypatch.chdir(tmp_path)
    assert not (tmp_path / "run" / "tension.json").exists()
    status, err = tension(["--resume", "run", "--threads", "1", "--quiet"], capsys)
    assert status == 0, err
    assert_same_files(whole / "run", tmp_path / "run",
                      files=[f"cases/{case}/history.h5" for case in CASES],
                      summary="tension.json")
    assert ((whole / "run" / "report.md").read_bytes()
            == (tmp_path / "run" / "report.md").read_bytes())


TENSION_FAULTS = {
    "zeroed bytes": (lambda p: zero_bytes(p, "particles/position", 32), ["checksum mismatch"]),
    "case forged": (lambda p: forge(p, edit_extra("case", 0)), ["finished cases"]),
    "pull start forged": (lambda p: forge(p, edit_extra("pull_start", 5)), ["pull_start = 5"]),
    "missing": (os.remove, ["checkpoint.h5 is missing"]),
}


@pytest.mark.parametrize("name", sorted(TENSION_FAULTS))
def test_a_damaged_tension_checkpoint_is_refused_naming_it(name, tension_runs, tmp_path,
                                                           capsys):
    run = tmp_path / "run"
    shutil.copytree(tension_runs[1] / "run", run)
    damage, words = TENSION_FAULTS[name]
    damage(str(run / "checkpoint.h5"))
    refused(*tension(["--resume", str(run), "--quiet"], capsys), "checkpoint.h5", *words)
    assert not (run / "tension.json").exists()


def test_a_tension_resume_that_changes_the_configuration_is_refused(tension_runs, tmp_path,
                                                                    capsys):
    run = tmp_path / "run"
    shutil.copytree(tension_runs[1] / "run", run)
    refused(*tension(["--resume", str(run), "--water-content", "3", "--quiet"], capsys),
            "--water-content", "cannot be changed")


# ---------------------------------------------------------------- liquid clusters

#: Laboratory tests with liquid clusters, updated every 10 records (CLUSTER_RECORDS patched),
#: their forces following the grains at every record between.
CLUSTERS = ["--particles", "60", "--liquid", "clusters", "--checkpoint-every", "300",
            "--threads", "1", "--quiet", "--no-plots"]
#: (command, its options, --stop-after): a triaxial at a suction with pores/ frames, one at a
#: water content (the closed liquid) without, a simple shear (a sheared periodic cell).
CLUSTER_CASES = {
    "suction": ("triaxial", ["--suction", "20000", "--max-strain", "0.01", "--records", "40",
                             "--vtk-frames", "5"], 1500),
    "water content": ("triaxial", ["--water-content", "3", "--max-strain", "0.01",
                                   "--records", "20", "--vtk-frames", "0"], 1500),
    "sheared cell": ("simple-shear", ["--suction", "20000", "--seed", "3", "--max-strain",
                                      "0.01", "--record-strain", "0.0005", "--vtk-frames", "5"],
                     1500)}


def saved_state(checkpoint, kind, name):
    """(step, {key: value} of the state of the operation ``name`` among ``kind``) of a
    checkpoint, its groups as dicts."""
    def read(group):
        return {**dict(group.attrs), **{key: read(item) if isinstance(item, h5py.Group)
                                        else item[()] for key, item in group.items()}}

    with h5py.File(checkpoint) as handle:
        for group in handle["operations"][kind].values():
            if group.attrs["type"].endswith(name):
                return int(handle.attrs["step"]), read(group["state"])
    raise KeyError(name)


def assert_between_updates(checkpoint):
    """The checkpoint holds clusters updated at least once, whose forces have followed the
    grains since their last update."""
    step, updates = saved_state(checkpoint, "writers", "ClusterUpdates")
    assert updates["updates"] >= 1 and updates["updated"] < step, (step, updates)
    return saved_state(checkpoint, "forces", "LiquidClusters")[1]


@pytest.mark.parametrize("case", sorted(CLUSTER_CASES))
def test_a_stopped_laboratory_test_with_clusters_resumes_bit_for_bit(case, tmp_path, capsys,
                                                                     monkeypatch):
    monkeypatch.setattr(laboratory, "CLUSTER_RECORDS", 10)
    command, options, stop = CLUSTER_CASES[case]
    argv = CLUSTERS + options
    whole, run = tmp_path / "whole", tmp_path / "run"
    assert run_in_process(command, argv + ["--out", whole], capsys)[0] == 0
    status, err = run_in_process(command, argv + ["--stop-after", stop, "--out", run], capsys)
    assert status == 130 and f"--resume {run}" in err, err
    clusters = assert_between_updates(run / "checkpoint.h5")
    if case == "water content":          # the closed liquid's front partly filled
        assert 0.0 < clusters["liquid"]["front_fraction"] < 1.0
    if case == "sheared cell":           # the units of a sheared cell: (Lx, Ly, Lz, offset)
        assert len(clusters["units"]["period"]) == 4 and clusters["units"]["period"][3] != 0
    status, err = run_in_process(command, ["--resume", run, "--quiet"], capsys)
    assert status == 0, err
    assert_same_files(whole, run, files=("history.h5",), summary="summary.json")
    frames = sorted(path.name for path in (whole / "pores").glob("*")) \
        if (whole / "pores").exists() else []
    assert frames == sorted(path.name for path in (run / "pores").glob("*"))
    for name in frames:
        assert (whole / "pores" / name).read_bytes() == (run / "pores" / name).read_bytes()


#: A direct tension with liquid clusters: its closed liquid solved again 40 times over the
#: pull (about 770 steps), checkpoints every 150 steps, stopped after 400.
CLUSTER_TENSION = ["--particles", "100", "--void-ratio", "0.72", "--water-content", "2",
                   "--max-strain", "0.004", "--roughness", "0", "--liquid", "clusters",
                   "--vtk-frames", "0", "--threads", "1", "--quiet"]


def test_a_stopped_tension_with_clusters_resumes_bit_for_bit(tmp_path, capsys, monkeypatch):
    """(The three runs prepare one sample: the preparation, deterministic, is the first
    run's, which the existing tension resume test proves the same when prepared again.)"""
    prepared = {}
    prepare = tension_module.prepare_void_ratio

    def once(*arguments):
        key = repr(arguments)
        if key not in prepared:
            prepared[key] = prepare(*arguments)
        return copy.deepcopy(prepared[key])

    monkeypatch.setattr(tension_module, "prepare_void_ratio", once)
    for name in ("whole", "stopped"):
        (tmp_path / name).mkdir()
    monkeypatch.chdir(tmp_path / "whole")
    assert tension(CLUSTER_TENSION + ["--out", "run"], capsys)[0] == 0
    monkeypatch.chdir(tmp_path / "stopped")
    status, err = tension(CLUSTER_TENSION + ["--checkpoint-every", "150", "--stop-after", "400",
                                             "--out", "run"], capsys)
    assert status == 130, err
    step, _ = saved_state("run/checkpoint.h5", "forces", "LiquidClusters")
    with h5py.File("run/checkpoint.h5") as handle:
        start = json.loads(handle.attrs["extra_state"])["pull_start"]
    case = json.loads((tmp_path / "whole" / "run" / "tension.json").read_text())["cases"][0]
    assert not case["ruptured"]          # pulled to --max-strain: its pull_steps as planned
    period = update_period(case["pull_steps"])
    assert step - start > period and (step - start) % period, (step, start)   # between updates
    status, err = tension(["--resume", "run", "--quiet"], capsys)
    assert status == 0, err
    assert_same_files(tmp_path / "whole" / "run", tmp_path / "stopped" / "run",
                      files=["cases/e0.72_w2.00/history.h5"], summary="tension.json")
