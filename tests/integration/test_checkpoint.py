"""Checkpoints (pendular.dem.checkpoint): bit-identical resume, atomic writes under kill -9, checks,
the operations' declared state (state_dict / load_state, stateless) and per-pair fields, and
forged checkpoints (valid checksum, invalid content) refused with one ValueError."""

import copy
import os
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from conftest import two_body_scene
from pendular.capillary.bridges import SuctionBridges, VolumeBridges
from pendular.dem.cell import ConstantShearRate
from pendular.dem.checkpoint import (FORMAT, CheckpointWriter, _read_state, _write_state,
    load_checkpoint, save_checkpoint)
from pendular.dem.contact_law import ContactForces
from pendular.dem.integrate import Integrator
from pendular.dem.neighbors import NeighborList
from pendular.dem.protocols import PairField, Stateful, pair_arrays
from pendular.dem.record import HistoryRecorder
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.walls import ConstantStrainRate, StressServo, WallForces
from pendular.io.vtk import VtkWriter
from pendular.procedures.config import ShearConfig
from pendular.procedures.guards import AxialStressGuard
from pendular.procedures.guards import SampleGuard
from pendular.procedures.loading import MixedStress, Stage, Strain
from pendular.procedures.preparation import PrepareConfig, prepare_sample
from pendular.procedures.triaxial import TriaxialShear
from pendular.utils.integrity import stamp, verify

HERE = os.path.dirname(os.path.abspath(__file__))


@pytest.fixture(scope="module")
def prepared():
    config = PrepareConfig(particles=60, unload_steps=200, confining=750.0)
    sim, _ = prepare_sample(config, progress=False)
    return config, sim


@pytest.fixture(scope="module")
def prepared_rolling():
    """A sample with rolling and twisting resistance: their springs are per-pair state."""
    config = PrepareConfig(particles=60, unload_steps=200, confining=750.0,
                           rolling_friction=0.2, twisting_friction=0.1)
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


