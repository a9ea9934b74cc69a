"""Numba kernels of the liquid bridges in the DEM (thesis Ch. 5, docs/physics.md
'The bridge model').

Per pair (parallel over pairs) a bridge forms when the spheres touch (overlap > 0, from the
contact law of the same step) and breaks when contact is lost or, across gaps, where no bridge
exists at that gap; its force F [N] acts along the branch vector, attractive (force on j from
i: -F n, n unit i -> j). Gathers add the forces per particle, each particle summing its own
pairs in a fixed order (deterministic for any thread count, no atomics).

Lookups (the units of docs/units.md): r = R2/R1 with R2 the larger radius, u* = s R2 / gamma,
d* = max(gap, 0) / R2, F = F* 2 pi gamma R2, V = V* R2^3, filling angles delta1 on the smaller
sphere and delta2 on the larger one.

The GPU engine's bridges are _follow_contact (at contact), _follow_across_gap (persisting)
and _form_at_contact (a new suction) and what they call, compiled for the device from this
source (pendular.gpu.cuda.device_twin).

The kernels take their arrays in tuples, one per kind, each unpacked at the kernel's top:
``pairs`` (pair_geometry: what they read of the particles and the neighbour list), ``rows``
(particle_pairs: each particle's pairs, for per-particle loops), ``table`` / ``volume_table``
(a BridgeTable's / VolumeBridgeTable's arrays()), which they only read, are plain tuples;
``bridges`` (a pendular.capillary.bridge_state.BridgeState) and ``liquid`` (a LiquidExchange),
which they write, are named tuples. The scalars and the per-pair force vectors ``pair_force``
(K, 3) [N] (force on j from i) are loose.

Why two kinds. A parallel kernel names every array its ``prange`` loop writes before the loop,
by attribute (``force = bridges.force``), and writes through that name: Numba's parallel loops
silently drop the writes to an array taken from a tuple inside the loop, or unpacked from one
anywhere (numba issues 5872 and 7135: their alias analysis does not see that it is the
argument's array; tests/unit/test_bridge_operations.py checks every parallel kernel's writes).
Its loop body reads loose arrays only, unpacked before the loop: a tuple read inside the loop
costs a reload per access. Numba's dispatch types a plain tuple of arrays in C, as it does
loose arrays, and a named tuple in Python, so only the bundles written carry names.
"""

import math
from typing import NamedTuple

import numba
import numpy as np

from pendular.dem.neighbors import branch_vector
from pendular.dem.virial import SUM_BLOCKS, ZERO9, add_face_term, add_to_block, block_bounds

from pendular.capillary.bridge_state import ACROSS_GAP, AT_CONTACT, NO_BRIDGE
from pendular.capillary.table import lookup_interface, lookup_suction
from pendular.capillary.volume_table import lookup_volume, lookup_volume_interface


def pair_geometry(sim):
    """``pairs`` of the kernels: (position (N, 3) [m], radius (N,) [m], pair_i, pair_j (K,)
    int64, image (K, 3) int8, period (3,) [m], overlap (K,) [m], normal (K, 3)) of ``sim`` now:
    the particles, the pairs with their periodic images and the box period
    (pendular.dem.neighbors.branch_vector), and the contact law's overlap (negative: a gap) and
    unit normal i -> j of this step."""
    p, c = sim.particles, sim.contacts
    return (p.position, p.radius, c.pair_i, c.pair_j, c.image, sim.walls.period, c.overlap,
            c.normal)


def particle_pairs(contacts):
    """``rows`` of the kernels: (row_start, second_start, second_pair) of ``contacts``
    (pendular.dem.neighbors.Contacts): p is the first member of pairs
    row_start[p]:row_start[p + 1] and the second of
    second_pair[second_start[p]:second_start[p + 1]]."""
    return contacts.row_start, contacts.second_start, contacts.second_pair


class LiquidExchange(NamedTuple):
    """The liquid a closed amount moves between bridges and grains: ``film`` (N,) [m^3] held on
    each grain; per pair, ``released`` (K,) [m^3] the volume of a bridge that ruptured and
    ``events`` (K,) int8 what exchange_liquid has to do (NO_EVENT, RUPTURED,
    FORMS_FROM_FILMS)."""

    film: np.ndarray
    released: np.ndarray
    events: np.ndarray


