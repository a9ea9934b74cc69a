"""Checkpoints (pendular.dem.checkpoint): bit-identical resume, atomic writes under kill -9, checks,
and forged checkpoints (valid checksum, invalid content) refused with one ValueError."""

import copy
import io
import os
import pickle
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from conftest import two_body_scene
from pendular.dem.checkpoint import FORMAT, CheckpointWriter, load_checkpoint, save_checkpoint
from pendular.utils.integrity import stamp, verify
from pendular.dem.neighbors import NeighborList
from pendular.procedures.preparation import PrepareConfig, prepare_sample
from pendular.dem.integrate import Integrator
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.walls import StressServo
from pendular.procedures.config import ShearConfig
from pendular.procedures.triaxial import TriaxialShear

HERE = os.path.dirname(os.path.abspath(__file__))


@pytest.fixture(scope="module")
def prepared():
    config = PrepareConfig(particles=60, unload_steps=200, confining=750.0)
    sim, _ = prepare_sample(config, progress=False)
    return config, sim


def sheared(prepared, checkpoint_path):
    """The prepared sample in triaxial shear, built the same way every time."""
    config, sample = prepared
    sim = copy.deepcopy(sample)
    shear = ShearConfig(max_strain=0.05, inertial_number=2e-3, records=100)
    run = TriaxialShear(sim, shear, 750.0, config.radius, config.density)
    sim.writers.append(CheckpointWriter(checkpoint_path, period=10 ** 9))
    return sim, run.recorder


