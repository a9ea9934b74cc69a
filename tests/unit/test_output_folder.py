"""A run's output folder never ends with less than it had (pendular.io.outputs.OutputFolder):
the earlier results are set aside while a new run writes, and come back if it fails."""

import json
import os

import pytest

from pendular.io.outputs import EARLIER, MANIFEST, OutputFolder


def run_into(out, files, fail=None, phase=None, commit_first=False):
    """A run owning ``files`` (name -> text) into ``out``; ``fail``: an exception raised after
    they are written (after ``commit`` if ``commit_first``)."""
    with OutputFolder(out, "run") as folder:
        folder.claim("summary.json")
        folder.phase = phase
        for name, text in files.items():
            path = folder.claim(name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w") as handle:
                handle.write(text)
        if commit_first:
            folder.commit()
        if fail is not None:
            raise fail


def contents(out):
    return {str(p.relative_to(out)): p.read_text() for p in sorted(out.rglob("*"))
            if p.is_file() and p.name not in (MANIFEST, ".pendular.lock")}


@pytest.fixture
def earlier(tmp_path):
    out = tmp_path / "out"
    run_into(out, {"summary.json": "earlier", "vtk/frame.vtu": "earlier frame"})
    (out / "notes.txt").write_text("the user's")
    return out


def test_a_run_that_succeeds_replaces_the_earlier_results_and_says_so(earlier, capsys):
    run_into(earlier, {"summary.json": "new"})
    assert contents(earlier) == {"notes.txt": "the user's", "summary.json": "new"}
    said = capsys.readouterr().err.strip().splitlines()
    assert said == [f"{earlier}: holds the results of an earlier run; this run replaces them "
                    "when it ends (they stay if it fails)"]
    assert json.loads((earlier / MANIFEST).read_text())["finished"] is True


@pytest.mark.parametrize("stop", [KeyboardInterrupt(), ValueError("diverged")])
def test_a_run_that_stops_brings_the_earlier_results_back(earlier, stop):
    before = contents(earlier)
    with pytest.raises(type(stop)):
        run_into(earlier, {"history.h5": "partial", "vtk/frame.vtu": "new frame"}, fail=stop)
    assert contents(earlier) == before and not (earlier / EARLIER).exists()
    assert json.loads((earlier / MANIFEST).read_text())["finished"] is True


def test_results_committed_before_a_stop_are_kept(earlier):
    with pytest.raises(KeyboardInterrupt):
        run_into(earlier, {"summary.json": "new"}, fail=KeyboardInterrupt(), commit_first=True)
    assert contents(earlier) == {"notes.txt": "the user's", "summary.json": "new"}


@pytest.mark.parametrize("stop, says", [(KeyboardInterrupt(), {"interrupted": True}),
                                        (ValueError("not static"),
                                         {"interrupted": False, "error": "not static"})])
def test_a_stopped_run_with_nothing_to_fall_back_on_says_where_it_stopped(tmp_path, stop, says):
    out = tmp_path / "out"
    with pytest.raises(type(stop)):
        run_into(out, {"sample.h5": "partial"}, fail=stop, phase="wet")
    assert json.loads((out / "summary.json").read_text()) == {
        "completed": False, "phase": "wet", **says}
    assert (out / "sample.h5").read_text() == "partial"


def test_a_summary_the_run_wrote_itself_is_not_replaced(tmp_path):
    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt):
        run_into(out, {"summary.json": "its own"}, fail=KeyboardInterrupt())
    assert (out / "summary.json").read_text() == "its own"


def test_the_files_of_a_killed_run_are_put_in_order_by_the_next(earlier):
    """kill -9 leaves the new files in place and the earlier ones aside: a new run restores
    the earlier ones first (and falls back on them), a resume keeps them aside until it ends."""
    before = contents(earlier)
    killed = OutputFolder(earlier, "killed").__enter__()
    (earlier / "summary.json").write_text("killed")
    killed.claim("summary.json")
    killed._release()                         # what kill -9 leaves: the lock freed, no exit
    assert (earlier / EARLIER).is_dir()
    with pytest.raises(ValueError):
        run_into(earlier, {"summary.json": "failed"}, fail=ValueError("bad"))
    assert contents(earlier) == before

    killed = OutputFolder(earlier, "killed").__enter__()
    (earlier / "summary.json").write_text("resumable")
    killed.claim("summary.json")
    killed._release()
    with pytest.raises(KeyboardInterrupt):
        with OutputFolder(earlier, "resume", keep=True):
            raise KeyboardInterrupt
    assert (earlier / EARLIER).is_dir() and (earlier / "summary.json").read_text() == "resumable"
    with OutputFolder(earlier, "resume", keep=True):
        (earlier / "summary.json").write_text("resumed")
    assert contents(earlier) == {"notes.txt": "the user's", "summary.json": "resumed"}