@numba.njit(cache=True, inline="always")
def _clear(k, state, volume, force, filling_i, filling_j, pair_force):
    """Pair k holds no bridge and no force."""
    state[k] = NO_BRIDGE
    volume[k] = 0.0
    force[k] = 0.0
    filling_i[k] = 0.0
    filling_j[k] = 0.0
    pair_force[k, 0] = 0.0
    pair_force[k, 1] = 0.0
    pair_force[k, 2] = 0.0


@numba.njit(cache=True, inline="always")
def _store(k, radius_i, radius_j, force_star, delta1, delta2, surface_tension, force,
           filling_i, filling_j):
    """Write the force [N] and filling angles of pair k; delta1 belongs to the smaller sphere."""
    force[k] = force_star * 2.0 * math.pi * surface_tension * max(radius_i, radius_j)
    if radius_i <= radius_j:
        filling_i[k] = delta1
        filling_j[k] = delta2
    else:
        filling_i[k] = delta2
        filling_j[k] = delta1


@numba.njit(cache=True, inline="always")
def _apply_along(k, magnitude, n0, n1, n2, pair_force):
    """Attractive force on j from i: -F n (n unit i -> j)."""
    pair_force[k, 0] = -magnitude * n0
    pair_force[k, 1] = -magnitude * n1
    pair_force[k, 2] = -magnitude * n2


@numba.njit(cache=True, inline="always")
def _apply_across_gap(k, position, i, j, image, period, magnitude, pair_force):
    """_apply_along the branch vector of pair k (i, j)."""
    d0, d1, d2 = branch_vector(position, i, j, image, k, period)
    inverse = 1.0 / math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    _apply_along(k, magnitude, d0 * inverse, d1 * inverse, d2 * inverse, pair_force)


@numba.njit(cache=True, inline="always")
def _form_at_contact(k, radius_i, radius_j, state, volume, force, filling_i, filling_j, suction,
                     surface_tension, radius_ratios, suction_axis, distance_low,
                     log_distance_rupture, log_values):
    """Give pair k the suction-controlled bridge of touching spheres (table at d* = 0)."""
    larger = max(radius_i, radius_j)
    _, force_star, volume_star, delta1, delta2 = lookup_suction(
        radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values,
        larger / min(radius_i, radius_j), suction * larger / surface_tension, 0.0)
    _store(k, radius_i, radius_j, force_star, delta1, delta2, surface_tension, force, filling_i,
           filling_j)
    volume[k] = volume_star * larger * larger * larger
    state[k] = AT_CONTACT


@numba.njit(cache=True, parallel=True)
def contact_bridges(pairs, bridges, suction, surface_tension, table):
    """Suction-controlled bridges that exist exactly while the spheres touch (thesis Ch. 5.2.2).

    A pair that starts touching gets its bridge from the table at d* = 0 (force, volume and
    filling angles depend only on the radii then); a pair that stops touching loses it. In
    steady state this pass only reads overlap and state. suction [Pa], surface_tension [N/m].
    """
    _, radius, pair_i, pair_j, _, _, overlap, _ = pairs
    radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values = table
    state = bridges.state           # written in the loop: named by attribute (module docstring)
    volume = bridges.volume
    force = bridges.force
    filling_i = bridges.filling_i
    filling_j = bridges.filling_j
    for k in numba.prange(len(pair_i)):
        _follow_contact(k, radius, pair_i, pair_j, overlap, state, volume, force, filling_i,
                        filling_j, suction, surface_tension, radius_ratios, suction_axis,
                        distance_low, log_distance_rupture, log_values)


@numba.njit(cache=True, _nrt=False)
def serial_contact_bridges(pairs, bridges, suction, surface_tension, table):
    """contact_bridges on one thread, without the parallel launch (2-3 us a call)."""
    _, radius, pair_i, pair_j, _, _, overlap, _ = pairs
    radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values = table
    for k in range(len(pair_i)):
        _follow_contact(k, radius, pair_i, pair_j, overlap, bridges.state, bridges.volume,
                        bridges.force, bridges.filling_i, bridges.filling_j, suction,
                        surface_tension, radius_ratios, suction_axis, distance_low,
                        log_distance_rupture, log_values)