def test_resumed_shear_is_bit_identical_to_an_uninterrupted_one(prepared, tmp_path):
    path = tmp_path / "checkpoint.h5"
    whole, whole_history = sheared(prepared, path)
    steps = 40 * whole_history.period
    whole.run(steps)

    first, _ = sheared(prepared, path)
    first.run(steps // 2)
    skipped = save_checkpoint(path, first, extra_state={"phase": "shear"})
    assert skipped == {"writers[0] HistoryRecorder": ["quantities"],     # closures: rebuilt
                       "writers[1] SampleGuard": ["describe"],
                       "writers[2] CheckpointWriter": ["path", "period", "extra_state",
                                                       "identity"]}

    resumed, resumed_history = sheared(prepared, path)
    assert load_checkpoint(path, resumed) == {"phase": "shear"}
    assert resumed.step == first.step and resumed.time == first.time
    resumed.run(steps - steps // 2)

    assert np.array_equal(resumed.particles.position, whole.particles.position)
    assert np.array_equal(resumed.particles.angular_velocity, whole.particles.angular_velocity)
    assert np.array_equal(resumed.contacts.shear_force, whole.contacts.shear_force)
    assert np.array_equal(resumed.walls.position, whole.walls.position)
    assert resumed.time == whole.time
    assert resumed.operation(NeighborList).rebuilds == whole.operation(NeighborList).rebuilds
    expected, got = whole_history.arrays(), resumed_history.arrays()
    assert len(got["step"]) == len(expected["step"]) > 40
    for name in expected:
        assert np.array_equal(got[name], expected[name]), name

    # the operations' state matters: without the servo's memory the run departs
    again, _ = sheared(prepared, path)
    load_checkpoint(path, again)
    assert np.any(again.operation(StressServo).previous != 0.0)
    again.operation(StressServo).previous[:] = 0.0
    again.run(steps - steps // 2)
    assert not np.array_equal(again.walls.position, whole.walls.position)


class CachingOperation:
    """An operation that keeps references to the simulation's objects, a random generator,
    a closure and an attribute it asks not to save."""

    checkpoint_exclude = ("scratch",)

    def __init__(self):
        self.contacts = None
        self.position = None
        self.generator = np.random.default_rng(3)
        self.callback = lambda sim: sim.step
        self.scratch = "fresh"
        self.kicks = []

    def apply(self, sim):
        self.contacts = sim.contacts
        self.position = sim.particles.position
        self.kicks.append(self.generator.random())


def scene_with_bridges(operation):
    sim = two_body_scene([[0, 0, 0], [1.9e-3, 0, 0], [0, 1.9e-3, 0]], np.zeros((3, 3)),
                         extra=[operation])
    sim.run(3)
    extra = sim.contacts.extra
    extra["bridge"] = sim.contacts.overlap > 0          # bool
    extra["state"] = np.arange(len(sim.contacts), dtype=np.int8)
    extra["bridge_force"] = np.linspace(1.0, 2.0, len(sim.contacts))
    return sim


def test_references_extra_arrays_and_unpicklable_attributes(tmp_path):
    saved = scene_with_bridges(CachingOperation())
    saved.forces[2].scratch = "saved"
    path = tmp_path / "c.h5"
    skipped = save_checkpoint(path, saved)
    assert skipped == {"forces[2] CachingOperation": ["callback", "scratch"]}

    fresh_operation = CachingOperation()
    fresh_callback = fresh_operation.callback
    loaded = two_body_scene(np.zeros((1, 3)), np.zeros((1, 3)), extra=[fresh_operation])
    load_checkpoint(path, loaded)
    assert len(loaded.particles) == 3 and loaded.step == 3
    for name, values in saved.contacts.extra.items():
        assert loaded.contacts.extra[name].dtype == values.dtype
        assert np.array_equal(loaded.contacts.extra[name], values)
    for name in ("pair_i", "pair_j", "row_start", "second_start", "second_pair", "overlap"):
        assert np.array_equal(getattr(loaded.contacts, name), getattr(saved.contacts, name))
    op = loaded.forces[2]
    assert op.contacts is loaded.contacts                       # references follow the load
    assert op.position is loaded.particles.position
    assert op.callback is fresh_callback and op.scratch == "fresh"
    assert op.kicks == saved.forces[2].kicks
    saved.run(5)
    loaded.run(5)
    assert op.kicks == saved.forces[2].kicks                # generator state carried on
    assert np.array_equal(loaded.particles.position, saved.particles.position)
    assert np.array_equal(loaded.contacts.extra["state"], saved.contacts.extra["state"])


def test_loading_into_a_differently_built_simulation_raises_and_changes_nothing(prepared,
                                                                                 tmp_path):
    path = tmp_path / "checkpoint.h5"
    sim, _ = sheared(prepared, path)
    sim.run(10)
    save_checkpoint(path, sim)
    _, sample = prepared
    other = copy.deepcopy(sample)          # six-wall servo, no strain control, no writers
    before = other.particles.position.copy()
    with pytest.raises(ValueError, match="controls.*ConstantStrainRate"):
        load_checkpoint(path, other)
    assert other.step == sample.step and np.array_equal(other.particles.position, before)
    missing_writer, _ = sheared(prepared, path)
    missing_writer.writers.pop()
    with pytest.raises(ValueError, match="writers"):
        load_checkpoint(path, missing_writer)
    with h5py.File(tmp_path / "other.h5", "w") as handle:
        handle.attrs["format"] = "something else"
    with pytest.raises(ValueError, match="not a checksummed pendular checkpoint"):
        load_checkpoint(tmp_path / "other.h5", sim)


def test_a_checkpoint_of_version_1_is_refused_naming_its_version(tmp_path):
    """Version 1 (an operations list, before the declared pipeline) cannot be resumed."""
    path = tmp_path / "c.h5"
    scene = [[0, 0, 0], [1.9e-3, 0, 0]], np.zeros((2, 3))
    sim = two_body_scene(*scene)
    sim.run(2)
    save_checkpoint(path, sim)
    with h5py.File(path, "r+") as handle:
        handle.attrs["version"] = 1
        stamp(handle, {"kind": "checkpoint", "format": FORMAT, "version": 1})
    fresh = two_body_scene(*scene)
    with pytest.raises(ValueError, match="checkpoint version 1; this code reads version 3"):
        load_checkpoint(path, fresh)
    assert fresh.step == 0 and fresh.contacts is None


def test_checkpoint_writer_saves_every_period(tmp_path):
    path = tmp_path / "c.h5"
    sim = two_body_scene([[0, 0, 0], [1.9e-3, 0, 0]], np.zeros((2, 3)))
    sim.writers.append(CheckpointWriter(path, period=4, extra_state=lambda s: s.step * 10))
    sim.run(10)
    assert sim.writers[0].written == 2
    with h5py.File(path) as handle:
        assert handle.attrs["step"] == 8
    # a checkpoint of an older pendular, which saved the writer's path too
    forge(str(path), edit_state(lambda tree: tree["writers"][0].update(path=str(path))))
    fresh = two_body_scene([[0, 0, 0], [1.9e-3, 0, 0]], np.zeros((2, 3)))
    moved = tmp_path / "copied" / "c.h5"            # a run folder copied, then resumed
    fresh.writers.append(CheckpointWriter(moved, period=5))
    assert load_checkpoint(path, fresh) == 80
    assert fresh.step == 8 and fresh.writers[0].written == 2
    assert fresh.writers[0].path == str(moved) and fresh.writers[0].period == 5
    with pytest.raises(ValueError, match="checkpoint period"):
        CheckpointWriter(path, period=0)


def bulky_scene():
    """50,000 spheres (a 7 MB checkpoint), no contacts: a checkpoint takes some milliseconds."""
    count = 50_000
    particles = Particles(np.zeros((count, 3)), np.ones(count), 1000.0)
    return Simulation(particles, Walls.box([0, 0, 0], [1, 1, 1]), 1.0,
                      neighbors=NeighborList(1.0), controls=[StressServo("xyz", 1.0, 1.0)],
                      integrator=Integrator(0.0))


def checkpoint_forever(path):
    """Run in a subprocess: write checkpoints of a changing state until killed."""
    sim = bulky_scene()
    while True:
        sim.step += 1
        sim.time = 0.5 * sim.step
        for array in (sim.particles.position, sim.particles.velocity, sim.walls.position,
                      sim.controls[0].previous):
            array[:] = sim.step
        save_checkpoint(path, sim, extra_state=sim.step)


def test_kill_during_checkpointing_leaves_a_loadable_checkpoint(tmp_path):
    path = str(tmp_path / "checkpoint.h5")
    # this file and conftest.py (one folder up) importable in the child
    code = (f"import sys; sys.path[:0] = [{HERE!r}, {os.path.dirname(HERE)!r}]; "
            "import test_checkpoint; "
            f"test_checkpoint.checkpoint_forever({path!r})")
    child = subprocess.Popen([sys.executable, "-c", code])
    temporary = str(tmp_path / f".checkpoint.h5.tmp{child.pid}")   # pendular.utils.atomic.replacing
    try:
        deadline = time.monotonic() + 60.0
        while not os.path.exists(path):
            assert child.poll() is None and time.monotonic() < deadline, "no checkpoint written"
            time.sleep(0.01)
        time.sleep(0.2)
        while not os.path.exists(temporary):    # kill while the next checkpoint is being written
            assert time.monotonic() < deadline
        os.kill(child.pid, signal.SIGKILL)
    finally:
        child.kill()
        child.wait()
    assert child.returncode == -signal.SIGKILL
    sim = bulky_scene()
    step = load_checkpoint(path, sim)
    assert step == sim.step > 1 and sim.time == 0.5 * step
    for array in (sim.particles.position, sim.particles.velocity, sim.walls.position,
                  sim.controls[0].previous):
        assert np.all(array == step)


def test_samples_and_checkpoints_describe_their_datasets(prepared, tmp_path):
    """Every dataset of a sample and of a checkpoint has units and a description (an array
    pendular.dem.checkpoint does not declare: units "unknown"); both files carry pendular_version and
    schema_version, written before the checksum, so that they still load."""
    from pendular.dem.sample import DATASETS, load_sample, save_sample

    _, sample = prepared
    sim = copy.deepcopy(sample)
    sim.run(1)
    sim.contacts.extra["someone.thing"] = np.zeros(len(sim.contacts))
    save_sample(tmp_path / "sample.h5", sim, {"porosity": 0.4})
    save_checkpoint(tmp_path / "checkpoint.h5", sim)
    for name in ("sample.h5", "checkpoint.h5"):
        datasets = []
        with h5py.File(tmp_path / name, "r") as handle:
            assert handle.attrs["pendular_version"] and int(handle.attrs["schema_version"]) >= 2
            handle.visititems(lambda path, item: datasets.append((path, dict(item.attrs)))
                              if isinstance(item, h5py.Dataset) else None)
        assert len(datasets) >= 5
        for path, attrs in datasets:
            assert attrs.get("units") and attrs.get("description"), (name, path)
        units = dict((path, attrs["units"]) for path, attrs in datasets)
        if name == "sample.h5":
            assert set(units) == set(DATASETS)
            assert units["velocity"] == "m/s" and units["angular_velocity"] == "rad/s"
        else:
            assert units["particles/position"] == "m" and units["contacts/overlap"] == "m"
            assert units["contacts/extra/someone.thing"] == "unknown"
    load_sample(tmp_path / "sample.h5")
    del sim.contacts.extra["someone.thing"]
    load_checkpoint(tmp_path / "checkpoint.h5", copy.deepcopy(sample))


# ---------------------------------------------------------------- forged checkpoints
def forge(path, change):
    """Apply ``change(handle)`` to the checkpoint and stamp it again with its own identity: a
    valid checksum over a wrong content (a writer's bug, or a forger)."""
    identity = verify(path, kind="checkpoint")
    with h5py.File(path, "r+") as handle:
        change(handle)
    stamp(path, identity)


def put(name, index, value):
    def change(handle):
        handle[name][index] = value
    return change


def replace(name, value):
    def change(handle):
        del handle[name]
        handle[name] = value
    return change


def attribute(name, value):
    def change(handle):
        handle.attrs[name] = value
    return change


class _Reference:
    """A reference to the simulation's objects inside a state pickle, kept as it is."""

    def __init__(self, path):
        self.path = path


class _KeepReferences(pickle.Unpickler):
    def persistent_load(self, path):
        return _Reference(path)


class _PutReferences(pickle.Pickler):
    def persistent_id(self, obj):
        return obj.path if isinstance(obj, _Reference) else None


def edit_state(change):
    """A change of the checkpoint's pickled state tree: ``change(tree)`` edits it in place or
    returns its replacement."""
    def apply(handle):
        tree = _KeepReferences(io.BytesIO(handle["state"][()].tobytes())).load()
        replaced = change(tree)
        buffer = io.BytesIO()
        _PutReferences(buffer, protocol=5).dump(tree if replaced is None else replaced)
        replace("state", np.frombuffer(buffer.getvalue(), np.uint8))(handle)
    return apply


def _garbage(handle):
    replace("state", np.frombuffer(b"not a pickle, but checksummed" * 4, np.uint8))(handle)


def _truncated_state(handle):
    blob = handle["state"][()]
    replace("state", blob[:len(blob) // 2])(handle)


def _drop_last_force(tree):
    del tree["forces"][-1]


FORGED = {
    # pair indices and per-pair state
    "pair_j past the particles": (put("contacts/pair_j", 1, 10 ** 6),
                                  "contacts/pair_j[1] = 1000000 is outside the valid range [0, 3) "
                                  "of the checkpoint's 3 particles"),
    "negative pair_i": (put("contacts/pair_i", 0, -1), "contacts/pair_i[0] = -1 is outside"),
    "a pair of a particle with itself": (put("contacts/pair_j", 0, 0),
                                         "pair 0 joins particles i = 0, j = 0; valid: "
                                         "0 <= i < j < 3"),
    "pair indices as floats": (replace("contacts/pair_j", np.array([1.0, 2.0])),
                               "contacts/pair_j holds float64; valid: int64"),
    "shear force of another shape": (replace("contacts/shear_force", np.zeros((2, 2))),
                                     "contacts/shear_force has shape (2, 2); valid: (2, 3)"),
    "NaN shear force": (put("contacts/shear_force", (1, 2), np.nan),
                        "contacts/shear_force[1, 2] = nan is not finite"),
    "NaN overlap": (put("contacts/overlap", 0, np.nan), "contacts/overlap[0] = nan"),
    "CSR rows that miss a pair": (put("contacts/row_start", -1, 1),
                                  "contacts/row_start does not index the pairs"),
    "second index shuffled": (replace("contacts/second_pair", np.array([1, 0])),
                              "second_start and second_pair do not index"),
    "near_wall past the particles": (replace("contacts/near_wall", np.array([0, 7])),
                                     "near_wall is not an ascending list of particle indices "
                                     "in [0, 3)"),
    "a bridge array of another length": (replace("contacts/extra/bridge_force", np.ones(5)),
                                         "contacts/extra/bridge_force holds float64 of shape "
                                         "(5,); valid: numbers, one row per pair (2, ...)"),
    "an infinite bridge force": (put("contacts/extra/bridge_force", 1, np.inf),
                                 "contacts/extra/bridge_force[1] = inf is not finite"),
    # particles, walls and clock
    "one radius fewer": (replace("particles/radius", np.full(2, 1e-3)),
                         "particles/radius has shape (2,); valid: (3,)"),
    "a negative radius": (put("particles/radius", 2, -1e-3),
                          "particles/radius[2] = -0.001 is outside the valid range (0, inf)"),
    "a wall at infinity": (put("walls/position", 1, np.inf), "walls/position[1] = inf is not "
                                                             "finite"),
    "dt NaN": (attribute("dt", np.nan), "dt = nan is outside the valid range (0, inf) s"),
    # the operations' state
    "garbage state": (_garbage, "the saved state of its operations (dataset 'state') cannot be "
                                "restored: UnpicklingError"),
    "truncated state": (_truncated_state, "cannot be restored: UnpicklingError"),
    "a state of another shape": (edit_state(lambda tree: [1, 2]),
                                 "the saved state of its operations holds list"),
    "an operation's state missing": (edit_state(_drop_last_force),
                                     "the saved state of its forces holds 2 entries; this "
                                     "simulation has 3 forces"),
    "an attribute of another type": (
        edit_state(lambda tree: tree["forces"][2].update(generator=17)),
        "the saved forces[2] CachingOperation.generator cannot be restored: it is of type int, "
        "not Generator"),
    "an array of another dtype": (
        edit_state(lambda tree: tree["controls"][0].update(previous=np.zeros(4, np.int64))),
        "the saved controls[0] StressServo.previous cannot be restored: it is an array of int64"),
    "a method named as state": (edit_state(lambda tree: tree["forces"][2].update(apply=None)),
                                "forces[2] CachingOperation names 'apply', a method"),
}


def servoed_scene(operation):
    """The scene of scene_with_bridges (not run), with a stress servo among its controls."""
    sim = two_body_scene(np.zeros((1, 3)), np.zeros((1, 3)), extra=[operation])
    sim.controls.append(StressServo("xyz", 1.0, 1.0))
    return sim


@pytest.mark.parametrize("name", sorted(FORGED))
def test_a_forged_checkpoint_is_refused_naming_the_file_and_the_fault(name, tmp_path):
    saved = scene_with_bridges(CachingOperation())
    saved.controls.append(StressServo("xyz", 1.0, 1.0))
    saved.run(1)
    assert (len(saved.particles), len(saved.contacts)) == (3, 2)
    path = str(tmp_path / "checkpoint.h5")
    save_checkpoint(path, saved)
    change, words = FORGED[name]
    forge(path, change)
    fresh = servoed_scene(CachingOperation())
    position = fresh.particles.position.copy()
    with pytest.raises(ValueError) as error:
        load_checkpoint(path, fresh)
    message = str(error.value)
    assert message.startswith(f"checkpoint {path!r}: ") and "\n" not in message
    assert words in message, message
    # refused before anything changed
    assert fresh.step == 0 and fresh.contacts is None
    assert np.array_equal(fresh.particles.position, position)
    assert fresh.forces[2].kicks == [] and fresh.forces[2].generator is not None


def test_the_unforged_checkpoint_of_the_forgery_tests_loads(tmp_path):
    saved = scene_with_bridges(CachingOperation())
    saved.controls.append(StressServo("xyz", 1.0, 1.0))
    saved.run(1)
    path = str(tmp_path / "checkpoint.h5")
    save_checkpoint(path, saved)
    forge(path, edit_state(lambda tree: None))         # re-pickled as it was
    fresh = servoed_scene(CachingOperation())
    load_checkpoint(path, fresh)
    assert fresh.step == saved.step and len(fresh.contacts) == 2
    assert np.array_equal(fresh.controls[0].previous, saved.controls[0].previous)


@pytest.fixture(scope="module")
def interrupted_run(tmp_path_factory):
    """An interrupted triaxial run of 60 spheres with a checkpoint, made in-process."""
    from pendular.cli import INTERRUPTED, run_command

    out = tmp_path_factory.mktemp("interrupted") / "run"
    status = run_command("triaxial", ["--particles", "60", "--max-strain", "0.005",
                                      "--inertial-number", "2e-3", "--vtk-frames", "0", "--quiet",
                                      "--checkpoint-every", "50", "--stop-after", "120",
                                      "--out", str(out)], prog="triaxial.py")
    assert status == INTERRUPTED
    return out


@pytest.mark.parametrize("change, words", [
    (put("contacts/pair_j", 3, 10 ** 6), "contacts/pair_j[3] = 1000000 is outside the valid "
                                         "range [0, 60)"),
    (_garbage, "the saved state of its operations (dataset 'state') cannot be restored: "
               "UnpicklingError")], ids=["pair index past the particles", "garbage state"])
def test_triaxial_resume_of_a_forged_checkpoint_is_one_error_line(interrupted_run, tmp_path,
                                                                   capsys, change, words):
    from pendular.cli import run_command

    run = tmp_path / "run"
    shutil.copytree(interrupted_run, run)
    forge(str(run / "checkpoint.h5"), change)
    capsys.readouterr()
    with pytest.raises(SystemExit) as stop:
        run_command("triaxial", ["--resume", str(run), "--quiet"], prog="triaxial.py")
    err = capsys.readouterr().err
    assert stop.value.code == 2 and "Traceback" not in err
    (line,) = err.splitlines()
    assert line.startswith(f"triaxial.py: error: checkpoint {str(run / 'checkpoint.h5')!r}: ")
    assert words in line, line
