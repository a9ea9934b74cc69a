"""Fault injection against the triaxial command (issue 12): what a hostile user can give it ends
in one ``<prog>: error: ...`` line naming the parameter or the path (exit 2), or in a correct
result; never a traceback, never exit 0 with garbage.

Classes: extreme settings (huge, tiny, NaN, beyond 2**63; quasi-static guards), output paths,
corrupt / truncated / edited / forged / foreign checkpoints, corrupt and mismatched samples,
concurrent runs on one folder, a run into a used folder, SIGINT during a shear. Checksums,
identities and the physical checks of samples at the library level, and tampered table caches,
are in tests/unit/test_integrity.py (not repeated here).

Option cases, the runs the tests damage or run over, and runs whose ending the test reads from
their exit status and stderr, run in-process through pendular.cli.run_command; the runs a
signal stops are subprocesses; all of 60 spheres.
"""

import contextlib
import io
import json
import os
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numba
import numpy as np
import pytest
from numba.core import event

from conftest import ROOT, refused, run_in_process, zero_bytes
from pendular.utils.integrity import stamp, verify
from pendular.utils.interrupt import catching_interrupts
from pendular.cli import run_command
from pendular.io.outputs import OutputFolder

SCRIPT = os.path.join(ROOT, "scenarios", "triaxial.py")
TINY = ["--particles", "60", "--max-strain", "0.005", "--inertial-number", "2e-3",
        "--vtk-frames", "0", "--quiet"]
BIG = "18446744073709551617"      # 2**64 + 1


def command(argv, capsys):
    """(exit status, stderr) of ``triaxial.py ARGV`` run in-process."""
    return run_in_process("triaxial", argv, capsys, prog="triaxial.py")


