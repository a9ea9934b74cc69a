"""Verlet neighbour list, with per-pair contact history carried across rebuilds.

Pairs are stored once (i < j) in CSR order: the pairs of particle i are
``row_start[i]:row_start[i+1]``, sorted by j. ``second_start``/``second_pair`` index,
for each particle, the pairs in which it is the second member, so that per-pair results
can be gathered per particle without atomics (deterministic for any thread count).

Operations keep their own per-pair state in ``Contacts.extra`` (declared as PairFields and read
through ``pair_arrays``, pendular.dem.protocols); ``build_contacts`` carries every such array to
the same (i, j) pair across rebuilds, as it does for the shear history. ``NeighborList``
reaches beyond touching as far as the scene's forces declare (``reach(sim)``, e.g. liquid
bridges across gaps). The candidate pairs come from a cell list (pendular.dem.cell_list).
"""

from dataclasses import dataclass, field

import numba
import numpy as np

from pendular.dem.cell_list import build_pairs, build_periodic_pairs, group_members
from pendular.dem.protocols import state_array
from pendular.dem.state import period_layout
from pendular.utils.validate import check_int, check_positive, check_range
from pendular.dem.virial import SUM_BLOCKS, add_face_block, block_bounds, face_block_starts


@dataclass
class Contacts:
    """Candidate pairs and their per-pair state (K pairs).

    pair_i, pair_j: (K,) int64 particle indices, i < j.
    shear_force: (K, 3) elastic tangential force on j from i [N], the incremental spring history.
    normal: (K, 3) unit vector i -> j at the last force evaluation (for rotating shear_force).
    overlap: (K,) r_i + r_j - |x_j - x_i| at the last evaluation [m] (negative = gap).
    normal_force: (K,) magnitude of the spring's normal force [N] (0 when apart).
    force: (K, 3) total contact force on j from i [N] (its torques: pendular.dem.contact_law).
    extra: name -> (K, ...) per-pair state owned by other operations (e.g. capillary bridges),
    carried to the same pair by ``build_contacts``; absent pairs start at 0.
    image: (K, 3) int8 periodic image of j seen from i: the branch vector is
    x_j - x_i + image * period (``branch_vector``; zeros inside walls);
    through_face: (F,) int64 the pairs whose image is not zero, in pair order; face_start:
    (SUM_BLOCKS + 1,) int64 where each block of particles' share of them starts
    (pendular.dem.virial.face_block_starts).
    near_wall: (M,) int64 ascending, the particles that may touch a wall before the next
    rebuild (``near_wall_particles``: gap to a wall below the skin at the rebuild; the wall
    forces visit only these); default every particle (a list built without walls).
    """

    pair_i: np.ndarray
    pair_j: np.ndarray
    row_start: np.ndarray
    second_start: np.ndarray
    second_pair: np.ndarray
    shear_force: np.ndarray
    normal: np.ndarray
    overlap: np.ndarray
    normal_force: np.ndarray
    force: np.ndarray
    extra: dict = field(default_factory=dict)
    image: np.ndarray = None
    through_face: np.ndarray = None
    face_start: np.ndarray = None
    near_wall: np.ndarray = None

    def __post_init__(self):
        if self.near_wall is None:
            self.near_wall = np.arange(len(self.row_start) - 1, dtype=np.int64)
        if self.through_face is None:   # no images: none through a face (no scan of zeros)
            self.through_face = (np.zeros(0, np.int64) if self.image is None else
                                 np.flatnonzero(self.image.any(axis=1)).astype(np.int64))
        if self.image is None:
            self.image = np.zeros((len(self.pair_j), 3), np.int8)
        if self.face_start is None:
            self.face_start = face_block_starts(self.through_face, self.row_start)

    def __len__(self):
        return len(self.pair_i)

    def touching(self):
        """Boolean mask of pairs in mechanical contact (overlap > 0)."""
        return self.overlap > 0.0


