"""Exact liquid bridge between a sphere and a plane (Young–Laplace), its suction-controlled
family and its table (docs/capillary.md 'Sphere–wall bridges').

The sphere–plane bridge is the limit of the sphere–sphere bridge (pendular.capillary.meniscus)
as the second radius grows without bound, solved directly: the meridian leaves the sphere
(radius R, filling angle delta1, contact angle theta) at the tangent angle
phi0 = delta1 + theta - 90 deg, has the constant mean curvature of the suction s, and meets
the plane at the contact angle, phi_end = 90 deg - theta (the sphere–sphere end condition
with delta2 = 0). The force invariant

    F / (2 pi gamma R) = sin(delta1) sin(delta1 + theta) + (s R / 2 gamma) sin(delta1)**2

gives the height y(phi) in closed form (meniscus.profile_height), and the gap, volume and
interface integrals are quadratures in tau = artanh(sin phi): the sphere's panel as the
sphere–sphere solver's, the plane's in panels of PANEL_WIDTH up to tau_end = artanh(cos theta),
cut where the profile has flattened to round-off (theta = 0: tau_end is infinite, the meniscus
meets the plane tangentially at the height sqrt(2 F* / u)). Suction s >= 0 only: a bridge at
zero suction and zero contact angle has no end (a catenoid-like meridian never turns parallel
to the plane), so the suctions are positive.

Units: the sphere's radius R. u = s R / gamma, distance D/R (from the sphere's surface to the
plane), volume V/R**3, force F/(2 pi gamma R), wetted radius on the plane a/R,
nn_ii = (1/R**2) ∫ n_i n_i dS over the liquid–gas surface (axis 3 normal to the plane).
"""

from dataclasses import dataclass
import math

import numba
import numpy as np

from pendular.capillary.meniscus import (_GAUSS_NODES, _GAUSS_WEIGHTS, _gauss_panel,
    _tau_integrands, profile_height)
from pendular.capillary.roots import brent_maximum, brent_root
from pendular.capillary.suction_control import SMALLEST_FILLING_ANGLE
from pendular.capillary.table import (SPOT_NODES, TabulatedBridges, along_axis, check_node_count,
    compare_node, distance_cell, distance_fraction, grid_position, _interpolate_log, spot_nodes)
from pendular.capillary.validation import (check_contact_angle, check_distance,
    check_filling_angle, check_positive)

#: Width of the quadrature panels in tau on the plane's side of the neck: the integrands'
#: nearest complex singularities lie pi/2 off the real axis, so 32 Gauss nodes per panel of 2
#: integrate them to round-off.
PANEL_WIDTH = 2.0
#: The plane's side is cut where cos(phi) has fallen below this fraction of sqrt(2 u F*), the
#: flattened meniscus's own scale: what lies beyond is below round-off.
FLAT = 1e-17

#: Quantities stored at each node of a WallBridgeTable (last axis of ``values``): F*, V*,
#: delta1 [deg], the wetted radius on the plane a/R, nn11, nn33.
WALL_FIELDS = ("force", "volume", "delta1", "wetted_radius", "nn11", "nn33")


@dataclass(frozen=True)
class WallBridge:
    """One sphere–plane bridge in the sphere's units (module docstring); angles in degrees.

    contact_angle: theta; suction: u = s R / gamma; distance: D/R; volume: V/R**3; force:
    F/(2 pi gamma R), attractive; delta1: the filling angle on the sphere; wetted_radius: a/R
    of the wetted disc on the plane; nn11, nn33: (1/R**2) ∫ n_i n_i dS over the liquid–gas
    surface, axis 3 normal to the plane."""

    contact_angle: float
    suction: float
    distance: float
    volume: float
    force: float
    delta1: float
    wetted_radius: float
    nn11: float
    nn33: float


