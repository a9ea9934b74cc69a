"""Linear elastic–frictional contact law
(YADE's FrictMat / CundallStrack conventions, docs/physics.md 'The contact law').

Sphere–sphere: kn = 2 E R1 R2 / (R1 + R2), ks = shear_ratio * kn, Fn = kn * overlap (no tension),
incremental shear spring rotated into the current contact plane, Coulomb cap |Fs| <= Fn tan(phi).
Sphere–wall: frictionless, the wall acting as a virtual sphere of the same radius (kn = E R).

On one thread the pair forces go straight to the particles (scattered_pair_forces,
scatter_contact_forces): the sums of the multi-thread gather in the same order, so results do
not depend on the thread count. Those serial kernels are compiled without Numba's reference
counting (``_nrt=False``; they allocate nothing): a serial loop that hands arrays to
``inline="always"`` helpers counts references on every array at every pair, which a prange
loop does not. They run row by row, the first member's state and sums in registers through
its row, which a pair-by-pair loop would read again at every pair (docs/performance.md).

The GPU engine runs this module's per-pair functions (_first_member, _evaluate_pair,
_sum_pair_terms and what they call), compiled for the device from this source
(pendular.gpu.cuda.device_twin): they keep to what both targets compile (``math`` on scalars,
not NumPy's ufuncs).
"""

import math

import numba
import numpy as np

from pendular.dem import HOT_KERNEL_FASTMATH
from pendular.dem.prefetch import prefetch_distance, prefetch_row
from pendular.utils.validate import check_positive, check_range
from pendular.dem.virial import (SUM_BLOCKS, add_face_block, block_bounds,
    pair_force_with_attraction)

#: Largest ratio ks / kn of the tangential to the normal stiffness of a contact [-]
#: (``shear_ratio`` in [0, MAX_SHEAR_RATIO]).
MAX_SHEAR_RATIO = 10.0
#: Coulomb friction angles of a contact [deg]: [0, MAX_FRICTION_DEG) (a finite tan).
MAX_FRICTION_DEG = 90.0


@numba.njit(cache=True, inline="always")
def normal_stiffness(young, radius_i, radius_j):
    """Normal stiffness of a sphere pair kn = 2 E R1 R2 / (R1 + R2) [N/m] (YADE FrictMat,
    docs/physics.md 'The contact law'; E R for equal spheres); scalars or arrays."""
    return 2.0 * young * radius_i * radius_j / (radius_i + radius_j)


@numba.njit(cache=True, inline="always")
def wall_contact_stiffness(young, radius):
    """Normal stiffness of a sphere–wall contact kn = E R [N/m] (the wall as a virtual sphere
    of the same radius, YADE's Ig2_Box_Sphere_ScGeom); scalars or arrays."""
    return young * radius


@numba.njit(cache=True, inline="always")
def wall_gap(p, w, position, radius, wall_position):
    """(axis, side, gap [m]) of sphere p and wall w (0-5: the low and high walls of x, y, z):
    the wall's normal into the box is side e_axis; gap < 0 where they overlap."""
    axis = w // 2
    side = 1.0 if w % 2 == 0 else -1.0
    return axis, side, side * (position[p, axis] - wall_position[w]) - radius[p]


@numba.njit(cache=True, inline="always")
def _first_member(i, position, velocity, angular_velocity, radius):
    """Particle i's position, velocity, angular velocity and radius as one tuple of ten
    scalars (_evaluate_pair's ``first``): the row loops read it once for all of i's pairs."""
    return (position[i, 0], position[i, 1], position[i, 2], velocity[i, 0], velocity[i, 1],
            velocity[i, 2], angular_velocity[i, 0], angular_velocity[i, 1],
            angular_velocity[i, 2], radius[i])


@numba.njit(cache=True, inline="always")
def _stretched(affine_rate):
    """Whether ``affine_rate`` carries the particles: a stretching, or a sheared cell's (4,)."""
    return (len(affine_rate) > 3 or affine_rate[0] != 0.0 or affine_rate[1] != 0.0
            or affine_rate[2] != 0.0)


