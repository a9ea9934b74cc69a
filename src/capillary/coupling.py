"""Liquid bridges in the DEM: the capillary operation of wet scenes (thesis Ch. 5, SPEC section 4).

A wet scene inserts ``CapillaryBridges`` after the contact law and the wall springs, before the
servo and the integrator (YADE's order: InteractionLoop, Law2_ScGeom_CapillaryPhys_Capillarity,
TriaxialStressController, NewtonIntegrator); a dry scene never imports this module. Each step:

1. per pair (parallel over pairs): a bridge forms when the spheres touch (overlap > 0, from
   the contact law of the same step) and breaks when contact is lost (the thesis's choice) or,
   with ``persist``, where no bridge exists at that gap: the table says no solution (suction
   control), or the volume-controlled rupture distance is passed (volume control). Its force
   F [N] acts along the branch vector, attractive: the force on j from i is -F n (n unit i -> j);
2. the forces are gathered per particle, -f to i and +f to j, each particle summing its own
   pairs in a fixed order (deterministic for any thread count, no atomics).

Default (suction control, bridges only at contact): ``contact_bridges`` only reads overlap and
the bridge state and looks a bridge up when it forms, and ``gather_contact_bridges`` applies the
cached magnitudes along the contact law's normals without building per-pair vectors (about
0.15-0.2 of a dry step's cost for 10,000 spheres). Bridges across gaps (``persist``, volume
control): ``suction_bridges`` / ``volume_bridges`` write per-pair force vectors ``pair_force``,
gathered by ``dem.neighbors.gather_pair_vectors``.

The capillary force is added on top of the mechanical contact force and does not enter the
Coulomb cap |Fs| <= Fn tan(phi): in YADE, Law2_ScGeom_FrictPhys_CundallStrack caps the shear
force with ``phys->normalForce`` (the spring's force only), and
Law2_ScGeom_CapillaryPhys_Capillarity adds fCap separately through ``scene->forces.addForce``
(YADE 2023 sources, pkg/dem/ElasticContactLaw.cpp and
pkg/dem/Law2_ScGeom_CapillaryPhys_Capillarity.cpp). There are no sphere-wall bridges (YADE's
capillary law skips pairs of different shapes), and ``contacts.force`` stays the mechanical
force, so that homogenize.contact_stress is Eq. 3.41's contact stress.

Lookups (SPEC section 1 units): r = R2/R1 with R2 the larger radius, u* = s R2 / gamma,
d* = max(gap, 0) / R2 (overlaps read the table's contact values, as YADE does), F = F* 2 pi gamma
R2, V = V* R2^3, filling angles delta1 on the smaller sphere and delta2 on the larger one. At
d* = 0 a bridge's force, volume and filling angles depend only on the radii (suction control)
or on the radii and its volume (volume control): they are looked up once when the bridge forms
(or comes back into contact) and cached in its per-pair arrays, so a bridge at contact costs
no lookup per step; only bridges across a gap (``persist``, volume control) are looked up
each step.

Per-pair state, in ``sim.contacts.extra`` (carried across neighbour-list rebuilds):
    bridge             int8: 0 no bridge, 1 bridge at contact (cached values), 2 across a gap
    bridge_volume      [m^3] liquid volume
    bridge_force       [N] magnitude of the attractive capillary force (> 0)
    filling_angle_i    [deg] filling angle on particle pair_i (delta1 if it is the smaller sphere)
    filling_angle_j    [deg] filling angle on particle pair_j
    bridge_suction     [Pa] (volume control only) the bridge's suction, negative for convex menisci

Volume control: a bridge forms at contact with the volume of the suction-controlled bridge at
contact at ``suction`` (the formation suction, the same for bridges that form later), then keeps
that volume; its force and suction follow from (V*, d*) and it ruptures at the
volume-controlled rupture distance (capillary.VolumeBridgeTable). Bridges persist across gaps.
"""

import math

import numba
import numpy as np

from capillary.table import YADE_RADIUS_RATIOS, BridgeTable, lookup_suction
from capillary.validation import (check_bridge_stiffness, check_contact_angle,
                                  check_pendular_suction)
from capillary.volume_table import VolumeBridgeTable, lookup_volume
from dem.contact_law import ContactForces
from dem.neighbors import NeighborList, gather_pair_vectors
from dem.validate import check_positive, check_range
from dem.walls import WallForces
from homogenize.contact_stress import pair_stress_sum

