"""Checkpoints (pendular.dem.checkpoint): bit-identical resume, atomic writes under kill -9, checks."""

import copy
import os
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from conftest import two_body_scene
from pendular.dem.checkpoint import FORMAT, CheckpointWriter, load_checkpoint, save_checkpoint
from pendular.dem.integrity import stamp
from pendular.dem.neighbors import NeighborList
from pendular.dem.preparation import PrepareConfig, prepare_sample
from pendular.dem.integrate import Integrator
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.walls import StressServo
from pendular.config import ShearConfig
from pendular.triaxial import TriaxialShear

TESTS = os.path.dirname(os.path.abspath(__file__))


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
    assert skipped == {"writers[0] HistoryRecorder": ["quantities"]}    # closures: rebuilt

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
    fresh = two_body_scene([[0, 0, 0], [1.9e-3, 0, 0]], np.zeros((2, 3)))
    fresh.writers.append(CheckpointWriter(path, period=4))
    assert load_checkpoint(path, fresh) == 80
    assert fresh.step == 8 and fresh.writers[0].written == 2
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
    code = (f"import sys; sys.path.insert(0, {TESTS!r}); import test_checkpoint; "
            f"test_checkpoint.checkpoint_forever({path!r})")
    child = subprocess.Popen([sys.executable, "-c", code])
    temporary = str(tmp_path / f".checkpoint.h5.tmp{child.pid}")   # pendular.dem.atomic.replacing
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
