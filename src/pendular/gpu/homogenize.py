"""Homogenised quantities of the device's state at a record step, reduced on the device: the
host receives a few numbers, not the particles (pendular.dem.measure, pendular.homogenize on
the CPU).

From the device's own arrays (pendular.gpu.state; pair k = s * N + p, particle p's s-th
neighbour j > p), inside walls or in a periodic cell (no walls; V the cell's volume; each
branch vector through the faces with its pair's image, by the CPU's
pendular.dem.neighbors.branch_vector compiled for the device):

- the Love–Weber stress of the contact forces (1/V) [sum l (x) f + walls] (Eq. 3.41,
  pendular.homogenize.contact_stress.contact_stress), l = x_j - x_i (+ image L in a cell), f
  the force on j from i;
- the contact fabric (1/Nc) sum n n (Eq. 4.1, the contact law's normals), the coordination
  2 Nc / N, the unbalanced force and the spheres' volume (pendular.dem.measure,
  Particles.solid_volume), the largest overlap over the smaller radius, pairs and (inside
  walls) walls, and the radii's range (pendular.procedures.guards.SampleGuard's measures);
- wet: the bridges' count and water volume V_w, the sums of Eqs. 3.44-3.46 (chi, B, psi; each
  rotated cap tensor summed as a_k I + (c_k - a_k) n n, bridge_tensors.axisymmetric_sum), the
  bridge fabric (Eq. 3.53) over the unit branch vectors, the Love–Weber stress of the
  capillary forces (on_the_fly.capillary_force_stress; bridges across gaps, ``persist``: the
  forces on j from i applied at the last step, SuctionBridges.pair_forces) and, with the exact
  model, the liquid-gas interface term (on_the_fly's I_ij, from the exact table at each
  bridge's gap, read by the CPU's own lookup: bridge_kernels._bridge_gap_star and
  table.lookup_interface compiled for the device, pendular.gpu.cuda.device_twin; volume
  control: the volume table's, bridge_kernels.volume_interfaces), and the overlapping menisci
  on a same particle (capillary.bridges.CapillaryBridges.pendular_overlaps). Volume control's
  psi weighs each bridge by its own suction (on_the_fly.homogenize_bridges).

The reduction, fixed in order (the result does not depend on the launch): each thread sums the
rows of CHUNK particles, particle after particle and each row in order, into its block's row
of ``partial`` (``homogenize_partials``); one thread per column then adds the blocks in order
(``sum_columns``). For up to CHUNK particles the sums over pairs run in the CPU's pair order.
A few columns (MAXIMA) hold largest values instead, exact in any order.
The cap and contact-line tensors (Eqs. 3.48-3.49) are restated here from
pendular.homogenize.bridge_tensors, whose NumPy code does not compile for the device, and the
menisci's overlap test from bridge_kernels.pendular_overlap_counts (whose scratch rows the
device does without: each pair of a particle's menisci is read from its pairs).
"""

import math
from collections import namedtuple

import numpy as np

from pendular.capillary.bridge_kernels import _bridge_gap_star
from pendular.capillary.bridge_state import AT_CONTACT, NO_BRIDGE
from pendular.capillary.table import lookup_interface
from pendular.capillary.volume_table import lookup_volume_interface
from pendular.dem.neighbors import branch_vector
from pendular.gpu.cuda import configured, cuda, device, device_twin
from pendular.gpu.state import BRIDGE_COLUMNS
from pendular.homogenize.fabric import principal_anisotropy
from pendular.utils.validate import check_positive

bridge_gap_star = device_twin(_bridge_gap_star)
image_branch = device_twin(branch_vector)
interface_lookup = device_twin(lookup_interface)
volume_interface_lookup = device_twin(lookup_volume_interface)

#: Particles summed by one thread of homogenize_partials.
CHUNK = 32

