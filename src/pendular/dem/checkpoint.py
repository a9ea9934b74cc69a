"""Checkpoints: everything a simulation needs to continue bit-identically, written atomically.

A checkpoint is one HDF5 file::

    attrs        format, version, step, time [s], dt [s], has_contacts, extra_state (the
                 caller's, JSON)
    particles/   every array attribute of ``sim.particles`` (position, radius, velocity, ...);
                 scalar attributes (density) as attributes of the group
    walls/       likewise for ``sim.walls`` (a periodic cell's shear offset and strain too)
    contacts/    every per-pair array of ``sim.contacts`` (CSR indices, shear history, forces);
                 contacts/extra/ the per-pair fields that the operations declare
                 (``pair_owner``, ``pair_state``: pendular.dem.protocols.PairField), each
                 described by its declaration (absent if no contacts yet)
    operations/  <kind>/<index>/ for each operation in step order (kind: neighbors, forces,
                 controls, integrator, writers): attribute ``type`` (module.Class) and, for a
                 Stateful operation, its ``state_dict()`` in state/: numbers, strings and None
                 as attributes, arrays and lists as datasets, dicts as groups

Every dataset has ``units`` and ``description`` attributes (DATASETS; an operation's state:
its ``state_dict`` docstring), and the file ``pendular_version`` and ``schema_version``
(VERSION). Nothing is pickled: an operation says what it keeps (pendular.dem.protocols:
``state_dict``/``load_state``, or ``stateless = True``), and one that says neither is refused
when saved, so that nothing is skipped silently.

``load_checkpoint`` restores into a simulation built the same way (same operation types in
the same places, in the same order; what the scene builds, its configuration and functions,
is not saved) and raises ValueError otherwise; a checkpoint of another format version (1:
before the declared pipeline; 2: with per-pair torques; 3: the operations' attributes
pickled) is refused with its version. A checksum only proves a file unchanged since it was
stamped, so the content is checked before use as well (pendular.dem.checkpoint_checks):
arrays of the right dtype, shape and finiteness, pair indices within the particles and
consistent with their CSR indices (a bad index would crash a compiled kernel), per-pair
fields as declared, and each operation's state
with the keys of its own ``state_dict``, values of the same kinds (arrays of the same dtype),
accepted by its ``load_state``; anything else is refused with one ValueError naming the file
(and the operation and key), before anything of the simulation changes.
The file is written under a temporary name, flushed to disk (fsync) and renamed over the
previous checkpoint, so a run killed at any moment (kill -9 included) leaves the previous
checkpoint intact.
"""

import json
import numbers
import os

import h5py
import numpy as np

from pendular.utils.atomic import replacing
from pendular.utils.integrity import software_version, stamp, verify
from pendular.dem.checkpoint_checks import (check_box, check_clock, check_contacts, check_owned,
                                            check_particles)
from pendular.dem.neighbors import Contacts
from pendular.dem.protocols import pair_key
from pendular.utils.validate import check_int, reading

FORMAT = "pendular-checkpoint"
VERSION = 4

#: Units and description of the particle arrays (pendular.dem.state.Particles), as a
#: checkpoint and a sample file (pendular.dem.sample) describe them.
PARTICLE_DATASETS = {
    "position": ("m", "sphere centres (N, 3): x, y, z"),
    "radius": ("m", "sphere radii (N,)"),
    "velocity": ("m/s", "sphere translational velocities (N, 3)"),
    "angular_velocity": ("rad/s", "sphere angular velocities (N, 3)"),
    "force": ("N", "resultant force on each sphere (N, 3)"),
    "torque": ("N m", "resultant torque on each sphere (N, 3)"),
    "mass": ("kg", "sphere masses"), "inertia": ("kg m^2", "sphere moments of inertia")}