@numba.njit(cache=True, inline="always")
def _contact_gap(k, first, j, position, radius, image, period, periodic, overlap, shear_force,
                 normal_force, force):
    """The branch vector d [m] of pair k of first member ``first`` (_first_member) and second
    member j, its length [m] and the pair's overlap [m] (stored; negative: a gap), the force
    arrays of a pair that has just separated zeroed. ``periodic``, ``period``: as
    _evaluate_pair's. The first part of every contact law's pair (this module's,
    pendular.dem.hertz_mindlin), then _turned_contact for a touching pair."""
    d0 = position[j, 0] - first[0]
    d1 = position[j, 1] - first[1]
    d2 = position[j, 2] - first[2]
    if periodic:        # as pendular.dem.neighbors.branch_vector, skipped for most pairs
        m0 = image[k, 0]
        m1 = image[k, 1]
        m2 = image[k, 2]
        if m0 != 0 or m1 != 0 or m2 != 0:
            d0 += m0 * period[0]
            d1 += m1 * period[1]
            d2 += m2 * period[2]
            if len(period) > 3:     # Lees–Edwards: the images above in z offset along x
                d0 += m2 * period[3]
    distance = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    gap_overlap = first[9] + radius[j] - distance
    was_touching = overlap[k] > 0.0
    overlap[k] = gap_overlap
    if gap_overlap <= 0.0 and was_touching:   # else still zero from when it separated
        normal_force[k] = 0.0
        for c in range(3):
            shear_force[k, c] = 0.0
            force[k, c] = 0.0
    return d0, d1, d2, distance, gap_overlap


@numba.njit(cache=True, inline="always")
def _turned_contact(k, first, j, d0, d1, d2, distance, velocity, angular_velocity, radius,
                    affine_rate, stretched, shear_force, normal, dt):
    """A touching pair k's normal n (i to j), its stored shear force turned with the contact
    [N] and the relative velocity of j with respect to i at the contact [m/s], from its
    branch vector d and length (_contact_gap); ``stretched``, ``affine_rate``: as
    _evaluate_pair's.

    The shear force turns as in YADE's Law2_ScGeom_FrictPhys_CundallStrack: tilt of the
    normal (axis n_old x n), then twist by the mean spin about n; the relative velocity takes
    the radii as lever arms (YADE's avoidGranularRatcheting)."""
    xi0, xi1, xi2, ui0, ui1, ui2, wi0, wi1, wi2, ri = first
    rj = radius[j]
    n0 = d0 / distance
    n1 = d1 / distance
    n2 = d2 / distance
    fs0 = shear_force[k, 0]
    fs1 = shear_force[k, 1]
    fs2 = shear_force[k, 2]
    # rotate the shear force with the contact: tilt axis = n_old x n, then twist about n
    o0 = normal[k, 0]
    o1 = normal[k, 1]
    o2 = normal[k, 2]
    a0 = o1 * n2 - o2 * n1
    a1 = o2 * n0 - o0 * n2
    a2 = o0 * n1 - o1 * n0
    fs0, fs1, fs2 = (fs0 - (fs1 * a2 - fs2 * a1), fs1 - (fs2 * a0 - fs0 * a2),
                     fs2 - (fs0 * a1 - fs1 * a0))
    wj0 = angular_velocity[j, 0]
    wj1 = angular_velocity[j, 1]
    wj2 = angular_velocity[j, 2]
    spin = 0.5 * dt * (n0 * (wi0 + wj0) + n1 * (wi1 + wj1) + n2 * (wi2 + wj2))
    a0 = spin * n0
    a1 = spin * n1
    a2 = spin * n2
    fs0, fs1, fs2 = (fs0 - (fs1 * a2 - fs2 * a1), fs1 - (fs2 * a0 - fs0 * a2),
                     fs2 - (fs0 * a1 - fs1 * a0))
    # relative velocity of j with respect to i at the contact point
    v0 = velocity[j, 0] - ui0 - rj * (wj1 * n2 - wj2 * n1) - ri * (wi1 * n2 - wi2 * n1)
    v1 = velocity[j, 1] - ui1 - rj * (wj2 * n0 - wj0 * n2) - ri * (wi2 * n0 - wi0 * n2)
    v2 = velocity[j, 2] - ui2 - rj * (wj0 * n1 - wj1 * n0) - ri * (wi0 * n1 - wi1 * n0)
    if stretched:
        v0 += affine_rate[0] * d0
        v1 += affine_rate[1] * d1
        v2 += affine_rate[2] * d2
        if len(affine_rate) > 3:    # simple shear: the velocity gamma_dot * z along x
            v0 += affine_rate[3] * d2
    return n0, n1, n2, fs0, fs1, fs2, v0, v1, v2