@numba.njit(cache=True)
def wall_bridge_kernel(theta, suction, delta1):
    """Exact sphere–plane bridge for theta [rad], u = s R / gamma >= 0 and delta1 [rad]:
    (distance D/R, volume V/R**3, force F/(2 pi gamma R), wetted radius a/R, nn11, nn33), all
    NaN where no such meniscus exists (u = 0 and theta = 0, or a non-positive force)."""
    nan = np.nan
    sin1 = math.sin(delta1)
    force_invariant = sin1 * (math.sin(delta1 + theta) + 0.5 * suction * sin1)
    if not (force_invariant > 0.0 and suction >= 0.0):
        return nan, nan, nan, nan, nan, nan
    scale = math.sqrt(2.0 * suction * force_invariant)
    if theta > 0.0:
        tau_end = -math.log(math.tan(0.5 * theta))             # artanh(cos theta)
        if scale > 0.0:
            tau_end = min(tau_end, math.acosh(1.0 / (FLAT * scale)))
    elif scale > 0.0:
        tau_end = math.acosh(1.0 / (FLAT * scale))
    else:
        return nan, nan, nan, nan, nan, nan
    shape = (force_invariant, suction)
    tau_start = math.log(math.tan(0.5 * (delta1 + theta)))
    length, volume, area11, area33 = _gauss_panel(_tau_integrands, tau_start, 0.0, shape,
                                                  _GAUSS_NODES, _GAUSS_WEIGHTS)
    panels = max(1, int(math.ceil(tau_end / PANEL_WIDTH)))
    for k in range(panels):
        l, v, a, b = _gauss_panel(_tau_integrands, tau_end * k / panels,
                                  tau_end * (k + 1) / panels, shape, _GAUSS_NODES,
                                  _GAUSS_WEIGHTS)
        length += l
        volume += v
        area11 += a
        area33 += b
    versine = 2.0 * math.sin(0.5 * delta1) ** 2               # 1 - cos(delta1)
    cap = math.pi / 3.0 * versine * versine * (3.0 - versine)
    wetted = profile_height(0.5 * math.pi - theta, force_invariant, suction)
    return length - versine, volume - cap, force_invariant, wetted, area11, area33


@numba.njit(cache=True)
def _wall_distance_at_log_filling_angle(log_delta1, args):
    theta, suction = args
    return wall_bridge_kernel(theta, suction, math.exp(log_delta1))[0]


@numba.njit(cache=True)
def _wall_distance_residual(delta1, args):
    theta, suction, distance = args
    return wall_bridge_kernel(theta, suction, delta1)[0] - distance


@numba.njit(cache=True)
def wall_rupture_point(theta, suction):
    """(delta1 [rad], D/R) at the largest distance of the family at suction u > 0: no bridge
    exists farther from the plane (pendular.capillary.suction_control.rupture_point's rule)."""
    log_delta1, distance = brent_maximum(
        _wall_distance_at_log_filling_angle, (theta, suction), math.log(SMALLEST_FILLING_ANGLE),
        math.log(0.5 * math.pi - theta), 1e-12)
    return math.exp(log_delta1), distance


@numba.njit(cache=True)
def wall_stable_filling_angle(theta, suction, distance, delta1_rupture, distance_rupture):
    """delta1 [rad] of the stable (larger) bridge at D/R = ``distance``, given the rupture
    point; NaN beyond rupture or below the distance at delta1 = 90 deg - theta."""
    if distance > distance_rupture:
        return np.nan
    largest = 0.5 * math.pi - theta
    args = (theta, suction, distance)
    residual_largest = _wall_distance_residual(largest, args)
    if residual_largest > 0.0:
        return np.nan
    return brent_root(_wall_distance_residual, args, delta1_rupture, largest,
                      distance_rupture - distance, residual_largest, 1e-15)


def _bridge(contact_angle, suction, delta1):
    distance, volume, force, wetted, nn11, nn33 = wall_bridge_kernel(
        math.radians(contact_angle), suction, delta1)
    return WallBridge(contact_angle, suction, distance, volume, force, math.degrees(delta1),
                      wetted, nn11, nn33)


def solve_wall_bridge(contact_angle, suction, filling_angle):
    """Exact sphere–plane bridge from its filling angle on the sphere: contact_angle theta in
    [0, 90) deg, suction u = s R / gamma > 0, filling_angle delta1 in (0, 90 - theta] deg.
    Returns a WallBridge (the sphere's units, angles in degrees)."""
    contact_angle = check_contact_angle(contact_angle)
    suction = check_positive("suction", suction)
    filling_angle = check_filling_angle(filling_angle, contact_angle)
    return _bridge(contact_angle, suction, math.radians(filling_angle))