@numba.njit(cache=True, inline="always")
def _follow_contact(k, radius, pair_i, pair_j, overlap, state, volume, force, filling_i,
                    filling_j, suction, surface_tension, radius_ratios, suction_axis,
                    distance_low, log_distance_rupture, log_values):
    """Pair k's bridge at contact (contact_bridges): formed if the pair touches and has none,
    gone if it has one and does not touch."""
    touching = overlap[k] > 0.0
    if touching == (state[k] == AT_CONTACT):   # no change: the (predictable) common case
        return
    if touching:
        _form_at_contact(k, radius[pair_i[k]], radius[pair_j[k]], state, volume, force,
                         filling_i, filling_j, suction, surface_tension, radius_ratios,
                         suction_axis, distance_low, log_distance_rupture, log_values)
    else:
        state[k] = NO_BRIDGE
        volume[k] = 0.0
        force[k] = 0.0
        filling_i[k] = 0.0
        filling_j[k] = 0.0


@numba.njit(cache=True, parallel=True)
def refresh_contact_bridges(pairs, bridges, suction, surface_tension, table):
    """Look every bridge at contact (AT_CONTACT, values cached) up again at a new ``suction``
    [Pa] (a suction path); bridges across gaps are looked up each step anyway."""
    _, radius, pair_i, pair_j, _, _, _, _ = pairs
    radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values = table
    state = bridges.state           # written in the loop: named by attribute (module docstring)
    volume = bridges.volume
    force = bridges.force
    filling_i = bridges.filling_i
    filling_j = bridges.filling_j
    for k in numba.prange(len(pair_i)):
        if state[k] == AT_CONTACT:
            _form_at_contact(k, radius[pair_i[k]], radius[pair_j[k]], state, volume, force,
                             filling_i, filling_j, suction, surface_tension, radius_ratios,
                             suction_axis, distance_low, log_distance_rupture, log_values)


@numba.njit(cache=True, inline="always")
def _add_contact_bridges(p, force, normal, row_start, second_start, second_pair, out):
    """Add to ``out[p]`` its bridges' forces (+F n where p is i, -F n where p is j) in a fixed
    order."""
    f0 = f1 = f2 = 0.0
    for k in range(row_start[p], row_start[p + 1]):
        f = force[k]
        f0 += f * normal[k, 0]
        f1 += f * normal[k, 1]
        f2 += f * normal[k, 2]
    for slot in range(second_start[p], second_start[p + 1]):
        k = second_pair[slot]
        f = force[k]
        f0 -= f * normal[k, 0]
        f1 -= f * normal[k, 1]
        f2 -= f * normal[k, 2]
    out[p, 0] += f0
    out[p, 1] += f1
    out[p, 2] += f2


@numba.njit(cache=True, parallel=True)
def gather_contact_bridges(force, normal, row_start, second_start, second_pair, out):
    """Add bridge forces of magnitude ``force`` (0 where no bridge) along the contact normals
    (unit i -> j, current for touching pairs): +F n on i, -F n on j (attraction).

    Branch-free (a pair without bridge adds 0 x its normal); each particle sums its own pairs
    in a fixed order, as pendular.dem.neighbors.gather_pair_forces: deterministic without
    atomics. In a periodic cell use gather_contact_bridges_virial.
    """
    for p in numba.prange(len(row_start) - 1):
        _add_contact_bridges(p, force, normal, row_start, second_start, second_pair, out)


@numba.njit(cache=True, parallel=True)
def gather_contact_bridges_virial(force, normal, row_start, second_start, second_pair, out,
                                  image, through_face, face_start, period, virial):
    """gather_contact_bridges in a periodic cell, which also adds the face terms of the
    bridges' Love–Weber sum to ``virial`` (as pendular.dem.virial.add_face_block, the force on
    j from i being -F n)."""
    count = len(row_start) - 1
    for block in numba.prange(SUM_BLOCKS):
        start, stop = block_bounds(count, block)
        for p in range(start, stop):
            _add_contact_bridges(p, force, normal, row_start, second_start, second_pair, out)
        total = ZERO9
        for slot in range(face_start[block], face_start[block + 1]):
            k = through_face[slot]
            f = -force[k]           # the force on j from i is -F n
            total = add_face_term(total, image, k, period, f * normal[k, 0], f * normal[k, 1],
                                  f * normal[k, 2])
        add_to_block(virial, block, total)


