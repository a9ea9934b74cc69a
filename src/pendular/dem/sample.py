"""Save and load a prepared sample (positions, radii, walls, velocities) as HDF5.

A sample file is stamped (pendular.utils.integrity: checksum and identity) and every sample that enters
is checked before use (``check_packing``): finite values, every sphere inside the box, overlaps
within what the linear contact law holds, not collapsed to one point; ``check_consistent``
refuses a sample made with another radius, particle count or density than the run asks for.

A sample describes itself: every dataset has ``units`` and ``description`` attributes
(DATASETS), the file the attributes ``pendular_version``, ``schema_version`` (the layout
version, VERSION), ``format``, ``density`` [kg/m^3], ``periodic`` (the box is a periodic
cell, pendular.dem.cell, instead of walls; positions saved wrapped into it), ``report`` and ``config``
(JSON).
"""

import json
import math

import h5py
import numba
import numpy as np

from pendular.utils.atomic import replacing
from pendular.dem.grading import GRADING_UNITS, grading
from pendular.utils.integrity import config_hash, software_version, stamp, verify
from pendular.dem.cell import PeriodicCell
from pendular.dem.checkpoint import PARTICLE_DATASETS
from pendular.dem.state import WALL_NAMES, Particles, Walls
from pendular.utils.validate import reading

FORMAT = "pendular-sample"
VERSION = 2
"""Sample file layout version (1: before checksums)."""

MAX_OVERLAP = 0.2
"""Largest overlap a sample may hold, as a fraction of the smaller radius of the pair (of the
sphere's radius against a wall). The linear springs (kn = 2 E R1 R2 / (R1 + R2), walls E R)
are a small-overlap law; the stress / young limit of pendular.procedures.preparation (0.02) keeps prepared
samples below about 0.16 R at the most loaded contact, so 0.2 R bounds every valid sample and
refuses overlapped, edited or misplaced spheres."""

#: Units and description of each dataset of a sample file (its attributes).
DATASETS = {
    **{name: PARTICLE_DATASETS[name]
       for name in ("position", "radius", "velocity", "angular_velocity")},
    "walls": ("m", "wall plane (or periodic cell face) coordinates along their axis (6,), "
                   "ordered x-, x+, y-, y+, z-, z+ (pendular.dem.state.WALL_NAMES)"),
}

RADIUS_TOLERANCE = 1e-9
"""Relative difference allowed between a sample's mean radius (or density) and the run's."""

_MAX_CELLS_PER_AXIS = 2 ** 20     # cell keys (cx * ny + cy) * nz + cz fit in int64


def save_sample(path, sim, report=None, config=None, identity=None):
    """Write the particles and walls of ``sim`` (and the preparation report/config) atomically,
    each dataset with its ``units`` and ``description`` (DATASETS), the file with
    ``pendular_version`` and ``schema_version``, stamped last with a checksum and an identity:
    kind, format version, software version, hash of ``config``, and the entries of
    ``identity`` (e.g. the seed)."""
    if getattr(sim.walls, "shear_offset", 0.0) != 0.0:
        raise ValueError("a sheared periodic cell cannot be saved as a sample (a sample's "
                         "cell is a box, its images unshifted): save it before the shear")
    with replacing(path) as temporary, h5py.File(temporary, "w") as handle:
        p = sim.particles
        position = p.position
        if sim.walls.periodic:          # a copy: the live list still holds its images
            position = np.mod(position, sim.walls.lengths())
        handle.create_dataset("position", data=position)
        for name in ("radius", "velocity", "angular_velocity"):
            handle.create_dataset(name, data=getattr(p, name))
        handle.create_dataset("walls", data=sim.walls.position)
        handle.attrs["periodic"] = bool(sim.walls.periodic)
        for name, (units, description) in DATASETS.items():
            handle[name].attrs["units"] = units
            handle[name].attrs["description"] = description
        handle.attrs["pendular_version"] = software_version()
        handle.attrs["schema_version"] = VERSION
        handle.attrs["format"] = FORMAT
        handle.attrs["version"] = VERSION
        handle.attrs["density"] = p.density
        handle.attrs["report"] = json.dumps(report or {})
        handle.attrs["grading"] = json.dumps({**grading(p.radius), "units": GRADING_UNITS})
        handle.attrs["config"] = json.dumps(config or {})
        stamp(handle, {"kind": "sample", "format": FORMAT, "version": VERSION,
                       "config_hash": config_hash(config or {}), **(identity or {})})


def _finite(source, name, values):
    bad = ~np.isfinite(values)
    if bad.any():
        index = [int(i) for i in np.argwhere(bad)[0]]
        raise ValueError(f"{source}: {name}{index} = {values[tuple(index)]} is not finite")