#: The pairs' index: rows (``count``, ``first`` and ``second`` members) and the transposed
#: index (``second_count``, ``second_pair``) of pendular.gpu.neighbors.
PairIndex = namedtuple("PairIndex", "count first second second_count second_pair")
#: The box as a pair's branch vector reads it: ``periodic``, the pairs' ``image``, ``period``.
Box = namedtuple("Box", "periodic image period")
#: The pairs' contacts: overlap [m], normal, force on j from i [N].
Contacts = namedtuple("Contacts", "overlap normal force")
#: The bridges as the homogenisation reads them (add_bridge): ``wet``, the columns
#: ``bridges``, ``persist`` and their forces ``pair_force``, ``own_suction`` (volume control),
#: ``contact_angle`` [deg], ``surface_tension`` [N/m], ``interface``, ``suction`` [Pa],
#: ``roughness``.
Capillary = namedtuple("Capillary", "wet bridges persist pair_force own_suction contact_angle "
                                    "surface_tension interface suction roughness")
#: Radians per degree (numpy.radians multiplies by it).
RADIAN = math.pi / 180.0

#: The summed columns, (name, width) in order: touching pairs Nc; sum over particles of |F_p|
#: [N]; sum over touching pairs of |f| [N]; contact stress sum l (x) f [N m]; contact fabric sum
#: n n; sum of the radii cubed [m^3]; bridges; water volume [m^3]; capillary stress sum
#: l (x) f_cap [N m]; wetted caps (Eq. 3.44: sum a_k [m^3], sum (c_k - a_k) n n [m^3]); contact
#: lines (Eq. 3.45: [N m]); bridge fabric sum n n; interface (sum a_k, sum (c_k - a_k) n n
#: [m^2]); overlapping menisci; with each bridge's own suction s_k (volume control), sum s_k V_k
#: [N m] and the wetted caps weighted by s_k (sum s_k a_k, sum s_k (c_k - a_k) n n [N m]).
#: 3x3 sums row by row.
SUMS = (("touching", 1), ("resultant", 1), ("contact_force", 1), ("stress", 9),
        ("fabric", 9), ("radius_cubed", 1), ("bridges", 1), ("water_volume", 1),
        ("capillary", 9), ("cap_lateral", 1), ("cap_axial", 9), ("line_lateral", 1),
        ("line_axial", 9), ("bridge_fabric", 9), ("interface_lateral", 1),
        ("interface_axial", 9), ("pendular_overlaps", 1), ("suction_water", 1),
        ("suction_cap_lateral", 1), ("suction_cap_axial", 9))
#: The columns after SUMS, reduced to their largest value: the largest overlap over the smaller
#: radius [-] (at least 0, as dem.measure.largest_overlap), the largest radius and minus the
#: smallest [m].
MAXIMA = (("largest_overlap", 1), ("largest_radius", 1), ("negative_smallest_radius", 1))


def _offsets():
    """{name: first column} of SUMS then MAXIMA, and the number of columns."""
    first = {}
    column = 0
    for name, width in SUMS + MAXIMA:
        first[name] = column
        column += width
    return first, column


_FIRST, COLUMNS = _offsets()
TOUCHING = _FIRST["touching"]
RESULTANT = _FIRST["resultant"]
CONTACT_FORCE = _FIRST["contact_force"]
STRESS = _FIRST["stress"]
FABRIC = _FIRST["fabric"]
RADIUS_CUBED = _FIRST["radius_cubed"]
BRIDGES = _FIRST["bridges"]
WATER_VOLUME = _FIRST["water_volume"]
CAPILLARY = _FIRST["capillary"]
CAP_LATERAL = _FIRST["cap_lateral"]
CAP_AXIAL = _FIRST["cap_axial"]
LINE_LATERAL = _FIRST["line_lateral"]
LINE_AXIAL = _FIRST["line_axial"]
BRIDGE_FABRIC = _FIRST["bridge_fabric"]
INTERFACE_LATERAL = _FIRST["interface_lateral"]
INTERFACE_AXIAL = _FIRST["interface_axial"]
PENDULAR_OVERLAPS = _FIRST["pendular_overlaps"]
SUCTION_WATER = _FIRST["suction_water"]
SUCTION_CAP_LATERAL = _FIRST["suction_cap_lateral"]
SUCTION_CAP_AXIAL = _FIRST["suction_cap_axial"]
LARGEST_OVERLAP = _FIRST["largest_overlap"]
LARGEST_RADIUS = _FIRST["largest_radius"]
NEGATIVE_SMALLEST_RADIUS = _FIRST["negative_smallest_radius"]

