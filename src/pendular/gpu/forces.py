"""Contact forces on the device: the CPU's contact law (pendular.dem.contact_law) and, wet,
its capillary bridges (pendular.capillary.bridge_kernels: suction-controlled at contact or
persisting across gaps, volume-controlled with their liquid's exchange), compiled from the
CPU's own source (pendular.gpu.cuda.device_twin), one thread per particle's row of pairs; then
a gather of each particle's pair forces in a fixed order (no float atomics), with the
frictionless walls.

Pairs are kept as rows stored slot by slot (pendular.gpu.neighbors): pair k = s * N + p is
particle p's s-th neighbour j > p (rows sorted by j); ``second_pair`` lists, per particle, the
pairs in which it is the second member, sorted by their first member. The gather is the
CPU's sum of a particle's terms (pendular.dem.contact_law._sum_pair_terms) over these rows
(ranges of step N): first the pairs in which it is the second member, then its own, so that a
particle's force is the CPU's sum in the CPU's order.
"""

from collections import namedtuple

import numpy as np

from pendular.capillary.bridge_kernels import (FORMS_FROM_FILMS, RUPTURED,
    _exchange_ruptured, _follow_across_gap, _follow_contact, _follow_volume, _form_at_contact,
    _form_from_films)
from pendular.capillary.bridge_state import AT_CONTACT
from pendular.dem.contact_law import (ContactForces, _evaluate_pair, _first_member,
    _store_row_sums, _stretched, _sum_pair_terms, wall_contact_stiffness)
from pendular.dem.hertz_mindlin import (DampedLinearForces, HertzMindlinForces,
    _evaluate_damped_pair)
from pendular.dem.neighbors import _sum_pair_forces
from pendular.gpu.cuda import cuda, device, device_twin
from pendular.gpu.operations import DeviceSide, device_side

first_member = device_twin(_first_member)
evaluate_pair = device_twin(_evaluate_pair)
evaluate_damped_pair = device_twin(_evaluate_damped_pair)
is_stretched = device_twin(_stretched)
follow_contact = device_twin(_follow_contact)
follow_across_gap = device_twin(_follow_across_gap)
form_at_contact = device_twin(_form_at_contact)
follow_volume = device_twin(_follow_volume)
exchange_ruptured = device_twin(_exchange_ruptured)
form_from_films = device_twin(_form_from_films)
sum_pair_forces = device_twin(_sum_pair_forces)
sum_pair_terms = device_twin(_sum_pair_terms)
store_row_sums = device_twin(_store_row_sums)
wall_stiffness = device_twin(wall_contact_stiffness)


#: The particles' state the pair law reads: (N, 3) [m], [m/s], [rad/s]; (N,) [m], [kg].
Particles = namedtuple("Particles", "position velocity angular_velocity radius mass")
#: The pairs (pendular.gpu.neighbors' rows: ``count`` per particle, ``first`` and ``second``
#: members per pair) and their state: the tangential spring, normal, overlap, normal force
#: and force on j from i (pendular.gpu.state).
Pairs = namedtuple("Pairs", "count first second shear_force normal overlap normal_force force")
#: The box as the pair law sees it: each pair's ``image`` (K, 3) int8, ``period`` and
#: ``affine_rate`` (zeros inside walls: pendular.gpu.state's no_image, no_period).
Images = namedtuple("Images", "image period affine_rate")
#: The contact law's parameters (a law's device side, pendular.gpu.forces.LinearLaw.law) and
#: the time step dt [s].
Law = namedtuple("Law", "stiffness shear_stiffness tan_friction damped hertz damping dt")
#: Capillary bridges: what runs (``wet``, ``persist``, ``volume_control``), the columns of
#: pendular.gpu.state's ``bridges`` (BridgeState's fields), the forces on j from i of bridges
#: across gaps ``pair_force`` (K, 3) [N], ``suction`` [Pa] and ``surface_tension`` [N/m].
Bridges = namedtuple("Bridges", "wet persist volume_control state volume force filling_i "
                                "filling_j pair_suction pair_force suction surface_tension")