@numba.njit(cache=True, parallel=True)
def suction_bridges(pairs, bridges, pair_force, suction, surface_tension, table):
    """Suction-controlled bridges that persist across gaps (thesis Table 5.1, ``persist``).

    A bridge forms when the spheres touch and lives while the table has a bridge at the gap
    (d* = gap / R2 up to the rupture distance at u* = s R2 / gamma). At contact its values are
    cached (looked up once per contact); across a gap it is looked up each step and pulls along
    the current branch vector. suction [Pa], surface_tension [N/m]. Fills ``bridges`` and
    ``pair_force`` (force on j from i) [N].
    """
    position, radius, pair_i, pair_j, image, period, overlap, normal = pairs
    radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values = table
    state = bridges.state           # written in the loop: named by attribute (module docstring)
    volume = bridges.volume
    force = bridges.force
    filling_i = bridges.filling_i
    filling_j = bridges.filling_j
    for k in numba.prange(len(pair_i)):
        _follow_across_gap(k, position, radius, pair_i, pair_j, image, period, overlap, normal,
                           state, volume, force, filling_i, filling_j, pair_force, suction,
                           surface_tension, radius_ratios, suction_axis, distance_low,
                           log_distance_rupture, log_values)


@numba.njit(cache=True, inline="always")
def _follow_across_gap(k, position, radius, pair_i, pair_j, image, period, overlap, normal,
                       state, volume, force, filling_i, filling_j, pair_force, suction,
                       surface_tension, radius_ratios, suction_axis, distance_low,
                       log_distance_rupture, log_values):
    """Pair k's persisting bridge (suction_bridges): formed or kept at contact, looked up at
    its gap across one (ruptured where the table has none), and its force on j from i into
    ``pair_force`` (zeros without a bridge)."""
    i = pair_i[k]
    j = pair_j[k]
    if overlap[k] > 0.0:
        if state[k] != AT_CONTACT:
            _form_at_contact(k, radius[i], radius[j], state, volume, force, filling_i,
                             filling_j, suction, surface_tension, radius_ratios,
                             suction_axis, distance_low, log_distance_rupture, log_values)
        _apply_along(k, force[k], normal[k, 0], normal[k, 1], normal[k, 2], pair_force)
    elif state[k] != NO_BRIDGE:
        larger = max(radius[i], radius[j])
        exists, force_star, volume_star, delta1, delta2 = lookup_suction(
            radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values,
            larger / min(radius[i], radius[j]), suction * larger / surface_tension,
            -overlap[k] / larger)
        if exists:
            _store(k, radius[i], radius[j], force_star, delta1, delta2, surface_tension,
                   force, filling_i, filling_j)
            volume[k] = volume_star * larger * larger * larger
            state[k] = ACROSS_GAP
            _apply_across_gap(k, position, i, j, image, period, force[k], pair_force)
        else:
            _clear(k, state, volume, force, filling_i, filling_j, pair_force)
    else:
        pair_force[k, 0] = 0.0
        pair_force[k, 1] = 0.0
        pair_force[k, 2] = 0.0


#: Values of LiquidExchange.events (what exchange_liquid handles).
NO_EVENT = 0
RUPTURED = 1
FORMS_FROM_FILMS = 2


