"""Tabulated volume-controlled bridges over (V*, d*) for fast lookups inside Numba kernels.

Grid, per radius ratio r: ln V* uniform between the volumes of bridges formed at contact with
u* = CONTACT_SUCTION_MAX and u* = 0 (pendular.capillary.volume_control), and, for each volume,
the distance coordinate z of pendular.capillary.table (z = 0 at the volume-controlled rupture, 1 at
contact). Each node holds the exact bridge of pendular.capillary.volume_control.
Lookups interpolate u* and the logarithms of the other quantities linearly in (r, ln V*, z),
z relative to the interpolated rupture distance.
"""

from concurrent.futures import ProcessPoolExecutor
import math
import os

import numba
import numpy as np

from pendular.capillary.meniscus import bridge_kernel
from pendular.capillary.suction_control import contact_filling_angle
from pendular.capillary.table import (SPOT_NODES, YADE_RADIUS_RATIOS, TabulatedBridges,
    along_axis, bilinear, check_node_count, check_radius_ratios, compare_node, distance_cell,
    distance_fraction, grid_position, radius_ratio_bracket, spot_nodes)
from pendular.capillary.validation import check_contact_angle
from pendular.capillary.volume_control import (CONTACT_SUCTION_MAX, contour_point_at_distance,
    suction_at, trace_contour)

VOLUME_FIELDS = ("force", "suction", "delta1", "delta2", "nn11", "nn33")
"""Quantities stored at each node, last axis of `values`: F*, u*, delta1 and delta2 (degrees), nn11, nn33."""


def contact_volume_range(radius_ratio, contact_angle):
    """(smallest, largest) V* of bridges formed at contact with u* in [0, CONTACT_SUCTION_MAX]."""
    theta = math.radians(contact_angle)
    volumes = []
    for suction in (CONTACT_SUCTION_MAX, 0.0):
        delta1 = contact_filling_angle(radius_ratio, theta, suction)
        volumes.append(bridge_kernel(radius_ratio, theta, suction, delta1)[1])
    return volumes[0], volumes[1]


def volume_axis(radius_ratio, contact_angle):
    """(ln V*_min, ln V*_max) tabulated for a radius ratio: contact_volume_range, a round-off
    inside so that the contact end of each volume is found by bracketing."""
    smallest, largest = contact_volume_range(radius_ratio, contact_angle)
    return math.log(smallest) + 1e-9, math.log(largest) - 1e-9


def build_volume_rows(radius_ratio, contact_angle, n_volume, n_distance):
    """Nodes of one radius ratio: (ln V* bounds, distance_low (n_V,), distance_rupture (n_V,),
    values (n_V, n_distance, 6))."""
    theta = math.radians(contact_angle)
    log_bounds = volume_axis(radius_ratio, contact_angle)
    distance_low = np.empty(n_volume)
    distance_rupture = np.empty(n_volume)
    values = np.empty((n_volume, n_distance, len(VOLUME_FIELDS)))
    for m, log_volume in enumerate(np.linspace(*log_bounds, n_volume)):
        contour = trace_contour(radius_ratio, contact_angle, math.exp(log_volume))
        distance_low[m] = contour.contact_distance
        distance_rupture[m] = contour.rupture_distance
        for j in range(n_distance):
            if j == 0:
                point = contour.points[-1]
            elif j == n_distance - 1:
                point = contour.points[0]
            else:
                fraction = distance_fraction(j / (n_distance - 1))
                d = contour.contact_distance + (contour.rupture_distance - contour.contact_distance) * fraction
                point = contour_point_at_distance(contour, d)
            suction = suction_at(radius_ratio, point[0])
            _, _, force, delta2, nn11, nn33 = bridge_kernel(radius_ratio, theta, suction, point[1])
            values[m, j] = (force, suction, math.degrees(point[1]), math.degrees(delta2), nn11, nn33)
        trace_contour.cache_clear()
    return log_bounds, distance_low, distance_rupture, values


@numba.njit(cache=True)
def _volume_position(volume_axes, i_r, log_volume, n_volume):
    low, high = volume_axes[i_r, 0], volume_axes[i_r, 1]
    if not low <= log_volume <= high:
        raise ValueError("lookup_volume: volume_star is outside the table range for this radius ratio")
    return grid_position(log_volume - low, (high - low) / (n_volume - 1), n_volume)


@numba.njit(cache=True)
def _interpolate(grid, i_r, i_v, t_v, i_next, i_w, t_w, t_r, j, t_z, field):
    """grid field interpolated in the tables of radius ratios i_r and i_next, each at its own volume cell."""
    low = bilinear(grid, i_r, i_v, t_v, j, t_z, field)
    high = bilinear(grid, i_next, i_w, t_w, j, t_z, field)
    return (1.0 - t_r) * low + t_r * high