@numba.njit(cache=True, inline="always")
def _store_contact(k, fn, fs0, fs1, fs2, n0, n1, n2, shear_force, normal, normal_force, force):
    """Store pair k's shear force ``fs`` [N] (the spring the next step turns and increments),
    normal n and normal force ``fn`` [N]; return its force on j from i, fn n + fs [N]."""
    shear_force[k, 0] = fs0
    shear_force[k, 1] = fs1
    shear_force[k, 2] = fs2
    normal[k, 0] = n0
    normal[k, 1] = n1
    normal[k, 2] = n2
    normal_force[k] = fn
    f0 = fn * n0 + fs0
    f1 = fn * n1 + fs1
    f2 = fn * n2 + fs2
    force[k, 0] = f0
    force[k, 1] = f1
    force[k, 2] = f2
    return f0, f1, f2


@numba.njit(cache=True, inline="always")
def _evaluate_pair(k, first, j, position, velocity, angular_velocity, radius, image, period,
                   periodic, affine_rate, stretched, shear_force, normal, overlap, normal_force,
                   force, young, shear_ratio, tan_friction, dt):
    """Evaluate pair k of first member ``first`` (_first_member) and second member j
    (pair_forces), fill its per-pair arrays; (touching, the force on j from i [N], the normal,
    the overlap [m]), force and normal (0, 0, 0) for a pair apart. ``periodic``,
    ``stretched``: whether the scene has images, stretching (pair_forces); a sheared cell's
    ``period`` and ``affine_rate`` hold a fourth entry (the tests of their lengths are on
    the arrays' shapes, hoisted out of the loops)."""
    d0, d1, d2, distance, gap_overlap = _contact_gap(k, first, j, position, radius, image,
                                                     period, periodic, overlap, shear_force,
                                                     normal_force, force)
    if gap_overlap <= 0.0:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, gap_overlap
    kn = normal_stiffness(young, first[9], radius[j])
    ks = shear_ratio * kn
    n0, n1, n2, fs0, fs1, fs2, v0, v1, v2 = _turned_contact(
        k, first, j, d0, d1, d2, distance, velocity, angular_velocity, radius, affine_rate,
        stretched, shear_force, normal, dt)
    vn = v0 * n0 + v1 * n1 + v2 * n2
    fs0 -= ks * (v0 - vn * n0) * dt
    fs1 -= ks * (v1 - vn * n1) * dt
    fs2 -= ks * (v2 - vn * n2) * dt
    fn = kn * gap_overlap
    cap = fn * tan_friction
    magnitude = math.sqrt(fs0 * fs0 + fs1 * fs1 + fs2 * fs2)
    # a select, not a branch: whether a contact slides is unpredictable pair to pair (a fifth
    # of a dry shear's contacts slide); x * 1.0 == x, so a sticking contact is unchanged
    scale = cap / magnitude if magnitude > cap else 1.0
    fs0 *= scale
    fs1 *= scale
    fs2 *= scale
    f0, f1, f2 = _store_contact(k, fn, fs0, fs1, fs2, n0, n1, n2, shear_force, normal,
                                normal_force, force)
    return True, f0, f1, f2, n0, n1, n2, gap_overlap