@numba.njit(cache=True, parallel=True)
def volume_bridges(pairs, bridges, pair_force, formation_suction, surface_tension, roughness,
                   table, volume_table, liquid, closed):
    """Volume-controlled bridges: formed at contact, then of constant volume; force and suction
    from (V*, d*) (pendular.capillary.lookup_volume), rupture where no bridge of that volume exists.

    Formation: open liquid (``closed`` False, a reservoir), with the volume of the
    suction-controlled bridge at ``formation_suction`` [Pa]; closed liquid (a fixed water
    content), only where the two grains hold liquid as film (``liquid.film``, read here):
    the pair is marked FORMS_FROM_FILMS in ``liquid.events`` for exchange_liquid. A bridge that
    ruptures is marked RUPTURED with its volume [m^3] in ``liquid.released`` (closed liquid).
    Returns the number of events marked.

    roughness: the meniscus separation of touching spheres / R2 (asperities hold the wetted
    surfaces H = roughness R2 apart, thesis Ch. 4's H): d* = roughness at contact and
    gap / R2 + roughness across a gap; 0 for smooth spheres. A pair whose bridge at formation
    would not span H gets none.
    """
    position, radius, pair_i, pair_j, image, period, overlap, normal = pairs
    radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values = table
    film = liquid.film
    state = bridges.state           # written in the loop: named by attribute (module docstring)
    volume = bridges.volume
    force = bridges.force
    filling_i = bridges.filling_i
    filling_j = bridges.filling_j
    bridge_suction = bridges.suction
    released = liquid.released
    events = liquid.events
    marked = 0
    for k in numba.prange(len(pair_i)):
        marked += _follow_volume(k, position, radius, pair_i, pair_j, image, period, overlap,
                                 normal, state, volume, force, filling_i, filling_j,
                                 bridge_suction, pair_force, film, released, events,
                                 formation_suction, surface_tension, roughness, radius_ratios,
                                 suction_axis, distance_low, log_distance_rupture, log_values,
                                 volume_table, closed)
    return marked


@numba.njit(cache=True, inline="always")
def _follow_volume(k, position, radius, pair_i, pair_j, image, period, overlap, normal, state,
                   volume, force, filling_i, filling_j, bridge_suction, pair_force, film,
                   released, events, formation_suction, surface_tension, roughness,
                   radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values,
                   volume_table, closed):
    """Pair k's volume-controlled bridge (volume_bridges): formed, looked up at its volume and
    gap, or ruptured, its force on j from i into ``pair_force``; returns 1 when it marked an
    event for exchange_liquid, else 0. At most 30 arguments (the volume table's arrays in one
    tuple): a longer call compiles to a call with *args, which Numba does not inline."""
    i = pair_i[k]
    j = pair_j[k]
    touching = overlap[k] > 0.0
    if state[k] == NO_BRIDGE and not touching:
        pair_force[k, 0] = 0.0
        pair_force[k, 1] = 0.0
        pair_force[k, 2] = 0.0
        return 0
    larger = max(radius[i], radius[j])
    ratio = larger / min(radius[i], radius[j])
    cube = larger * larger * larger
    if state[k] == NO_BRIDGE:
        pair_force[k, 0] = 0.0
        pair_force[k, 1] = 0.0
        pair_force[k, 2] = 0.0
        if closed:
            if film[i] + film[j] > 0.0:
                events[k] = FORMS_FROM_FILMS
                return 1
            return 0
        forms, _, volume_star, _, _ = lookup_suction(
            radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values,
            ratio, formation_suction * larger / surface_tension, roughness)
        if not forms:
            return 0
        volume[k] = volume_star * cube
        state[k] = ACROSS_GAP   # not yet evaluated at contact
    if touching and state[k] == AT_CONTACT:
        _apply_along(k, force[k], normal[k, 0], normal[k, 1], normal[k, 2], pair_force)
        return 0
    gap_star = roughness if touching else roughness - overlap[k] / larger
    volume_ratios, volume_axes, volume_distance_low, volume_log_rupture, grid = volume_table
    exists, force_star, suction_star, delta1, delta2 = lookup_volume(
        volume_ratios, volume_axes, volume_distance_low, volume_log_rupture, grid, ratio,
        volume[k] / cube, gap_star)
    if not exists:
        marked = 0
        if closed:
            released[k] = volume[k]
            events[k] = RUPTURED
            marked = 1
        _clear(k, state, volume, force, filling_i, filling_j, pair_force)
        bridge_suction[k] = 0.0
        return marked
    _store(k, radius[i], radius[j], force_star, delta1, delta2, surface_tension, force,
           filling_i, filling_j)
    bridge_suction[k] = suction_star * surface_tension / larger
    if touching:
        state[k] = AT_CONTACT
        _apply_along(k, force[k], normal[k, 0], normal[k, 1], normal[k, 2], pair_force)
    else:
        state[k] = ACROSS_GAP
        _apply_across_gap(k, position, i, j, image, period, force[k], pair_force)
    return 0


