"""The content checks of a checkpoint (pendular.dem.checkpoint) before it is loaded.

A checksum only proves a file unchanged since it was stamped; these functions check what it
holds: arrays of the right dtype, shape and finiteness, a clock and particles within their
ranges, a box that holds its spheres, pair indices within the particles and consistent with
their CSR indices (a bad index would crash a compiled kernel), and per-pair fields as the
operations declare them. Each raises one ValueError naming the file (``source``) and what is
wrong, and changes nothing.
"""

import dataclasses
import math
import numbers

import numpy as np

from pendular.dem.neighbors import Contacts, second_index
from pendular.dem.virial import SUM_BLOCKS, face_block_starts


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


def check_owned(source, owner, arrays, scalars, current, count, per_particle):
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


def check_clock(source, step, time, dt):
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


def check_particles(source, arrays, scalars, particles):
    """The particle count of a checkpoint after checking its particle arrays; ValueError."""
    position = arrays.get("position")
    if not isinstance(position, np.ndarray) or position.ndim != 2 or len(position) == 0:
        raise ValueError(f"{source}: particles/position is not an array (N, 3) of at least one "
                         "sphere")
    count = len(position)
    check_owned(source, "particles", arrays, scalars, particles, count, True)
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


def check_box(source, particle_arrays, wall_arrays, walls):
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


def check_contacts(source, arrays, extra, count, fields):
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