#: Volume control's liquid: ``roughness``, ``closed`` and pendular.gpu.state's ``film``,
#: ``released``, ``events``, ``marked``.
Liquid = namedtuple("Liquid", "roughness closed film released events marked")
#: The transposed index of pendular.gpu.neighbors: per particle the ``count`` of pairs in
#: which it is the second member and those pairs, ``pair`` (slot by slot).
Transposed = namedtuple("Transposed", "count pair")
#: The bridges as the gather reads them: at contact (``wet``) their ``attraction`` (K,) [N]
#: along the normals, across gaps (``persist``) their forces on j from i ``pair_force``.
Gathered = namedtuple("Gathered", "wet attraction persist pair_force")


@cuda.jit
def pair_forces(particles, pairs, images, law, bridges, table, liquid, volume_table, flags):
    """Every pair of particle p's row (one thread per particle; the bundles Particles,
    Pairs, Images, Law, Bridges, Liquid; ``table`` a BridgeTable's arrays(),
    ``volume_table`` a VolumeBridgeTable's, stand-ins when dry): the CPU's contact law
    (_evaluate_pair; with ``damped``, the damped law of pendular.dem.hertz_mindlin,
    _evaluate_damped_pair, of ``mass`` (N,) [kg], ``hertz``, ``damping`` and the stiffnesses
    standing for its modulus and tangential stiffness; with its tests as the CPU's
    pair_forces: images where ``period`` (3,) [m] is not zero, each pair's in ``image``
    (K, 3) int8, and stretching where ``affine_rate`` (3,) [1/s] is not; inside walls
    (1, 3) and (3,) zeros stand for the arrays it then does not read), then (``wet``) its
    suction-controlled bridge at contact (_follow_contact: the bridge arrays of
    pendular.capillary.bridge_state.BridgeState; the pairs' first members read when a
    bridge forms) or, with ``persist``, across gaps up to its rupture distance
    (_follow_across_gap, the CPU's suction_bridges per pair: its force on j from i [N] into
    the bridges' ``pair_force`` (K, 3), pulling along the branch vector, which reads
    ``image`` and ``period``: zeros for every pair inside walls); with ``volume_control`` a
    volume-controlled bridge (_follow_volume, the CPU's volume_bridges per pair:
    ``suction`` the formation suction, the liquid; the events it marks counted in
    ``marked``, for exchange_liquid). Thread 0 clears the rebuild flag: this step's
    rebuild, if any, is done."""
    position, velocity, angular_velocity, radius, mass = particles
    pair_count, pair_i, pair_j, shear_force, normal, overlap, normal_force, force = pairs
    image, period, affine_rate = images
    young, shear_ratio, tan_friction, damped, hertz, damping, dt = law
    (wet, persist, volume_control, state, volume, bridge_force, filling_i, filling_j,
     bridge_suction, bridge_pair_force, suction, surface_tension) = bridges
    radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values = table
    roughness, closed, film, released, events, marked = liquid
    p = cuda.grid(1)
    if p == 0:
        flags[0] = 0
    n = position.shape[0]
    if p >= n:
        return
    periodic = period[0] != 0.0 or period[1] != 0.0 or period[2] != 0.0
    stretched = is_stretched(affine_rate)
    first = first_member(p, position, velocity, angular_velocity, radius)
    events_marked = 0
    for s in range(pair_count[p]):
        k = s * n + p
        if damped:
            evaluate_damped_pair(k, first, mass[p], pair_j[k], position, velocity,
                                 angular_velocity, radius, mass, image, period, periodic,
                                 affine_rate, stretched, shear_force, normal, overlap,
                                 normal_force, force, hertz, young, shear_ratio, damping,
                                 tan_friction, dt)
        else:
            evaluate_pair(k, first, pair_j[k], position, velocity, angular_velocity, radius,
                          image, period, periodic, affine_rate, stretched, shear_force, normal,
                          overlap, normal_force, force, young, shear_ratio, tan_friction, dt)
        if wet and volume_control:
            events_marked += follow_volume(
                k, position, radius, pair_i, pair_j, image, period, overlap, normal, state,
                volume, bridge_force, filling_i, filling_j, bridge_suction, bridge_pair_force,
                film, released, events, suction, surface_tension, roughness, radius_ratios,
                suction_axis, distance_low, log_distance_rupture, log_values, volume_table,
                closed)
        elif wet and persist:
            follow_across_gap(k, position, radius, pair_i, pair_j, image, period, overlap,
                              normal, state, volume, bridge_force, filling_i, filling_j,
                              bridge_pair_force, suction, surface_tension, radius_ratios,
                              suction_axis, distance_low, log_distance_rupture, log_values)
        elif wet:
            follow_contact(k, radius, pair_i, pair_j, overlap, state, volume, bridge_force,
                           filling_i, filling_j, suction, surface_tension, radius_ratios,
                           suction_axis, distance_low, log_distance_rupture, log_values)
    if events_marked > 0:
        cuda.atomic.add(marked, 0, events_marked)