@numba.njit(cache=True, parallel=True, fastmath=HOT_KERNEL_FASTMATH)
def pair_forces(position, velocity, angular_velocity, radius, pair_i, pair_j, image, period,
                affine_rate, shear_force, normal, overlap, normal_force, force, young,
                shear_ratio, tan_friction, dt, prefetch_ahead):
    """Evaluate every candidate pair; fill the per-pair arrays (``force``: the force on j from
    i; the torques follow from it, the normal and the overlap in the gather).

    pair_i, pair_j: the pairs (pendular.dem.neighbors.Contacts), taken one by one; the one-thread
    kernels take them row by row, from row_start instead of pair_i. image, period: each pair's
    periodic image and the box period (pendular.dem.neighbors.branch_vector; zeros inside walls);
    affine_rate (3,) [1/s]: the homogeneous stretching of a periodic cell, whose velocity
    affine_rate * l adds to the relative velocity of a pair of branch l; a sheared cell's
    (4,) adds its shear rate gamma_dot = affine_rate[3], the velocity gamma_dot * l_z along x
    (pendular.dem.cell). A scene without images or stretching (walls) skips these terms (a
    branch taken the same way by every pair: no cost). prefetch_ahead: how many pairs ahead
    particle j's rows and radius are asked of the cache (0: none;
    pendular.dem.prefetch.prefetch_distance; no effect on results).

    The shear spring follows YADE's Law2_ScGeom_FrictPhys_CundallStrack: the stored shear force
    is first rotated with the contact (tilt of the normal, then twist by the mean spin about it),
    then incremented by -ks * (tangential relative velocity at the contact) * dt, the relative
    velocity using the radii as lever arms (YADE's avoidGranularRatcheting), and finally capped
    at Fn tan(phi), the elastic part being kept on the cap when sliding.
    """
    periodic = period[0] != 0.0 or period[1] != 0.0 or period[2] != 0.0
    stretched = _stretched(affine_rate)
    for k in numba.prange(len(pair_i)):
        _prefetch_second(k, pair_j, prefetch_ahead, (position, velocity, angular_velocity),
                         radius)
        _evaluate_pair(k, _first_member(pair_i[k], position, velocity, angular_velocity, radius),
                       pair_j[k], position, velocity, angular_velocity, radius, image, period,
                       periodic, affine_rate, stretched, shear_force, normal, overlap,
                       normal_force, force, young, shear_ratio, tan_friction, dt)


@numba.njit(cache=True, fastmath=HOT_KERNEL_FASTMATH, _nrt=False)
def serial_pair_forces(position, velocity, angular_velocity, radius, row_start, pair_j, image,
                       period, affine_rate, shear_force, normal, overlap, normal_force,
                       force, young, shear_ratio, tan_friction, dt, prefetch_ahead):
    """pair_forces on one thread, row by row (particle i's state read once for its row,
    _first_member): no parallel launch (2-3 us a call) and a plain loop (the same results)."""
    periodic = period[0] != 0.0 or period[1] != 0.0 or period[2] != 0.0
    stretched = _stretched(affine_rate)
    for i in range(len(row_start) - 1):
        first = _first_member(i, position, velocity, angular_velocity, radius)
        for k in range(row_start[i], row_start[i + 1]):
            _prefetch_second(k, pair_j, prefetch_ahead, (position, velocity, angular_velocity),
                             radius)
            _evaluate_pair(k, first, pair_j[k], position, velocity, angular_velocity, radius,
                           image, period, periodic, affine_rate, stretched, shear_force, normal,
                           overlap, normal_force, force, young, shear_ratio, tan_friction, dt)


@numba.njit(cache=True, inline="always")
def _prefetch_second(k, pair_j, prefetch_ahead, arrays, radius):
    """Ask for the rows of ``arrays`` (a tuple of (N, 3) arrays) and the ``radius`` of the
    second member of the pair ``prefetch_ahead`` pairs after pair k (if prefetch_ahead > 0 and
    there is one: pendular.dem.prefetch)."""
    if prefetch_ahead > 0 and k + prefetch_ahead < len(pair_j):
        ahead = pair_j[k + prefetch_ahead]
        for rows in arrays:
            prefetch_row(rows, ahead)
        prefetch_row(radius, ahead)


@numba.njit(cache=True, inline="always")
def _contact_torque(n0, n1, n2, overlap_k, radius_p, a0, a1, a2):
    """Torque [N m] on a member of radius ``radius_p`` of a pair of normal n and overlap
    ``overlap_k`` [m] from the pair's force a (on j from i): -(radius_p - overlap_k / 2) n x a
    (_add_contact_forces)."""
    lever = 0.5 * overlap_k - radius_p
    return (lever * (n1 * a2 - n2 * a1), lever * (n2 * a0 - n0 * a2), lever * (n0 * a1 - n1 * a0))


@numba.njit(cache=True, inline="always")
def _pair_terms(pair_force, attraction, normal, overlap, k, radius_p):
    """Pair k's force on j from i with the attraction (pendular.dem.virial.pair_force_with_attraction)
    and the contact force's torque on a member of radius ``radius_p`` (_contact_torque; the
    central attraction has none)."""
    m0, m1, m2 = _contact_torque(normal[k, 0], normal[k, 1], normal[k, 2], overlap[k], radius_p,
                                 pair_force[k, 0], pair_force[k, 1], pair_force[k, 2])
    a0, a1, a2 = pair_force_with_attraction(pair_force, attraction, normal, k)
    return a0, a1, a2, m0, m1, m2


