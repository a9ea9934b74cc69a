"""Checkpoints: everything a simulation needs to continue bit-identically, written atomically.

A checkpoint is one HDF5 file:

    attrs        format, version, step, time [s], dt [s], pipeline (the types of the neighbour
                 list, forces, controls, integrator and writers, JSON), skipped (per operation,
                 the attributes not saved, JSON)
    particles/   every array attribute of ``sim.particles`` (position, radius, velocity, ...);
                 scalar attributes (density) as attributes of the group
    walls/       likewise for ``sim.walls``
    contacts/    every per-pair array of ``sim.contacts`` (CSR indices, shear history, forces);
                 contacts/extra/ the arrays of ``Contacts.extra`` (absent if no contacts yet)
    state        pickled state of every operation and writer, and the caller's ``extra_state``

Every dataset has ``units`` and ``description`` attributes (DATASETS; an array this module does
not know, e.g. another operation's ``Contacts.extra`` entry, gets units "unknown" and a
description naming it), and the file ``pendular_version`` and ``schema_version`` (VERSION).

The state of an operation is its ``vars(op)``: arrays, scalars and any picklable value
(``StressServo.previous``, the NeighborList's reference positions and rebuild count,
``HistoryRecorder.rows``, a writer's list of frames ...). Values that cannot be pickled
(functions such as the recorder's quantities) are configuration that the scene rebuilds: they
are skipped, listed in the ``skipped`` attribute, and the freshly built operation keeps its own.
An operation may name attributes not worth saving in a class attribute ``checkpoint_exclude``.
References to the simulation's own objects (the simulation, particles, walls, contacts, their
arrays, ``contacts.extra``, other operations) are saved as references and point, after loading,
to the loaded simulation's objects, so an operation that caches ``sim.contacts`` stays in sync.

``load_checkpoint`` restores into a simulation built the same way (same operation types in
the same places, in the same order; the scene's closures are not saved) and raises ValueError
otherwise; a checkpoint of another format version (1: before the declared pipeline; 2:
with per-pair torques, which the contact law no longer stores) is refused with its version.
The file is written under a temporary name, flushed to disk (fsync) and renamed over the
previous checkpoint, so a run killed at any moment (kill -9 included) leaves the previous
checkpoint intact. Checkpoints hold pickles: load only files you trust.
"""

import io
import json
import os
import pickle

import h5py
import numpy as np

from .atomic import replacing
from .integrity import software_version, stamp, verify
from .neighbors import Contacts
from .validate import check_int, reading

FORMAT = "pendular-checkpoint"
VERSION = 3
_SCALARS = (bool, int, float, str, np.generic)

#: Units and description of the datasets of a checkpoint, by group (dataset attributes).
DATASETS = {
    "particles": {
        "position": ("m", "sphere centres (N, 3)"), "radius": ("m", "sphere radii"),
        "velocity": ("m/s", "translational velocities (N, 3)"),
        "angular_velocity": ("rad/s", "angular velocities (N, 3)"),
        "force": ("N", "resultant force on each sphere (N, 3)"),
        "torque": ("N m", "resultant torque on each sphere (N, 3)"),
        "mass": ("kg", "sphere masses"), "inertia": ("kg m^2", "sphere moments of inertia")},
    "walls": {
        "position": ("m", "wall plane coordinates (6,), x-, x+, y-, y+, z-, z+"),
        "velocity": ("m/s", "outward wall speeds of the last step (6,)"),
        "force": ("N", "normal force of the particles on each wall, compression positive"),
        "stiffness": ("N/m", "sum of the normal stiffnesses of each wall's contacts"),
        "moment": ("N m", "sum over each wall's contacts of distance * force"),
        "rate": ("1/s", "periodic cell: stretching rate L'/L of each axis, extension positive"),
        "stress_tensor": ("Pa", "periodic cell: Love-Weber stress of the pair forces (3, 3), "
                                "compression positive"),
        "wraps": ("1", "periodic cell: periods crossed by each particle (N, 3)")},
    "contacts": {
        "pair_i": ("1", "first particle of each candidate pair (K,), i < j"),
        "pair_j": ("1", "second particle of each candidate pair (K,)"),
        "row_start": ("1", "CSR row starts of the pairs by first particle"),
        "second_start": ("1", "CSR row starts of the pairs by second particle"),
        "second_pair": ("1", "pair indices ordered by second particle"),
        "shear_force": ("N", "elastic tangential force on j from i (K, 3), spring history"),
        "normal": ("1", "unit normal i -> j at the last force evaluation (K, 3)"),
        "overlap": ("m", "r_i + r_j - |x_j - x_i| (negative: gap)"),
        "normal_force": ("N", "magnitude of the spring normal force (0 when apart)"),
        "force": ("N", "total contact force on j from i (K, 3)"),
        "image": ("1", "periodic image of j seen from i (K, 3): branch x_j - x_i + image * L"),
        "through_face": ("1", "the pairs whose image is not zero (through a periodic face)"),
        "face_start": ("1", "where each block of particles' share of through_face starts "
                            "(pendular.dem.virial.face_block_starts)"),
        "near_wall": ("1", "the particles within the skin of a wall at the last rebuild "
                           "(the wall forces visit only these; absent: every particle)")},
    "": {"state": ("1", "pickled state of every operation and writer and the caller's "
                        "extra_state (bytes; see pendular.dem.checkpoint)")},
}