@numba.njit(cache=True, inline="always")
def _give_to_bridges(p, share, own_pairs, second_slots, second_pair, radius, pair_i, pair_j,
                     state, volume, film, largest_star):
    """Share ``share`` [m^3] of grain p's liquid equally among its bridges (its pairs
    ``own_pairs``, then ``second_pair[slot]`` for ``slot`` in ``second_slots``; each capped at
    ``largest_star`` R2^3, the volume table's range; the rest stays on the grain as film); a
    grain without bridge keeps it all as film. Bridges that receive liquid are marked
    ACROSS_GAP, so volume_bridges looks them up again."""
    count = 0
    for k in own_pairs:
        count += state[k] != NO_BRIDGE
    for slot in second_slots:
        count += state[second_pair[slot]] != NO_BRIDGE
    if count == 0:
        film[p] += share
        return
    each = share / count
    kept = 0.0
    for k in own_pairs:
        kept += _give_to_bridge(k, each, radius, pair_i, pair_j, state, volume, largest_star)
    for slot in second_slots:
        kept += _give_to_bridge(second_pair[slot], each, radius, pair_i, pair_j, state, volume,
                                largest_star)
    film[p] += kept


@numba.njit(cache=True, inline="always")
def _give_to_bridge(k, each, radius, pair_i, pair_j, state, volume, largest_star):
    """Give pair k's bridge ``each`` [m^3] up to its cap (_give_to_bridges); returns what it
    could not take [m^3] (0 without a bridge)."""
    if state[k] == NO_BRIDGE:
        return 0.0
    larger = max(radius[pair_i[k]], radius[pair_j[k]])
    room = largest_star * larger * larger * larger - volume[k]
    given = min(each, max(room, 0.0))
    volume[k] += given
    state[k] = ACROSS_GAP
    return each - given


@numba.njit(cache=True, inline="always")
def _exchange_ruptured(k, share, own_i, second_i, own_j, second_j, second_pair, radius, pair_i,
                       pair_j, state, volume, film, released, events, largest_star):
    """The liquid of pair k's ruptured bridge (exchange_liquid's RUPTURED; ``own_i``,
    ``second_i``, ``own_j``, ``second_j``: the pairs of its two grains, as _give_to_bridges
    takes them); returns the liquid lost [m^3]."""
    lost = 0.0
    if share:
        _give_to_bridges(pair_i[k], 0.5 * released[k], own_i, second_i, second_pair, radius,
                         pair_i, pair_j, state, volume, film, largest_star)
        _give_to_bridges(pair_j[k], 0.5 * released[k], own_j, second_j, second_pair, radius,
                         pair_i, pair_j, state, volume, film, largest_star)
    else:
        lost = released[k]
    released[k] = 0.0
    events[k] = NO_EVENT
    return lost


@numba.njit(cache=True, inline="always")
def _form_from_films(k, radius, pair_i, pair_j, state, volume, film, events, smallest_star,
                     largest_star):
    """Pair k's bridge from the films of its two grains (exchange_liquid's
    FORMS_FROM_FILMS)."""
    events[k] = NO_EVENT
    i = pair_i[k]
    j = pair_j[k]
    larger = max(radius[i], radius[j])
    cube = larger * larger * larger
    held = film[i] + film[j]
    if state[k] != NO_BRIDGE or not smallest_star * cube <= held <= largest_star * cube:
        return
    volume[k] = held
    state[k] = ACROSS_GAP
    film[i] = 0.0
    film[j] = 0.0