NO_BRIDGE = 0
AT_CONTACT = 1
ACROSS_GAP = 2

#: Names of the per-pair arrays kept in ``Contacts.extra`` (volume control adds bridge_suction).
PAIR_ARRAYS = ("bridge", "bridge_volume", "bridge_force", "filling_angle_i", "filling_angle_j")

MODELS = ("exact", "toroidal")
CONTROLS = ("suction", "volume")


@numba.njit(cache=True, inline="always")
def _clear(k, state, volume, force, filling_i, filling_j, pair_force):
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
def _apply_across_gap(k, position, i, j, magnitude, pair_force):
    d0 = position[j, 0] - position[i, 0]
    d1 = position[j, 1] - position[i, 1]
    d2 = position[j, 2] - position[i, 2]
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
def contact_bridges(radius, pair_i, pair_j, overlap, state, volume, force, filling_i, filling_j,
                    suction, surface_tension, radius_ratios, suction_axis, distance_low,
                    log_distance_rupture, log_values):
    """Suction-controlled bridges that exist exactly while the spheres touch (thesis Ch. 5.2.2).

    A pair that starts touching gets its bridge from the table at d* = 0 (force, volume and
    filling angles depend only on the radii then); a pair that stops touching loses it. In
    steady state this pass only reads overlap and state. overlap: the contact law's, this step.
    """
    for k in numba.prange(len(pair_i)):
        touching = overlap[k] > 0.0
        if touching == (state[k] == AT_CONTACT):   # no change: the (predictable) common case
            continue
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
def gather_contact_bridges(force, normal, row_start, second_start, second_pair, out):
    """Add bridge forces of magnitude ``force`` (0 where no bridge) along the contact normals
    (unit i -> j, current for touching pairs): +F n on i, -F n on j (attraction).

    Branch-free (a pair without bridge adds 0 x its normal); each particle sums its own pairs
    in a fixed order, as dem.neighbors.gather_pair_vectors: deterministic without atomics.
    """
    for p in numba.prange(len(row_start) - 1):
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
def suction_bridges(position, radius, pair_i, pair_j, overlap, normal, state, volume, force,
                    filling_i, filling_j, pair_force, suction, surface_tension, radius_ratios,
                    suction_axis, distance_low, log_distance_rupture, log_values):
    """Suction-controlled bridges that persist across gaps (thesis Table 5.1, ``persist``).

    A bridge forms when the spheres touch and lives while the table has a bridge at the gap
    (d* = gap / R2 up to the rupture distance at u* = s R2 / gamma). At contact its values are
    cached (looked up once per contact); across a gap it is looked up each step and pulls along
    the current branch vector. overlap and normal: the contact law's values of this step.
    suction [Pa], surface_tension [N/m]; the last five arguments are a BridgeTable's arrays().
    Fills the per-pair state and pair_force (force on j from i) [N].
    """
    for k in numba.prange(len(pair_i)):
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
                _apply_across_gap(k, position, i, j, force[k], pair_force)
            else:
                _clear(k, state, volume, force, filling_i, filling_j, pair_force)
        else:
            pair_force[k, 0] = 0.0
            pair_force[k, 1] = 0.0
            pair_force[k, 2] = 0.0