@pytest.mark.parametrize("sample", ["prepared", "prepared_rolling"])
def test_resumed_shear_is_bit_identical_to_an_uninterrupted_one(sample, request, tmp_path):
    prepared = request.getfixturevalue(sample)
    path = tmp_path / "checkpoint.h5"
    whole, whole_history = sheared(prepared, path)
    steps = 40 * whole_history.period
    whole.run(steps)

    first, _ = sheared(prepared, path)
    first.run(steps // 2)
    save_checkpoint(path, first, extra_state={"phase": "shear"})

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
    for key, array in whole.contacts.extra.items():            # the rolling springs
        assert np.array_equal(resumed.contacts.extra[key], array), key
    if sample == "prepared_rolling":
        assert any(key.startswith("rolling.") for key in whole.contacts.extra)
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


class Kicks:
    """A force that keeps state of each kind a checkpoint stores: a step count, an optional
    value, a list, a dict of arrays and, per pair, an int64 count and a float32 vector
    (declared PairFields)."""

    pair_owner = "kicks"
    pair_state = (PairField("touches", np.int64, "1", "steps in contact"),
                  PairField("push", np.float32, "N", "last push", (3,)))

    def __init__(self):
        self.calls = 0
        self.last_gap = None
        self.labels = []
        self.history = {"step": np.zeros(0, np.int64), "gap": np.zeros((0, 2))}

    def apply(self, sim):
        c = sim.contacts
        fields = pair_arrays(c, self.pair_owner, self.pair_state)
        fields["touches"][c.overlap > 0.0] += 1
        fields["push"][:] = (1e-6 * c.overlap[:, None]).astype(np.float32)
        sim.particles.force[:, 1] += 1e-9 * self.calls      # the state acts on the motion
        self.calls += 1
        self.last_gap = float(-c.overlap.max())
        self.labels.append(f"step {sim.step}")
        self.history = {"step": np.append(self.history["step"], sim.step),
                        "gap": np.vstack([self.history["gap"], [[self.last_gap, self.calls]]])}

    def state_dict(self):
        return {"calls": self.calls, "last_gap": self.last_gap, "labels": list(self.labels),
                "history": {k: v.copy() for k, v in self.history.items()}}

    def load_state(self, state):
        if state["calls"] < 0:
            raise ValueError(f"calls = {state['calls']} is outside the valid range [0, inf)")
        self.calls, self.last_gap = state["calls"], state["last_gap"]
        self.labels = list(state["labels"])
        self.history = {k: np.array(v) for k, v in state["history"].items()}


class Nudge:
    """A new operation type without state: declares it."""

    stateless = True

    def apply(self, sim):
        sim.particles.force[:, 2] += 1e-9


class Undeclared:
    """An operation that says nothing of its state."""

    def apply(self, sim):
        pass


def kicked_scene(run=0):
    """Three spheres, two pairs, with Kicks and Nudge among the forces and a stress servo."""
    sim = two_body_scene([[0, 0, 0], [1.9e-3, 0, 0], [0, 1.9e-3, 0]], np.zeros((3, 3)),
                         extra=[Kicks(), Nudge()])
    sim.controls.append(StressServo("xyz", 1.0, 1.0))
    sim.run(run)
    return sim


def test_a_new_operation_keeps_its_state_and_per_pair_fields_through_a_checkpoint(tmp_path):
    saved = kicked_scene(3)
    path = tmp_path / "c.h5"
    save_checkpoint(path, saved)
    with h5py.File(path, "r") as handle:        # per-pair fields described by their PairField
        assert handle["contacts/extra/kicks.push"].attrs["units"] == "N"
        assert handle["contacts/extra/kicks.push"].dtype == np.float32
        assert "state" not in handle["operations/forces/3"]         # Nudge: stateless
        assert handle["operations/forces/3"].attrs["type"].endswith("Nudge")
    loaded = kicked_scene()
    load_checkpoint(path, loaded)
    assert len(loaded.particles) == 3 and loaded.step == 3
    for name, values in saved.contacts.extra.items():
        assert loaded.contacts.extra[name].dtype == values.dtype
        assert loaded.contacts.extra[name].shape == values.shape
        assert np.array_equal(loaded.contacts.extra[name], values)
    op = loaded.forces[2]
    assert (op.calls, op.last_gap, op.labels) == (3, saved.forces[2].last_gap,
                                                  ["step 0", "step 1", "step 2"])
    assert op.history["step"].dtype == np.int64
    saved.run(5)
    loaded.run(5)
    assert np.array_equal(loaded.particles.position, saved.particles.position)
    for name in ("touches", "push"):
        assert np.array_equal(loaded.contacts.extra[f"kicks.{name}"],
                              saved.contacts.extra[f"kicks.{name}"])
    assert op.labels == saved.forces[2].labels
    for key in ("step", "gap"):
        assert np.array_equal(op.history[key], saved.forces[2].history[key])


def test_an_operation_that_declares_no_state_is_refused_naming_it(tmp_path):
    sim = two_body_scene([[0, 0, 0], [1.9e-3, 0, 0]], np.zeros((2, 3)), extra=[Undeclared()])
    sim.run(1)
    path = tmp_path / "c.h5"
    with pytest.raises(TypeError, match=r"cannot checkpoint forces\[2\] Undeclared: it "
                                        "declares neither state_dict"):
        save_checkpoint(path, sim)
    assert not path.exists()
    sim.forces[2] = Nudge()
    sim.contacts.extra["someone.thing"] = np.zeros(len(sim.contacts))
    with pytest.raises(TypeError, match=r"contacts.extra\['someone.thing'\]: no operation"):
        save_checkpoint(path, sim)


def test_the_state_of_every_operation_survives_a_round_trip(tmp_path):
    """Each operation's state_dict, taken back by a freshly built one of the same type
    (load_state) and through the checkpoint's HDF5 form, is the same state again."""
    run = kicked_scene(4)
    x_servo, y_servo = StressServo("x", 750.0, 1.0), StressServo("y", 750.0, 1.0)
    b_stage = Stage(stress={"x": 750.0}, strain_rate={"z": 1.0}, b=0.4, until=Strain(0.1))
    p_stage = Stage(stress={"x": 750.0}, strain_rate={"z": 1.0}, mean_stress=900.0,
                    until=Strain(0.1))
    recorder = HistoryRecorder(2, {"step": lambda s: s.step,
                                   "sigma": lambda s: s.walls.stress()}, origin=1)
    vtk = VtkWriter(tmp_path / "vtk", 2)
    writer = CheckpointWriter(tmp_path / "c.h5", 7)
    suction, volume = SuctionBridges(2000.0, persist=True), VolumeBridges(1500.0)
    pairs = []

    def changed(op, fresh, change):
        change(op)
        pairs.append((op, fresh))

    changed(run.neighbors, NeighborList(1.0), lambda op: None)
    changed(ContactForces(1e6, 0.3, 0.0), ContactForces(1e6), lambda op: setattr(
        op, "friction_deg", 25.0))
    changed(run.controls[0], StressServo("z", 1.0, 2.0), lambda op: None)
    changed(ConstantStrainRate("x", 2.0, 0.01), ConstantStrainRate("z", 1.0, 0.02),
            lambda op: None)
    changed(ConstantShearRate(-3.0), ConstantShearRate(1.0), lambda op: None)
    changed(MixedStress(b_stage, {0: x_servo, 1: y_servo}),
            MixedStress(p_stage, {0: x_servo, 1: y_servo}), lambda op: None)
    for _ in range(5):
        run.advance()
        recorder.apply(run)
    changed(recorder, HistoryRecorder(2, recorder.quantities), lambda op: None)
    changed(vtk, VtkWriter(tmp_path / "vtk2", 2), lambda op: op.apply(run))
    changed(writer, CheckpointWriter(tmp_path / "d.h5", 1), lambda op: op.write(run))

    def wetted(op):
        op.required_range, op._bridges, op._applied_suction = 1e-4, 3, 2500.0

    changed(suction, SuctionBridges(2000.0, persist=True), wetted)

    def closed(op):
        op.required_range, op._bridges = 2e-4, 5
        op._set_liquid("shared")
        op.liquid_initial, op.liquid_lost, op.film = 1e-9, 1e-11, np.linspace(0, 1e-12, 3)

    changed(volume, VolumeBridges(1500.0), closed)
    assert isinstance(run.integrator, Integrator)
    for op, fresh in pairs:
        state = op.state_dict()
        assert isinstance(op, Stateful) and fresh.state_dict().keys() == state.keys()
        fresh.load_state(state)
        assert_same_state(fresh.state_dict(), state)
        with h5py.File(tmp_path / "state.h5", "w") as handle:
            _write_state(handle.create_group("state"), state, type(op).__name__)
        with h5py.File(tmp_path / "state.h5", "r") as handle:
            assert_same_state(_read_state(handle["state"]), state)
    assert pairs[2][1].walls == run.controls[0].walls and pairs[3][1].axis == 0
    assert volume.liquid == "shared" and pairs[-1][1].shares
    assert len(recorder) == 3 and len(pairs[6][1]) == 3
    for stateless in (WallForces(1e6), Integrator(), Nudge(), SampleGuard(10),
                      AxialStressGuard(str, "")):
        assert stateless.stateless and not hasattr(stateless, "state_dict")


def assert_same_state(got, expected):
    """The same keys, and values of the same types and contents (arrays: dtype too)."""
    assert got.keys() == expected.keys()
    for key, value in expected.items():
        assert type(got[key]) is type(value), (key, got[key], value)
        if isinstance(value, dict):
            assert_same_state(got[key], value)
        elif isinstance(value, np.ndarray):
            assert got[key].dtype == value.dtype and np.array_equal(got[key], value), key
        else:
            assert got[key] == value, key


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


@pytest.mark.parametrize("version", [1, 3])
def test_a_checkpoint_of_an_older_format_is_refused_naming_its_version(tmp_path, version):
    """Version 1 (an operations list, before the declared pipeline) and 3 (the operations'
    attributes pickled) cannot be resumed."""
    path = tmp_path / "c.h5"
    scene = [[0, 0, 0], [1.9e-3, 0, 0]], np.zeros((2, 3))
    sim = two_body_scene(*scene)
    sim.run(2)
    save_checkpoint(path, sim)
    with h5py.File(path, "r+") as handle:
        handle.attrs["version"] = version
        stamp(handle, {"kind": "checkpoint", "format": FORMAT, "version": version})
    fresh = two_body_scene(*scene)
    with pytest.raises(ValueError, match=f"checkpoint version {version}; this code reads "
                                         "version 4 only .*3 with the operations' attributes "
                                         "pickled"):
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
    particles = Particles(np.full((count, 3), 0.5), np.full(count, 0.1), 1000.0)
    return Simulation(particles, Walls.box([0, 0, 0], [1, 1, 1]), 1.0,
                      neighbors=NeighborList(1.0), controls=[StressServo("xyz", 1.0, 1.0)],
                      integrator=Integrator(0.0))


#: The faces of the unit box of bulky_scene.
BOX_FACES = np.array([0.0, 1.0, 0.0, 1.0, 0.0, 1.0])


def checkpoint_forever(path):
    """Run in a subprocess: write checkpoints of a changing state until killed."""
    sim = bulky_scene()
    while True:
        sim.step += 1
        sim.time = 0.5 * sim.step
        for array in (sim.particles.velocity, sim.controls[0].previous):
            array[:] = sim.step
        sim.particles.position[:] = sim.step + 0.5      # the box moves with its spheres
        sim.walls.position[:] = sim.step + BOX_FACES
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
    assert step == sim.step >= 1 and sim.time == 0.5 * step
    for array in (sim.particles.velocity, sim.controls[0].previous):
        assert np.all(array == step)
    assert np.all(sim.particles.position == step + 0.5)
    assert np.array_equal(sim.walls.position, step + BOX_FACES)


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
    del sim.contacts.extra["someone.thing"]         # declared by no operation: refused
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
            assert units["operations/controls/0/state/previous"] == "see description"
    load_sample(tmp_path / "sample.h5")
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


def operation_state(kind, index, key, value=None, remove=False):
    """A change of one value of an operation's saved state (an attribute or a dataset of
    operations/<kind>/<index>/state)."""
    def change(handle):
        group = handle[f"operations/{kind}/{index}/state"]
        for holder in (group.attrs, group):
            if key in holder:
                del holder[key]
        if not remove:
            if isinstance(value, np.ndarray):
                group[key] = value
            else:
                group.attrs[key] = value
    return change


def _drop_last_force(handle):
    del handle["operations/forces/3"]


def _stateless_with_a_state(handle):
    handle["operations/forces/1"].create_group("state").attrs["young"] = 1e6


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
    "a per-pair field of another length": (replace("contacts/extra/kicks.touches",
                                                   np.ones(5, np.int64)),
                                           "contacts/extra/kicks.touches has shape (5,); "
                                           "valid: (2,)"),
    "a per-pair field of another dtype": (replace("contacts/extra/kicks.push",
                                                  np.zeros((2, 3))),
                                          "contacts/extra/kicks.push holds float64; valid: "
                                          "float32"),
    "a per-pair vector of another shape": (replace("contacts/extra/kicks.push",
                                                   np.zeros((2, 2), np.float32)),
                                           "contacts/extra/kicks.push has shape (2, 2); "
                                           "valid: (2, 3)"),
    "an infinite per-pair value": (put("contacts/extra/kicks.push", (1, 0), np.inf),
                                   "contacts/extra/kicks.push[1, 0] = inf is not finite"),
    "an undeclared per-pair field": (lambda handle: handle.create_dataset(
        "contacts/extra/someone.thing", data=np.zeros(2)),
                                     "contacts/extra/someone.thing is not a per-pair field of "
                                     "an operation of this simulation"),
    "one of an owner's per-pair fields missing": (
        lambda handle: handle.__delitem__("contacts/extra/kicks.push"),
        "contacts/extra/kicks.push is missing (the other per-pair fields of 'kicks' are "
        "there)"),
    # particles, walls and clock
    "one radius fewer": (replace("particles/radius", np.full(2, 1e-3)),
                         "particles/radius has shape (2,); valid: (3,)"),
    "a negative radius": (put("particles/radius", 2, -1e-3),
                          "particles/radius[2] = -0.001 is outside the valid range (0, inf)"),
    "a wall at infinity": (put("walls/position", 1, np.inf), "walls/position[1] = inf is not "
                                                             "finite"),
    "walls swapped on their axes": (
        lambda handle: replace("walls/position", handle["walls/position"][()][[1, 0, 3, 2, 5, 4]])(
            handle),
        "on the x axis the high face lies at or below the low face"),
    "a sphere wider than the box": (put("particles/radius", 0, 1.0),
                                    "particles/radius[0] = 1 m: a sphere of that diameter does "
                                    "not fit in the box"),
    "a centre outside the walls": (put("particles/position", (1, 0), 10.0),
                                   "lies outside the walls"),
    "dt NaN": (attribute("dt", np.nan), "dt = nan is outside the valid range (0, inf) s"),
    "extra_state not JSON": (attribute("extra_state", "{not json"),
                             "its extra_state attribute is not JSON"),
    # the operations' state
    "an operation missing": (_drop_last_force, "does not match this simulation's forces: "
                                               "saved ['pendular.dem.contact_law.ContactForces'"),
    "a state key missing": (operation_state("controls", 0, "calls", remove=True),
                            "the saved state of controls[0] StressServo is refused: calls is "
                            "missing"),
    "a state key too many": (operation_state("controls", 0, "scratch", 1.0),
                             "the saved state of controls[0] StressServo is refused: scratch "
                             "is not a key of its state"),
    "a nested key missing": (lambda handle: handle.__delitem__(
        "operations/forces/2/state/history/gap"),
        "the saved state of forces[2] Kicks is refused: history/gap is missing"),
    "a value of another kind": (operation_state("controls", 0, "calls", "many"),
                                "controls[0] StressServo is refused: calls = 'many' is a str; "
                                "valid: a number"),
    "an array of another dtype": (operation_state("controls", 0, "previous",
                                                  np.zeros(6, np.int64)),
                                  "controls[0] StressServo is refused: previous holds int64; "
                                  "valid: an array of float64"),
    "an array of another shape": (operation_state("controls", 0, "previous", np.zeros(4)),
                                  "controls[0] StressServo is refused: previous has shape "
                                  "(4,); valid: (6,)"),
    "a value out of its range": (operation_state("controls", 0, "target", -1.0),
                                 "controls[0] StressServo is refused: target = -1.0 Pa is "
                                 "outside the valid range [0, inf] Pa"),
    "a reference array of another length": (
        operation_state("neighbors", 0, "reference_radius", np.ones(2)),
        "neighbors[0] NeighborList is refused: reference_radius has 2 entries; valid: one "
        "per reference position (3)"),
    "a state refused by the operation": (operation_state("forces", 2, "calls", -4),
                                         "forces[2] Kicks is refused: calls = -4 is outside"),
    "a state where none is declared": (_stateless_with_a_state,
                                       "the saved forces[1] WallForces has a state; this "
                                       "simulation's declares none"),
}