STATE = BRIDGE_COLUMNS.index("state")
VOLUME = BRIDGE_COLUMNS.index("volume")
FORCE = BRIDGE_COLUMNS.index("force")
FILLING_I = BRIDGE_COLUMNS.index("filling_i")
FILLING_J = BRIDGE_COLUMNS.index("filling_j")
SUCTION = BRIDGE_COLUMNS.index("suction")


@device
def add_outer(partial, b, column, a0, a1, a2, c0, c1, c2):
    """partial[b, column:column + 9] plus the outer product a (x) c, row by row."""
    partial[b, column] += a0 * c0
    partial[b, column + 1] += a0 * c1
    partial[b, column + 2] += a0 * c2
    partial[b, column + 3] += a1 * c0
    partial[b, column + 4] += a1 * c1
    partial[b, column + 5] += a1 * c2
    partial[b, column + 6] += a2 * c0
    partial[b, column + 7] += a2 * c1
    partial[b, column + 8] += a2 * c2


@device
def larger(value, largest):
    """The larger of ``value`` and ``largest``, NaN once either is (numpy.max's NaN)."""
    if value > largest or math.isnan(value):
        return value
    return largest


@device
def branch(position, i, j, k, periodic, image, period):
    """Branch vector of pair k from i to j [m]: x_j - x_i, through the faces of a ``periodic``
    cell with the pair's image (pendular.dem.neighbors.branch_vector: image_k L, and a sheared
    cell's offset when ``period`` holds one); inside walls ``image`` and ``period`` are
    one-entry stand-ins, not read."""
    if periodic:
        return image_branch(position, i, j, image, k, period)
    return (position[j, 0] - position[i, 0], position[j, 1] - position[i, 1],
            position[j, 2] - position[i, 2])


@device
def versine(filling_angle):
    """1 - cos(alpha) = 2 sin^2(alpha / 2) [-], alpha [deg] (bridge_tensors._versine)."""
    half = math.sin(0.5 * (filling_angle * RADIAN))
    return 2.0 * (half * half)


@device
def wetted_cap(radius, filling_angle):
    """(a, c) [m^3] of the wetted-cap integral A = diag(a, a, c) in the bridge frame
    (Eq. 3.48; bridge_tensors.wetted_cap_diagonal), radius [m], filling angle [deg]."""
    v = versine(filling_angle)
    scale = math.pi * (radius * radius * radius) / 3.0
    return scale * (v * v) * (3.0 - v), scale * 2.0 * v * (3.0 - 3.0 * v + v * v)


@device
def contact_line(radius, filling_angle, contact_angle, surface_tension):
    """(a, c) [N m] of the contact-line integral B' = diag(a, a, c) in the bridge frame
    (Eq. 3.49; bridge_tensors.contact_line_diagonal), angles [deg], surface tension [N/m]."""
    alpha = filling_angle * RADIAN
    wetting = alpha + contact_angle * RADIAN
    scale = math.pi * (radius * radius) * surface_tension
    sine = math.sin(alpha)
    return (-scale * (sine * sine) * math.cos(wetting),
            scale * math.sin(2.0 * alpha) * math.sin(wetting))


@device
def add_axisymmetric(partial, b, lateral_column, axial_column, lateral, axial, n0, n1, n2):
    """One bridge's diag(a, a, c) rotated onto the normal n, as a I + (c - a) n n: a into
    ``lateral_column``, (c - a) n n into the nine from ``axial_column``."""
    partial[b, lateral_column] += lateral
    weight = axial - lateral
    add_outer(partial, b, axial_column, n0 * weight, n1 * weight, n2 * weight, n0, n1, n2)