def _json_attribute(source, handle, name):
    """The JSON object stored in the file attribute ``name`` (ValueError naming ``source`` and
    the attribute when it is not one)."""
    text = handle.attrs[name]
    try:
        value = json.loads(text.decode() if isinstance(text, bytes) else text)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{source}: attribute {name!r} is not readable JSON ({error}): a "
                         "damaged or foreign file; prepare the sample again") from None
    if not isinstance(value, dict):
        raise ValueError(f"{source}: attribute {name!r} holds a JSON {type(value).__name__}, "
                         "not an object: a damaged or foreign file; prepare the sample again")
    return value


def load_sample(path, expected=None, expected_identity=None):
    """Read a sample written by ``save_sample``: (Particles, Walls or PeriodicCell, report dict,
    config dict).

    The file's checksum and identity are verified first (pendular.utils.integrity.verify with
    ``expected_identity``), then its state (``check_packing``) and, if ``expected`` is given (a
    dict or an object with ``radius`` [m], ``particles``, ``density`` [kg/m^3], e.g. the run's
    PrepareConfig), its consistency with the run (``check_consistent``). ValueError naming the
    path and the reason for a corrupt, edited, foreign, old or physically invalid file.
    """
    verify(path, expected_identity, kind="sample")
    source = f"sample = {str(path)!r}"
    with reading(path, "pendular sample (pendular.dem.sample.save_sample)"), h5py.File(path, "r") as handle:
        arrays = {name: handle[name][()] for name in ("position", "radius", "velocity",
                                                       "angular_velocity", "walls")}
        density = handle.attrs["density"]
        periodic = bool(handle.attrs.get("periodic", False))
        report = _json_attribute(source, handle, "report")
        config = _json_attribute(source, handle, "config")
    for name, values in arrays.items():
        if not np.issubdtype(np.asarray(values).dtype, np.number):
            raise ValueError(f"{source}: {name} holds {np.asarray(values).dtype}, not numbers")
        _finite(source, name, np.asarray(values, dtype=np.float64))
    try:
        particles = Particles(arrays["position"], arrays["radius"], float(density),
                              velocity=arrays["velocity"],
                              angular_velocity=arrays["angular_velocity"])
        box = PeriodicCell if periodic else Walls
        walls = box(position=np.asarray(arrays["walls"], dtype=np.float64))
    except (ValueError, TypeError) as error:
        raise ValueError(f"{source}: {error}") from None
    check_packing(particles, walls, source)
    if expected is not None:
        check_consistent(sample_parameters(particles), expected, source)
        asked = _get(expected, "periodic")
        if asked is not None and bool(asked) != periodic:
            kinds = {True: "a periodic cell", False: "six walls"}
            raise ValueError(f"{source} is a sample in {kinds[periodic]}; the run asks for "
                             f"{kinds[bool(asked)]} (periodic = {bool(asked)}): prepare a "
                             f"sample with periodic = {bool(asked)}")
    return particles, walls, report, config


# ---------------------------------------------------------------- physical checks
def sample_parameters(particles):
    """What a sample was made with, read from its spheres: {"radius": mean radius [m],
    "radius_min", "radius_max" [m], "particles": count, "density": [kg/m^3]} (preparation
    rescales the spheres to the configured mean radius)."""
    return {"radius": float(np.mean(particles.radius)),
            "radius_min": float(np.min(particles.radius)),
            "radius_max": float(np.max(particles.radius)), "particles": len(particles),
            "density": float(particles.density)}


def _get(data, name):
    if isinstance(data, dict):
        return data.get(name)
    return getattr(data, name, None)