@pytest.mark.parametrize("name", sorted(FORGED))
def test_a_forged_checkpoint_is_refused_naming_the_file_and_the_fault(name, tmp_path):
    saved = kicked_scene(1)
    assert (len(saved.particles), len(saved.contacts)) == (3, 2)
    path = str(tmp_path / "checkpoint.h5")
    save_checkpoint(path, saved)
    change, words = FORGED[name]
    forge(path, change)
    fresh = kicked_scene()
    position = fresh.particles.position.copy()
    with pytest.raises(ValueError) as error:
        load_checkpoint(path, fresh)
    message = str(error.value)
    assert message.startswith(f"checkpoint {path!r}") and "\n" not in message
    assert words in message, message
    # refused before anything changed (operations loaded before the fault: taken back)
    assert fresh.step == 0 and fresh.contacts is None
    assert np.array_equal(fresh.particles.position, position)
    assert fresh.neighbors.state_dict()["reference_position"] is None
    assert fresh.neighbors.rebuilds == 0 and fresh.forces[2].calls == 0
    assert fresh.forces[2].labels == [] and not fresh.controls[0].previous.any()


def test_the_unforged_checkpoint_of_the_forgery_tests_loads(tmp_path):
    saved = kicked_scene(1)
    path = str(tmp_path / "checkpoint.h5")
    save_checkpoint(path, saved)
    forge(path, lambda handle: None)                # stamped again as it was
    fresh = kicked_scene()
    load_checkpoint(path, fresh)
    assert fresh.step == saved.step and len(fresh.contacts) == 2
    assert np.array_equal(fresh.controls[0].previous, saved.controls[0].previous)
    assert fresh.forces[2].calls == 1 and fresh.neighbors.rebuilds == 1


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
    (operation_state("controls", 0, "target", -750.0),
     "the saved state of controls[0] StressServo is refused: target = -750.0 Pa is outside")],
    ids=["pair index past the particles", "a servo's negative target"])
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