@cuda.jit
def exchange_liquid(radius, pairs, transposed, state, volume, liquid, share, smallest_star,
                    largest_star, liquid_lost):
    """The liquid exchanges of the events pair_forces marked (volume control, a closed amount:
    the CPU's exchange_liquid), on one thread, in the CPU's pair order (each particle's row in
    turn): the ruptured bridges' liquid shared among their grains' bridges (``share``) or
    lost, added to ``liquid_lost`` (1,) [m^3], then the bridges that form from films; nothing
    when ``marked`` (1,) counted no event (the CPU's test), else it is cleared. The pairs of a
    grain q are ranges of step N: its own, slots q + s N, and those where it is second,
    ``second_pair[q + s N]`` (the bundles Pairs, Transposed, Liquid)."""
    pair_count, pair_i, pair_j = pairs.count, pairs.first, pairs.second
    second_count, second_pair = transposed
    film, released, events, marked = liquid.film, liquid.released, liquid.events, liquid.marked
    if cuda.grid(1) != 0 or marked[0] == 0:
        return
    marked[0] = 0
    n = radius.shape[0]
    lost = 0.0
    for p in range(n):
        for s in range(pair_count[p]):
            k = s * n + p
            if events[k] == RUPTURED:
                j = pair_j[k]
                lost += exchange_ruptured(
                    k, share, range(p, p + pair_count[p] * n, n),
                    range(p, p + second_count[p] * n, n), range(j, j + pair_count[j] * n, n),
                    range(j, j + second_count[j] * n, n), second_pair, radius, pair_i, pair_j,
                    state, volume, film, released, events, largest_star)
    for p in range(n):
        for s in range(pair_count[p]):
            k = s * n + p
            if events[k] == FORMS_FROM_FILMS:
                form_from_films(k, radius, pair_i, pair_j, state, volume, film, events,
                                smallest_star, largest_star)
    liquid_lost[0] += lost


@cuda.jit
def refresh_bridges(radius, pair_count, pair_j, columns, suction, surface_tension, table):
    """Every bridge at contact (AT_CONTACT) of particle p's row looked up again at a new
    ``suction`` [Pa] (the CPU's refresh_contact_bridges at the first step after
    SuctionBridges.set_suction; its values depend on the radii alone), one thread per row;
    ``columns`` the bridges' state, volume, force and filling angles, ``table`` a
    BridgeTable's arrays()."""
    state, volume, bridge_force, filling_i, filling_j = columns
    radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values = table
    p = cuda.grid(1)
    n = radius.shape[0]
    if p >= n:
        return
    for s in range(pair_count[p]):
        k = s * n + p
        if state[k] == AT_CONTACT:
            form_at_contact(k, radius[p], radius[pair_j[k]], state, volume, bridge_force,
                            filling_i, filling_j, suction, surface_tension, radius_ratios,
                            suction_axis, distance_low, log_distance_rupture, log_values)


@device
def wall_push(p, axis, high, position, radius, wall_position, young):
    """(push [N], kn [N/m], overlap [m]) of particle p on the low or ``high`` wall of
    ``axis`` (pendular.dem.contact_law.wall_forces; push 0 when apart)."""
    r = radius[p]
    if high:
        gap_overlap = r - (wall_position[2 * axis + 1] - position[p, axis])
    else:
        gap_overlap = r - (position[p, axis] - wall_position[2 * axis])
    if gap_overlap > 0.0:
        kn = wall_stiffness(young, r)
        return kn * gap_overlap, kn, gap_overlap
    return 0.0, 0.0, 0.0