@numba.njit(cache=True)
def lookup_volume(
    radius_ratios, volume_axes, distance_low, log_distance_rupture, grid, radius_ratio, volume_star, distance_star
):
    """Volume-controlled bridge from a VolumeBridgeTable's arrays(): r = R2/R1, V* = V/R2**3, d* = D/R2.

    Returns (exists, F*, u*, delta1, delta2): F* = F/(2 pi gamma R2), u* = s R2/gamma (negative
    for convex menisci), filling angles in degrees. exists is False beyond the volume-controlled
    rupture distance (then the other values are 0); distances below contact get the contact
    values. Raises ValueError for r outside the table's radius ratios, V* outside the volume
    range of either bracketing radius ratio, or non-finite input. The grid holds u* and the
    logarithms of the other (positive) quantities; interpolation as in lookup_suction.
    """
    exists, cells = _volume_cell(radius_ratios, volume_axes, distance_low, log_distance_rupture,
                                 grid, radius_ratio, volume_star, distance_star)
    if not exists:
        return False, 0.0, 0.0, 0.0, 0.0
    force = math.exp(_interpolate(*cells, 0))
    suction = _interpolate(*cells, 1)
    delta1 = math.exp(_interpolate(*cells, 2))
    delta2 = math.exp(_interpolate(*cells, 3))
    return True, force, suction, delta1, delta2


@numba.njit(cache=True)
def _volume_cell(radius_ratios, volume_axes, distance_low, log_distance_rupture, grid,
                 radius_ratio, volume_star, distance_star):
    """Checked table cell of (r, V*, d*) for _interpolate: (exists, cell); exists is False
    beyond the volume-controlled rupture distance, and the cell is then the rupture node."""
    if not (math.isfinite(volume_star) and math.isfinite(distance_star) and math.isfinite(radius_ratio)):
        raise ValueError("lookup_volume: non-finite radius_ratio, volume_star or distance_star")
    if not volume_star > 0.0:
        raise ValueError("lookup_volume: volume_star must be positive")
    n_volume = grid.shape[1]
    log_volume = math.log(volume_star)
    i_r, t_r = radius_ratio_bracket(radius_ratios, radius_ratio)
    i_next = i_r + 1 if t_r > 0.0 else i_r
    i_v, t_v = _volume_position(volume_axes, i_r, log_volume, n_volume)
    i_w, t_w = _volume_position(volume_axes, i_next, log_volume, n_volume)
    d_rupture = math.exp(
        (1.0 - t_r) * along_axis(log_distance_rupture, i_r, i_v, t_v)
        + t_r * along_axis(log_distance_rupture, i_next, i_w, t_w)
    )
    d_low = (1.0 - t_r) * along_axis(distance_low, i_r, i_v, t_v) + t_r * along_axis(distance_low, i_next, i_w, t_w)
    j, t_z = distance_cell(min(distance_star, d_rupture), d_low, d_rupture, grid.shape[2])
    return distance_star <= d_rupture, (grid, i_r, i_v, t_v, i_next, i_w, t_w, t_r, j, t_z)


@numba.njit(cache=True)
def lookup_volume_interface(radius_ratios, volume_axes, distance_low, log_distance_rupture, grid,
                            radius_ratio, volume_star, distance_star):
    """The liquid-gas interface of a volume-controlled bridge (arguments as lookup_volume):
    (exists, nn11*, nn33*), nn_ii* = (1/R2^2) ∫_interface n_i n_i dS, axis 3 along the bridge;
    beyond the rupture distance exists is False and the values are those at rupture."""
    exists, cells = _volume_cell(radius_ratios, volume_axes, distance_low, log_distance_rupture,
                                 grid, radius_ratio, volume_star, distance_star)
    return exists, math.exp(_interpolate(*cells, 4)), math.exp(_interpolate(*cells, 5))


def _build_one_radius_ratio(job):
    return build_volume_rows(*job)