@numba.njit(cache=True, inline="always")
def _add_contact_forces(p, pair_force, attraction, normal, overlap, radius, row_start,
                        second_start, second_pair, force, torque):
    """Add to ``force[p]``, ``torque[p]`` its pairs' contact forces (-F where p is i, +F where p
    is j; F the force on j from i) and their torques, with the central ``attraction``
    (pendular.dem.virial.pair_force_with_attraction; it has no torque) when there is one.

    F acts at the middle of the overlap, r_p - overlap / 2 from p's centre along +n (p is i,
    force -F) or -n (p is j, force +F): either way its torque on p is
    -(r_p - overlap / 2) n x F, the torque of the shear force alone since n x n = 0 (YADE's
    Law2_ScGeom_FrictPhys_CundallStrack). overlap and normal: this step's (pair_forces).

    Order: the terms are added one by one to p's force and torque in pair order, the order in
    which a loop over the pairs meets them (scatter_contact_forces), so that the one-thread
    kernels give the same sums: first the pairs in which p is the second member (their first
    member is below p, so they come before p's own in the CSR list; second_pair holds them in
    pair order), then p's own (_sum_pair_terms)."""
    sums = _sum_pair_terms(_row_sums(p, force, torque), radius[p], pair_force, attraction,
                           normal, overlap, second_pair,
                           range(second_start[p], second_start[p + 1]),
                           range(row_start[p], row_start[p + 1]))
    _store_row_sums(p, sums, force, torque)


@numba.njit(cache=True, inline="always")
def _sum_pair_terms(sums, radius_p, pair_force, attraction, normal, overlap, second_pair,
                    second_slots, own_pairs):
    """``sums`` (_row_sums) of a particle p of radius ``radius_p`` [m] with its pairs' terms
    (_pair_terms) added one by one: +F and its torque for the pairs in which p is the second
    member, second_pair[slot] for slot in the range ``second_slots``, then -F and its torque
    for its own pairs, the range ``own_pairs`` (_add_contact_forces). The ranges step by 1 in
    the CPU's list (CSR), by the particle count in the device's rows (pendular.gpu.neighbors).
    """
    f0, f1, f2, t0, t1, t2 = sums
    for slot in second_slots:
        a0, a1, a2, m0, m1, m2 = _pair_terms(pair_force, attraction, normal, overlap,
                                             second_pair[slot], radius_p)
        f0 += a0
        f1 += a1
        f2 += a2
        t0 += m0
        t1 += m1
        t2 += m2
    for k in own_pairs:
        a0, a1, a2, m0, m1, m2 = _pair_terms(pair_force, attraction, normal, overlap, k,
                                             radius_p)
        f0 -= a0
        f1 -= a1
        f2 -= a2
        t0 += m0
        t1 += m1
        t2 += m2
    return f0, f1, f2, t0, t1, t2


@numba.njit(cache=True, parallel=True, fastmath=HOT_KERNEL_FASTMATH)
def gather_contact_forces(pair_force, attraction, normal, overlap, radius, row_start,
                          second_start, second_pair, force, torque):
    """Add the contact forces, the central ``attraction`` (K,) [N] unless None, and the
    torques to the particles (_add_contact_forces). In a periodic cell use
    gather_contact_forces_virial; on one thread scatter_contact_forces is faster."""
    for p in numba.prange(len(row_start) - 1):
        _add_contact_forces(p, pair_force, attraction, normal, overlap, radius, row_start,
                            second_start, second_pair, force, torque)


@numba.njit(cache=True, parallel=True, fastmath=HOT_KERNEL_FASTMATH)
def gather_contact_forces_virial(pair_force, attraction, normal, overlap, radius, row_start,
                                 second_start, second_pair, force, torque, image, through_face,
                                 face_start, period, virial):
    """gather_contact_forces in a periodic cell, which also adds the face terms of the
    forces' Love–Weber sum to ``virial`` (as pendular.dem.virial.add_face_block)."""
    count = len(row_start) - 1
    for block in numba.prange(SUM_BLOCKS):
        start, stop = block_bounds(count, block)
        for p in range(start, stop):
            _add_contact_forces(p, pair_force, attraction, normal, overlap, radius, row_start,
                                second_start, second_pair, force, torque)
        add_face_block(virial, block, through_face, face_start, image, period, pair_force,
                       attraction, normal)