@numba.njit(cache=True, inline="always")
def branch_vector(position, i, j, image, k, period):
    """Branch vector of pair k from i to j [m]: x_j - x_i + image_k * period (the periodic
    image of j nearest to i; period zeros inside walls); a sheared cell's ``period`` (4,)
    adds its offset delta = period[3] along x per image in z (Lees–Edwards,
    pendular.dem.cell). The length test is on the array's shape: hoisted out of any loop."""
    d0 = position[j, 0] - position[i, 0] + image[k, 0] * period[0]
    if len(period) > 3:
        d0 += image[k, 2] * period[3]
    return (d0, position[j, 1] - position[i, 1] + image[k, 1] * period[1],
            position[j, 2] - position[i, 2] + image[k, 2] * period[2])


@numba.njit(cache=True)
def second_index(row_start, pair_j, count):
    """(second_start, second_pair): for each of the ``count`` particles, the pair indices in
    which it is the second member (CSR), in pair order. The pairs of a CSR list (``row_start``,
    ``pair_j``) are numbered row after row, so this is pair_j's counting sort: ``row_start``
    is not read."""
    return group_members(pair_j, count)


@numba.njit(cache=True, parallel=True)
def previous_pair_index(old_row_start, old_pair_j, new_row_start, new_pair_j):
    """(K,) int64: for each pair of the new list, the index of the same (i, j) pair in the old
    one, or -1 for a pair new to the list (both lists in CSR order, each row sorted by j)."""
    index = np.empty(len(new_pair_j), np.int64)
    for i in numba.prange(len(new_row_start) - 1):
        old = old_row_start[i]
        old_end = old_row_start[i + 1]
        for k in range(new_row_start[i], new_row_start[i + 1]):
            j = new_pair_j[k]
            while old < old_end and old_pair_j[old] < j:
                old += 1
            index[k] = old if old < old_end and old_pair_j[old] == j else -1
    return index


@numba.njit(cache=True, parallel=True)
def _carry_rows(old_values, index, fill, new_values):
    """Row k of ``new_values`` becomes row index[k] of ``old_values``, or ``fill[0]`` throughout
    where index[k] is -1."""
    for k in numba.prange(len(index)):
        source = index[k]
        if source >= 0:
            for c in range(old_values.shape[1]):
                new_values[k, c] = old_values[source, c]
        else:
            for c in range(new_values.shape[1]):
                new_values[k, c] = fill[0]


@numba.njit(cache=True)
def moved_beyond(position, reference_position, radius, reference_radius, limit, lengths,
                 reference_lengths, shortest_unlisted):
    """True when some particle's displacement plus radius growth since the last rebuild exceeds
    ``limit`` [m].

    In a periodic cell of edges ``lengths`` (3,) [m], ``reference_lengths`` at the last
    rebuild (walls: ones for both), the particles ride the cell's stretching s = L / L_ref,
    which changes a branch vector l by (s - 1) l: displacements are measured from s x_ref, and
    the limit shrinks by max|s - 1| / 2 times ``shortest_unlisted`` [m], the shortest branch of
    a pair left out of the list. A sheared cell's (4,) adds its offset delta (pendular.dem.cell):
    the particles also ride the shear g = (delta - s_x delta_ref) / L_z,ref of x with z (the
    map that takes the reference cell's images to the current ones), measured from
    s_x x_ref + g z_ref, and the limit shrinks by |g| / 2 times more."""
    s0 = lengths[0] / reference_lengths[0]
    s1 = lengths[1] / reference_lengths[1]
    s2 = lengths[2] / reference_lengths[2]
    shear = 0.0
    if len(lengths) > 3 or len(reference_lengths) > 3:
        offset = lengths[3] if len(lengths) > 3 else 0.0
        reference_offset = reference_lengths[3] if len(reference_lengths) > 3 else 0.0
        shear = (offset - s0 * reference_offset) / reference_lengths[2]
    stretch = max(abs(s0 - 1.0), abs(s1 - 1.0), abs(s2 - 1.0)) + abs(shear)
    limit -= 0.5 * stretch * shortest_unlisted
    if limit <= 0.0:
        return True
    limit_squared = limit * limit
    for p in range(position.shape[0]):
        growth = max(radius[p] - reference_radius[p], 0.0)
        d0 = position[p, 0] - s0 * reference_position[p, 0]
        if shear != 0.0:
            d0 -= shear * reference_position[p, 2]
        d1 = position[p, 1] - s1 * reference_position[p, 1]
        d2 = position[p, 2] - s2 * reference_position[p, 2]
        if growth == 0.0:
            if d0 * d0 + d1 * d1 + d2 * d2 > limit_squared:
                return True
        elif np.sqrt(d0 * d0 + d1 * d1 + d2 * d2) + growth > limit:
            return True
    return False