@device
def add_bridge(partial, b, k, i, j, l0, l1, l2, position, radius, pair_i, pair_j, image,
               period, normal, bridges, persist, bridge_pair_force, own_suction,
               contact_angle, surface_tension, interface, radius_ratios, suction_axis,
               distance_low, log_distance_rupture, log_values, suction, roughness,
               volume_ratios, volume_axes, volume_distance_low, volume_log_rupture,
               volume_grid):
    """Bridge k (between i and j, branch vector l; ``image`` and ``period`` as ``branch``)
    into block b's sums: its force on j from i, ``persist``: as applied at the last step
    (``bridge_pair_force``, along the branch vector across a gap; SuctionBridges.pair_forces),
    else the attraction along the contact's normal; ``own_suction`` (volume control): its
    caps weighted by its own suction too, and its interface from the volume table at its
    volume and gap (``roughness`` [-]; bridge_kernels.volume_interfaces)."""
    partial[b, BRIDGES] += 1.0
    partial[b, WATER_VOLUME] += bridges[k, VOLUME]
    if persist:
        add_outer(partial, b, CAPILLARY, l0, l1, l2, bridge_pair_force[k, 0],
                  bridge_pair_force[k, 1], bridge_pair_force[k, 2])
    else:
        pull = -bridges[k, FORCE]       # the attraction along the contact's normal, on j
        add_outer(partial, b, CAPILLARY, l0, l1, l2, pull * normal[k, 0], pull * normal[k, 1],
                  pull * normal[k, 2])
    distance = math.sqrt(l0 * l0 + l1 * l1 + l2 * l2)
    n0 = l0 / distance
    n1 = l1 / distance
    n2 = l2 / distance
    a_i, c_i = wetted_cap(radius[i], bridges[k, FILLING_I])
    a_j, c_j = wetted_cap(radius[j], bridges[k, FILLING_J])
    add_axisymmetric(partial, b, CAP_LATERAL, CAP_AXIAL, a_i + a_j, c_i + c_j, n0, n1, n2)
    if own_suction:
        own = bridges[k, SUCTION]
        partial[b, SUCTION_WATER] += own * bridges[k, VOLUME]
        add_axisymmetric(partial, b, SUCTION_CAP_LATERAL, SUCTION_CAP_AXIAL, own * (a_i + a_j),
                         own * (c_i + c_j), n0, n1, n2)
    a_i, c_i = contact_line(radius[i], bridges[k, FILLING_I], contact_angle, surface_tension)
    a_j, c_j = contact_line(radius[j], bridges[k, FILLING_J], contact_angle, surface_tension)
    add_axisymmetric(partial, b, LINE_LATERAL, LINE_AXIAL, a_i + a_j, c_i + c_j, n0, n1, n2)
    add_outer(partial, b, BRIDGE_FABRIC, n0, n1, n2, n0, n1, n2)
    if interface:
        larger, ratio, distance_star = bridge_gap_star(
            position, radius, pair_i, pair_j, image, period, k,
            bridges[k, STATE] == AT_CONTACT, roughness if own_suction else 0.0)
        if own_suction:
            _, nn11, nn33 = volume_interface_lookup(
                volume_ratios, volume_axes, volume_distance_low, volume_log_rupture,
                volume_grid, ratio, bridges[k, VOLUME] / (larger * larger * larger),
                distance_star)
        else:
            _, nn11, nn33 = interface_lookup(radius_ratios, suction_axis, distance_low,
                                             log_distance_rupture, log_values, ratio,
                                             suction * larger / surface_tension,
                                             distance_star)
        nn11 = nn11 * larger * larger
        nn33 = nn33 * larger * larger
        add_axisymmetric(partial, b, INTERFACE_LATERAL, INTERFACE_AXIAL, nn11 + nn33,
                         2.0 * nn11, n0, n1, n2)


@device
def meniscus(p, slot, n, position, pair_count, pair_j, second_pair, periodic, image, period,
             bridges):
    """Particle p's meniscus in its ``slot``-th pair (its own row first, then the pairs in
    which it is the second member): (bridged, unit direction from p to the other sphere,
    through the faces in a ``periodic`` cell, cosine and sine of p's filling angle);
    bridge_kernels._meniscus_caps."""
    if slot < pair_count[p]:
        k = slot * n + p
        i = p
        j = pair_j[k]
        sign = 1.0
        cap = bridges[k, FILLING_I]
    else:
        k = second_pair[(slot - pair_count[p]) * n + p]
        i = k % n
        j = p
        sign = -1.0
        cap = bridges[k, FILLING_J]
    if bridges[k, STATE] == NO_BRIDGE:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0
    d0, d1, d2 = branch(position, i, j, k, periodic, image, period)
    scale = sign / math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    return (True, d0 * scale, d1 * scale, d2 * scale, math.cos(cap * RADIAN),
            math.sin(cap * RADIAN))