def wall_rupture_distance(contact_angle, suction):
    """The sphere–plane rupture distance D/R at u = s R / gamma > 0."""
    contact_angle = check_contact_angle(contact_angle)
    suction = check_positive("suction", suction)
    return wall_rupture_point(math.radians(contact_angle), suction)[1]


def wall_bridge_at_distance(contact_angle, suction, distance):
    """The stable sphere–plane bridge at u = s R / gamma > 0 and D/R = ``distance``;
    ValueError beyond the rupture distance or below the distance of delta1 = 90 - theta."""
    contact_angle = check_contact_angle(contact_angle)
    suction = check_positive("suction", suction)
    distance = check_distance(distance)
    theta = math.radians(contact_angle)
    delta1_rupture, distance_rupture = wall_rupture_point(theta, suction)
    delta1 = wall_stable_filling_angle(theta, suction, distance, delta1_rupture,
                                       distance_rupture)
    if math.isnan(delta1):
        low = wall_bridge_kernel(theta, suction, 0.5 * math.pi - theta)[0]
        raise ValueError(f"distance = {distance} is outside the valid range [{low:.8g}, "
                         f"{distance_rupture:.8g}] of a sphere-wall bridge at contact_angle = "
                         f"{contact_angle} deg, suction = {suction}")
    return _bridge(contact_angle, suction, delta1)


# ---------------------------------------------------------------- table

@numba.njit(cache=True)
def _write_fields(theta, suction, delta1, out):
    _, volume, force, wetted, nn11, nn33 = wall_bridge_kernel(theta, suction, delta1)
    out[0] = force
    out[1] = volume
    out[2] = math.degrees(delta1)
    out[3] = wetted
    out[4] = nn11
    out[5] = nn33


@numba.njit(cache=True, parallel=True)
def build_wall_grid(theta, suction_nodes, n_distance):
    """Exact stable sphere–plane bridges on the (u, z) grid (z: the sphere–sphere tables'
    distance coordinate, pendular.capillary.table.distance_coordinate); theta [rad].
    Returns distance_low, distance_rupture (1, n_u) and values (1, n_u, n_distance, 6)."""
    n_u = suction_nodes.size
    distance_low = np.empty((1, n_u))
    distance_rupture = np.empty((1, n_u))
    values = np.empty((1, n_u, n_distance, len(WALL_FIELDS)))
    largest = 0.5 * math.pi - theta
    for k in numba.prange(n_u):
        u = suction_nodes[k]
        delta1_rupture, d_rupture = wall_rupture_point(theta, u)
        d_low = max(0.0, wall_bridge_kernel(theta, u, largest)[0])
        distance_low[0, k] = d_low
        distance_rupture[0, k] = d_rupture
        for j in range(n_distance):
            if j == 0:
                delta1 = delta1_rupture
            elif j == n_distance - 1 and d_low > 0.0:
                delta1 = largest
            else:
                d = d_low + (d_rupture - d_low) * distance_fraction(j / (n_distance - 1))
                delta1 = wall_stable_filling_angle(theta, u, d, delta1_rupture, d_rupture)
            _write_fields(theta, u, delta1, values[0, k, j])
    return distance_low, distance_rupture, values


def wall_suction_nodes(suction_min, suction_max, n_suction):
    """u at the nodes of a WallBridgeTable's suction axis: geometric from suction_min to
    suction_max (ln u uniform)."""
    return np.exp(np.linspace(math.log(suction_min), math.log(suction_max), n_suction))


