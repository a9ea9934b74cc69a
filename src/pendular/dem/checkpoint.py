"""Checkpoints: everything a simulation needs to continue bit-identically, written atomically.

A checkpoint is one HDF5 file::

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
are skipped at saving, listed in the ``skipped`` attribute, and the freshly built operation
keeps its own (at loading nothing is skipped: a saved value that cannot be restored is an
error).
An operation may name attributes not worth saving in a class attribute ``checkpoint_exclude``.
References to the simulation's own objects (the simulation, particles, walls, contacts, their
arrays, ``contacts.extra``, other operations) are saved as references and point, after loading,
to the loaded simulation's objects, so an operation that caches ``sim.contacts`` stays in sync.

``load_checkpoint`` restores into a simulation built the same way (same operation types in
the same places, in the same order; the scene's closures are not saved) and raises ValueError
otherwise; a checkpoint of another format version (1: before the declared pipeline; 2:
with per-pair torques, which the contact law no longer stores) is refused with its version.
A checksum only proves a file unchanged since it was stamped, so the content is checked before
use as well: arrays of the right dtype, shape and finiteness, pair indices within the particles
and consistent with their CSR indices (a bad index would crash a compiled kernel), and an
operation state that unpickles, fits the pipeline and holds values of the types the freshly
built operations hold; anything else is refused with one ValueError naming the file.
The file is written under a temporary name, flushed to disk (fsync) and renamed over the
previous checkpoint, so a run killed at any moment (kill -9 included) leaves the previous
checkpoint intact. Checkpoints hold pickles: load only files you trust.
"""

import dataclasses
import io
import json
import math
import numbers
import os
import pickle

import h5py
import numpy as np

from pendular.utils.atomic import replacing
from pendular.utils.integrity import software_version, stamp, verify
from pendular.dem.neighbors import Contacts, second_index
from pendular.utils.validate import check_int, reading
from pendular.dem.virial import SUM_BLOCKS, face_block_starts

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
    seed), stamped with a content checksum (pendular.utils.integrity) and checked by ``load_checkpoint``.
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
    try:
        saved_pipeline = json.loads(handle.attrs["pipeline"])
    except json.JSONDecodeError as error:
        raise ValueError(f"checkpoint {handle.filename!r}: its pipeline attribute is not JSON "
                         f"({error})") from None
    if not isinstance(saved_pipeline, dict):
        raise ValueError(f"checkpoint {handle.filename!r}: its pipeline attribute is not a JSON "
                         "object of the operation types by kind")
    for kind, ops in _pipeline(sim).items():
        saved = saved_pipeline.get(kind)
        current = [_type_name(op) for op in ops]
        if saved != current:
            raise ValueError(
                f"checkpoint {handle.filename!r} does not match this simulation's {kind}: "
                f"saved {saved}, this simulation has {current}; build the simulation the way "
                "the checkpointed one was built")


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


def _check_contacts(source, arrays, extra, count):
    """ValueError unless the contact arrays of a checkpoint form a valid neighbour list of
    ``count`` particles (pendular.dem.neighbors.Contacts): dtypes and shapes, finite per-pair
    state, 0 <= i < j < count, CSR indices that match the pairs, and per-pair ``extra``
    arrays of numbers with one row per pair."""
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
    for name, values in extra.items():
        if not isinstance(values, np.ndarray) or values.dtype.kind not in "biuf" or \
                values.ndim == 0 or len(values) != pairs:
            raise ValueError(f"{source}: contacts/extra/{name} holds {np.asarray(values).dtype} "
                             f"of shape {np.shape(values)}; valid: numbers, one row per pair "
                             f"({pairs}, ...)")
        if values.dtype.kind == "f" and not np.isfinite(values).all():
            index = _first(~np.isfinite(values))
            raise ValueError(f"{source}: contacts/extra/{name}{list(index)} = {values[index]} "
                             "is not finite")


def _unfit(fresh, value):
    """Why ``value`` cannot replace an operation's attribute ``fresh`` (the value its freshly
    built operation holds), or None: an array for an array (same dtype and trailing shape),
    a boolean for a boolean, a number for a number, else an instance of the same type. None on
    either side fits (attributes set when first needed, caches cleared)."""
    if fresh is None or value is None:
        return None
    if isinstance(fresh, np.ndarray):
        if not isinstance(value, np.ndarray):
            return f"of type {type(value).__name__}, not an array"
        if value.dtype != fresh.dtype or value.ndim != fresh.ndim or \
                value.shape[1:] != fresh.shape[1:]:
            return (f"an array of {value.dtype} and shape {value.shape}; this simulation's is "
                    f"{fresh.dtype} of shape {fresh.shape}")
        return None
    if isinstance(fresh, (bool, np.bool_)):
        return None if isinstance(value, (bool, np.bool_)) else f"{value!r}, not a boolean"
    if isinstance(fresh, numbers.Number):
        if isinstance(value, numbers.Number) and not isinstance(value, (bool, np.bool_)):
            return None
        return f"{value!r}, not a number"
    if not isinstance(value, type(fresh)):
        return f"of type {type(value).__name__}, not {type(fresh).__name__}"
    return None


