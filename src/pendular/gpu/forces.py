"""Contact forces on the device: the CPU's contact law (pendular.dem.contact_law) and, wet,
its suction-controlled bridges at contact (pendular.capillary.bridge_kernels), compiled from
the CPU's own source (pendular.gpu.cuda.device_twin), one thread per particle's row of pairs;
then a gather of each particle's pair forces in a fixed order (no float atomics), with the
frictionless walls.

Pairs are kept as rows stored slot by slot (pendular.gpu.neighbors): pair k = s * N + p is
particle p's s-th neighbour j > p (rows sorted by j); ``second_pair`` lists, per particle, the
pairs in which it is the second member, sorted by their first member. The gather is the
CPU's sum of a particle's terms (pendular.dem.contact_law._sum_pair_terms) over these rows
(ranges of step N): first the pairs in which it is the second member, then its own, so that a
particle's force is the CPU's sum in the CPU's order.
"""

from pendular.capillary.bridge_kernels import _follow_contact
from pendular.dem.contact_law import (_evaluate_pair, _first_member, _store_row_sums,
    _stretched, _sum_pair_terms, wall_contact_stiffness)
from pendular.gpu.cuda import cuda, device, device_twin

first_member = device_twin(_first_member)
evaluate_pair = device_twin(_evaluate_pair)
is_stretched = device_twin(_stretched)
follow_contact = device_twin(_follow_contact)
sum_pair_terms = device_twin(_sum_pair_terms)
store_row_sums = device_twin(_store_row_sums)
wall_stiffness = device_twin(wall_contact_stiffness)


@cuda.jit
def pair_forces(position, velocity, angular_velocity, radius, pair_count, pair_i, pair_j,
                image, period, affine_rate, shear_force, normal, overlap, normal_force, force,
                young, shear_ratio, tan_friction, dt, flags, wet, state, volume, bridge_force,
                filling_i, filling_j, suction, surface_tension, radius_ratios, suction_axis,
                distance_low, log_distance_rupture, log_values):
    """Every pair of particle p's row (one thread per particle): the CPU's contact law
    (_evaluate_pair, with its tests as the CPU's pair_forces: images where ``period`` (3,)
    [m] is not zero, each pair's in ``image`` (K, 3) int8, and stretching where
    ``affine_rate`` (3,) [1/s] is not; inside walls (1, 3) and (3,) zeros stand for the
    arrays it then does not read), then (``wet``) its suction-controlled bridge at contact
    (_follow_contact: the bridge arrays of pendular.capillary.bridge_state.BridgeState, a
    BridgeTable's arrays(); ``pair_i``
    (K,) the pairs' first members, read when a bridge forms). Thread 0 clears the rebuild
    flag: this step's rebuild, if any, is done."""
    p = cuda.grid(1)
    if p == 0:
        flags[0] = 0
    n = position.shape[0]
    if p >= n:
        return
    periodic = period[0] != 0.0 or period[1] != 0.0 or period[2] != 0.0
    stretched = is_stretched(affine_rate)
    first = first_member(p, position, velocity, angular_velocity, radius)
    for s in range(pair_count[p]):
        k = s * n + p
        evaluate_pair(k, first, pair_j[k], position, velocity, angular_velocity, radius,
                      image, period, periodic, affine_rate, stretched, shear_force, normal,
                      overlap, normal_force, force, young, shear_ratio, tan_friction, dt)
        if wet:
            follow_contact(k, radius, pair_i, pair_j, overlap, state, volume, bridge_force,
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
def gather(position, radius, pair_count, second_count, second_pair, pair_force, normal,
           overlap, wet, attraction, walls_first, wall_position, wall_young, force, torque):
    """Each particle's force and torque from its pairs, by the CPU's sum (_sum_pair_terms
    over the device's rows; less the ``attraction`` (K,) [N] along the normals when ``wet``:
    bridges at contact) and the walls, set (not added), in the CPU's order: the walls first
    when WallForces runs before the operation that gathers the pairs (``walls_first``: the
    contact law, or the bridges that join its gather), else after; ``wall_young`` 0 [Pa] in
    a periodic cell, which has no walls (their springs add zeros)."""
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
    store_row_sums(p, (f0, f1, f2, t0, t1, t2), force, torque)