def _describe(dataset, group, name):
    """Set the ``units`` and ``description`` attributes of a dataset (DATASETS), "unknown"
    units for a name not declared there."""
    units, description = DATASETS.get(group, {}).get(
        name, ("unknown", f"{group}/{name}: an array of the simulation's state not declared "
                          "in pendular.dem.checkpoint.DATASETS (e.g. another operation's per-pair "
                          "Contacts.extra entry); see pendular.dem.checkpoint"))
    dataset.attrs["units"] = units
    dataset.attrs["description"] = description


def _type_name(obj):
    kind = type(obj)
    return f"{kind.__module__}.{kind.__qualname__}"


def _owned_arrays(obj, owner):
    """(arrays, scalars): the attributes of ``obj`` by kind; TypeError for any other value."""
    arrays, scalars = {}, {}
    for name, value in vars(obj).items():
        if isinstance(value, np.ndarray):
            arrays[name] = value
        elif isinstance(value, _SCALARS):
            scalars[name] = value
        else:
            raise TypeError(f"cannot checkpoint {owner}.{name} of type {type(value).__name__}: "
                            "only arrays and scalars are supported")
    return arrays, scalars


def _pipeline(sim):
    """Kind -> list of the simulation's operations of that kind, in step order."""
    return {"neighbors": [sim.neighbors], "forces": sim.forces, "controls": sim.controls,
            "integrator": [sim.integrator], "writers": sim.writers}


def _references(sim, particle_arrays, wall_arrays, contacts):
    """Path -> object of the simulation's own objects, saved by reference in the state pickle."""
    references = {("sim",): sim, ("particles",): sim.particles, ("walls",): sim.walls,
                  ("contacts",): contacts}
    for kind, ops in _pipeline(sim).items():
        for index, op in enumerate(ops):
            references[(kind, index)] = op
    for kind in ("forces", "controls", "writers"):
        references[(kind,)] = getattr(sim, kind)
    for owner, arrays in (("particles", particle_arrays), ("walls", wall_arrays)):
        for name, value in arrays.items():
            references[(owner, name)] = value
    if contacts is not None:
        references[("contacts", "extra")] = contacts.extra
        for name, value in vars(contacts).items():
            if isinstance(value, np.ndarray):
                references[("contacts", name)] = value
        for name, value in contacts.extra.items():
            references[("extra", name)] = value
    return references


class _Pickler(pickle.Pickler):
    def __init__(self, handle, references):
        super().__init__(handle, protocol=5)
        self._paths = {id(obj): path for path, obj in references.items() if obj is not None}

    def persistent_id(self, obj):
        return self._paths.get(id(obj))


class _Unpickler(pickle.Unpickler):
    def __init__(self, handle, references):
        super().__init__(handle)
        self._references = references

    def persistent_load(self, path):
        try:
            return self._references[tuple(path)]
        except KeyError:
            raise ValueError(f"checkpoint refers to {path}, absent from this simulation") from None