@device
def add_wall_pushes(p, f0, f1, f2, position, radius, wall_position, young):
    """(f0, f1, f2) plus the wall springs' forces on p, low then high wall of each axis."""
    for axis in range(3):
        low, _, _ = wall_push(p, axis, False, position, radius, wall_position, young)
        high, _, _ = wall_push(p, axis, True, position, radius, wall_position, young)
        if axis == 0:
            f0 = f0 + low - high
        elif axis == 1:
            f1 = f1 + low - high
        else:
            f2 = f2 + low - high
    return f0, f1, f2


@cuda.jit
def gather(position, radius, pairs, transposed, gathered, walls_first, wall_position,
           wall_young, force, torque):
    """Each particle's force and torque from its pairs, by the CPU's sum (_sum_pair_terms
    over the device's rows; less the ``attraction`` (K,) [N] along the normals when ``wet``:
    bridges at contact) and the walls, set (not added), in the CPU's order: the walls first
    when WallForces runs before the operation that gathers the pairs (``walls_first``: the
    contact law, or the bridges that join its gather), else after; ``wall_young`` 0 [Pa] in
    a periodic cell, which has no walls (their springs add zeros). With ``persist`` the
    bridges' forces on j from i ``bridge_pair_force`` (K, 3) [N] are added last, by the CPU's
    sum (_sum_pair_forces, the CPU's gather_pair_forces after the contact law and the
    walls). The bundles Pairs, Transposed and Gathered."""
    pair_count, pair_force, normal, overlap = (pairs.count, pairs.force, pairs.normal,
                                               pairs.overlap)
    second_count, second_pair = transposed
    wet, attraction, persist, bridge_pair_force = gathered
    p = cuda.grid(1)
    n = position.shape[0]
    if p >= n:
        return
    f0 = f1 = f2 = 0.0
    if walls_first:
        f0, f1, f2 = add_wall_pushes(p, f0, f1, f2, position, radius, wall_position,
                                     wall_young)
    sums = (f0, f1, f2, 0.0, 0.0, 0.0)
    second_slots = range(p, p + second_count[p] * n, n)
    own_pairs = range(p, p + pair_count[p] * n, n)
    if wet:         # a kernel takes no None: the dry sum gets it here (no attraction term)
        sums = sum_pair_terms(sums, radius[p], pair_force, attraction, normal, overlap,
                              second_pair, second_slots, own_pairs)
    else:
        sums = sum_pair_terms(sums, radius[p], pair_force, None, normal, overlap,
                              second_pair, second_slots, own_pairs)
    f0, f1, f2, t0, t1, t2 = sums
    if not walls_first:
        f0, f1, f2 = add_wall_pushes(p, f0, f1, f2, position, radius, wall_position,
                                     wall_young)
    if persist:
        v0, v1, v2 = sum_pair_forces(bridge_pair_force, second_pair, own_pairs, second_slots)
        f0 += v0
        f1 += v1
        f2 += v2
    store_row_sums(p, (f0, f1, f2, t0, t1, t2), force, torque)


def tan_friction(law):
    """tan of the friction angle of ``law`` (a contact law: ``friction_deg`` [deg]) [-], as
    the CPU's."""
    return float(np.tan(np.radians(law.friction_deg)))


@device_side(ContactForces)
class LinearLaw(DeviceSide):
    """The linear contact law's side (ContactForces): pair_forces runs _evaluate_pair."""

    family = "force"
    role = "contact law"
    #: Whether pair_forces runs the damped law (_evaluate_damped_pair).
    damped = False

    def law(self, dt):
        """The Law of pair_forces now, over steps of ``dt`` [s]: E [Pa] and ks / kn [-]."""
        op = self.op
        return Law(op.young, op.shear_ratio, tan_friction(op), False, False, 0.0, dt)


@device_side(HertzMindlinForces, DampedLinearForces)
class DampedLaw(LinearLaw):
    """The damped and Hertz–Mindlin laws' side (pendular.dem.hertz_mindlin): pair_forces runs
    _evaluate_damped_pair."""

    damped = True

    def law(self, dt):
        """The Law of pair_forces now: its modulus and tangential stiffness, damping."""
        op = self.op
        return Law(op.modulus, op.tangential, tan_friction(op), True, op.hertz, op.damping,
                   dt)

