"""Contact forces on the device: the linear law with Coulomb friction of
pendular.dem.contact_law, one thread per particle's row of pairs, then a gather of each
particle's pair forces in a fixed order (no float atomics), with the frictionless walls.

Pairs are kept as rows stored slot by slot (pendular.gpu.neighbors): pair k = s * N + p is
particle p's s-th neighbour j > p (rows sorted by j); ``second_pair`` lists, per particle, the
pairs in which it is the second member, sorted by their first member. The gather adds a
particle's terms in the order of the CPU gather (pendular.dem.contact_law._add_contact_forces):
first the pairs in which it is the second member, then its own, so that a particle's force is
the CPU's sum in the CPU's order.
"""

import math

from pendular.dem.contact_law import _contact_torque, normal_stiffness, wall_contact_stiffness
from pendular.gpu.bridges import follow_contact
from pendular.gpu.cuda import cuda, device

# the CPU law's leaves are plain math over scalars: the same source compiled for the device
pair_stiffness = device(normal_stiffness.py_func)
wall_stiffness = device(wall_contact_stiffness.py_func)
contact_torque = device(_contact_torque.py_func)


@device
def evaluate_pair(k, i, j, position, velocity, angular_velocity, radius, shear_force, normal,
                  overlap, normal_force, force, young, shear_ratio, tan_friction, dt):
    """Pair k (i, j) by the CPU law (pendular.dem.contact_law._evaluate_pair, walls: no
    periodic image, no stretching), its per-pair arrays filled: the same operations in the
    same order (math.sqrt for np.sqrt, the one the device has)."""
    ri = radius[i]
    d0 = position[j, 0] - position[i, 0]
    d1 = position[j, 1] - position[i, 1]
    d2 = position[j, 2] - position[i, 2]
    distance = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    rj = radius[j]
    gap_overlap = ri + rj - distance
    was_touching = overlap[k] > 0.0
    overlap[k] = gap_overlap
    if gap_overlap <= 0.0:
        if was_touching:
            normal_force[k] = 0.0
            for c in range(3):
                shear_force[k, c] = 0.0
                force[k, c] = 0.0
        return
    n0 = d0 / distance
    n1 = d1 / distance
    n2 = d2 / distance
    kn = pair_stiffness(young, ri, rj)
    ks = shear_ratio * kn
    fs0 = shear_force[k, 0]
    fs1 = shear_force[k, 1]
    fs2 = shear_force[k, 2]
    o0 = normal[k, 0]
    o1 = normal[k, 1]
    o2 = normal[k, 2]
    a0 = o1 * n2 - o2 * n1
    a1 = o2 * n0 - o0 * n2
    a2 = o0 * n1 - o1 * n0
    fs0, fs1, fs2 = (fs0 - (fs1 * a2 - fs2 * a1), fs1 - (fs2 * a0 - fs0 * a2),
                     fs2 - (fs0 * a1 - fs1 * a0))
    wi0 = angular_velocity[i, 0]
    wi1 = angular_velocity[i, 1]
    wi2 = angular_velocity[i, 2]
    wj0 = angular_velocity[j, 0]
    wj1 = angular_velocity[j, 1]
    wj2 = angular_velocity[j, 2]
    spin = 0.5 * dt * (n0 * (wi0 + wj0) + n1 * (wi1 + wj1) + n2 * (wi2 + wj2))
    a0 = spin * n0
    a1 = spin * n1
    a2 = spin * n2
    fs0, fs1, fs2 = (fs0 - (fs1 * a2 - fs2 * a1), fs1 - (fs2 * a0 - fs0 * a2),
                     fs2 - (fs0 * a1 - fs1 * a0))
    v0 = (velocity[j, 0] - velocity[i, 0] - rj * (wj1 * n2 - wj2 * n1)
          - ri * (wi1 * n2 - wi2 * n1))
    v1 = (velocity[j, 1] - velocity[i, 1] - rj * (wj2 * n0 - wj0 * n2)
          - ri * (wi2 * n0 - wi0 * n2))
    v2 = (velocity[j, 2] - velocity[i, 2] - rj * (wj0 * n1 - wj1 * n0)
          - ri * (wi0 * n1 - wi1 * n0))
    vn = v0 * n0 + v1 * n1 + v2 * n2
    fs0 -= ks * (v0 - vn * n0) * dt
    fs1 -= ks * (v1 - vn * n1) * dt
    fs2 -= ks * (v2 - vn * n2) * dt
    fn = kn * gap_overlap
    cap = fn * tan_friction
    magnitude = math.sqrt(fs0 * fs0 + fs1 * fs1 + fs2 * fs2)
    scale = cap / magnitude if magnitude > cap else 1.0
    fs0 *= scale
    fs1 *= scale
    fs2 *= scale
    shear_force[k, 0] = fs0
    shear_force[k, 1] = fs1
    shear_force[k, 2] = fs2
    normal[k, 0] = n0
    normal[k, 1] = n1
    normal[k, 2] = n2
    normal_force[k] = fn
    force[k, 0] = fn * n0 + fs0
    force[k, 1] = fn * n1 + fs1
    force[k, 2] = fn * n2 + fs2


