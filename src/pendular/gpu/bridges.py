"""Suction-controlled liquid bridges at contact on the device (thesis Ch. 5.2.2): a bridge
forms when its spheres touch and breaks when they part, its force, volume and filling angles
read from the same exact-bridge table as the CPU (pendular.capillary.table, in device memory)
by the same interpolation.

The table's leaves (grid_position, distance_coordinate, along_axis, bilinear, and the store
of a pair's values) are the CPU's own source compiled for the device; the few functions above
them are restated here because a device function can call device functions only. They are the
CPU's operations in the CPU's order, less the range checks, which the host makes once
(pendular.capillary.bridges.CapillaryBridges.load_tables and its suction check).
"""

import math

from pendular.capillary.bridge_kernels import _store
from pendular.capillary.bridge_state import AT_CONTACT, NO_BRIDGE
from pendular.capillary.table import along_axis, bilinear, distance_coordinate, grid_position
from pendular.gpu.cuda import device

table_grid_position = device(grid_position.py_func)
table_distance_coordinate = device(distance_coordinate.py_func)
table_along_axis = device(along_axis.py_func)
table_bilinear = device(bilinear.py_func)
store_bridge = device(_store.py_func)


@device
def radius_ratio_bracket(radius_ratios, radius_ratio):
    """(index i, weight t) of ``radius_ratio`` among the table's ratios
    (pendular.capillary.table.radius_ratio_bracket; the host checked the range)."""
    n_r = radius_ratios.shape[0]
    if n_r == 1:
        return 0, 0.0
    i = 0
    while i < n_r - 2 and radius_ratio > radius_ratios[i + 1]:
        i += 1
    return i, (radius_ratio - radius_ratios[i]) / (radius_ratios[i + 1] - radius_ratios[i])


@device
def interpolate_log(log_values, i_r, i_next, t_r, i_u, t_u, j, t_z, field):
    """exp of the log-values interpolated in (r, xi, z)
    (pendular.capillary.table._interpolate_log)."""
    low = table_bilinear(log_values, i_r, i_u, t_u, j, t_z, field)
    high = table_bilinear(log_values, i_next, i_u, t_u, j, t_z, field)
    return math.exp((1.0 - t_r) * low + t_r * high)


@device
def lookup_suction(radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values,
                   radius_ratio, suction_star, distance_star):
    """(exists, F*, V*, delta1, delta2) as pendular.capillary.table.lookup_suction."""
    suction_scale = suction_axis[0]
    suction_step = suction_axis[1]
    i_r, t_r = radius_ratio_bracket(radius_ratios, radius_ratio)
    i_next = i_r + 1 if t_r > 0.0 else i_r
    i_u, t_u = table_grid_position(math.log1p(suction_star / suction_scale), suction_step,
                                   log_values.shape[1])
    d_rupture = math.exp((1.0 - t_r) * table_along_axis(log_distance_rupture, i_r, i_u, t_u)
                         + t_r * table_along_axis(log_distance_rupture, i_next, i_u, t_u))
    if distance_star > d_rupture:
        return False, 0.0, 0.0, 0.0, 0.0
    d_low = ((1.0 - t_r) * table_along_axis(distance_low, i_r, i_u, t_u)
             + t_r * table_along_axis(distance_low, i_next, i_u, t_u))
    n_z = log_values.shape[2]
    z = table_distance_coordinate((distance_star - d_low) / (d_rupture - d_low))
    j, t_z = table_grid_position(z, 1.0 / (n_z - 1), n_z)
    force = interpolate_log(log_values, i_r, i_next, t_r, i_u, t_u, j, t_z, 0)
    volume = interpolate_log(log_values, i_r, i_next, t_r, i_u, t_u, j, t_z, 1)
    delta1 = interpolate_log(log_values, i_r, i_next, t_r, i_u, t_u, j, t_z, 2)
    delta2 = interpolate_log(log_values, i_r, i_next, t_r, i_u, t_u, j, t_z, 3)
    return True, force, volume, delta1, delta2


@device
def form_at_contact(k, radius_i, radius_j, state, volume, force, filling_i, filling_j, suction,
                    surface_tension, radius_ratios, suction_axis, distance_low,
                    log_distance_rupture, log_values):
    """Pair k gets the bridge of touching spheres
    (pendular.capillary.bridge_kernels._form_at_contact)."""
    larger = max(radius_i, radius_j)
    _, force_star, volume_star, delta1, delta2 = lookup_suction(
        radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values,
        larger / min(radius_i, radius_j), suction * larger / surface_tension, 0.0)
    store_bridge(k, radius_i, radius_j, force_star, delta1, delta2, surface_tension, force,
                 filling_i, filling_j)
    volume[k] = volume_star * larger * larger * larger
    state[k] = AT_CONTACT


@device
def follow_contact(k, radius_i, radius_j, overlap_k, state, volume, force, filling_i, filling_j,
                   suction, surface_tension, radius_ratios, suction_axis, distance_low,
                   log_distance_rupture, log_values):
    """Pair k's bridge at contact: formed if it touches and has none, gone if it has one and
    does not touch (pendular.capillary.bridge_kernels._follow_contact)."""
    touching = overlap_k > 0.0
    if touching == (state[k] == AT_CONTACT):
        return
    if touching:
        form_at_contact(k, radius_i, radius_j, state, volume, force, filling_i, filling_j,
                        suction, surface_tension, radius_ratios, suction_axis, distance_low,
                        log_distance_rupture, log_values)
    else:
        state[k] = NO_BRIDGE
        volume[k] = 0.0
        force[k] = 0.0
        filling_i[k] = 0.0
        filling_j[k] = 0.0