@numba.njit(cache=True)
def near_wall_particles(position, radius, wall_position, margin):
    """Indices (ascending, int64) of the particles whose gap to some wall, distance minus
    radius, is below ``margin`` [m]; wall_position (6,) [m] as pendular.dem.state.Walls. Every other
    particle stays off the walls while no particle moves or grows more than margin / 2 and no
    wall moves more than margin / 2 (NeighborList.apply)."""
    near = np.empty(position.shape[0], np.int64)
    count = 0
    for p in range(position.shape[0]):
        reach = radius[p] + margin
        for axis in range(3):
            if (position[p, axis] - wall_position[2 * axis] < reach
                    or wall_position[2 * axis + 1] - position[p, axis] < reach):
                near[count] = p
                count += 1
                break
    return near[:count].copy()


@numba.njit(cache=True)
def walls_moved_beyond(wall_position, reference_wall_position, limit):
    """True when some wall moved more than ``limit`` [m] since ``reference_wall_position``."""
    for w in range(6):
        if abs(wall_position[w] - reference_wall_position[w]) > limit:
            return True
    return False


@numba.njit(cache=True, inline="always")
def _sum_pair_forces(pair_force, second_pair, own_pairs, second_slots):
    """(v0, v1, v2) [N]: a particle's pair forces in a fixed order, -f of its pairs
    ``own_pairs`` (it is i), then +f of the pairs ``second_pair[slot]`` for ``slot`` in
    ``second_slots`` (it is j); ranges, so that the GPU's rows (pendular.gpu.forces) sum the
    same way."""
    v0 = v1 = v2 = 0.0
    for k in own_pairs:
        v0 -= pair_force[k, 0]
        v1 -= pair_force[k, 1]
        v2 -= pair_force[k, 2]
    for slot in second_slots:
        k = second_pair[slot]
        v0 += pair_force[k, 0]
        v1 += pair_force[k, 1]
        v2 += pair_force[k, 2]
    return v0, v1, v2


@numba.njit(cache=True, inline="always")
def _add_pair_forces(p, pair_force, row_start, second_start, second_pair, out):
    """Add to ``out[p]`` its pair forces (-f where p is i, +f where p is j) in a fixed order."""
    v0, v1, v2 = _sum_pair_forces(pair_force, second_pair, range(row_start[p], row_start[p + 1]),
                                  range(second_start[p], second_start[p + 1]))
    out[p, 0] += v0
    out[p, 1] += v1
    out[p, 2] += v2


@numba.njit(cache=True, parallel=True)
def gather_pair_forces(pair_force, row_start, second_start, second_pair, out):
    """Add per-pair forces (K, 3) [N], each the force on j from i, to particles (N, 3): -f to
    the first member i, +f to j (action and reaction).

    Each particle sums its own pairs in a fixed order: deterministic for any thread count,
    without atomics. In a periodic cell use gather_pair_forces_virial.
    """
    for p in numba.prange(len(row_start) - 1):
        _add_pair_forces(p, pair_force, row_start, second_start, second_pair, out)