def quietly(argv):
    """(exit status, stderr) of ``triaxial.py ARGV`` run in-process, its output kept from the
    test's (for the module's fixtures, which have no capsys)."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            status = run_command("triaxial", [str(a) for a in argv], prog="triaxial.py")
        except SystemExit as stop:
            status = stop.code
    return status, err.getvalue()


# ---------------------------------------------------------------- extreme settings
EXTREMES = {
    "radius huge": (["--radius", "1e300"], ["radius", "[1e-06, 1] m"]),
    "radius tiny": (["--radius", "1e-300"], ["radius"]),
    "young huge": (["--young", "1e300"], ["steps"]),
    "young 1e12": (["--young", "1e12"], ["young"]),
    "young 1e8 (growth cannot settle)": (["--young", "1e8"], ["young", "prep_stress"]),
    "strain rate huge": (["--strain-rate", "1e300"], ["--strain-rate", "(0, 1e+06] 1/s"]),
    "strain rate 1e6": (["--strain-rate", "1e6"], ["inertial number", "--force"]),
    "strain rate 1e-12": (["--strain-rate", "1e-12"], ["steps", "h here"]),
    "inertial number 1": (["--inertial-number", "1"], ["inertial number"]),
    "confining 1": (["--confining", "1"], ["confining"]),
    "max strain 1e-300": (["--max-strain", "1e-300"], ["--max-strain", "[1e-06, 0.5]"]),
    "max strain 0.9 (a crushed sample)": (["--max-strain", "0.9"], ["--max-strain", "0.5"]),
    "particles 2": (["--particles", "2"], ["--particles", "[50, "]),
    "vtk frames beyond the steps": (["--vtk-frames", "99999999999999999999"],
                                    ["--vtk-frames", "valid range [0, "]),
    "confining 0": (["--confining", "0"], ["confining"]),
    "confining nan": (["--confining", "nan"], ["confining", "not finite"]),
    "young inf": (["--young", "inf"], ["young", "not finite"]),
    "radius negative": (["--radius", "-1"], ["radius"]),
    "particles 2**64": (["--particles", BIG], ["particles", "10000000"]),
    "particles 1e9": (["--particles", "1000000000"], ["particles"]),
    "seed 2**64": (["--seed", BIG], ["seed", "4294967295"]),
    "records 2**64": (["--records", BIG], ["records"]),
    "wet steps 2**64": (["--wet-steps", BIG], ["--wet-steps"]),
    "checkpoint every 2**64": (["--checkpoint-every", BIG], ["--checkpoint-every"]),
    "threads 2**64": (["--threads", BIG], ["--threads"]),
    "table resolution 1e9": (["--suction", "1000", "--table-resolution", "1000000000,80"],
                             ["--table-resolution"]),
    "table resolution 2**64": (["--suction", "1000", "--table-resolution", f"{BIG},80"],
                               ["--table-resolution"]),
    "table nodes beyond the limit": (["--suction", "1000", "--table-resolution", "5000,80"],
                                     ["--table-resolution", "nodes"]),
    "table resolution negative": (["--suction", "1000", "--table-resolution=-1,80"],
                                  ["--table-resolution"]),
    "surface tension 1e300": (["--suction", "1000", "--surface-tension", "1e300"],
                              ["--surface-tension", "(0, 1] N/m"]),
    "suction negative": (["--suction", "-5"], ["--suction"]),
    "out empty": (["--out", ""], ["out", "empty"]),
    "out /dev/null": (["--out", "/dev/null"], ["/dev/null"]),
    "out under /proc": (["--out", "/proc/pendular-no-such"], ["/proc/pendular-no-such"]),
    "sample missing": (["--sample", "/nonexistent/sample.h5"], ["/nonexistent/sample.h5"]),
    "sample a folder": (["--sample", "/"], ["'/'"]),
    "resume missing": (["--resume", "/nonexistent"], ["/nonexistent"]),
}


@pytest.mark.parametrize("name", sorted(EXTREMES))
def test_extreme_settings_are_refused_naming_the_parameter(name, tmp_path, capsys,
                                                          monkeypatch):
    monkeypatch.chdir(tmp_path)
    options, words = EXTREMES[name]
    argv = ([] if "--resume" in options else TINY) + options
    if "--out" not in options and "--resume" not in options:
        argv += ["--out", str(tmp_path / "out")]
    refused(*command(argv, capsys), *words)


def test_an_out_that_is_a_file_is_refused(tmp_path, capsys):
    path = tmp_path / "afile"
    path.write_text("mine")
    refused(*command(TINY + ["--out", str(path)], capsys), str(path), "a file")
    assert path.read_text() == "mine"


# ---------------------------------------------------------------- a run to damage
@pytest.fixture(scope="module")
def interrupted(tmp_path_factory):
    """An interrupted run of 60 spheres with a checkpoint (folder), as --stop-after leaves it."""
    out = tmp_path_factory.mktemp("faults") / "run"
    status, err = quietly(TINY + ["--checkpoint-every", "50", "--stop-after", "120",
                                  "--out", out])
    assert status == 130, err
    assert json.loads((out / "summary.json").read_text())["completed"] is False
    return out


def copy_run(interrupted, tmp_path):
    target = tmp_path / "run"
    shutil.copytree(interrupted, target)
    return target


def forge(path, change, **identity):
    """Edit the HDF5 file and stamp it again (a valid checksum over a wrong content)."""
    stored = verify(path, kind="file")
    stored.update(identity)
    with h5py.File(path, "r+") as handle:
        change(handle)
    stamp(path, stored)


def set_step(handle):
    handle.attrs["step"] = -5


CHECKPOINT_FAULTS = {
    "zeroed bytes": (lambda p: zero_bytes(p, "particles/position", 32), ["checksum mismatch"]),
    "truncated": (lambda p: os.truncate(p, os.path.getsize(p) // 2), ["not a readable"]),
    "not HDF5": (lambda p: open(p, "w").write("not a checkpoint"), ["not a readable"]),
    "step edited to -5": (lambda p: _edit_step(p), ["checksum mismatch"]),
    "step -5, checksum forged": (lambda p: forge(p, set_step), ["step = -5", "outside"]),
    "another run's (seed 1)": (lambda p: forge(p, lambda h: None, seed=1), ["identity mismatch",
                                                                            "seed"]),
    "missing": (os.remove, ["checkpoint.h5 is missing"]),
    "dt x 10, checksum forged": (lambda p: forge(p, lambda h: h.attrs.__setitem__(
        "dt", 10.0 * h.attrs["dt"])), ["dt = ", "not this run's time step"]),
    "two spheres at one position, checksum forged": (lambda p: forge(p, lambda h: h[
        "particles/position"].__setitem__(1, h["particles/position"][0])),
        ["particles 0 and 1 share the position"]),
}


def _edit_step(path):
    with h5py.File(path, "r+") as handle:
        handle.attrs["step"] = -5


@pytest.mark.parametrize("name", sorted(CHECKPOINT_FAULTS))
def test_a_damaged_checkpoint_is_refused_naming_it(name, interrupted, tmp_path, capsys):
    run = copy_run(interrupted, tmp_path)
    damage, words = CHECKPOINT_FAULTS[name]
    damage(str(run / "checkpoint.h5"))
    before = (run / "history.h5").read_bytes()
    refused(*command(["--resume", str(run), "--quiet"], capsys), "checkpoint.h5", *words)
    assert (run / "history.h5").read_bytes() == before      # nothing written over


SAMPLE_FAULTS = {
    "zeroed bytes": (lambda p: zero_bytes(p, "position", 32), ["checksum mismatch"]),
    "truncated": (lambda p: os.truncate(p, os.path.getsize(p) // 2), ["not a readable"]),
    "sphere moved outside, checksum forged": (
        lambda p: forge(p, lambda h: h["position"].__setitem__(0, [1.0, 1.0, 1.0])),
        ["particle 0", "wall"]),
}


@pytest.mark.parametrize("name", sorted(SAMPLE_FAULTS))
def test_a_damaged_sample_is_refused_naming_it(name, interrupted, tmp_path, capsys):
    path = tmp_path / "sample.h5"
    shutil.copy(interrupted / "sample.h5", path)
    damage, words = SAMPLE_FAULTS[name]
    damage(str(path))
    argv = TINY + ["--sample", str(path), "--out", str(tmp_path / "out")]
    refused(*command(argv, capsys), str(path), *words)


def test_a_sample_of_another_radius_is_refused(interrupted, tmp_path, capsys):
    argv = TINY + ["--sample", str(interrupted / "sample.h5"), "--radius", "3e-5",
                   "--out", str(tmp_path / "out")]
    refused(*command(argv, capsys), "radius", "3e-05")


# ---------------------------------------------------------------- output folders
def test_a_second_run_on_a_folder_in_use_is_refused(tmp_path, capsys):
    out = tmp_path / "out"
    with OutputFolder(str(out), "triaxial (another run)"):
        refused(*command(TINY + ["--out", str(out)], capsys), str(out), "in use")


def test_a_run_into_a_used_folder_clears_what_the_old_run_owned(interrupted, tmp_path, capsys):
    """A dry run into an old wet run's folder: its ParaView frames and wet-only plots go, the
    user's own files stay."""
    out = copy_run(interrupted, tmp_path)
    (out / "vtk").mkdir()
    (out / "vtk" / "shear.pvd").write_text("old")
    (out / "plots").mkdir(exist_ok=True)
    (out / "plots" / "saturation.png").write_text("old")
    (out / "notes.txt").write_text("mine")
    manifest = json.loads((out / ".pendular-outputs.json").read_text())
    manifest["files"] = sorted(set(manifest["files"]) | {"vtk", "plots"})
    (out / ".pendular-outputs.json").write_text(json.dumps(manifest))
    status, err = command(TINY + ["--sample", str(interrupted / "sample.h5"), "--out", str(out)],
                          capsys)
    assert status == 0, err
    assert not (out / "vtk").exists() and not (out / "checkpoint.h5").exists()
    assert not (out / "plots" / "saturation.png").exists()
    assert (out / "notes.txt").read_text() == "mine"
    assert json.loads((out / "summary.json").read_text())["completed"] is True


