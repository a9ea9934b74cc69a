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
stamped, so the content is checked before use as well: arrays of the right dtype, shape and
finiteness, pair indices within the particles and consistent with their CSR indices (a bad
index would crash a compiled kernel), per-pair fields as declared, and each operation's state
with the keys of its own ``state_dict``, values of the same kinds (arrays of the same dtype),
accepted by its ``load_state``; anything else is refused with one ValueError naming the file
(and the operation and key), before anything of the simulation changes.
The file is written under a temporary name, flushed to disk (fsync) and renamed over the
previous checkpoint, so a run killed at any moment (kill -9 included) leaves the previous
checkpoint intact.
"""

import dataclasses
import json
import math
import numbers
import os

import h5py
import numpy as np

from pendular.utils.atomic import replacing
from pendular.utils.integrity import software_version, stamp, verify
from pendular.dem.neighbors import Contacts, second_index
from pendular.dem.protocols import pair_key
from pendular.utils.validate import check_int, reading
from pendular.dem.virial import SUM_BLOCKS, face_block_starts

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


#: Per-pair arrays of Contacts: name -> (dtype, trailing shape); each holds one row per pair.
_PAIR_ARRAYS = {
    "pair_i": (np.int64, ()), "pair_j": (np.int64, ()), "second_pair": (np.int64, ()),
    "shear_force": (np.float64, (3,)), "normal": (np.float64, (3,)),
    "overlap": (np.float64, ()), "normal_force": (np.float64, ()),
    "force": (np.float64, (3,)), "image": (np.int8, (3,))}

#: Index arrays of Contacts that are not per pair: name -> expected length (None: any), from
#: the particle count.
_INDEX_ARRAYS = {"row_start": lambda count: count + 1, "second_start": lambda count: count + 1,
                 "through_face": lambda count: None, "face_start": lambda count: SUM_BLOCKS + 1,
                 "near_wall": lambda count: None}


def _first(mask):
    """Index (a tuple, one entry per axis) of the first True of ``mask``."""
    return tuple(int(i) for i in np.argwhere(mask)[0])


def _check_array(source, name, value, dtype, shape, finite=True):
    """ValueError unless ``value`` is an array of ``dtype`` and ``shape`` (None: any length on
    that axis), its floating-point entries finite if ``finite``."""
    if not isinstance(value, np.ndarray):
        raise ValueError(f"{source}: {name} is a {type(value).__name__}, not an array of "
                         f"{np.dtype(dtype)}")
    if value.dtype != np.dtype(dtype):
        raise ValueError(f"{source}: {name} holds {value.dtype}; valid: {np.dtype(dtype)}")
    if value.ndim != len(shape) or any(want is not None and got != want
                                       for got, want in zip(value.shape, shape)):
        wanted = "(" + ", ".join("any" if n is None else str(n) for n in shape) + \
            ("," if len(shape) == 1 else "") + ")"
        raise ValueError(f"{source}: {name} has shape {value.shape}; valid: {wanted}")
    if finite and value.dtype.kind == "f" and not np.isfinite(value).all():
        index = _first(~np.isfinite(value))
        raise ValueError(f"{source}: {name}{list(index)} = {value[index]} is not finite")


def _check_owned(source, owner, arrays, scalars, current, count, per_particle):
    """The arrays and scalars of ``owner`` (particles, walls) against those of the ``current``
    object: the same array names, each of the same dtype and trailing shape and finite, with
    one row per particle (``count``) if ``per_particle``, else as many rows as the current one
    or one per particle (a periodic cell's wraps); each scalar of the current one's kind."""
    expected = {name for name, value in vars(current).items() if isinstance(value, np.ndarray)}
    odd = sorted(expected ^ set(arrays))
    if odd:
        where = "is missing" if odd[0] in expected else f"is not an array of {owner}"
        raise ValueError(f"{source}: {owner}/{odd[0]} {where}")
    for name, value in arrays.items():
        fresh = getattr(current, name)
        if fresh.ndim == 0:
            shape = ()
        elif per_particle:
            shape = (count,) + fresh.shape[1:]
        else:
            rows = count if np.shape(value)[:1] == (count,) else fresh.shape[0]
            shape = (rows,) + fresh.shape[1:]
        _check_array(source, f"{owner}/{name}", value, fresh.dtype, shape)
    for name, value in scalars.items():
        reason = _unfit(getattr(current, name, None), value)
        if reason is None and isinstance(value, numbers.Real) and not math.isfinite(value):
            reason = "not finite"
        if reason is not None:
            raise ValueError(f"{source}: {owner} attribute {name} = {value!r}: {reason}")


def _check_clock(source, step, time, dt):
    """(step, time [s], dt [s]) of a checkpoint as int, float, float; ValueError unless the
    step is an integer >= 0, the time finite >= 0 and dt finite > 0."""
    def real(value):
        return isinstance(value, numbers.Real) and math.isfinite(value)

    for name, value, good, valid in (
            ("step", step, isinstance(step, numbers.Integral) and step >= 0, "an integer >= 0"),
            ("time", time, real(time) and time >= 0.0, "[0, inf) s"),
            ("dt", dt, real(dt) and dt > 0.0, "(0, inf) s")):
        if not good:
            shown = value.item() if isinstance(value, np.generic) else value
            raise ValueError(f"{source}: {name} = {shown!r} is outside the valid range {valid}")
    return int(step), float(time), float(dt)


def _check_particles(source, arrays, scalars, particles):
    """The particle count of a checkpoint after checking its particle arrays; ValueError."""
    position = arrays.get("position")
    if not isinstance(position, np.ndarray) or position.ndim != 2 or len(position) == 0:
        raise ValueError(f"{source}: particles/position is not an array (N, 3) of at least one "
                         "sphere")
    count = len(position)
    _check_owned(source, "particles", arrays, scalars, particles, count, True)
    for name in ("radius", "mass", "inertia"):
        if name in arrays and not (arrays[name] > 0.0).all():
            index = _first(~(arrays[name] > 0.0))
            raise ValueError(f"{source}: particles/{name}{list(index)} = {arrays[name][index]} "
                             "is outside the valid range (0, inf)")
    density = scalars.get("density")
    if density is not None and not density > 0.0:
        raise ValueError(f"{source}: particles density = {density} is outside the valid range "
                         "(0, inf) kg/m^3")
    return count


def _check_box(source, particle_arrays, wall_arrays, walls):
    """ValueError unless the box of a checkpoint is one (each high face above its low face)
    that holds its spheres: none wider than the box's narrowest side and, inside walls (not a
    periodic cell), every centre between the faces."""
    position = wall_arrays["position"]
    width = position[1::2] - position[0::2]
    if (width <= 0).any():
        axis = "xyz"[int(np.argmin(width))]
        raise ValueError(f"{source}: walls/position = {position.tolist()} m: on the {axis} axis "
                         "the high face lies at or below the low face (valid: high > low on "
                         "every axis)")
    radius = particle_arrays["radius"]
    widest = int(np.argmax(radius))
    if 2.0 * radius[widest] >= width.min():
        raise ValueError(f"{source}: particles/radius[{widest}] = {radius[widest]:g} m: a "
                         f"sphere of that diameter does not fit in the box, whose narrowest "
                         f"side is {width.min():g} m (valid: a diameter below it)")
    if not walls.periodic:
        centre = particle_arrays["position"]
        outside = ((centre < position[0::2]) | (centre > position[1::2])).any(axis=1)
        if outside.any():
            k = int(np.flatnonzero(outside)[0])
            raise ValueError(f"{source}: particles/position[{k}] = {centre[k].tolist()} m lies "
                             f"outside the walls {position.tolist()} m (valid: every centre "
                             "between its walls)")


def _check_contacts(source, arrays, extra, count, fields):
    """ValueError unless the contact arrays of a checkpoint form a valid neighbour list of
    ``count`` particles (pendular.dem.neighbors.Contacts): dtypes and shapes, finite per-pair
    state, 0 <= i < j < count, CSR indices that match the pairs, and per-pair ``extra``
    arrays of the fields declared (``fields``, _check_pair_fields)."""
    unknown = sorted(set(arrays) - set(_PAIR_ARRAYS) - set(_INDEX_ARRAYS))
    if unknown:
        raise ValueError(f"{source}: contacts/{unknown[0]} is not an array of "
                         "pendular.dem.neighbors.Contacts")
    missing = sorted(item.name for item in dataclasses.fields(Contacts)
                     if item.default is dataclasses.MISSING
                     and item.default_factory is dataclasses.MISSING and item.name not in arrays)
    if missing:
        raise ValueError(f"{source}: contacts/{missing[0]} is missing")
    pair_i = arrays["pair_i"]
    _check_array(source, "contacts/pair_i", pair_i, np.int64, (None,))
    pairs = len(pair_i)
    for name, (dtype, tail) in _PAIR_ARRAYS.items():
        if name in arrays:          # overlap: -inf for a pair never touched, checked below
            _check_array(source, f"contacts/{name}", arrays[name], dtype, (pairs,) + tail,
                         finite=name != "overlap")
    for name, length in _INDEX_ARRAYS.items():
        if name in arrays:
            _check_array(source, f"contacts/{name}", arrays[name], np.int64, (length(count),))
    pair_j = arrays["pair_j"]
    for name, values in (("pair_i", pair_i), ("pair_j", pair_j)):
        outside = (values < 0) | (values >= count)
        if outside.any():
            (k,) = _first(outside)
            raise ValueError(f"{source}: contacts/{name}[{k}] = {values[k]} is outside the valid "
                             f"range [0, {count}) of the checkpoint's {count} particles")
    if (pair_i >= pair_j).any():
        (k,) = _first(pair_i >= pair_j)
        raise ValueError(f"{source}: pair {k} joins particles i = {pair_i[k]}, j = {pair_j[k]}; "
                         f"valid: 0 <= i < j < {count} (each pair stored once, i < j)")
    overlap = arrays["overlap"]
    if (np.isnan(overlap) | (overlap == np.inf)).any():
        (k,) = _first(np.isnan(overlap) | (overlap == np.inf))
        raise ValueError(f"{source}: contacts/overlap[{k}] = {overlap[k]}; valid: a finite "
                         "overlap [m], or -inf for a pair that never touched")
    row_start = arrays["row_start"]
    if row_start[0] != 0 or row_start[-1] != pairs or (np.diff(row_start) < 0).any() or \
            not np.array_equal(pair_i, np.repeat(np.arange(count), np.diff(row_start))):
        raise ValueError(f"{source}: contacts/row_start does not index the pairs by their first "
                         f"particle (CSR over {count} particles and {pairs} pairs)")
    same_row = pair_i[1:] == pair_i[:-1]
    if (pair_j[1:][same_row] <= pair_j[:-1][same_row]).any():
        k = int(np.flatnonzero(same_row & (pair_j[1:] <= pair_j[:-1]))[0]) + 1
        raise ValueError(f"{source}: pair {k} (i = {pair_i[k]}, j = {pair_j[k]}) is out of "
                         "order: the pairs of a particle are sorted by j, each once")
    second_start, second_pair = second_index(row_start, pair_j, count)
    if not (np.array_equal(arrays["second_start"], second_start)
            and np.array_equal(arrays["second_pair"], second_pair)):
        raise ValueError(f"{source}: contacts/second_start and second_pair do not index the "
                         "pairs by their second particle")
    image = arrays.get("image")
    through_face = (np.zeros(0, np.int64) if image is None
                    else np.flatnonzero(image.any(axis=1)).astype(np.int64))
    if "through_face" in arrays and not np.array_equal(arrays["through_face"], through_face):
        raise ValueError(f"{source}: contacts/through_face is not the list of the pairs whose "
                         "periodic image is not zero")
    if "face_start" in arrays and not np.array_equal(
            arrays["face_start"], face_block_starts(through_face, row_start)):
        raise ValueError(f"{source}: contacts/face_start does not match through_face and "
                         "row_start")
    near_wall = arrays.get("near_wall")
    if near_wall is not None and len(near_wall) and (
            near_wall[0] < 0 or near_wall[-1] >= count or (np.diff(near_wall) <= 0).any()):
        raise ValueError(f"{source}: contacts/near_wall is not an ascending list of particle "
                         f"indices in [0, {count})")
    _check_pair_fields(source, extra, fields, pairs)


def _check_pair_fields(source, extra, fields, pairs):
    """ValueError unless every per-pair array of ``extra`` is a field that the simulation's
    operations declare (``fields``: key -> (owner, PairField)), of its declared dtype and
    shape with one row per pair, finite; each owner's fields all there or none (none: its
    operation had not run yet, ``pair_arrays`` creates them)."""
    for key, values in extra.items():
        if key not in fields:
            raise ValueError(f"{source}: contacts/extra/{key} is not a per-pair field of an "
                             "operation of this simulation (pair_owner, pair_state)")
        field = fields[key][1]
        _check_array(source, f"contacts/extra/{key}", values, field.dtype,
                     (pairs, *field.shape))
    present = {owner for key, (owner, _) in fields.items() if key in extra}
    for key, (owner, _) in fields.items():
        if owner in present and key not in extra:
            raise ValueError(f"{source}: contacts/extra/{key} is missing (the other per-pair "
                             f"fields of {owner!r} are there)")


def _unfit(fresh, value):
    """Why the scalar ``value`` cannot replace a particles' or walls' attribute ``fresh`` (its
    value in the simulation loaded into), or None: a boolean for a boolean, a number for a
    number, else an instance of the same type."""
    if isinstance(fresh, (bool, np.bool_)):
        return None if isinstance(value, (bool, np.bool_)) else f"{value!r}, not a boolean"
    if isinstance(fresh, numbers.Number):
        if isinstance(value, numbers.Number) and not isinstance(value, (bool, np.bool_)):
            return None
        return f"{value!r}, not a number"
    if not isinstance(value, type(fresh)):
        return f"of type {type(value).__name__}, not {type(fresh).__name__}"
    return None


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
    step, time, dt = _check_clock(source, step, time, dt)
    count = _check_particles(source, particle_arrays, particle_scalars, sim.particles)
    _check_owned(source, "walls", wall_arrays, wall_scalars, sim.walls, count, False)
    _check_box(source, particle_arrays, wall_arrays, sim.walls)
    contacts = None
    if has_contacts:
        try:
            fields = _pair_fields(sim)
        except TypeError as error:
            raise ValueError(f"{source}: {error}") from None
        _check_contacts(source, contact_arrays, extra, count, fields)
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