@numba.njit(cache=True, inline="always")
def _row_sums(i, force, torque):
    """Particle i's force and torque as one tuple of six sums, which a row loop carries in
    registers through i's row (_scatter_to_both) and stores at its end (_store_row_sums)."""
    return force[i, 0], force[i, 1], force[i, 2], torque[i, 0], torque[i, 1], torque[i, 2]


@numba.njit(cache=True, inline="always")
def _scatter_to_both(sums, j, a0, a1, a2, c0, c1, c2, n0, n1, n2, overlap_k, radius_i, radius,
                     force, torque):
    """A pair's terms on both members: -a and the torque of its contact force c on the first
    member (of radius ``radius_i``) taken into its ``sums`` (_row_sums; returned), +a and
    c's torque on the second member j added to ``force[j]`` and ``torque[j]`` (a [N] with any
    attraction, _pair_terms; normal n, overlap ``overlap_k`` [m]; _add_contact_forces)."""
    m0, m1, m2 = _contact_torque(n0, n1, n2, overlap_k, radius[j], c0, c1, c2)
    force[j, 0] += a0
    force[j, 1] += a1
    force[j, 2] += a2
    torque[j, 0] += m0
    torque[j, 1] += m1
    torque[j, 2] += m2
    m0, m1, m2 = _contact_torque(n0, n1, n2, overlap_k, radius_i, c0, c1, c2)
    return (sums[0] - a0, sums[1] - a1, sums[2] - a2, sums[3] + m0, sums[4] + m1,
            sums[5] + m2)


@numba.njit(cache=True, inline="always")
def _store_row_sums(i, sums, force, torque):
    """Store particle i's ``sums`` (_row_sums) in its rows of ``force`` and ``torque``."""
    force[i, 0], force[i, 1], force[i, 2], torque[i, 0], torque[i, 1], torque[i, 2] = sums


@numba.njit(cache=True, fastmath=HOT_KERNEL_FASTMATH, _nrt=False)
def scatter_contact_forces(pair_force, attraction, normal, overlap, radius, row_start, pair_j,
                           force, torque, prefetch_ahead):
    """gather_contact_forces on one thread: one loop over the rows adding each pair's terms
    to its two particles, the same sums in the same order (_add_contact_forces; particle i's
    own in registers through its row, as scattered_pair_forces), the pair arrays read once
    and in order instead of twice, once through the transposed index. prefetch_ahead: as
    pair_forces', for particle j's force and torque rows and radius."""
    for i in range(len(row_start) - 1):
        start = row_start[i]
        stop = row_start[i + 1]
        if start == stop:
            continue
        radius_i = radius[i]
        sums = _row_sums(i, force, torque)
        for k in range(start, stop):
            _prefetch_second(k, pair_j, prefetch_ahead, (force, torque), radius)
            a0, a1, a2 = pair_force_with_attraction(pair_force, attraction, normal, k)
            sums = _scatter_to_both(sums, pair_j[k], a0, a1, a2, pair_force[k, 0],
                                    pair_force[k, 1], pair_force[k, 2], normal[k, 0],
                                    normal[k, 1], normal[k, 2], overlap[k], radius_i, radius,
                                    force, torque)
        _store_row_sums(i, sums, force, torque)