# ---------------------------------------------------------------- signals
# Each run waits at a known phase (pendular.utils.interrupt.pause_point, PENDULAR_TEST_PAUSE_AT)
# until the test's signal arrives there: nothing races the machine's speed. The runs stopped
# in the shear or after it start from the finished run's sample (--sample).
@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished run of 60 spheres (folder) with a checkpoint."""
    out = tmp_path_factory.mktemp("finished") / "run"
    status, err = quietly(TINY + ["--checkpoint-every", "100", "--out", out])
    assert status == 0, err
    assert json.loads((out / "summary.json").read_text())["completed"] is True
    return out


def interrupt_at(phase, argv, cwd, signum=signal.SIGINT):
    """Run scenarios/triaxial.py with ``argv``, paused at ``phase``, and send it ``signum``
    there; returns (exit status, stderr without the pause's line)."""
    log = cwd / f"stderr-{phase}.txt"
    environment = dict(os.environ, PENDULAR_TEST_PAUSE_AT=phase)
    paused = f"paused at {phase}\n"
    with open(log, "w") as stderr:
        # a child of a shell started with & ignores SIGINT: give it the default disposition
        process = subprocess.Popen([sys.executable, SCRIPT, *argv], cwd=cwd, text=True,
                                   env=environment, stdout=subprocess.DEVNULL, stderr=stderr,
                                   preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
        try:
            waited = time.monotonic()
            while paused not in log.read_text() and process.poll() is None:
                assert time.monotonic() - waited < 600, "the run never reached " + phase
                time.sleep(0.05)
            process.send_signal(signum)
            process.wait(timeout=300)
        finally:
            if process.poll() is None:
                process.kill()
    err = log.read_text()
    assert paused in err, err
    return process.returncode, err.replace(paused, "")


def last_line(err):
    assert "Traceback" not in err, err
    return err.strip().splitlines()[-1]


def outputs(folder):
    """File name -> bytes of a run's results (what must survive a failed run intact)."""
    return {name: (folder / name).read_bytes() for name in ("summary.json", "history.h5",
                                                            "sample.h5", "triaxial.png")}


WET = ["--suction", "30000"]


@pytest.mark.parametrize("phase, extra", [("import", []), ("prepare", []), ("wet", WET)])
def test_ctrl_c_before_the_shear_exits_in_one_line_leaving_the_phase_reached(phase, extra,
                                                                            tmp_path):
    out = tmp_path / "out"
    status, err = interrupt_at(phase, TINY + extra + ["--out", str(out)], tmp_path)
    assert status == 130 and last_line(err) == "triaxial.py: interrupted", err
    if phase == "import":            # nothing had started: no folder
        assert not out.exists()
        return
    assert json.loads((out / "summary.json").read_text()) == {
        "completed": False, "phase": phase, "interrupted": True}
    assert not (out / "sample.h5").exists() and not (out / ".pendular-earlier").exists()


def test_ctrl_c_during_the_shear_keeps_the_history_so_far(finished, tmp_path):
    out = tmp_path / "out"
    sample = ["--sample", str(finished / "sample.h5")]
    status, err = interrupt_at("shear", TINY + sample + ["--out", str(out)], tmp_path)
    assert status == 130 and "interrupted at step" in last_line(err), err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["completed"] is False and summary["phase"] == "shear"
    with h5py.File(out / "history.h5", "r") as handle:
        steps = handle["history/step"][()]
    assert len(steps) >= 2 and steps[-1] - steps[0] < summary["steps"]


def test_ctrl_c_while_the_results_are_written_leaves_them_whole(finished, tmp_path):
    """Between history.h5 and summary.json: both are written, then the run ends (130)."""
    out = tmp_path / "out"
    sample = ["--sample", str(finished / "sample.h5")]
    status, err = interrupt_at("write", TINY + sample + ["--out", str(out)], tmp_path)
    assert status == 130 and last_line(err) == "triaxial.py: interrupted", err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["completed"] is True and "phase" not in summary
    with h5py.File(out / "history.h5", "r") as handle:
        assert handle["history/axial_strain"][-1] == pytest.approx(0.005, rel=0.02)


@pytest.mark.parametrize("phase", ["prepare", "shear"])
def test_ctrl_c_in_a_used_folder_keeps_the_earlier_results(phase, finished, tmp_path):
    out = tmp_path / "run"
    shutil.copytree(finished, out)
    before = outputs(out)
    status, err = interrupt_at(phase, TINY + ["--seed", "1", "--out", str(out)], tmp_path)
    assert status == 130, err
    if phase == "shear":
        assert last_line(err).endswith(f"the earlier results in {out} are kept")
    assert outputs(out) == before and not (out / ".pendular-earlier").exists()
    assert json.loads((out / ".pendular-outputs.json").read_text())["finished"] is True


def test_a_run_that_fails_keeps_the_earlier_results_or_says_where_it_stopped(finished,
                                                                             tmp_path, capsys):
    """--wet-steps 1: the equilibrium after wetting is not reached (exit 2, one line)."""
    out = tmp_path / "run"
    shutil.copytree(finished, out)
    before = outputs(out)
    failing = TINY + WET + ["--wet-steps", "1"]
    status, err = command(failing + ["--out", str(out)], capsys)
    said, error = err.strip().splitlines()
    assert said.endswith("holds the results of an earlier run; this run replaces them when it "
                         "ends (they stay if it fails)")
    refused(status, error, "equilibrium after wetting", "--wet-steps")
    assert outputs(out) == before and not (out / ".pendular-earlier").exists()
    fresh = tmp_path / "fresh"
    status, err = command(failing + ["--out", str(fresh)], capsys)
    assert status == 2, err
    summary = json.loads((fresh / "summary.json").read_text())
    assert summary["completed"] is False and summary["phase"] == "wet"
    assert "equilibrium after wetting" in summary["error"]


def test_a_bad_sample_into_a_used_folder_touches_nothing(finished, tmp_path, capsys):
    out = tmp_path / "run"
    shutil.copytree(finished, out)
    before = {path: path.read_bytes() for path in out.rglob("*") if path.is_file()}
    damaged = tmp_path / "damaged.h5"
    shutil.copy(finished / "sample.h5", damaged)
    zero_bytes(str(damaged), "position", 32)
    refused(*command(TINY + ["--sample", str(damaged), "--out", str(out)], capsys),
            str(damaged), "checksum mismatch")
    assert {path: path.read_bytes() for path in out.rglob("*") if path.is_file()} == before


def test_a_run_killed_in_a_used_folder_can_be_resumed_or_replaced(finished, tmp_path, capsys):
    """kill -9 during the shear leaves the earlier results aside and the new run's checkpoint
    in place: --resume finishes the new run (the earlier results go then); a new run instead
    first puts the earlier results back, and keeps them if it fails (the killed runs are
    processes; the runs after them, in-process)."""
    argv = TINY + ["--seed", "1", "--checkpoint-every", "100",
                   "--sample", str(finished / "sample.h5")]
    for then in ("resume", "replace"):
        out = tmp_path / then
        shutil.copytree(finished, out)
        before = outputs(out)
        status, _ = interrupt_at("shear", argv + ["--out", str(out)], tmp_path, signal.SIGKILL)
        assert status == -signal.SIGKILL and (out / ".pendular-earlier").is_dir()
        if then == "resume":
            status, err = command(["--resume", out, "--quiet"], capsys)
            assert status == 0, err
            assert "holds the results of an earlier run" in err
            assert json.loads((out / "summary.json").read_text())["completed"] is True
            assert outputs(out)["summary.json"] != before["summary.json"]
        else:
            status, err = command(TINY + WET + ["--wet-steps", "1", "--out", out], capsys)
            assert status == 2, err
            assert outputs(out) == before
        assert not (out / ".pendular-earlier").exists()


@pytest.fixture
def python_sigint():
    """Python's own SIGINT handler in this process, as in a command started from a terminal
    (a test run started in the background by a shell ignores SIGINT)."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def interrupt_this_process():
    os.kill(os.getpid(), signal.SIGINT)
    for _ in range(1000):      # the handler runs between two of these bytecodes
        pass


def test_an_interrupt_while_numba_compiles_waits_for_the_kernel_to_be_whole(python_sigint):
    """A SIGINT in the middle of a compile (sent here as the compile starts) raised there, as
    Python's own handler does, leaves no kernel: the half-made one of a real run fails to be
    cached, or the interrupt is lost. Under the command line's handler it is raised as Numba's
    compiler lock is released, the kernel compiled whole; elsewhere at once, and once."""
    class InterruptTheCompile(event.Listener):
        def on_start(self, started):
            interrupt_this_process()

        def on_end(self, ended):
            pass

    def add(a, b):
        return a + b

    with event.install_listener("numba:compile", InterruptTheCompile()):
        broken, whole = numba.njit(add), numba.njit(add)
        with pytest.raises(KeyboardInterrupt):
            broken(1.0, 2.0)
        with catching_interrupts():
            with pytest.raises(KeyboardInterrupt):
                whole(1.0, 2.0)
    assert not broken.signatures
    assert len(whole.signatures) == 1 and whole(1.0, 2.0) == 3.0
    with catching_interrupts():
        with pytest.raises(KeyboardInterrupt):
            interrupt_this_process()
        assert numba.njit(add)(1.0, 2.0) == 3.0      # a caught interrupt is not raised again
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler      # restored


# ---------------------------------------------------------------- stress bookkeeping
def test_records_whose_wall_and_love_weber_stresses_drift_apart_are_flagged():
    from pendular.procedures.laboratory import STRESS_BALANCE_BOUND, stress_balance_error
    from pendular.procedures.triaxial import summarize

    records = 5
    wall = np.tile([1000.0, 1000.0, 3000.0], (records, 1))        # p = 5/3 kPa
    contact = np.array([np.diag(row) for row in wall])
    capillary = np.zeros_like(contact)
    capillary[3] = np.diag([0.0, 0.0, -0.1 * 5000.0 / 3.0])       # 10 % of p missing on z
    history = {"sigma_wall": wall, "sigma_contact": contact - capillary,
               "sigma_capillary": capillary, "axial_strain": np.linspace(0.0, 0.01, records)}
    history["sigma_contact"][3] = contact[3]                       # the bridges' pull unbalanced
    assert stress_balance_error(history) == pytest.approx([0, 0, 0, 0.1, 0], abs=1e-12)
    summary = summarize(history)
    assert summary["stress_balance_flagged"] == [3]
    assert summary["stress_balance_bound"] == STRESS_BALANCE_BOUND < 0.1


def test_a_forced_fast_shear_is_flagged_in_its_summary(tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["--particles", "60", "--max-strain", "0.01", "--inertial-number", "0.05", "--force",
            "--vtk-frames", "0", "--quiet", "--out", str(out)]
    status, err = command(argv, capsys)
    assert status == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stress_balance_error"] > summary["stress_balance_bound"]
    assert summary["stress_balance_flagged"]
    assert "not quasi-static" in err and "Traceback" not in err


def test_an_interrupt_wrapped_by_numba_is_an_interrupt(capsys, monkeypatch):
    """Ctrl-C that Numba's C dispatcher reports as a SystemError whose cause is the
    KeyboardInterrupt (pendular.utils.interrupt) ends like any interrupt (exit 130, one line)."""
    from pendular.cli.commands import triaxial as command

    def interrupted_while_loading(args):
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as stop:
            raise SystemError("CPUDispatcher returned a result with an exception set") from stop

    monkeypatch.setattr(command, "run", interrupted_while_loading)
    with pytest.raises(SystemExit) as stop:
        run_command("triaxial", ["--particles", "60"], prog="triaxial.py")
    assert stop.value.code == 130
    assert capsys.readouterr().err.strip() == "triaxial.py: interrupted"