@device
def overlapping_menisci(p, n, position, pair_count, pair_j, second_count, second_pair,
                        periodic, image, period, bridges):
    """How many pairs of particle p's menisci overlap: their directions closer than the sum of
    their filling angles (bridge_kernels.pendular_overlap_counts)."""
    slots = pair_count[p] + second_count[p]
    found = 0
    for a in range(slots):
        bridged, a0, a1, a2, cos_a, sin_a = meniscus(p, a, n, position, pair_count, pair_j,
                                                     second_pair, periodic, image, period,
                                                     bridges)
        if not bridged:
            continue
        for b in range(a + 1, slots):
            bridged, b0, b1, b2, cos_b, sin_b = meniscus(p, b, n, position, pair_count,
                                                         pair_j, second_pair, periodic, image,
                                                         period, bridges)
            if bridged and a0 * b0 + a1 * b1 + a2 * b2 > cos_a * cos_b - sin_a * sin_b:
                found += 1
    return found


@cuda.jit
def homogenize_partials(position, radius, force, wall_position, pairs, box, contacts,
                        capillary, table, volume_table, partial):
    """partial[b, :]: block b's sums (SUMS) over its CHUNK particles in order and, for each, its
    row of pairs in order: the touching pairs' (overlap > 0) contact terms and, ``wet``, the
    bridges' (BridgeState ``state`` != NO_BRIDGE; ``bridges`` (K, BRIDGE_COLUMNS)); the
    interface term when ``interface`` (the exact table's arrays, the suction [Pa]; with
    ``own_suction``, the volume table's and the roughness); ``persist``, ``bridge_pair_force``
    and ``own_suction`` as ``add_bridge``; then its
    largest values (MAXIMA), the walls' overlaps inside walls. ``periodic``: a periodic cell,
    the pairs' ``image`` (K, 3) and the ``period`` [m] (``branch``). The bundles PairIndex,
    Box, Contacts and Capillary; ``table`` a BridgeTable's arrays(), ``volume_table`` a
    VolumeBridgeTable's (stand-ins when unread)."""
    pair_count, pair_i, pair_j, second_count, second_pair = pairs
    periodic, image, period = box
    overlap, normal, pair_force = contacts
    (wet, bridges, persist, bridge_pair_force, own_suction, contact_angle, surface_tension,
     interface, suction, roughness) = capillary
    radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values = table
    volume_ratios, volume_axes, volume_distance_low, volume_log_rupture, volume_grid = \
        volume_table
    b = cuda.grid(1)
    if b >= partial.shape[0]:
        return
    for column in range(COLUMNS):
        partial[b, column] = 0.0
    partial[b, LARGEST_RADIUS] = -math.inf
    partial[b, NEGATIVE_SMALLEST_RADIUS] = -math.inf
    n = position.shape[0]
    for p in range(b * CHUNK, min((b + 1) * CHUNK, n)):
        partial[b, LARGEST_RADIUS] = larger(radius[p], partial[b, LARGEST_RADIUS])
        partial[b, NEGATIVE_SMALLEST_RADIUS] = larger(-radius[p],
                                                      partial[b, NEGATIVE_SMALLEST_RADIUS])
        for axis in range(0 if periodic else 3):        # a cell has no walls
            inside = min(position[p, axis] - wall_position[2 * axis],
                         wall_position[2 * axis + 1] - position[p, axis])
            partial[b, LARGEST_OVERLAP] = larger(1.0 - inside / radius[p],
                                                 partial[b, LARGEST_OVERLAP])
        partial[b, RESULTANT] += math.sqrt(force[p, 0] * force[p, 0] + force[p, 1] * force[p, 1]
                                           + force[p, 2] * force[p, 2])
        partial[b, RADIUS_CUBED] += radius[p] * radius[p] * radius[p]
        if wet:
            partial[b, PENDULAR_OVERLAPS] += overlapping_menisci(
                p, n, position, pair_count, pair_j, second_count, second_pair, periodic,
                image, period, bridges)
        for k in range(p, p + pair_count[p] * n, n):
            j = pair_j[k]
            partial[b, LARGEST_OVERLAP] = larger(overlap[k] / min(radius[p], radius[j]),
                                                 partial[b, LARGEST_OVERLAP])
            l0, l1, l2 = branch(position, p, j, k, periodic, image, period)
            if overlap[k] > 0.0:
                f0 = pair_force[k, 0]
                f1 = pair_force[k, 1]
                f2 = pair_force[k, 2]
                partial[b, TOUCHING] += 1.0
                partial[b, CONTACT_FORCE] += math.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
                add_outer(partial, b, STRESS, l0, l1, l2, f0, f1, f2)
                add_outer(partial, b, FABRIC, normal[k, 0], normal[k, 1], normal[k, 2],
                          normal[k, 0], normal[k, 1], normal[k, 2])
            if wet and bridges[k, STATE] != NO_BRIDGE:
                add_bridge(partial, b, k, p, j, l0, l1, l2, position, radius, pair_i, pair_j,
                           image, period, normal, bridges, persist, bridge_pair_force,
                           own_suction, contact_angle, surface_tension, interface,
                           radius_ratios, suction_axis, distance_low, log_distance_rupture,
                           log_values, suction, roughness, volume_ratios, volume_axes,
                           volume_distance_low, volume_log_rupture, volume_grid)