@numba.njit(cache=True, parallel=True)
def gather_pair_forces_virial(pair_force, row_start, second_start, second_pair, out, image,
                              through_face, face_start, period, virial):
    """gather_pair_forces in a periodic cell, which also adds the face terms of the forces'
    Love–Weber sum [N m] to ``virial`` (SUM_BLOCKS, 9), block by block (pendular.dem.virial). A kernel
    apart: the blocked loop in the walled kernel, even behind a branch, slowed walled scenes
    (docs/performance.md)."""
    count = len(row_start) - 1
    for block in numba.prange(SUM_BLOCKS):
        start, stop = block_bounds(count, block)
        for p in range(start, stop):
            _add_pair_forces(p, pair_force, row_start, second_start, second_pair, out)
        add_face_block(virial, block, through_face, face_start, image, period, pair_force,
                       None, None)


def branch_vectors(position, contacts, period, index=None):
    """Branch vectors i -> j [m] (B, 3) of the pairs ``index`` (all if None) of ``contacts``:
    x_j - x_i + image * period (branch_vector; ``period`` (3,) [m], zeros inside walls, or a
    sheared cell's (4,))."""
    index = np.arange(len(contacts)) if index is None else index
    branch = position[contacts.pair_j[index]] - position[contacts.pair_i[index]]
    period = np.asarray(period)
    if np.any(period):
        image = contacts.image[index]
        branch += image * period[:3]
        if len(period) > 3:
            branch[:, 0] += image[:, 2] * period[3]
    return branch


def carry_pair_array(values, index, fill=0):
    """``values`` (one row per pair of the old list) moved to the pairs of a new list, whose
    pair k was pair index[k] of the old one (previous_pair_index; -1: new to the list, gets
    ``fill``). Any dtype and trailing shape."""
    shape = (len(index),) + values.shape[1:]
    if not (len(index) and len(values)):
        return np.full(shape, fill, dtype=values.dtype)
    carried = np.empty(shape, dtype=values.dtype)
    _carry_rows(np.ascontiguousarray(values).reshape(len(values), -1), index,
                np.full(1, fill, dtype=values.dtype), carried.reshape(len(index), -1))
    return carried


def build_contacts(position, radius, skin, previous=None, period=None, walls=None,
                   wall_margin=0.0):
    """Build the neighbour list (pairs with gap < ``skin``); carry shear history, normals,
    overlaps (new pairs: -inf, never touched) and every ``extra`` per-pair array from
    ``previous`` if given. ``period`` (3,) [m]: a periodic box [0, period) holding the
    positions, pairs through the nearest image (ValueError if the box is narrower than 3
    times 2 max(radius) + skin on an axis); (4,): a sheared cell's, its offset last
    (branch_vector). ``walls`` (6,) [m]: wall planes, whose particles
    within ``wall_margin`` [m] make Contacts.near_wall (None: every particle).
    FloatingPointError if a position is not finite (a diverged simulation would otherwise get
    a meaningless list)."""
    if not np.isfinite(position).all():
        particle = int(np.argwhere(~np.isfinite(position))[0, 0])
        raise FloatingPointError(
            f"position of particle {particle} = {position[particle].tolist()} is not finite: the "
            "simulation diverged (lower the time step, e.g. timestep_safety, or check the forces)")
    if period is not None and not np.isfinite(period).all():
        raise FloatingPointError(f"the periodic cell's period {np.asarray(period).tolist()} m is "
                                 "not finite: the cell diverged (lower the time step or the "
                                 "strain rate)")
    count = len(radius)
    if period is None:
        row_start, pair_j = build_pairs(position, radius, skin)
        image = None
    else:
        narrowest = 3.0 * (2.0 * float(radius.max()) + skin)
        if np.min(period[:3]) < narrowest:
            raise ValueError(
                f"periodic cell edges {np.asarray(period[:3]).tolist()} m: valid range at least "
                f"{narrowest:g} m (3 times the largest diameter plus the neighbour reach "
                f"{skin:g} m); use more particles")
        row_start, pair_j, image = build_periodic_pairs(position, radius, skin,
                                                        period_layout(period))
    pair_i = np.repeat(np.arange(count, dtype=np.int64), np.diff(row_start))
    second_start, second_pair = second_index(row_start, pair_j, count)
    size = len(pair_j)
    # shear spring, normal and overlap of the last evaluation: a pair that was touching and
    # is found apart at the first evaluation after the rebuild forgets its spring there; a
    # new pair has never touched (overlap -inf)
    if previous is None:            # no history: empty arrays to carry from
        shear_force, normal, overlap, extra = np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), {}
    else:
        shear_force, normal, overlap, extra = (previous.shear_force, previous.normal,
                                               previous.overlap, previous.extra)
    index = (previous_pair_index(previous.row_start, previous.pair_j, row_start, pair_j)
             if len(overlap) else np.full(size, -1, np.int64))
    return Contacts(
        pair_i=pair_i, pair_j=pair_j, row_start=row_start,
        second_start=second_start, second_pair=second_pair,
        shear_force=carry_pair_array(shear_force, index),
        normal=carry_pair_array(normal, index),
        overlap=carry_pair_array(overlap, index, -np.inf),
        normal_force=np.zeros(size), force=np.zeros((size, 3)), image=image,
        extra={name: carry_pair_array(values, index) for name, values in extra.items()},
        near_wall=None if walls is None else near_wall_particles(position, radius, walls,
                                                                 wall_margin))