#: Units and description of the datasets of a checkpoint, by group (dataset attributes).
DATASETS = {
    "particles": PARTICLE_DATASETS,
    "walls": {
        "position": ("m", "wall plane coordinates (6,), x-, x+, y-, y+, z-, z+"),
        "velocity": ("m/s", "outward wall speeds of the last step (6,)"),
        "force": ("N", "normal force of the particles on each wall, compression positive"),
        "stiffness": ("N/m", "sum of the normal stiffnesses of each wall's contacts"),
        "moment": ("N m", "sum over each wall's contacts of distance * force"),
        "rate": ("1/s", "periodic cell: stretching rate L'/L of each axis, extension positive"),
        "stress_tensor": ("Pa", "periodic cell: Love-Weber stress of the pair forces (3, 3), "
                                "compression positive"),
        "wraps": ("1", "periodic cell: periods crossed by each particle (N, 3)"),
        "virial_blocks": ("N m", "periodic cell: face terms of the pair forces' sum of l f "
                                 "gathered this step (pendular.dem.virial)")},
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
    # written as declared, listed for the outputs reference
    "contacts/extra": {"<owner>.<field>": (
        "declared", "a per-pair field an operation declares (pair_owner, pair_state: a "
                    "pendular.dem.protocols.PairField, whose units and description it has)")},
    "operations": {"<kind>/<index>/state/<key>": (
        "see description", "state_dict()[key] of a Stateful operation, whose docstring gives "
                           "the units; the group <kind>/<index> has the operation's type")},
}
#: The kinds of the simulation's operations, in step order (operations/<kind>).
KINDS = ("neighbors", "forces", "controls", "integrator", "writers")


def _describe(dataset, units, description):
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
        elif isinstance(value, (bool, int, float, str, np.generic)):
            scalars[name] = value
        else:
            raise TypeError(f"cannot checkpoint {owner}.{name} of type {type(value).__name__}: "
                            "only arrays and scalars are supported")
    return arrays, scalars


def _pipeline(sim):
    """Kind -> list of the simulation's operations of that kind, in step order."""
    return dict(zip(KINDS, ([sim.neighbors], sim.forces, sim.controls, [sim.integrator],
                            sim.writers)))


def _operations(sim):
    """(kind, index, 'kind[index] Type', operation) of every operation, in step order."""
    return [(kind, index, f"{kind}[{index}] {type(op).__name__}", op)
            for kind, ops in _pipeline(sim).items() for index, op in enumerate(ops)]


def _stateful(op, owner):
    """Whether ``op`` keeps state (Stateful) rather than none (``stateless``); TypeError for
    an operation that declares neither (pendular.dem.protocols)."""
    if getattr(op, "stateless", False):
        return False
    if callable(getattr(op, "state_dict", None)) and callable(getattr(op, "load_state", None)):
        return True
    raise TypeError(f"cannot checkpoint {owner}: it declares neither state_dict() and "
                    "load_state(state) nor stateless = True (pendular.dem.protocols)")


def _pair_fields(sim):
    """Key in Contacts.extra -> (owner, PairField) of the per-pair fields the forces declare
    (``pair_owner``, ``pair_state``); TypeError for one declared without an owner or twice
    with different declarations."""
    fields = {}
    for op in sim.forces:
        declared = getattr(op, "pair_state", ())
        if not declared:
            continue
        owner = getattr(op, "pair_owner", None)
        if not isinstance(owner, str):
            raise TypeError(f"{type(op).__name__} declares pair_state but no pair_owner (the "
                            "name of its per-pair fields in Contacts.extra)")
        for field in declared:
            key = pair_key(owner, field)
            if fields.setdefault(key, (owner, field)) != (owner, field):
                raise TypeError(f"per-pair field {key} is declared twice, differently")
    return fields


# ---------------------------------------------------------------- the state of an operation
def _value_kind(value):
    """The kind of a state value (pendular.dem.protocols.Stateful.state_dict), None for
    another."""
    if value is None:
        return "none"
    if isinstance(value, (bool, np.bool_)):
        return "bool"
    if isinstance(value, numbers.Real):
        return "number"
    for kind, types in (("str", str), ("array", np.ndarray), ("list", list), ("dict", dict)):
        if isinstance(value, types):
            return kind
    return None


def _storable(kind, value):
    """Whether a state value of ``kind`` is stored as a dataset: an array of numbers or
    booleans, a list of numbers or of strings."""
    if kind == "array":
        return value.dtype.kind in "biuf"
    return kind == "list" and (all(isinstance(v, str) for v in value) or
                               all(_value_kind(v) in ("bool", "number") for v in value))


def _write_state(group, state, where):
    """``state`` (a state_dict) into ``group``; TypeError naming ``where`` and the key for a
    value that is not a plain value (Stateful.state_dict)."""
    for key, value in state.items():
        kind = _value_kind(value)
        if not isinstance(key, str) or not key or "/" in key or key == ".":
            raise TypeError(f"cannot checkpoint {where}: its state key {key!r} is not a name")
        if kind == "none":
            group.attrs[key] = h5py.Empty("f8")
        elif kind in ("bool", "number", "str"):
            group.attrs[key] = value
        elif kind == "dict":
            _write_state(group.create_group(key), value, f"{where}/{key}")
        elif _storable(kind, value):
            strings = kind == "list" and bool(value) and isinstance(value[0], str)
            data = np.array(value, dtype=h5py.string_dtype() if strings else None)
            dataset = group.create_dataset(key, data=data)
            if kind == "list":
                dataset.attrs["list"] = True
            _describe(dataset, "see description",
                      f"state_dict()[{key!r}] of {where}, whose docstring gives the units")
        else:
            raise TypeError(f"cannot checkpoint {where}: its state {key!r} is a "
                            f"{type(value).__name__}; valid: None, bool, int, float, str, "
                            "an array of numbers, a list of numbers or strings, a dict")