@numba.njit(cache=True, fastmath=HOT_KERNEL_FASTMATH, _nrt=False)
def scattered_pair_forces(position, velocity, angular_velocity, radius, row_start, pair_j,
                          image, period, affine_rate, shear_force, normal, overlap,
                          normal_force, force, young, shear_ratio, tan_friction, dt,
                          prefetch_ahead, particle_force, particle_torque):
    """pair_forces then gather_contact_forces on one thread, in one loop over the rows: each
    touching pair's force and torques go to its particles' ``particle_force`` [N] and
    ``particle_torque`` [N m] as soon as it is evaluated, the same sums in the same order
    (_add_contact_forces). Particle i's own sums stay in registers through its row: the terms
    in which it is the second member come from earlier rows, so they are in its rows of
    ``particle_force`` and ``particle_torque`` when its row starts. A pair apart adds nothing,
    where the gather adds its zeros (the same sums but for a zero's sign)."""
    periodic = period[0] != 0.0 or period[1] != 0.0 or period[2] != 0.0
    stretched = _stretched(affine_rate)
    for i in range(len(row_start) - 1):
        start = row_start[i]
        stop = row_start[i + 1]
        if start == stop:
            continue
        first = _first_member(i, position, velocity, angular_velocity, radius)
        sums = _row_sums(i, particle_force, particle_torque)
        for k in range(start, stop):
            _prefetch_second(k, pair_j, prefetch_ahead, (position, velocity, angular_velocity,
                                                         particle_force, particle_torque), radius)
            j = pair_j[k]
            touching, a0, a1, a2, n0, n1, n2, overlap_k = _evaluate_pair(
                k, first, j, position, velocity, angular_velocity, radius, image, period,
                periodic, affine_rate, stretched, shear_force, normal, overlap, normal_force,
                force, young, shear_ratio, tan_friction, dt)
            if touching:
                sums = _scatter_to_both(sums, j, a0, a1, a2, a0, a1, a2, n0, n1, n2, overlap_k,
                                        first[9], radius, particle_force, particle_torque)
        _store_row_sums(i, sums, particle_force, particle_torque)


@numba.njit(cache=True, fastmath=HOT_KERNEL_FASTMATH, _nrt=False)
def add_face_terms(virial, through_face, face_start, image, period, pair_force, attraction,
                   normal):
    """The face terms that gather_contact_forces_virial adds to ``virial`` beside its gather,
    every block's (pendular.dem.virial.add_face_block): for the one-thread kernels, which scatter."""
    for block in range(SUM_BLOCKS):
        add_face_block(virial, block, through_face, face_start, image, period, pair_force,
                       attraction, normal)


@numba.njit(cache=True)
def wall_forces(position, radius, near_wall, wall_position, young, force, wall_force,
                wall_stiffness, wall_moment):
    """Frictionless sphere–wall springs (kn = E R) of the particles ``near_wall`` (ascending
    indices; pendular.dem.neighbors.Contacts.near_wall: every particle that can touch a wall); add to
    ``force``, fill wall totals.

    wall_force[w] is the compressive normal force the particles exert on wall w [N],
    wall_stiffness[w] the sum of its contacts' kn [N/m] (used by the stress servo) and
    wall_moment[w] the sum of (centre-to-wall distance) * force [N m] (Love–Weber, Eq. 3.41).
    Serial: a pass over the particles near the walls only (a fifth of a 10,000-sphere sample,
    a tenth of a 100,000), cheaper than a parallel pass over every particle.
    """
    wall_force[:] = 0.0
    wall_stiffness[:] = 0.0
    wall_moment[:] = 0.0
    low0, high0, low1, high1, low2, high2 = wall_position
    for p in near_wall:
        r = radius[p]
        x0 = position[p, 0]
        x1 = position[p, 1]
        x2 = position[p, 2]
        if r <= min(x0 - low0, high0 - x0, x1 - low1, high1 - x1, x2 - low2, high2 - x2):
            continue                # near a wall, touching none
        kn = wall_contact_stiffness(young, r)
        for axis in range(3):
            low_overlap = r - (position[p, axis] - wall_position[2 * axis])
            if low_overlap > 0.0:
                push = kn * low_overlap
                force[p, axis] += push
                wall_force[2 * axis] += push
                wall_stiffness[2 * axis] += kn
                wall_moment[2 * axis] += (r - low_overlap) * push
            high_overlap = r - (wall_position[2 * axis + 1] - position[p, axis])
            if high_overlap > 0.0:
                push = kn * high_overlap
                force[p, axis] -= push
                wall_force[2 * axis + 1] += push
                wall_stiffness[2 * axis + 1] += kn
                wall_moment[2 * axis + 1] += (r - high_overlap) * push