class _Discard:
    def write(self, data):
        return len(data)


def _operation_state(op, references):
    """(picklable attributes of ``op``, names skipped)."""
    exclude = set(getattr(op, "checkpoint_exclude", ()))
    state, skipped = {}, []
    for name, value in vars(op).items():
        if name in exclude:
            skipped.append(name)
            continue
        try:
            _Pickler(_Discard(), references).dump(value)
        except Exception:      # functions, lambdas, open files: configuration, rebuilt by the scene
            skipped.append(name)
            continue
        state[name] = value
    return state, skipped


def _write_group(handle, name, arrays, scalars=None, kind=None):
    """Group ``name`` with a described dataset per array (``kind``: its DATASETS key, default
    ``name``) and the ``scalars`` as group attributes."""
    group = handle.create_group(name)
    for key, value in arrays.items():
        _describe(group.create_dataset(key, data=value), name if kind is None else kind, key)
    for key, value in (scalars or {}).items():
        group.attrs[key] = value
    return group


def save_checkpoint(path, sim, extra_state=None, identity=None):
    """Write the complete state of ``sim`` to ``path`` atomically (module docstring).

    ``extra_state``: any picklable value (e.g. the scenario's phase), returned by
    ``load_checkpoint``; ``identity``: what made the run (dict, e.g. its configuration hash and
    seed), stamped with a content checksum (pendular.dem.integrity) and checked by ``load_checkpoint``.
    Returns the names of the operation attributes not saved ({"forces[i] Type": [names]}).
    """
    path = os.fspath(path)
    contacts = sim.contacts
    particle_arrays, particle_scalars = _owned_arrays(sim.particles, "particles")
    wall_arrays, wall_scalars = _owned_arrays(sim.walls, "walls")
    references = _references(sim, particle_arrays, wall_arrays, contacts)
    skipped = {}
    tree = {"extra_state": extra_state}
    pipeline = _pipeline(sim)
    for kind, ops in pipeline.items():
        tree[kind] = []
        for index, op in enumerate(ops):
            state, names = _operation_state(op, references)
            tree[kind].append(state)
            if names:
                skipped[f"{kind}[{index}] {type(op).__name__}"] = names
    buffer = io.BytesIO()
    _Pickler(buffer, references).dump(tree)
    blob = np.frombuffer(buffer.getbuffer(), np.uint8)

    with replacing(path, durable=True) as temporary, h5py.File(temporary, "w") as handle:
        handle.attrs.update({
            "format": FORMAT, "version": VERSION, "step": int(sim.step),
            "time": float(sim.time), "dt": float(sim.dt),
            "pipeline": json.dumps({kind: [_type_name(op) for op in ops]
                                    for kind, ops in pipeline.items()}),
            "skipped": json.dumps(skipped), "has_contacts": contacts is not None})
        _write_group(handle, "particles", particle_arrays, particle_scalars)
        _write_group(handle, "walls", wall_arrays, wall_scalars)
        if contacts is not None:
            arrays = {k: v for k, v in vars(contacts).items() if k != "extra"}
            for key, value in arrays.items():
                if not isinstance(value, np.ndarray):
                    raise TypeError(f"cannot checkpoint contacts.{key} of type "
                                    f"{type(value).__name__}: only arrays are supported")
            group = _write_group(handle, "contacts", arrays)
            for key, value in contacts.extra.items():
                if not isinstance(value, np.ndarray):
                    raise TypeError(f"cannot checkpoint contacts.extra[{key!r}] of type "
                                    f"{type(value).__name__}: only arrays are supported")
            _write_group(group, "extra", contacts.extra, kind="contacts/extra")
        _describe(handle.create_dataset("state", data=blob), "", "state")
        handle.attrs["pendular_version"] = software_version()
        handle.attrs["schema_version"] = VERSION
        stamp(handle, {"kind": "checkpoint", "format": FORMAT, "version": VERSION,
                       **(identity or {})})
    return skipped


def _read_group(group):
    return {key: group[key][()] for key in group if isinstance(group[key], h5py.Dataset)}