def _read_state(group):
    """The state_dict written into ``group`` by _write_state."""
    state = {}
    for key, value in group.attrs.items():
        if isinstance(value, h5py.Empty):
            value = None
        elif isinstance(value, np.generic):
            value = value.item()
        elif isinstance(value, bytes):
            value = value.decode()
        state[key] = value
    for key, item in group.items():
        if isinstance(item, h5py.Group):
            state[key] = _read_state(item)
        elif item.attrs.get("list", False):
            state[key] = [v.decode() if isinstance(v, bytes) else v for v in item[()].tolist()]
        else:
            state[key] = item[()]
    return state


def _state_fault(template, saved, key=""):
    """Why ``saved`` cannot be loaded where the operation's own state_dict holds
    ``template`` (text beginning with the key), or None: a dict with the same keys, values of
    the same kinds (None fits any: an optional value) and arrays of the same dtype."""
    where = key or "its state"
    if isinstance(template, dict) and isinstance(saved, dict):
        inner = {name: f"{key}/{name}" if key else name for name in {*template, *saved}}
        for name in template:
            if name not in saved:
                return f"{inner[name]} is missing"
        for name in saved:
            if name not in template:
                return f"{inner[name]} is not a key of its state"
        for name in template:
            fault = _state_fault(template[name], saved[name], inner[name])
            if fault is not None:
                return fault
        return None
    wanted, found = _value_kind(template), _value_kind(saved)
    if found is None:
        return f"{where} holds a {type(saved).__name__}"
    if "none" in (wanted, found):
        return None
    if wanted != found:
        return f"{where} = {_shown(saved)} is a {found}; valid: a {wanted}"
    if wanted == "array" and saved.dtype != template.dtype:
        return f"{where} holds {saved.dtype}; valid: an array of {template.dtype}"
    return None


def _shown(value):
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _write_group(handle, name, arrays, scalars=None):
    """Group ``name`` with a dataset per array, described by DATASETS[name] ("unknown" units
    for an array it does not declare), and the ``scalars`` as group attributes."""
    group = handle.create_group(name)
    for key, value in arrays.items():
        units, description = DATASETS[name].get(key, (
            "unknown", f"{name}/{key}: an array of the simulation's state not declared in "
                       "pendular.dem.checkpoint.DATASETS"))
        _describe(group.create_dataset(key, data=value), units, description)
    for key, value in (scalars or {}).items():
        group.attrs[key] = value
    return group