def check_consistent(sample_config, requested, source="sample"):
    """ValueError naming the parameter when the sample (``sample_config``: dict or object with
    ``radius`` [m], ``particles``, ``density`` [kg/m^3], e.g. ``sample_parameters(particles)``)
    was made with another particle count, mean radius or density (relative difference above
    RADIUS_TOLERANCE) than the run asks for (``requested``: dict or object, e.g. its
    PrepareConfig). Parameters absent from either side are not compared."""
    made, asked = _get(sample_config, "particles"), _get(requested, "particles")
    if made is not None and asked is not None and int(made) != int(asked):
        raise ValueError(f"{source} has {int(made)} particles; the run asks for particles = "
                         f"{int(asked)}: use a sample made with particles = {int(asked)}, or "
                         f"particles = {int(made)}")
    for name, unit in (("radius", "m"), ("density", "kg/m^3")):
        made, asked = _get(sample_config, name), _get(requested, name)
        if made is None or asked is None:
            continue
        made, asked = float(made), float(asked)
        difference = abs(made - asked) / max(abs(asked), abs(made), 1e-300)
        if not difference <= RADIUS_TOLERANCE:
            what = "mean radius" if name == "radius" else name
            raise ValueError(
                f"{source} was made with {what} {made!r} {unit}; the run asks for {name} = "
                f"{asked!r} {unit} (relative difference {difference:.3g}, allowed "
                f"{RADIUS_TOLERANCE:g}): use {name} = {made!r} or prepare a sample with "
                f"{name} = {asked!r}")
    sizes = getattr(requested, "radii", None)          # a PrepareConfig's size distribution
    low, high = _get(sample_config, "radius_min"), _get(sample_config, "radius_max")
    if callable(sizes) and low is not None and high is not None:
        radii = sizes()
        for made, asked in ((low, radii.min()), (high, radii.max())):
            if not abs(made - asked) <= RADIUS_TOLERANCE * max(abs(made), abs(asked)):
                raise ValueError(
                    f"{source} has radii from {low:.6g} to {high:.6g} m; the run's sizes "
                    f"(radius_spread = {getattr(requested, 'radius_spread', 0.0):g}, psd = "
                    f"{'given' if getattr(requested, 'psd', None) else 'none'}) give "
                    f"{radii.min():.6g} to {radii.max():.6g} m: use the radius_spread or psd "
                    "the sample was made with, or prepare a new sample")


def _wall_overlaps(position, radius, walls):
    """(6, N) overlap of each sphere with each wall, as a fraction of its radius (> 1: the
    centre is outside the box)."""
    lo, hi = walls.position[0::2], walls.position[1::2]
    inside = np.empty((6, len(radius)))
    inside[0::2] = (position - lo).T
    inside[1::2] = (hi - position).T
    return (radius - inside) / radius


@numba.njit(cache=True)
def _worst_overlap(position, radius, cells, order, sorted_keys, dims):
    """(worst overlap / smaller radius, i, j) over all pairs, by a cell list (cells of edge at
    least twice the largest radius: touching spheres are in the same or adjacent cells)."""
    worst = -np.inf
    worst_i = -1
    worst_j = -1
    for i in range(position.shape[0]):
        for dx in range(-1, 2):
            cx = cells[i, 0] + dx
            if cx < 0 or cx >= dims[0]:
                continue
            for dy in range(-1, 2):
                cy = cells[i, 1] + dy
                if cy < 0 or cy >= dims[1]:
                    continue
                for dz in range(-1, 2):
                    cz = cells[i, 2] + dz
                    if cz < 0 or cz >= dims[2]:
                        continue
                    key = (cx * dims[1] + cy) * dims[2] + cz
                    start = np.searchsorted(sorted_keys, key, side="left")
                    end = np.searchsorted(sorted_keys, key, side="right")
                    for k in range(start, end):
                        j = order[k]
                        if j <= i:
                            continue
                        d = 0.0
                        for a in range(3):
                            d += (position[j, a] - position[i, a]) ** 2
                        ratio = (radius[i] + radius[j] - math.sqrt(d)) / min(radius[i], radius[j])
                        if ratio > worst:
                            worst = ratio
                            worst_i = i
                            worst_j = j
    return worst, worst_i, worst_j


def _cell_list(position, radius):
    """(cells (N, 3) int64, order, sorted keys, dims (3,), cell edge [m]) of a cubic cell grid
    over the centres, cell edge >= 2 max radius."""
    low = position.min(axis=0)
    extent = float(np.max(position.max(axis=0) - low))
    cell = max(2.0 * float(radius.max()), extent / (_MAX_CELLS_PER_AXIS - 1))
    cells = np.floor((position - low) / cell).astype(np.int64)
    dims = cells.max(axis=0) + 1
    keys = (cells[:, 0] * dims[1] + cells[:, 1]) * dims[2] + cells[:, 2]
    order = np.argsort(keys, kind="stable")
    return cells, order, np.ascontiguousarray(keys[order]), dims, cell


def _crowding_bound(cell, smallest):
    """Most centres a cubic cell of edge ``cell`` can hold when no pair overlaps by more than
    MAX_OVERLAP of the smaller radius: balls of radius (1 - MAX_OVERLAP / 2) r_min around the
    centres are then disjoint and lie in the cell grown by that radius on each side."""
    core = (1.0 - 0.5 * MAX_OVERLAP) * smallest
    return math.floor((cell + 2.0 * core) ** 3 / (4.0 / 3.0 * math.pi * core ** 3))