@numba.njit(cache=True, parallel=True)
def volume_bridges(position, radius, pair_i, pair_j, overlap, normal, state, volume, force,
                   filling_i, filling_j, bridge_suction, pair_force, formation_suction,
                   surface_tension, roughness, suction_table, volume_table):
    """Volume-controlled bridges: formed at contact with the volume of the suction-controlled
    bridge at ``formation_suction`` [Pa], then of constant volume; force and suction from
    (V*, d*) (capillary.lookup_volume), rupture where no bridge of that volume exists.

    roughness: the meniscus separation of touching spheres / R2 (asperities hold the wetted
    surfaces H = roughness R2 apart, thesis Ch. 4's H): d* = roughness at contact and
    gap / R2 + roughness across a gap; 0 for smooth spheres. A pair whose bridge at formation
    would not span H gets none.
    suction_table, volume_table: the arrays() of a BridgeTable and a VolumeBridgeTable.
    """
    for k in numba.prange(len(pair_i)):
        i = pair_i[k]
        j = pair_j[k]
        touching = overlap[k] > 0.0
        if state[k] == NO_BRIDGE and not touching:
            pair_force[k, 0] = 0.0
            pair_force[k, 1] = 0.0
            pair_force[k, 2] = 0.0
            continue
        larger = max(radius[i], radius[j])
        ratio = larger / min(radius[i], radius[j])
        cube = larger * larger * larger
        if state[k] == NO_BRIDGE:
            forms, _, volume_star, _, _ = lookup_suction(
                suction_table[0], suction_table[1], suction_table[2], suction_table[3],
                suction_table[4], ratio, formation_suction * larger / surface_tension, roughness)
            if not forms:
                pair_force[k, 0] = 0.0
                pair_force[k, 1] = 0.0
                pair_force[k, 2] = 0.0
                continue
            volume[k] = volume_star * cube
            state[k] = ACROSS_GAP   # not yet evaluated at contact
        if touching and state[k] == AT_CONTACT:
            _apply_along(k, force[k], normal[k, 0], normal[k, 1], normal[k, 2], pair_force)
            continue
        gap_star = roughness if touching else roughness - overlap[k] / larger
        exists, force_star, suction_star, delta1, delta2 = lookup_volume(
            volume_table[0], volume_table[1], volume_table[2], volume_table[3], volume_table[4],
            ratio, volume[k] / cube, gap_star)
        if not exists:
            _clear(k, state, volume, force, filling_i, filling_j, pair_force)
            bridge_suction[k] = 0.0
            continue
        _store(k, radius[i], radius[j], force_star, delta1, delta2, surface_tension, force,
               filling_i, filling_j)
        bridge_suction[k] = suction_star * surface_tension / larger
        if touching:
            state[k] = AT_CONTACT
            _apply_along(k, force[k], normal[k, 0], normal[k, 1], normal[k, 2], pair_force)
        else:
            state[k] = ACROSS_GAP
            _apply_across_gap(k, position, i, j, force[k], pair_force)


@numba.njit(cache=True, parallel=True)
def pendular_overlap_counts(position, row_start, second_start, second_pair, pair_i, pair_j,
                            state, filling_i, filling_j):
    """Per particle, the number of pairs of its menisci that overlap (SPEC section 4 pendular
    limit): two wetted caps whose normals are separated by less than the sum of their filling
    angles (YADE's Law2_ScGeom_CapillaryPhys_Capillarity fusion test)."""
    count = len(row_start) - 1
    overlaps = np.zeros(count, np.int64)
    for p in numba.prange(count):
        size = row_start[p + 1] - row_start[p] + second_start[p + 1] - second_start[p]
        direction = np.empty((size, 3))
        angle = np.empty(size)
        found = 0
        for slot in range(size):
            if slot < row_start[p + 1] - row_start[p]:
                k = row_start[p] + slot
                other = pair_j[k]
                cap = filling_i[k]
            else:
                k = second_pair[second_start[p] + slot - (row_start[p + 1] - row_start[p])]
                other = pair_i[k]
                cap = filling_j[k]
            if state[k] == NO_BRIDGE:
                continue
            length = 0.0
            for c in range(3):
                direction[found, c] = position[other, c] - position[p, c]
                length += direction[found, c] ** 2
            length = math.sqrt(length)
            for c in range(3):
                direction[found, c] /= length
            angle[found] = math.radians(cap)
            found += 1
        for a in range(found):
            for b in range(a + 1, found):
                cosine = (direction[a, 0] * direction[b, 0] + direction[a, 1] * direction[b, 1]
                          + direction[a, 2] * direction[b, 2])
                if math.acos(min(max(cosine, -1.0), 1.0)) < angle[a] + angle[b]:
                    overlaps[p] += 1
    return overlaps


def table_radius_ratios(largest_ratio):
    """YADE's radius ratios 1 ... 10 up to the first one covering ``largest_ratio``."""
    if largest_ratio > YADE_RADIUS_RATIOS[-1] * (1.0 + 1e-12):
        raise ValueError(f"radius ratio R2/R1 = {largest_ratio:g} of the sample is outside the "
                         f"valid range [1, {YADE_RADIUS_RATIOS[-1]:g}] of the bridge tables")
    for index, ratio in enumerate(YADE_RADIUS_RATIOS):
        if ratio >= largest_ratio * (1.0 - 1e-12):
            return YADE_RADIUS_RATIOS[:index + 1]
    return YADE_RADIUS_RATIOS