def save_checkpoint(path, sim, extra_state=None, identity=None):
    """Write the complete state of ``sim`` to ``path`` atomically (module docstring).

    ``extra_state``: what the caller needs to resume besides the simulation (e.g. the
    scenario's phase), a JSON value (numbers, strings, lists, dicts, None), returned by
    ``load_checkpoint``; ``identity``: what made the run (dict, e.g. its configuration hash
    and seed), stamped with a content checksum (pendular.utils.integrity) and checked by
    ``load_checkpoint``. TypeError, the previous checkpoint left as it was, for an operation
    that declares no state (pendular.dem.protocols), a state or an extra_state that is not
    plain values, or a per-pair array that no operation declares.
    """
    path = os.fspath(path)
    sim.fetch()                     # a device run's state back on the host first
    contacts = sim.contacts
    particle_arrays, particle_scalars = _owned_arrays(sim.particles, "particles")
    wall_arrays, wall_scalars = _owned_arrays(sim.walls, "walls")
    states = [(kind, index, op, op.state_dict() if _stateful(op, owner) else None)
              for kind, index, owner, op in _operations(sim)]
    try:
        extra_json = json.dumps(extra_state)
    except TypeError as error:
        raise TypeError(f"cannot checkpoint extra_state: {error} (valid: a JSON value)") \
            from None
    fields = _pair_fields(sim)
    if contacts is not None:
        arrays = {k: v for k, v in vars(contacts).items() if k != "extra"}
        for key, value in arrays.items():
            if not isinstance(value, np.ndarray):
                raise TypeError(f"cannot checkpoint contacts.{key} of type "
                                f"{type(value).__name__}: only arrays are supported")
        for key in contacts.extra:
            if key not in fields:
                raise TypeError(f"cannot checkpoint contacts.extra[{key!r}]: no operation of "
                                "this simulation declares it (pair_owner, pair_state; "
                                "pendular.dem.protocols)")

    with replacing(path, durable=True) as temporary, h5py.File(temporary, "w") as handle:
        handle.attrs.update({
            "format": FORMAT, "version": VERSION, "step": int(sim.step),
            "time": float(sim.time), "dt": float(sim.dt), "has_contacts": contacts is not None,
            "extra_state": extra_json})
        _write_group(handle, "particles", particle_arrays, particle_scalars)
        _write_group(handle, "walls", wall_arrays, wall_scalars)
        if contacts is not None:
            group = _write_group(handle, "contacts", arrays)
            extra = group.create_group("extra")
            for key, value in contacts.extra.items():
                owner, field = fields[key]
                _describe(extra.create_dataset(key, data=value), field.unit,
                          f"{field.description} (per pair: {owner}'s {field.name})")
        operations = handle.create_group("operations")
        for kind in KINDS:
            operations.create_group(kind)
        for kind, index, op, state in states:
            group = operations[kind].create_group(str(index))
            group.attrs["type"] = _type_name(op)
            if state is not None:
                _write_state(group.create_group("state"), state, _type_name(op))
        handle.attrs["pendular_version"] = software_version()
        handle.attrs["schema_version"] = VERSION
        stamp(handle, {"kind": "checkpoint", "format": FORMAT, "version": VERSION,
                       **(identity or {})})


def _read_group(group):
    return {key: group[key][()] for key in group if isinstance(group[key], h5py.Dataset)}


def _read_operations(source, handle, sim):
    """Kind -> the saved state of each of the checkpoint's operations of that kind (None:
    stateless), after checking that their types are those of ``sim``'s pipeline, in the
    same order."""
    operations = handle.get("operations")
    if not isinstance(operations, h5py.Group):
        raise ValueError(f"{source}: its operations group is missing")
    saved = {}
    for kind, ops in _pipeline(sim).items():
        group = operations.get(kind)
        names = sorted(group, key=lambda n: (len(n), n)) if isinstance(group, h5py.Group) \
            else None
        if names != [str(i) for i in range(len(names or ()))]:
            raise ValueError(f"{source}: operations/{kind} is not a group of operations "
                             "numbered 0, 1, ...")
        entries = []
        for name in names:
            item = group[name]
            state = item.get("state")
            entries.append((item.attrs.get("type"),
                            _read_state(state) if isinstance(state, h5py.Group) else None))
        found, current = [name for name, _ in entries], [_type_name(op) for op in ops]
        if found != current:
            raise ValueError(
                f"{source} does not match this simulation's {kind}: saved {found}, this "
                f"simulation has {current}; build the simulation the way the checkpointed one "
                "was built")
        saved[kind] = [state for _, state in entries]
    return saved


def _load_operations(source, sim, saved):
    """Every operation's saved state into ``sim``'s operations: checked against its own
    state_dict (_state_fault), then ``load_state``; ValueError naming the operation and the
    key, the operations already loaded taken back to their own state first, so that a
    refused checkpoint changes nothing."""
    loaded = []
    for kind, index, owner, op in _operations(sim):
        state = saved[kind][index]
        try:
            own = op.state_dict() if _stateful(op, owner) else None
            if (own is None) != (state is None):
                raise ValueError(f"the saved {owner} " + (
                    "has a state; this simulation's declares none" if own is None
                    else "has no state; this simulation's declares one"))
            if own is not None:
                fault = _state_fault(own, state)
                if fault is not None:
                    raise ValueError(f"the saved state of {owner} is refused: {fault}")
                try:
                    op.load_state(state)
                except ValueError as error:
                    raise ValueError(f"the saved state of {owner} is refused: {error}") \
                        from None
                loaded.append((op, own))
        except (TypeError, ValueError) as error:
            for earlier, earlier_state in reversed(loaded):
                earlier.load_state(earlier_state)
            raise ValueError(f"{source}: {error}") from None