def _check_inside_cell(position, cell, source):
    """ValueError naming the first centre outside the periodic cell ``cell``."""
    outside = np.flatnonzero(np.any((position < cell.lo) | (position > cell.hi), axis=1))
    if len(outside):
        raise ValueError(
            f"{source}: particle {int(outside[0])} (centre {position[outside[0]].tolist()} "
            f"m) lies outside the periodic cell lo = {cell.lo.tolist()} m, hi = "
            f"{cell.hi.tolist()} m; valid: every centre inside the cell")


def _check_walls(position, radius, walls, source):
    """ValueError naming the sphere that overlaps a wall by more than MAX_OVERLAP of its
    radius (its centre outside the box, or too deep against a wall)."""
    overlaps = _wall_overlaps(position, radius, walls)
    wall, sphere = np.unravel_index(int(np.argmax(overlaps)), overlaps.shape)
    if overlaps[wall, sphere] > MAX_OVERLAP:
        place = ("its centre lies outside the box" if overlaps[wall, sphere] > 1.0
                 else "its centre is inside the box")
        raise ValueError(
            f"{source}: particle {sphere} (radius {radius[sphere]:g} m, centre "
            f"{position[sphere].tolist()} m) overlaps wall {WALL_NAMES[wall]} (at "
            f"{walls.position[wall]:g} m) by {overlaps[wall, sphere]:.3g} of its radius, {place};"
            f" valid range: overlaps up to {MAX_OVERLAP:g} of the radius (linear wall contact "
            "law), box lo = "
            f"{walls.lo.tolist()} m, hi = {walls.hi.tolist()} m")


def check_packing(particles, walls, source="sample"):
    """ValueError naming ``source`` and the offending spheres unless the state can enter a
    simulation: finite values; every sphere inside the box, its overlap with each wall at most
    MAX_OVERLAP of its radius; every pair overlapping by at most MAX_OVERLAP of the smaller
    radius (found with a cell list, O(N), not through the faces of a periodic cell); not all
    centres at one point. A periodic cell (``walls.periodic``) has no walls: every centre
    must lie in it."""
    position, radius = particles.position, particles.radius
    for name, values in (("position", position), ("radius", radius),
                         ("velocity", particles.velocity),
                         ("angular_velocity", particles.angular_velocity),
                         ("walls position", walls.position)):
        _finite(source, name, np.asarray(values))
    count = len(radius)
    extent = position.max(axis=0) - position.min(axis=0)
    if count > 1 and float(extent.max()) <= 1e-9 * float(radius.max()):
        raise ValueError(f"{source}: all {count} particles are at one point "
                         f"{position[0].tolist()} m: not a packing (a damaged or edited file)")
    if walls.periodic:
        _check_inside_cell(position, walls, source)
    else:
        _check_walls(position, radius, walls, source)
    if count < 2:
        return
    cells, order, sorted_keys, dims, cell = _cell_list(position, radius)
    _, first, occupancy = np.unique(sorted_keys, return_index=True, return_counts=True)
    bound = _crowding_bound(cell, float(radius.min()))
    crowded = int(np.argmax(occupancy))
    if occupancy[crowded] > bound:
        # an example pair among (at most 64 of) the crowded centres
        members = order[first[crowded]:first[crowded] + min(int(occupancy[crowded]), 64)]
        x, r = position[members], radius[members]
        ratio = ((r[:, None] + r[None, :] - np.linalg.norm(x[:, None] - x[None, :], axis=2))
                 / np.minimum(r[:, None], r[None, :]))
        np.fill_diagonal(ratio, -np.inf)
        i, j = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
        worst = ratio[i, j]
        raise ValueError(
            f"{source}: {int(occupancy[crowded])} particle centres lie in one cube of edge "
            f"{cell:g} m, which holds at most {bound} spheres overlapping by at most "
            f"{MAX_OVERLAP:g} of the smaller radius (e.g. particles {int(members[i])} and "
            f"{int(members[j])} overlap by {worst:.3g} of the smaller radius): not a packing "
            "the linear contact law can hold")
    worst, i, j = _worst_overlap(position, radius, cells, order, sorted_keys, dims)
    if worst > MAX_OVERLAP:
        raise ValueError(
            f"{source}: particles {i} and {j} (radii {radius[i]:g} and {radius[j]:g} m) overlap "
            f"by {worst:.3g} of the smaller radius; valid range: overlaps up to "
            f"{MAX_OVERLAP:g} of the smaller radius (linear contact law kn = 2 E R1 R2 / "
            "(R1 + R2); prepared samples stay below about 0.16)")