class VolumeBridgeTable(TabulatedBridges):
    """Exact volume-controlled bridges tabulated over (r, V*, d*) for one contact angle.

    Build with VolumeBridgeTable.build(...) or, cached on disk, VolumeBridgeTable.cached(...).
    Inside Numba code call ``lookup_volume(*table.arrays(), radius_ratio, volume_star,
    distance_star)``.
    Covered range per radius ratio: volume_range(i); distances from contact to rupture.
    """

    kind = "volume"
    description = "volume-controlled bridge table"
    fields = VOLUME_FIELDS
    file_arrays = ("radius_ratios", "volume_axes", "distance_low", "distance_rupture", "values")
    file_prefix = "volume_bridge_table"
    axis_nodes = "n_volume"

    def __init__(self, contact_angle, radius_ratios, volume_axes, distance_low, distance_rupture, values):
        super().__init__(contact_angle, radius_ratios, distance_low, distance_rupture, values)
        self.volume_axes = np.ascontiguousarray(volume_axes, dtype=np.float64)
        self._grid = np.log(np.abs(self.values))
        self._grid[..., VOLUME_FIELDS.index("suction")] = self.values[..., VOLUME_FIELDS.index("suction")]

    @property
    def n_volume(self):
        return self.values.shape[1]

    def volume_range(self, index):
        """(smallest, largest) V* tabulated for radius ratio radius_ratios[index]."""
        return tuple(math.exp(x) for x in self.volume_axes[index])

    @staticmethod
    def _parameters(contact_angle, radius_ratios, n_volume, n_distance):
        return {
            "contact_angle": float(contact_angle),
            "radius_ratios": [float(r) for r in radius_ratios],
            "n_volume": int(n_volume),
            "n_distance": int(n_distance),
            "contact_suction_max": CONTACT_SUCTION_MAX,
        }

    @classmethod
    def build(cls, contact_angle=0.0, radius_ratios=YADE_RADIUS_RATIOS, n_volume=80, n_distance=80, workers=None):
        """Solve every node exactly, radius ratios in parallel processes (workers, default: CPU count)."""
        contact_angle = check_contact_angle(contact_angle)
        radius_ratios = check_radius_ratios(radius_ratios)
        n_volume = check_node_count("n_volume", n_volume)
        n_distance = check_node_count("n_distance", n_distance)
        jobs = [(float(r), contact_angle, n_volume, n_distance) for r in radius_ratios]
        workers = min(workers or os.cpu_count() or 1, len(jobs))
        if workers > 1:
            with ProcessPoolExecutor(workers) as pool:
                rows = list(pool.map(_build_one_radius_ratio, jobs))
        else:
            rows = [_build_one_radius_ratio(job) for job in jobs]
        return cls(
            contact_angle,
            radius_ratios,
            np.array([row[0] for row in rows]),
            np.array([row[1] for row in rows]),
            np.array([row[2] for row in rows]),
            np.array([row[3] for row in rows]),
        )

    @classmethod
    def cached(cls, contact_angle=0.0, radius_ratios=YADE_RADIUS_RATIOS, n_volume=80, n_distance=80, directory=None):
        """Load the table with these parameters from the cache directory, building and saving it if
        absent; a cached file failing its checksum, identity or node checks is rebuilt (cached_table)."""
        parameters = cls._parameters(contact_angle, radius_ratios, n_volume, n_distance)
        return cls.from_cache(parameters, directory,
                              lambda: cls.build(contact_angle, radius_ratios, n_volume, n_distance))

    @classmethod
    def array_shapes(cls, parameters):
        """Shapes (name -> tuple) of the arrays of the table of these build ``parameters``."""
        return {**super().array_shapes(parameters), "volume_axes": (len(parameters["radius_ratios"]), 2)}

    def check_nodes(self, count=SPOT_NODES):
        """ValueError naming the first of the ``spot_nodes`` whose stored state is not the exact
        bridge (pendular.capillary.meniscus.bridge_kernel at the node's own u* and delta1) of the
        node's volume and distance, or whose radius ratio's volume range differs from
        ``volume_axis``, beyond NODE_TOLERANCE (a relative tolerance)."""
        theta = math.radians(self.contact_angle)
        n_volume, n_distance = self.n_volume, self.n_distance
        checked_axes = set()
        for i, m, j in spot_nodes(self.values.shape[:3], count):
            r = float(self.radius_ratios[i])
            if i not in checked_axes:
                checked_axes.add(i)
                for name, found, exact in zip(("ln V*_min", "ln V*_max"), self.volume_axes[i],
                                              volume_axis(r, self.contact_angle)):
                    compare_node(f"r = {r:g}", f"volume range {name}", found, exact, 1.0)
            volume = math.exp(np.linspace(*self.volume_axes[i], n_volume)[m])
            low, rupture = self.distance_low[i, m], self.distance_rupture[i, m]
            if j == 0:
                distance = rupture
            elif j == n_distance - 1:
                distance = low
            else:
                distance = low + (rupture - low) * distance_fraction(j / (n_distance - 1))
            force, suction, delta1, delta2, nn11, nn33 = self.values[i, m, j]
            exact = bridge_kernel(r, theta, suction, math.radians(delta1))
            where = f"r = {r:g}, V* = {volume:.6g}, distance index {j} of {n_distance}"
            compare_node(where, "distance d*", distance, exact[0], abs(rupture))
            for name, found, solved in (("volume", volume, exact[1]), ("force", force, exact[2]),
                                        ("delta2", delta2, math.degrees(exact[3])),
                                        ("nn11", nn11, exact[4]), ("nn33", nn33, exact[5])):
                compare_node(where, name, found, solved)

    def arrays(self):
        """(radius_ratios, volume_axes = [[ln V*_min, ln V*_max]] per radius ratio, distance_low,
        ln distance_rupture, grid = values with ln of every field but u*): the contiguous float64
        arguments of lookup_volume."""
        return self.radius_ratios, self.volume_axes, self.distance_low, self._log_distance_rupture, self._grid

    def volume_star_bounds(self):
        """(smallest, largest) V* that every radius ratio of the table covers (a round-off
        inside)."""
        return (float(np.exp(np.max(self.volume_axes[:, 0]))) * (1.0 + 1e-9),
                float(np.exp(np.min(self.volume_axes[:, 1]))) * (1.0 - 1e-9))

    def lookup(self, radius_ratio, volume_star, distance_star):
        """Python-side lookup_volume: (exists, F*, u*, delta1, delta2)."""
        return lookup_volume(*self.arrays(), float(radius_ratio), float(volume_star), float(distance_star))