#: The lengths moved_beyond compares in walled scenes, no stretching (NeighborList.apply): the
#: current ones laid out as a cell's period (a strided view, as pendular.dem.state._NO_PERIOD), the
#: reference ones as the cell's contiguous copy at a rebuild, so that walled and periodic
#: scenes share one compiled moved_beyond.
_UNSTRETCHED = np.ones(6)[::2]
_UNSTRETCHED_REFERENCE = np.ones(3)


class NeighborList:
    """Keep ``sim.contacts`` current: rebuild when a particle moved (or grew) more than skin / 2
    (in a periodic cell: moved relative to the cell's stretching and shear, against a skin
    reduced by what they do to the pairs, ``moved_beyond``) or a wall more than skin / 2; the
    particles within the skin of a wall at a rebuild are the wall forces' (Contacts.near_wall).

    skin [m]: extra reach of the list beyond touching; larger means fewer rebuilds, more pairs;
    a new value takes effect through a rebuild at the next step (a list built with a thinner
    skin could miss a pair under the thicker one's rebuild criterion).
    The reach beyond touching is the largest ``reach(sim)`` [m] of the simulation's forces
    (a force acting across gaps, e.g. a liquid bridge up to its rupture distance, declares it;
    forces without ``reach`` need touching pairs only), asked every step: the list holds pairs
    with gap < reach + skin, so every pair with gap < reach is in it until the next rebuild,
    and a change of reach forces a rebuild. ``interaction_range`` [m]: the reach in use.
    """

    #: The rebuild test's references (``state_dict``): attribute -> (dtype, shape).
    _REFERENCES = {"reference_position": (np.float64, (None, 3)),
                   "reference_radius": (np.float64, (None,)),
                   "reference_lengths": (np.float64, (None,)),
                   "reference_walls": (np.float64, (6,))}

    def __init__(self, skin):
        self.skin = check_positive("skin", skin, "m")
        self.rebuilds = 0
        self.interaction_range = 0.0
        self._reference_position = None
        self._reference_radius = None
        self._reference_lengths = None
        self._reference_walls = None
        self._reference_skin = None
        self._shortest_unlisted = 0.0

    def state_dict(self):
        """``skin`` [m] (a procedure may change it), ``rebuilds``, ``interaction_range`` [m]
        and the rebuild test's references of the last rebuild, None before the first: the
        positions (N, 3) [m], radii (N,) [m], box lengths (3,) [m] (a sheared cell's period,
        (4,)), wall positions (6,) [m], the skin [m] and the shortest unlisted distance [m]."""
        state = {"skin": self.skin, "rebuilds": self.rebuilds,
                 "interaction_range": self.interaction_range,
                 "reference_skin": self._reference_skin,
                 "shortest_unlisted": self._shortest_unlisted}
        for name in self._REFERENCES:
            value = getattr(self, "_" + name)
            state[name] = None if value is None else value.copy()
        return state

    def load_state(self, state):
        loaded = {"skin": check_positive("skin", state["skin"], "m"),
                  "rebuilds": check_int("rebuilds", state["rebuilds"]),
                  "interaction_range": check_range("interaction_range",
                                                   state["interaction_range"], 0.0, unit="m"),
                  "_shortest_unlisted": check_range("shortest_unlisted",
                                                    state["shortest_unlisted"], 0.0, unit="m")}
        built = state["reference_position"] is not None
        for name, (dtype, shape) in self._REFERENCES.items():
            if (state[name] is not None) != built:
                raise ValueError(f"{name} is {'missing' if built else 'set'} while "
                                 f"reference_position is {'set' if built else 'missing'}")
            loaded["_" + name] = state_array(state, name, dtype, shape) if built else None
        loaded["_reference_skin"] = (check_positive("reference_skin", state["reference_skin"],
                                                    "m") if built else None)
        if built:
            count, radii, lengths = (len(loaded["_reference_" + name])
                                     for name in ("position", "radius", "lengths"))
            if radii != count:
                raise ValueError(f"reference_radius has {radii} entries; valid: one per "
                                 f"reference position ({count})")
            if lengths not in (3, 4):
                raise ValueError(f"reference_lengths has {lengths} entries; valid: 3 (4: a "
                                 "sheared cell)")
        for name, value in loaded.items():
            setattr(self, name, value)

    def required_reach(self, sim):
        """Largest reach [m] the simulation's forces declare (0: contacts only). A reach is
        checked when it differs from the list's (the check formats its message: a few us a
        step)."""
        reach = 0.0
        for op in sim.forces:
            # the ReachingForce contract, tested by attribute: isinstance against a runtime
            # protocol costs microseconds a force, every step
            reach_of = getattr(op, "reach", None)
            if reach_of is not None:
                value = reach_of(sim)
                if value != self.interaction_range:
                    value = check_range(f"{type(op).__name__}.reach", value, 0.0, unit="m")
                reach = max(reach, value)
        return reach

    def rebuild(self, sim):
        """Rebuild the list now (``apply`` does when needed; pendular.procedures.preparation.rescale after
        scaling every length)."""
        p = sim.particles
        box = sim.walls
        box.wrap(p)
        sim.contacts = build_contacts(p.position, p.radius, self.skin + self.interaction_range,
                                      previous=sim.contacts,
                                      period=box.period if box.periodic else None,
                                      walls=None if box.periodic else box.position,
                                      wall_margin=self.skin)
        self._reference_position = p.position.copy()
        self._reference_radius = p.radius.copy()
        self._reference_lengths = np.array(box.period) if box.periodic else box.lengths()
        self._reference_walls = box.position.copy()
        self._reference_skin = self.skin
        self._shortest_unlisted = 2.0 * float(p.radius.max()) + self.interaction_range + self.skin
        self.rebuilds += 1

    def apply(self, sim):
        p = sim.particles
        reach = self.required_reach(sim)
        lengths, reference = _UNSTRETCHED, _UNSTRETCHED_REFERENCE
        if sim.walls.periodic and self._reference_lengths is not None:
            lengths, reference = sim.walls.period, self._reference_lengths
        if (reach != self.interaction_range or sim.contacts is None
                or self._reference_position is None
                or self._reference_walls is None      # a checkpoint from before it was kept
                or self.skin != self._reference_skin
                or len(self._reference_radius) != len(p.radius)
                or (not sim.walls.periodic
                    and walls_moved_beyond(sim.walls.position, self._reference_walls,
                                           0.5 * self.skin))
                or moved_beyond(p.position, self._reference_position, p.radius,
                                self._reference_radius, 0.5 * self.skin, lengths, reference,
                                self._shortest_unlisted)):
            self.interaction_range = reach
            self.rebuild(sim)