@cuda.jit
def sum_columns(partial, totals):
    """One thread per column: the blocks' partial sums added in order (the largest of them
    for MAXIMA's columns)."""
    c = cuda.grid(1)
    if c >= partial.shape[1]:
        return
    total = partial[0, c]
    for b in range(1, partial.shape[0]):
        if c >= LARGEST_OVERLAP:
            total = larger(partial[b, c], total)
        else:
            total += partial[b, c]
    totals[c] = total


def _tensor(sums, name):
    """The 3x3 sum ``name`` of SUMS from the reduced columns."""
    return sums[_FIRST[name]:_FIRST[name] + 9].reshape(3, 3).copy()


def _axisymmetric_sum(sums, name):
    """sum_k a_k I + (c_k - a_k) n n (bridge_tensors.axisymmetric_sum) of ``name``'s sums."""
    return sums[_FIRST[f"{name}_lateral"]] * np.eye(3) + _tensor(sums, f"{name}_axial")


def launches(gpu, partial, totals):
    """The two launches (kernel, threads, arguments) that reduce the state of ``gpu`` (a
    pendular.gpu.GpuSimulation) into ``totals`` (COLUMNS,) through ``partial`` (blocks,
    COLUMNS), blocks = ceil(N / CHUNK)."""
    s = gpu.state
    bridges = gpu.bridges       # their device side (pendular.gpu.bridges)
    wet = bridges.wet
    interface = wet and bridges.op.model == "exact"
    period = s.period if s.periodic else s.no_period
    image = s.image if s.periodic else s.no_image   # zeros where bridges across gaps read it
    return ((homogenize_partials, partial.shape[0],
             (s.position, s.radius, s.force, s.wall_position,
              PairIndex(s.pair_count, s.pair_i, s.pair_j, s.second_count, s.second_pair),
              Box(s.periodic, image, period), Contacts(s.overlap, s.normal, s.pair_force),
              Capillary(wet, s.bridges, s.persist, s.bridge_pair_force, bridges.volume_control,
                        bridges.op.contact_angle if wet else 0.0, bridges.surface_tension,
                        interface, bridges.suction, bridges.roughness),
              bridges.table, bridges.volume_table, partial)),
            (sum_columns, COLUMNS, (partial, totals)))