@numba.njit(cache=True)
def exchange_liquid(liquid, rows, pairs, bridges, share, smallest_star, largest_star):
    """The liquid exchanges of the events volume_bridges marked, in pair order (deterministic);
    returns the liquid lost [m^3].

    RUPTURED: with ``share`` (Mani, Kadau & Herrmann 2012's liquid of a ruptured bridge going
    back to its grains), half of the released volume to each of the two grains, shared equally
    among that grain's remaining bridges, or kept on the grain as film when it has none;
    without ``share`` the volume is lost. FORMS_FROM_FILMS: a new contact takes the film of
    both grains as its bridge (marked ACROSS_GAP, evaluated at the next step) when that volume
    lies in the volume table's range [smallest_star, largest_star] R2^3; otherwise the films
    stay. Events are cleared."""
    events, released, film = liquid.events, liquid.released, liquid.film
    _, radius, pair_i, pair_j, _, _, _, _ = pairs
    row_start, second_start, second_pair = rows
    state, volume = bridges.state, bridges.volume
    lost = 0.0
    for k in range(len(events)):
        if events[k] != RUPTURED:
            continue
        i = pair_i[k]
        j = pair_j[k]
        lost += _exchange_ruptured(k, share, range(row_start[i], row_start[i + 1]),
                                   range(second_start[i], second_start[i + 1]),
                                   range(row_start[j], row_start[j + 1]),
                                   range(second_start[j], second_start[j + 1]), second_pair,
                                   radius, pair_i, pair_j, state, volume, film, released,
                                   events, largest_star)
    for k in range(len(events)):
        if events[k] == FORMS_FROM_FILMS:
            _form_from_films(k, radius, pair_i, pair_j, state, volume, film, events,
                             smallest_star, largest_star)
    return lost


@numba.njit(cache=True)
def bridges_across_gaps(pairs, bridges, formation_suction, surface_tension, roughness, max_gap,
                        table):
    """Wetting across gaps: every pair without a bridge whose spheres are apart by a gap in
    (0, max_gap] [m] gets, marked ACROSS_GAP, the volume [m^3] of the suction-controlled bridge
    at ``formation_suction`` [Pa] at its gap (d* = roughness + gap / R2), if one exists there;
    volume_bridges or suction_bridges then carries it. Returns the number of bridges formed."""
    radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values = table
    _, radius, pair_i, pair_j, _, _, overlap, _ = pairs
    formed = 0
    for k in range(len(pair_i)):
        gap = -overlap[k]
        if bridges.state[k] != NO_BRIDGE or gap <= 0.0 or gap > max_gap:
            continue
        larger = max(radius[pair_i[k]], radius[pair_j[k]])
        exists, _, volume_star, _, _ = lookup_suction(
            radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values,
            larger / min(radius[pair_i[k]], radius[pair_j[k]]),
            formation_suction * larger / surface_tension, roughness + gap / larger)
        if exists:
            bridges.volume[k] = volume_star * larger * larger * larger
            bridges.state[k] = ACROSS_GAP
            formed += 1
    return formed


@numba.njit(cache=True, inline="always")
def _bridge_gap_star(position, radius, pair_i, pair_j, image, period, k, at_contact,
                     roughness):
    """(R2, r, d*) of the bridge of pair k as the bridge kernels read it: d* = roughness
    at contact, roughness + gap / R2 across a gap."""
    i = pair_i[k]
    j = pair_j[k]
    larger = max(radius[i], radius[j])
    gap = 0.0
    if not at_contact:
        d0, d1, d2 = branch_vector(position, i, j, image, k, period)
        distance = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        gap = max(distance - radius[i] - radius[j], 0.0)
    return larger, larger / min(radius[i], radius[j]), roughness + gap / larger


@numba.njit(cache=True, parallel=True)
def suction_interfaces(pairs, bridges, index, suction, surface_tension, table):
    """Liquid-gas interfaces of the suction-controlled bridges ``index`` (pair numbers) at the
    suction [Pa]: (B, 2) [m^2], per bridge nn11 = ∫ n_x n_x dS and nn33 = ∫ n_z n_z dS over
    its interface in the bridge frame (z along the branch vector; the area is 2 nn11 + nn33),
    from the suction table at its gap."""
    position, radius, pair_i, pair_j, image, period, _, _ = pairs
    radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values = table
    state = bridges.state
    out = np.empty((len(index), 2))
    for b in numba.prange(len(index)):
        k = index[b]
        larger, ratio, distance_star = _bridge_gap_star(position, radius, pair_i, pair_j, image,
                                                        period, k, state[k] == AT_CONTACT, 0.0)
        _, nn11, nn33 = lookup_interface(
            radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values, ratio,
            suction * larger / surface_tension, distance_star)
        out[b, 0] = nn11 * larger * larger
        out[b, 1] = nn33 * larger * larger
    return out