@numba.njit(cache=True)
def _wall_cell(suction_axis, distance_low, log_distance_rupture, log_values, suction, distance):
    """Checked table cell of (u, D/R): (exists, i_u, t_u, j, t_z); exists is False beyond
    the rupture distance, the cell then the rupture node (z = 0)."""
    if not (math.isfinite(suction) and math.isfinite(distance)):
        raise ValueError("lookup_wall: non-finite suction or distance")
    suction_min, step, suction_max = suction_axis[0], suction_axis[1], suction_axis[2]
    if not suction_min <= suction <= suction_max:
        raise ValueError("lookup_wall: suction is outside the table range [suction_min, "
                         "suction_max]")
    i_u, t_u = grid_position(math.log(suction / suction_min), step, log_values.shape[1])
    d_rupture = math.exp(along_axis(log_distance_rupture, 0, i_u, t_u))
    if distance > d_rupture:
        return False, i_u, t_u, 0, 0.0
    d_low = along_axis(distance_low, 0, i_u, t_u)
    j, t_z = distance_cell(distance, d_low, d_rupture, log_values.shape[2])
    return True, i_u, t_u, j, t_z


@numba.njit(cache=True)
def lookup_wall(suction_axis, distance_low, log_distance_rupture, log_values, suction,
                distance):
    """Suction-controlled sphere–plane bridge from a WallBridgeTable's arrays(): u = s R /
    gamma, D/R. Returns (exists, F*, V*, delta1 [deg], a/R); exists False beyond the rupture
    distance (the other values 0); a gap below the smallest tabulated distance gets the values
    there. Interpolation as pendular.capillary.table.lookup_suction (logarithms, linear in ln u
    and in the distance coordinate relative to the interpolated rupture distance). Raises for u
    outside [suction_min, suction_max] or non-finite input."""
    exists, i_u, t_u, j, t_z = _wall_cell(suction_axis, distance_low, log_distance_rupture,
                                          log_values, suction, distance)
    if not exists:
        return False, 0.0, 0.0, 0.0, 0.0
    return (True, _interpolate_log(log_values, 0, 0, 0.0, i_u, t_u, j, t_z, 0),
            _interpolate_log(log_values, 0, 0, 0.0, i_u, t_u, j, t_z, 1),
            _interpolate_log(log_values, 0, 0, 0.0, i_u, t_u, j, t_z, 2),
            _interpolate_log(log_values, 0, 0, 0.0, i_u, t_u, j, t_z, 3))


@numba.njit(cache=True)
def lookup_wall_interface(suction_axis, distance_low, log_distance_rupture, log_values,
                          suction, distance):
    """(nn11, nn33) / R**2 of the liquid–gas interface of the bridge of lookup_wall's
    arguments (beyond rupture: those at rupture)."""
    _, i_u, t_u, j, t_z = _wall_cell(suction_axis, distance_low, log_distance_rupture,
                                     log_values, suction, distance)
    return (_interpolate_log(log_values, 0, 0, 0.0, i_u, t_u, j, t_z, 4),
            _interpolate_log(log_values, 0, 0, 0.0, i_u, t_u, j, t_z, 5))