def reduced_sums(gpu):
    """(COLUMNS,) the sums of SUMS over the device's state, on the host (two launches and one
    copy of COLUMNS numbers)."""
    blocks = max(1, -(-gpu.state.count // CHUNK))
    partial = cuda.device_array((blocks, COLUMNS))
    totals = cuda.device_array(COLUMNS)
    for kernel, threads, arguments in launches(gpu, partial, totals):
        configured(kernel, threads)(*arguments)
    return totals.copy_to_host()


def device_homogenization(gpu, volume=None):
    """The homogenised quantities of the state ``gpu`` (a pendular.gpu.GpuSimulation) holds,
    reduced on the device, as the history's columns name them (pendular.procedures.loading.
    history_columns, pendular.homogenize.on_the_fly.CapillaryHomogenization): a dict of
    ``sigma_contact`` (3, 3) [Pa], ``coordination`` [-], ``fabric`` (3, 3), ``anisotropy``
    (Eq. 3.51), ``unbalanced_force`` [-], ``solid_volume`` [m^3] (the spheres'),
    ``largest_overlap`` [-] (pendular.dem.measure.largest_overlap), ``smallest_radius``
    and ``largest_radius`` [m]; wet, also ``bridges``, ``pendular_overlaps``,
    ``water_volume`` [m^3], ``chi`` (3, 3) [-], ``B``, ``psi``, ``sigma_capillary`` (3, 3)
    [Pa], ``fabric_bridges``, ``anisotropy_bridges``, ``a_psi``, and with the exact model
    ``psi_interface`` (3, 3) [Pa].

    volume: V [m^3] homogenised over; None: the box inside the device's walls, or the
    periodic cell's volume (its faces). The walls' positions and moments (six numbers each;
    a cell's faces alone) and the sums come back; the particles do not. In a cell the sums
    run over the branch vectors through its faces and there are no wall terms (the CPU's
    contact_stress, largest_overlap, homogenize_bridges with the cell's period)."""
    s = gpu.state
    if volume is None:
        wall_position = s.wall_position.copy_to_host()
        volume = float(np.prod(wall_position[1::2] - wall_position[0::2]))
    volume = check_positive("volume", volume, "m^3")
    sums = reduced_sums(gpu)
    stress = _tensor(sums, "stress")
    if not s.periodic:          # the walls' l f; a cell has none
        moment = s.wall_moment.copy_to_host()
        stress[np.diag_indices(3)] += moment[0::2] + moment[1::2]
    touching = sums[TOUCHING]
    fabric = _tensor(sums, "fabric")
    if touching:
        fabric = fabric / touching
    count = s.count
    unbalanced = ((sums[RESULTANT] / count) / (sums[CONTACT_FORCE] / touching) if touching
                  else np.inf)
    out = {"sigma_contact": stress / volume,
           "coordination": 2.0 * touching / count,
           "fabric": fabric,
           "anisotropy": principal_anisotropy(fabric),
           "unbalanced_force": float(unbalanced),
           "solid_volume": float(4.0 / 3.0 * np.pi * sums[RADIUS_CUBED]),
           "largest_overlap": float(sums[LARGEST_OVERLAP]),
           "smallest_radius": float(-sums[NEGATIVE_SMALLEST_RADIUS]),
           "largest_radius": float(sums[LARGEST_RADIUS])}
    bridges = gpu.bridges
    if not bridges.wet:
        return out
    water_volume = float(sums[WATER_VOLUME])
    chi = (water_volume * np.eye(3) + _axisymmetric_sum(sums, "cap")) / volume   # Eq. 3.44
    tension = _axisymmetric_sum(sums, "line") / volume                          # Eq. 3.45
    if bridges.volume_control:  # each bridge at its own suction (on_the_fly's psi)
        psi = (sums[SUCTION_WATER] * np.eye(3) + _axisymmetric_sum(sums, "suction_cap")
               ) / volume + tension
    else:
        psi = chi * bridges.suction + tension                                     # Eq. 3.46
    bridge_count = sums[BRIDGES]
    bridge_fabric = _tensor(sums, "bridge_fabric")
    if bridge_count:
        bridge_fabric = bridge_fabric / bridge_count                            # Eq. 3.53
    out.update({"bridges": int(bridge_count),
                "pendular_overlaps": int(sums[PENDULAR_OVERLAPS]),
                "water_volume": water_volume, "chi": chi,
                "B": tension, "psi": psi, "sigma_capillary": _tensor(sums, "capillary") / volume,
                "fabric_bridges": bridge_fabric,
                "anisotropy_bridges": principal_anisotropy(bridge_fabric),      # Eq. 3.54
                "a_psi": principal_anisotropy(psi)})                            # Eq. 4.5
    if bridges.op.model == "exact":
        out["psi_interface"] = (bridges.surface_tension
                                * _axisymmetric_sum(sums, "interface") / volume)
    return out