@numba.njit(cache=True, parallel=True)
def volume_interfaces(pairs, bridges, index, roughness, volume_table):
    """As suction_interfaces for volume-controlled bridges, from the volume table at each
    bridge's volume [m^3] and gap (d* with the roughness): a bridge near its volume-controlled
    rupture is off the stable branch of the suction-controlled family, so its suction alone does
    not name it."""
    position, radius, pair_i, pair_j, image, period, _, _ = pairs
    volume_ratios, volume_axes, volume_distance_low, volume_log_rupture, grid = volume_table
    state = bridges.state
    volume = bridges.volume
    out = np.empty((len(index), 2))
    for b in numba.prange(len(index)):
        k = index[b]
        larger, ratio, distance_star = _bridge_gap_star(position, radius, pair_i, pair_j, image,
                                                        period, k, state[k] == AT_CONTACT,
                                                        roughness)
        _, nn11, nn33 = lookup_volume_interface(
            volume_ratios, volume_axes, volume_distance_low, volume_log_rupture, grid, ratio,
            volume[k] / (larger * larger * larger), distance_star)
        out[b, 0] = nn11 * larger * larger
        out[b, 1] = nn33 * larger * larger
    return out


@numba.njit(cache=True, inline="always")
def _meniscus_caps(p, position, row_start, second_start, second_pair, pair_i, pair_j, image,
                   period, state, filling_i, filling_j, caps):
    """Write into the rows of ``caps`` the menisci of particle p: the unit direction from p to
    the other sphere, the cosine and the sine of p's filling angle. Returns how many."""
    first = row_start[p + 1] - row_start[p]
    found = 0
    for slot in range(first + second_start[p + 1] - second_start[p]):
        if slot < first:
            k = row_start[p] + slot
            sign = 1.0
            cap = filling_i[k]
        else:
            k = second_pair[second_start[p] + slot - first]
            sign = -1.0
            cap = filling_j[k]
        if state[k] == NO_BRIDGE:
            continue
        d0, d1, d2 = branch_vector(position, pair_i[k], pair_j[k], image, k, period)
        scale = sign / math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        caps[found, 0] = d0 * scale
        caps[found, 1] = d1 * scale
        caps[found, 2] = d2 * scale
        caps[found, 3] = math.cos(math.radians(cap))
        caps[found, 4] = math.sin(math.radians(cap))
        found += 1
    return found


@numba.njit(cache=True, parallel=True)
def pendular_overlap_counts(pairs, rows, bridges):
    """Per particle, the number of pairs of its menisci that overlap (the pendular limit,
    docs/physics.md 'The bridge model'): two wetted caps whose normals are separated by less
    than the sum of their filling angles a + b (YADE's Law2_ScGeom_CapillaryPhys_Capillarity
    fusion test), i.e. whose normals' dot product exceeds cos(a + b) (filling angles at most 90
    deg: a + b <= 180 deg, where the arc cosine falls). Each block of particles has its own
    scratch rows."""
    position, _, pair_i, pair_j, image, period, _, _ = pairs
    row_start, second_start, second_pair = rows
    state, filling_i, filling_j = bridges.state, bridges.filling_i, bridges.filling_j
    count = len(row_start) - 1
    overlaps = np.zeros(count, np.int64)
    widest = 0
    for p in range(count):
        widest = max(widest, row_start[p + 1] - row_start[p] + second_start[p + 1]
                     - second_start[p])
    for block in numba.prange(SUM_BLOCKS):
        start, stop = block_bounds(count, block)
        caps = np.empty((widest, 5))
        for p in range(start, stop):
            found = _meniscus_caps(p, position, row_start, second_start, second_pair, pair_i,
                                   pair_j, image, period, state, filling_i, filling_j, caps)
            for a in range(found):
                for b in range(a + 1, found):
                    cosine = (caps[a, 0] * caps[b, 0] + caps[a, 1] * caps[b, 1]
                              + caps[a, 2] * caps[b, 2])
                    if cosine > caps[a, 3] * caps[b, 3] - caps[a, 4] * caps[b, 4]:
                        overlaps[p] += 1
    return overlaps