class CapillaryBridges:
    """Capillary bridges between touching spheres (SPEC section 4); an operation ``apply(sim)``.

    suction [Pa] >= 0: imposed matric suction (suction control), or the suction at which bridges
        form (volume control);
    surface_tension [N/m] > 0 (thesis Ch. 5: 0.073); contact_angle [deg] in [0, 90);
    model: "exact" (Young–Laplace tables, capillary.BridgeTable) or "toroidal" (thesis
        Appendix A, equal spheres only);
    control: "suction" (default, thesis Ch. 5) or "volume" (each bridge keeps its volume);
    persist: suction control only: bridges live up to the rupture distance instead of breaking
        when contact is lost (volume-controlled bridges always persist up to rupture);
    roughness: volume control only: meniscus separation of touching spheres H / R2 in [0, 0.5]
        (rough grains, thesis Ch. 4's H/R; 0: smooth spheres, the default);
    table_options: keyword arguments of BridgeTable.cached (model 'exact') or
        capillary.toroidal_table.toroidal_table (model 'toroidal'): resolution, range.

    Use ``insert(sim)`` to place it after the contact and wall forces and, for bridges across
    gaps, widen the neighbour list's reach. Radii must not change while bridges exist.
    """

    def __init__(self, suction, surface_tension=0.073, contact_angle=0.0, model="exact",
                 control="suction", persist=False, table_options=None, roughness=0.0):
        self.suction = check_range("suction", suction, 0.0, unit="Pa")
        self.surface_tension = check_positive("surface_tension", surface_tension, "N/m")
        self.contact_angle = check_contact_angle(contact_angle)
        if model not in MODELS:
            raise ValueError(f"model = {model!r} is not one of {MODELS}")
        if control not in CONTROLS:
            raise ValueError(f"control = {control!r} is not one of {CONTROLS}")
        if control == "volume" and model != "exact":
            raise ValueError("volume-controlled bridges need model='exact'")
        self.model = model
        self.control = control
        self.persist = bool(persist) or control == "volume"
        self.roughness = check_range("roughness", roughness, 0.0, 0.5)
        if self.roughness > 0.0 and control != "volume":
            raise ValueError(f"roughness = {self.roughness:g} needs control='volume' (suction-"
                             "controlled bridges are between smooth spheres: roughness 0)")
        self.table_options = dict(table_options or {})
        self.suction_table = None
        self.volume_table = None
        self.required_range = 0.0
        self.pair_force = np.zeros((0, 3))
        self._table_arrays = None
        self._contacts = None
        self._bridges = 0
        self._radius_bounds = None

    # ---------------------------------------------------------------- set-up, once per sample
    def insert(self, sim):
        """Add this operation to ``sim`` right after its ContactForces / WallForces operations
        (before servo and integrator), load the tables and, when bridges can persist across
        gaps, set the NeighborList's interaction_range to the largest rupture distance."""
        indices = [n for n, op in enumerate(sim.operations)
                   if isinstance(op, (ContactForces, WallForces))]
        if not indices:
            raise ValueError("CapillaryBridges must follow a ContactForces operation: the "
                             "simulation has none")
        for contact_law in (op for op in sim.operations if isinstance(op, ContactForces)):
            check_bridge_stiffness(contact_law.young, float(sim.particles.radius.min()),
                                   self.surface_tension)
        sim.operations.insert(max(indices) + 1, self)
        self.load_tables(float(sim.particles.radius.min()), float(sim.particles.radius.max()))
        if self.persist:
            neighbors = sim.operation(NeighborList)
            neighbors.interaction_range = max(neighbors.interaction_range, self.required_range)
        return self

    def load_tables(self, low, high):
        """Check the input against spheres of radii in [low, high] [m] and load (or build and
        cache) the tables; ValueError naming the parameter when out of range."""
        low = check_positive("smallest radius", low, "m")
        high = check_range("largest radius", high, low, unit="m")
        if self._radius_bounds == (low, high):
            return
        ratio = high / low
        suction_star_high = self.suction * high / self.surface_tension
        options = dict(self.table_options)
        if self.model == "toroidal":
            if ratio > 1.0:
                raise ValueError(f"model='toroidal' needs equal spheres; the radii range from "
                                 f"{low:g} to {high:g} m (use model='exact')")
            from capillary.toroidal_table import toroidal_table

            options.setdefault("suction_max", max(suction_star_high * 1.001, 1e-3))
            self.suction_table = toroidal_table(self.contact_angle, **options)
        else:
            options.setdefault("radius_ratios", table_radius_ratios(ratio))
            self.suction_table = BridgeTable.cached(self.contact_angle, **options)
        if suction_star_high > self.suction_table.suction_max:
            raise ValueError(
                f"suction = {self.suction:g} Pa is outside the valid range [0, "
                f"{self.suction_table.suction_max * self.surface_tension / high:g}] Pa for these "
                f"spheres: u* = s R2/gamma = {suction_star_high:g} (R2 = {high:g} m, gamma = "
                f"{self.surface_tension:g} N/m) exceeds the table's "
                f"{self.suction_table.suction_max:g}")
        check_pendular_suction(self.suction_table, self.suction, low, self.surface_tension)
        if self.control == "volume":
            self.volume_table = VolumeBridgeTable.cached(
                self.contact_angle, radius_ratios=self.suction_table.radius_ratios)
        self._table_arrays = self.suction_table.arrays()
        self.required_range = self._rupture_range(low, high)
        self._radius_bounds = (low, high)

    def _rupture_range(self, low, high):
        """Upper bound of the gap [m] at which a bridge can still exist (0 if none persists).

        The rupture distance d*_rupture(u*) decreases with u*, and u* = s R2/gamma >= s Rmin/gamma,
        so Rmax * max_r d*_rupture(r, s Rmin/gamma) bounds D (5 % margin). Volume control: the
        largest volume forms at the smallest suction; d*_rupture grows with the volume.
        """
        if not self.persist:
            return 0.0
        table = self.suction_table
        xi = math.log1p(self.suction * low / self.surface_tension / table.suction_scale)
        nodes = np.log1p(table.suction / table.suction_scale)
        ruptures = [np.interp(xi, nodes, row) for row in table.distance_rupture]
        if self.control == "suction":
            return 1.05 * high * max(ruptures)
        volumes = [table.lookup(r, self.suction * low / self.surface_tension, 0.0)[2]
                   for r in table.radius_ratios]
        largest = []
        vtable = self.volume_table
        for index, axis in enumerate(vtable.volume_axes):
            volume_nodes = np.linspace(axis[0], axis[1], vtable.n_volume)
            largest.append(np.interp(math.log(max(volumes)), volume_nodes,
                                     vtable.distance_rupture[index]))
        return 1.05 * high * max(largest)

    # ---------------------------------------------------------------- every step
    def _attach(self, sim):
        """Per-pair arrays for a new neighbour list (after a rebuild): create or pick them up."""
        contacts = sim.contacts
        names = PAIR_ARRAYS + (("bridge_suction",) if self.control == "volume" else ())
        for name in names:
            if name not in contacts.extra:
                contacts.extra[name] = np.zeros(len(contacts), np.int8 if name == "bridge"
                                                else np.float64)
        carried = int(np.count_nonzero(contacts.extra["bridge"]))
        if carried < self._bridges:
            raise RuntimeError(
                f"{self._bridges - carried} liquid bridge(s) left the neighbour list at a "
                f"rebuild: its reach (NeighborList.interaction_range = "
                f"{sim.operation(NeighborList).interaction_range:g} m plus skin) is shorter than "
                f"the rupture distance ({self.required_range:g} m); use "
                f"CapillaryBridges.insert(sim) or set NeighborList.interaction_range >= "
                f"{self.required_range:g}")
        self.pair_force = np.zeros((len(contacts) if self.persist else 0, 3))
        self._contacts = contacts

    def _sync(self, sim):
        """Tables and per-pair arrays for the current radii and neighbour list."""
        if sim.contacts is self._contacts:
            return
        self.load_tables(float(sim.particles.radius.min()), float(sim.particles.radius.max()))
        reach = sim.operation(NeighborList).interaction_range
        if self.persist and reach < self.required_range:
            raise ValueError(
                f"NeighborList.interaction_range = {reach:g} m is below the largest rupture "
                f"distance {self.required_range:g} m of persisting bridges: bridges could be "
                f"missed; use CapillaryBridges.insert(sim) or raise it")
        self._attach(sim)

    def apply(self, sim):
        self._sync(sim)
        p = sim.particles
        c = sim.contacts
        extra = c.extra
        if self.control == "suction" and not self.persist:
            contact_bridges(p.radius, c.pair_i, c.pair_j, c.overlap, extra["bridge"],
                            extra["bridge_volume"], extra["bridge_force"],
                            extra["filling_angle_i"], extra["filling_angle_j"], self.suction,
                            self.surface_tension, *self._table_arrays)
            gather_contact_bridges(extra["bridge_force"], c.normal, c.row_start, c.second_start,
                                   c.second_pair, p.force)
            return
        if self.control == "suction":
            suction_bridges(p.position, p.radius, c.pair_i, c.pair_j, c.overlap, c.normal,
                            extra["bridge"], extra["bridge_volume"], extra["bridge_force"],
                            extra["filling_angle_i"], extra["filling_angle_j"], self.pair_force,
                            self.suction, self.surface_tension, *self._table_arrays)
        else:
            volume_bridges(p.position, p.radius, c.pair_i, c.pair_j, c.overlap, c.normal,
                           extra["bridge"], extra["bridge_volume"], extra["bridge_force"],
                           extra["filling_angle_i"], extra["filling_angle_j"],
                           extra["bridge_suction"], self.pair_force, self.suction,
                           self.surface_tension, self.roughness, self._table_arrays,
                           self.volume_table.arrays())
        gather_pair_vectors(self.pair_force, c.row_start, c.second_start, c.second_pair, p.force)
        if self.persist:
            self._bridges = int(np.count_nonzero(extra["bridge"]))

    # ---------------------------------------------------------------- measures (record time)
    def bridges(self, contacts):
        """Boolean mask of the pairs holding a bridge."""
        return contacts.extra["bridge"] != NO_BRIDGE

    def count(self, sim):
        """Number of bridges."""
        self._sync(sim)
        return int(np.count_nonzero(sim.contacts.extra["bridge"]))

    def water_volume(self, contacts):
        """Total liquid volume of the bridges [m^3]."""
        return float(np.sum(contacts.extra["bridge_volume"]))

    def saturation(self, sim):
        """Degree of saturation Sr = sum(V_bridge) / V_voids, V_voids = box volume minus the
        solid volume."""
        self._sync(sim)
        voids = sim.walls.volume() - sim.particles.solid_volume()
        return self.water_volume(sim.contacts) / voids

    def mean_suction(self, sim):
        """The imposed suction [Pa] (suction control) or the bridges' mean suction (volume
        control; NaN without bridges)."""
        self._sync(sim)
        if self.control == "suction":
            return self.suction
        mask = self.bridges(sim.contacts)
        if not mask.any():
            return math.nan
        return float(np.mean(sim.contacts.extra["bridge_suction"][mask]))

    def capillary_stress(self, sim):
        """Love–Weber stress of the capillary forces (1/V) sum l_i f^cap_j [Pa] (3x3), with the
        sign convention of homogenize.contact_stress (l = x_j - x_i, f on j from i,
        compression positive): attractive bridges give a negative (tensile) stress, and in
        static equilibrium sigma_wall = sigma_contact + sigma_capillary."""
        self._sync(sim)
        c = sim.contacts
        total = pair_stress_sum(sim.particles.position, c.pair_i, c.pair_j,
                                self.pair_forces(sim), self.bridges(c))
        return total / sim.walls.volume()

    def pair_forces(self, sim):
        """Capillary force on j from i per pair (K, 3) [N] as applied at the last step."""
        self._sync(sim)
        if self.persist:
            return self.pair_force
        c = sim.contacts
        return -c.extra["bridge_force"][:, None] * c.normal

    def pendular_overlaps(self, sim):
        """Number of pairs of overlapping menisci on a same particle, summed over particles."""
        self._sync(sim)
        c = sim.contacts
        e = c.extra
        return int(np.sum(pendular_overlap_counts(
            sim.particles.position, c.row_start, c.second_start, c.second_pair, c.pair_i,
            c.pair_j, e["bridge"], e["filling_angle_i"], e["filling_angle_j"])))

    def quantities(self):
        """Recorded columns for a history recorder (dem.triaxial.start_shear picks them up)."""
        return {
            "saturation": self.saturation,
            "suction": self.mean_suction,
            "sigma_capillary": self.capillary_stress,
            "bridges": self.count,
            "pendular_overlaps": self.pendular_overlaps,
        }