class ContactForces:
    """Sphere–sphere linear contacts for every candidate pair of ``sim.contacts``.

    young [Pa], shear_ratio = ks/kn, friction [deg] (changeable between runs: ``friction_deg``).
    """

    def __init__(self, young, shear_ratio=0.3, friction_deg=18.0):
        self.young = check_positive("young", young, "Pa")
        self.shear_ratio = check_range("shear_ratio", shear_ratio, 0.0, MAX_SHEAR_RATIO)
        self.friction_deg = friction_deg

    @property
    def friction_deg(self):
        return self._friction_deg

    @friction_deg.setter
    def friction_deg(self, value):
        self._friction_deg = check_range("friction_deg", value, 0.0, MAX_FRICTION_DEG,
                                         high_inclusive=False, unit="deg")
        self._tan_friction = float(np.tan(np.radians(self._friction_deg)))

    def state_dict(self):
        """``friction_deg`` [deg], which a procedure may change after building the law (the
        preparation sets the test's after the growth); the springs' history is the
        contacts'."""
        return {"friction_deg": self.friction_deg}

    def load_state(self, state):
        self.friction_deg = state["friction_deg"]

    def pair_forces(self, sim):
        """Contact force on j from i (K, 3) [N] of the last evaluation."""
        return sim.contacts.force

    def apply(self, sim):
        """This step's pair forces, gathered onto the particles unless a later force
        operation joins the gather (``joined_by``). On one thread the forces go to the
        particles as they are evaluated (scattered_pair_forces; the same sums), and the
        kernels run without the parallel launch."""
        p = sim.particles
        c = sim.contacts
        box = sim.walls
        kinematics = (p.position, p.velocity, p.angular_velocity, p.radius)
        per_pair = (c.image, box.period, box.affine_rate, c.shear_force, c.normal, c.overlap,
                    c.normal_force, c.force, self.young, self.shear_ratio, self._tan_friction,
                    sim.dt, prefetch_distance(len(c)))
        joined = self.joined_by(sim) is not None
        if numba.get_num_threads() > 1:
            pair_forces(*kinematics, c.pair_i, c.pair_j, *per_pair)
            if not joined:
                self.gather(sim)
        elif joined:
            serial_pair_forces(*kinematics, c.row_start, c.pair_j, *per_pair)
        else:
            scattered_pair_forces(*kinematics, c.row_start, c.pair_j, *per_pair, p.force,
                                  p.torque)
            self._add_face_terms(sim, None)

    def joined_by(self, sim):
        """The force operation after this one in ``sim.forces`` whose ``joins_contact_gather``
        is true (capillary bridges at contact: central forces along the contact normals), or
        None. That operation gathers this step's contact forces with its own in one pass
        over the pairs (``gather``), one pass instead of two."""
        after = False
        for op in sim.forces:
            if op is self:
                after = True
            elif after and getattr(op, "joins_contact_gather", False):
                return op
        return None

    def gather(self, sim, attraction=None):
        """Add this step's contact forces and their torques to the particles, with a central
        ``attraction`` (K,) [N] along each contact normal (+a n on i, -a n on j) if given."""
        p = sim.particles
        c = sim.contacts
        box = sim.walls
        if attraction is not None and attraction.shape != (len(c),):
            raise ValueError(f"attraction has shape {attraction.shape}; the gather needs one "
                             f"value per pair of the neighbour list, ({len(c)},)")
        if numba.get_num_threads() == 1:
            scatter_contact_forces(c.force, attraction, c.normal, c.overlap, p.radius,
                                   c.row_start, c.pair_j, p.force, p.torque,
                                   prefetch_distance(len(c)))
            self._add_face_terms(sim, attraction)
        elif box.periodic:
            gather_contact_forces_virial(c.force, attraction, c.normal, c.overlap, p.radius,
                                         c.row_start, c.second_start, c.second_pair, p.force,
                                         p.torque, c.image, c.through_face, c.face_start,
                                         box.period, box.virial_blocks)
        else:
            gather_contact_forces(c.force, attraction, c.normal, c.overlap, p.radius,
                                  c.row_start, c.second_start, c.second_pair, p.force, p.torque)

    @staticmethod
    def _add_face_terms(sim, attraction):
        """In a periodic cell, the face terms of this step's pair forces (with ``attraction``)
        that the multi-thread gather adds beside its sums (add_face_terms): for the one-thread
        kernels, which scatter."""
        box = sim.walls
        if box.periodic:
            c = sim.contacts
            add_face_terms(box.virial_blocks, c.through_face, c.face_start, c.image, box.period,
                           c.force, attraction, c.normal)