@cuda.jit
def pair_forces(position, velocity, angular_velocity, radius, pair_count, pair_j, shear_force,
                normal, overlap, normal_force, force, young, shear_ratio,
                tan_friction, dt, flags, wet, state, volume, bridge_force, filling_i,
                filling_j, suction, surface_tension, radius_ratios, suction_axis,
                distance_low, log_distance_rupture, log_values):
    """Every pair of particle p's row (one thread per particle): the contact law, then (``wet``)
    its suction-controlled bridge at contact (pendular.gpu.bridges.follow_contact: the bridge
    arrays of pendular.capillary.bridge_state.BridgeState, a BridgeTable's arrays()).
    Thread 0 clears the rebuild flag: this step's rebuild, if any, is done."""
    p = cuda.grid(1)
    if p == 0:
        flags[0] = 0
    n = position.shape[0]
    if p >= n:
        return
    for s in range(pair_count[p]):
        k = s * n + p
        j = pair_j[k]
        evaluate_pair(k, p, j, position, velocity, angular_velocity, radius, shear_force,
                      normal, overlap, normal_force, force, young, shear_ratio, tan_friction,
                      dt)
        if wet:
            follow_contact(k, radius[p], radius[j], overlap[k], state, volume, bridge_force,
                           filling_i, filling_j, suction, surface_tension, radius_ratios,
                           suction_axis, distance_low, log_distance_rupture, log_values)


@device
def pair_terms(k, pair_force, attraction, wet, normal, overlap, radius_p):
    """Pair k's force on j from i, less the central ``attraction`` along the normal when
    ``wet`` (pendular.dem.virial.pair_force_with_attraction), and its contact force's torque
    on a member of radius ``radius_p`` (pendular.dem.contact_law._pair_terms)."""
    m0, m1, m2 = contact_torque(normal[k, 0], normal[k, 1], normal[k, 2], overlap[k], radius_p,
                                pair_force[k, 0], pair_force[k, 1], pair_force[k, 2])
    a0 = pair_force[k, 0]
    a1 = pair_force[k, 1]
    a2 = pair_force[k, 2]
    if wet:
        b = attraction[k]
        a0 -= b * normal[k, 0]
        a1 -= b * normal[k, 1]
        a2 -= b * normal[k, 2]
    return a0, a1, a2, m0, m1, m2


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
    """Each particle's force and torque from its pairs (less the ``attraction`` along the
    normals when ``wet``: bridges at contact) and the walls, set (not added), in the CPU's
    order: the walls first when WallForces runs before the operation that gathers the pairs
    (``walls_first``: the contact law, or the bridges that join its gather), else after."""
    p = cuda.grid(1)
    n = position.shape[0]
    if p >= n:
        return
    f0 = f1 = f2 = 0.0
    t0 = t1 = t2 = 0.0
    if walls_first:
        f0, f1, f2 = add_wall_pushes(p, f0, f1, f2, position, radius, wall_position,
                                     wall_young)
    r = radius[p]
    for s in range(second_count[p]):
        a0, a1, a2, m0, m1, m2 = pair_terms(second_pair[s * n + p], pair_force, attraction, wet,
                                            normal, overlap, r)
        f0 += a0
        f1 += a1
        f2 += a2
        t0 += m0
        t1 += m1
        t2 += m2
    for s in range(pair_count[p]):
        a0, a1, a2, m0, m1, m2 = pair_terms(s * n + p, pair_force, attraction, wet, normal,
                                            overlap, r)
        f0 -= a0
        f1 -= a1
        f2 -= a2
        t0 += m0
        t1 += m1
        t2 += m2
    if not walls_first:
        f0, f1, f2 = add_wall_pushes(p, f0, f1, f2, position, radius, wall_position,
                                     wall_young)
    force[p, 0] = f0
    force[p, 1] = f1
    force[p, 2] = f2
    torque[p, 0] = t0
    torque[p, 1] = t1
    torque[p, 2] = t2