def load_checkpoint(path, sim, expected_identity=None):
    """Restore the state saved by ``save_checkpoint`` into ``sim``; return its ``extra_state``.

    The file's checksum is verified first, and its identity against ``expected_identity``
    (ValueError naming the path: edited or damaged, another run's, or older than checksums).
    ``sim`` must have neighbour list, forces, controls, integrator and writers of the same
    types in the same order, and the content must be valid (module docstring): ValueError
    naming the file and what is wrong otherwise, before anything is changed. Particles,
    walls, contacts (with the declared per-pair fields), step, time, dt and the state of
    every Stateful operation (``load_state``) are replaced; what the scene built (its
    operations' configuration) stays.
    """
    path = os.fspath(path)
    verify(path, expected_identity, kind="checkpoint")
    source = f"checkpoint {path!r}"
    with reading(path, "pendular checkpoint"), h5py.File(path, "r") as handle:
        if handle.attrs.get("format") != FORMAT:
            raise ValueError(f"{path!r} is not a pendular checkpoint")
        if int(handle.attrs["version"]) != VERSION:
            raise ValueError(f"{path!r} has checkpoint version {handle.attrs['version']}; "
                             f"this code reads version {VERSION} only (version 1 was written "
                             "before the declared pipeline, 2 with per-pair torques, 3 with "
                             "the operations' attributes pickled): restart the run from its "
                             "sample")
        operations = _read_operations(source, handle, sim)
        particle_arrays = _read_group(handle["particles"])
        particle_scalars = dict(handle["particles"].attrs)
        wall_arrays = _read_group(handle["walls"])
        wall_scalars = dict(handle["walls"].attrs)
        has_contacts = bool(handle.attrs["has_contacts"])
        if has_contacts:
            contact_arrays = _read_group(handle["contacts"])
            extra = _read_group(handle["contacts/extra"])
        step, time, dt = (handle.attrs[name] for name in ("step", "time", "dt"))
        extra_json = handle.attrs.get("extra_state")

    try:
        extra_state = json.loads(extra_json)
    except (TypeError, json.JSONDecodeError) as error:
        raise ValueError(f"{source}: its extra_state attribute is not JSON ({error})") from None
    step, time, dt = check_clock(source, step, time, dt)
    count = check_particles(source, particle_arrays, particle_scalars, sim.particles)
    check_owned(source, "walls", wall_arrays, wall_scalars, sim.walls, count, False)
    check_box(source, particle_arrays, wall_arrays, sim.walls)
    contacts = None
    if has_contacts:
        try:
            fields = _pair_fields(sim)
        except TypeError as error:
            raise ValueError(f"{source}: {error}") from None
        check_contacts(source, contact_arrays, extra, count, fields)
        contacts = Contacts(**contact_arrays, extra=extra)
    _load_operations(source, sim, operations)

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
    return extra_state


def checkpoint_extra_state(path, expected_identity=None):
    """The ``extra_state`` of the checkpoint ``path``, its checksum (and identity) verified
    first, without a simulation to load it into (a run that reads its configuration from
    it); ValueError naming the path otherwise."""
    path = os.fspath(path)
    verify(path, expected_identity, kind="checkpoint")
    with reading(path, "pendular checkpoint"), h5py.File(path, "r") as handle:
        if handle.attrs.get("format") != FORMAT:
            raise ValueError(f"{path!r} is not a pendular checkpoint")
        extra_json = handle.attrs.get("extra_state")
    try:
        return json.loads(extra_json)
    except (TypeError, json.JSONDecodeError) as error:
        raise ValueError(f"checkpoint {path!r}: its extra_state attribute is not JSON "
                         f"({error})") from None


class CheckpointWriter:
    """Writer saving a checkpoint to ``path`` every ``period`` steps (``sim.step % period == 0``).

    Append it after the other writers, so that the checkpoint holds the record of its own step.
    ``extra_state``: None, a JSON value, or a function of sim returning one; ``identity``:
    see ``save_checkpoint``. Only the count of checkpoints written is its state: the resumed
    run's own path, period, extra_state and identity hold (a run folder copied and resumed
    writes its checkpoints into itself, not into the folder it was copied from).
    """

    def __init__(self, path, period, extra_state=None, identity=None):
        self.path = os.fspath(path)
        self.period = check_int("checkpoint period", period, low=1)
        self.extra_state = extra_state
        self.identity = identity
        self.written = 0

    def state_dict(self):
        """``written``: the checkpoints written so far."""
        return {"written": self.written}

    def load_state(self, state):
        self.written = check_int("written", state["written"])

    def apply(self, sim):
        if sim.step % self.period == 0:
            self.write(sim)

    def write(self, sim):
        """Save a checkpoint of the current state now."""
        extra = self.extra_state(sim) if callable(self.extra_state) else self.extra_state
        self.written += 1
        save_checkpoint(self.path, sim, extra, self.identity)