def _operation_states(source, blob, references, sim):
    """The unpickled state tree of a checkpoint after checking that it fits ``sim``'s pipeline:
    a state per operation, each attribute of the type the operation holds (an attribute absent
    from the state, e.g. one added to the operation after the checkpoint was written, keeps
    the operation's own value); ValueError naming the file otherwise. Nothing of ``sim`` is
    changed."""
    try:
        tree = _Unpickler(io.BytesIO(blob), references).load()
    except Exception as error:      # garbage bytes raise any of pickle's many errors
        raise ValueError(f"{source}: the saved state of its operations (dataset 'state') cannot "
                         f"be restored: {type(error).__name__}: {error}") from None
    pipeline = _pipeline(sim)
    if not isinstance(tree, dict) or set(tree) != {"extra_state", *pipeline}:
        found = sorted(map(str, tree)) if isinstance(tree, dict) else type(tree).__name__
        raise ValueError(f"{source}: the saved state of its operations holds {found}; valid: "
                         f"{sorted(['extra_state', *pipeline])}")
    for kind, ops in pipeline.items():
        states = tree[kind]
        if not isinstance(states, list) or len(states) != len(ops):
            found = len(states) if isinstance(states, list) else type(states).__name__
            raise ValueError(f"{source}: the saved state of its {kind} holds {found} entries; "
                             f"this simulation has {len(ops)} {kind}")
        for index, (op, state) in enumerate(zip(ops, states)):
            owner = f"{kind}[{index}] {type(op).__name__}"
            if not isinstance(state, dict) or not all(isinstance(name, str) for name in state):
                raise ValueError(f"{source}: the saved state of {owner} is of type "
                                 f"{type(state).__name__}, not attributes by name")
            current = vars(op)
            exclude = set(getattr(op, "checkpoint_exclude", ()))
            for name, value in state.items():
                if name in exclude:         # kept from the operation, not restored
                    continue
                defined = getattr(type(op), name, None)
                if name not in current and (name.startswith("__") or callable(defined)
                                            or isinstance(defined, property)):
                    raise ValueError(f"{source}: the saved state of {owner} names {name!r}, "
                                     "a method or property of its class, not an attribute")
                reason = _unfit(current.get(name), value)
                if reason is not None:
                    raise ValueError(f"{source}: the saved {owner}.{name} cannot be restored: "
                                     f"it is {reason}")
    return tree


def load_checkpoint(path, sim, expected_identity=None):
    """Restore the state saved by ``save_checkpoint`` into ``sim``; return its ``extra_state``.

    The file's checksum is verified first, and its identity against ``expected_identity``
    (ValueError naming the path: edited or damaged, another run's, or older than checksums).
    ``sim`` must have neighbour list, forces, controls, integrator and writers of the same
    types in the same order, and the content must be valid (module docstring): ValueError
    naming the file and what is wrong otherwise, before anything is changed. Particles,
    walls, contacts, step, time, dt and the saved attributes of every operation and writer are
    replaced; attributes skipped at saving, or excluded (``checkpoint_exclude``), keep the
    values of ``sim``'s own operations.
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
        has_contacts = bool(handle.attrs["has_contacts"])
        if has_contacts:
            contact_arrays = _read_group(handle["contacts"])
            extra = _read_group(handle["contacts/extra"])
        blob = handle["state"][()].tobytes()
        step, time, dt = (handle.attrs[name] for name in ("step", "time", "dt"))

    source = f"checkpoint {path!r}"
    step, time, dt = _check_clock(source, step, time, dt)
    count = _check_particles(source, particle_arrays, particle_scalars, sim.particles)
    _check_owned(source, "walls", wall_arrays, wall_scalars, sim.walls, count, False)
    contacts = None
    if has_contacts:
        _check_contacts(source, contact_arrays, extra, count)
        contacts = Contacts(**contact_arrays, extra=extra)
    references = _references(sim, particle_arrays, wall_arrays, contacts)
    tree = _operation_states(source, blob, references, sim)

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
            exclude = set(getattr(op, "checkpoint_exclude", ()))
            for name, value in state.items():
                if name not in exclude:     # saved by a pendular that did not exclude it
                    setattr(op, name, value)
    return tree["extra_state"]


class CheckpointWriter:
    """Writer saving a checkpoint to ``path`` every ``period`` steps (``sim.step % period == 0``).

    Append it after the other writers, so that the checkpoint holds the record of its own step.
    ``extra_state``: None, a picklable value, or a function of sim returning one; ``identity``:
    see ``save_checkpoint``. Only the count of checkpoints written is restored on resuming:
    the resumed run's own path, period, extra_state and identity hold (a run folder copied and
    resumed writes its checkpoints into itself, not into the folder it was copied from).
    """

    checkpoint_exclude = ("path", "period", "extra_state", "identity")

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