def _check_types(handle, sim):
    saved_pipeline = json.loads(handle.attrs["pipeline"])
    for kind, ops in _pipeline(sim).items():
        saved = saved_pipeline.get(kind)
        current = [_type_name(op) for op in ops]
        if saved != current:
            raise ValueError(
                f"checkpoint {handle.filename!r} does not match this simulation's {kind}: "
                f"saved {saved}, this simulation has {current}; build the simulation the way "
                "the checkpointed one was built")


def load_checkpoint(path, sim, expected_identity=None):
    """Restore the state saved by ``save_checkpoint`` into ``sim``; return its ``extra_state``.

    The file's checksum is verified first, and its identity against ``expected_identity``
    (ValueError naming the path: edited or damaged, another run's, or older than checksums).
    ``sim`` must have neighbour list, forces, controls, integrator and writers of the same
    types in the same order (ValueError otherwise, before anything is changed). Particles,
    walls, contacts, step, time, dt and the saved attributes of every operation and writer are
    replaced; attributes skipped at saving keep the values of ``sim``'s own operations.
    """
    path = os.fspath(path)
    verify(path, expected_identity, kind="checkpoint")
    with reading(path, "pendular checkpoint"), h5py.File(path, "r") as handle:
        if handle.attrs.get("format") != FORMAT:
            raise ValueError(f"{path!r} is not a pendular checkpoint")
        if int(handle.attrs["version"]) != VERSION:
            raise ValueError(f"{path!r} has checkpoint version {handle.attrs['version']}; "
                             f"this code reads version {VERSION} only (version 1 was written "
                             "before the declared pipeline, 2 with per-pair torques): restart "
                             "the run from its sample")
        _check_types(handle, sim)
        particle_arrays = _read_group(handle["particles"])
        particle_scalars = dict(handle["particles"].attrs)
        wall_arrays = _read_group(handle["walls"])
        wall_scalars = dict(handle["walls"].attrs)
        contacts = None
        if bool(handle.attrs["has_contacts"]):
            extra = _read_group(handle["contacts/extra"])
            try:
                contacts = Contacts(**_read_group(handle["contacts"]), extra=extra)
            except TypeError as error:
                raise ValueError(f"contacts of checkpoint {path!r} do not match "
                                 f"pendular.dem.neighbors.Contacts: {error}") from None
        blob = handle["state"][()].tobytes()
        step = int(handle.attrs["step"])
        time = float(handle.attrs["time"])
        dt = float(handle.attrs["dt"])

    references = _references(sim, particle_arrays, wall_arrays, contacts)
    tree = _Unpickler(io.BytesIO(blob), references).load()

    for obj, arrays, scalars in ((sim.particles, particle_arrays, particle_scalars),
                                 (sim.walls, wall_arrays, wall_scalars)):
        for name, value in arrays.items():
            setattr(obj, name, value)
        for name, value in scalars.items():
            setattr(obj, name, value.item() if isinstance(value, np.generic) else value)
    sim.contacts = contacts
    sim.step = step
    sim.time = time
    sim.dt = dt
    for kind, ops in _pipeline(sim).items():
        for op, state in zip(ops, tree[kind]):
            for name, value in state.items():
                setattr(op, name, value)
    return tree["extra_state"]


class CheckpointWriter:
    """Writer saving a checkpoint to ``path`` every ``period`` steps (``sim.step % period == 0``).

    Append it after the other writers, so that the checkpoint holds the record of its own step.
    ``extra_state``: None, a picklable value, or a function of sim returning one; ``identity``:
    see ``save_checkpoint``.
    """

    def __init__(self, path, period, extra_state=None, identity=None):
        self.path = os.fspath(path)
        self.period = check_int("checkpoint period", period, low=1)
        self.extra_state = extra_state
        self.identity = identity
        self.written = 0

    def apply(self, sim):
        if sim.step % self.period == 0:
            self.write(sim)

    def write(self, sim):
        """Save a checkpoint of the current state now."""
        extra = self.extra_state(sim) if callable(self.extra_state) else self.extra_state
        self.written += 1
        save_checkpoint(self.path, sim, extra, self.identity)