class WallBridgeTable(TabulatedBridges):
    """Exact suction-controlled sphere–plane bridges over (u, D/R) for one contact angle, laid
    out as a sphere–sphere table (pendular.capillary.table.TabulatedBridges) of one row
    (``radius_ratios`` (1,) holds 1: the sphere's radius is the unit), its suction axis
    geometric over [suction_min, suction_max]. Build with ``build`` or, cached on disk,
    ``cached``; inside Numba code call ``lookup_wall(*table.arrays(), suction,
    distance)``."""

    kind = "wall_bridge_table"
    description = "sphere-wall bridge table"
    fields = WALL_FIELDS
    file_scalars = ("suction_min", "suction_max")
    file_arrays = ("radius_ratios", "distance_low", "distance_rupture", "values")
    file_prefix = "wall_bridges"
    axis_nodes = "n_suction"

    def __init__(self, contact_angle, radius_ratios, suction_min, suction_max, distance_low,
                 distance_rupture, values):
        super().__init__(contact_angle, radius_ratios, distance_low, distance_rupture, values)
        self.suction_min = float(suction_min)
        self.suction_max = float(suction_max)
        self._log_values = np.log(self.values)

    @property
    def suction(self):
        """u at the suction nodes."""
        return wall_suction_nodes(self.suction_min, self.suction_max, self.values.shape[1])

    @staticmethod
    def _parameters(contact_angle, n_suction, n_distance, suction_min, suction_max):
        return {"contact_angle": float(contact_angle), "radius_ratios": [1.0],
                "suction_min": float(suction_min), "suction_max": float(suction_max),
                "n_suction": int(n_suction), "n_distance": int(n_distance)}

    @classmethod
    def build(cls, contact_angle=0.0, n_suction=120, n_distance=80, suction_min=0.01,
              suction_max=1500.0):
        """Solve every node exactly (parallel over the suctions): contact_angle in [0, 90) deg,
        0 < suction_min < suction_max (u units), n_suction, n_distance >= 2."""
        contact_angle = check_contact_angle(contact_angle)
        suction_min = check_positive("suction_min", suction_min)
        suction_max = check_positive("suction_max", suction_max)
        if suction_max <= suction_min:
            raise ValueError(f"suction_max = {suction_max} must be above suction_min = "
                             f"{suction_min}")
        n_suction = check_node_count("n_suction", n_suction)
        n_distance = check_node_count("n_distance", n_distance)
        nodes = wall_suction_nodes(suction_min, suction_max, n_suction)
        low, rupture, values = build_wall_grid(math.radians(contact_angle), nodes, n_distance)
        return cls(contact_angle, np.ones(1), suction_min, suction_max, low, rupture, values)

    @classmethod
    def cached(cls, contact_angle=0.0, n_suction=120, n_distance=80, suction_min=0.01,
               suction_max=1500.0, directory=None):
        """The table of these parameters from the cache directory, built and saved there when
        absent or failing its checks (pendular.capillary.table.cached_table)."""
        parameters = cls._parameters(contact_angle, n_suction, n_distance, suction_min,
                                     suction_max)
        return cls.from_cache(parameters, directory, lambda: cls.build(
            contact_angle, n_suction, n_distance, suction_min, suction_max))

    def check_nodes(self, count=SPOT_NODES):
        """ValueError naming the first of the spot-checked nodes whose rupture distance,
        smallest distance or quantities differ from the exact solver's (NODE_TOLERANCE)."""
        theta = math.radians(self.contact_angle)
        largest = 0.5 * math.pi - theta
        suction = self.suction
        n_distance = self.n_distance
        for _, k, j in spot_nodes(self.values.shape[:3], count):
            u = float(suction[k])
            delta1_rupture, d_rupture = wall_rupture_point(theta, u)
            d_low = max(0.0, wall_bridge_kernel(theta, u, largest)[0])
            where = f"wall, u = {u:.6g}, distance index {j} of {n_distance}"
            compare_node(where, "rupture distance D/R", self.distance_rupture[0, k], d_rupture)
            compare_node(where, "smallest distance D/R", self.distance_low[0, k], d_low,
                         d_rupture)
            if j == 0:
                bridge = _bridge(self.contact_angle, u, delta1_rupture)
            elif j == n_distance - 1 and d_low > 0.0:
                bridge = _bridge(self.contact_angle, u, largest)
            else:
                distance = d_low + (d_rupture - d_low) * distance_fraction(j / (n_distance - 1))
                bridge = wall_bridge_at_distance(self.contact_angle, u, distance)
            for field, found in zip(WALL_FIELDS, self.values[0, k, j]):
                compare_node(where, field, found, getattr(bridge, field))

    def arrays(self):
        """(suction_axis = [suction_min, ln-u step, suction_max], distance_low, ln
        distance_rupture, ln values): the contiguous float64 arguments of lookup_wall."""
        step = math.log(self.suction_max / self.suction_min) / (self.values.shape[1] - 1)
        return (np.array([self.suction_min, step, self.suction_max]), self.distance_low,
                self._log_distance_rupture, self._log_values)

    def lookup(self, suction, distance):
        """Python-side lookup_wall: (exists, F*, V*, delta1 [deg], a/R)."""
        return lookup_wall(*self.arrays(), float(suction), float(distance))

    def interface(self, suction, distance):
        """Python-side lookup_wall_interface: (nn11, nn33) / R**2."""
        return lookup_wall_interface(*self.arrays(), float(suction), float(distance))
