"""Tabulated suction-controlled bridges over (u*, d*) for fast lookups inside Numba kernels.

Grid, per radius ratio r (the units of docs/units.md):

- suction: xi = ln(1 + u*/suction_scale) uniform on [0, ln(1 + suction_max/suction_scale)], so
  u* = 0 is the first node, small suctions are linear and large ones logarithmic;
- distance: z = arccos(2 f - 1)/pi uniform on [0, 1], with the fraction
  f = (d* - d*_low(u*)) / (d*_rupture(u*) - d*_low(u*)); z = 0 at rupture and z = 1 at the
  smallest tabulated distance d*_low = max(0, d* at delta1 = 90 deg - theta). Near rupture
  z is proportional to sqrt(d*_rupture - d*), which makes every quantity smooth there (they
  behave like sqrt(d*_rupture - d*)); the nodes also cluster near contact, where small
  volume-controlled bridges change fast.

Each node holds the exact stable bridge (pendular.capillary.suction_control). Lookups interpolate the
logarithms of the quantities linearly in (r, xi, z), z relative to the interpolated rupture
distance (YADE's capillary law interpolates the quantities themselves linearly in (r, u*, d*)).
"""

import hashlib
import json
import math
import os
import sys
import time
from pathlib import Path

import h5py
import numba
import numpy as np

from pendular.capillary.meniscus import bridge_from_kernel, bridge_kernel
from pendular.capillary.suction_control import bridge_at_distance, rupture_point, stable_filling_angle
from pendular.capillary.validation import check_contact_angle, check_positive, check_radius_ratio
from pendular.utils.atomic import replacing
from pendular.utils.integrity import stamp, verify
from pendular.utils.validate import reading

YADE_RADIUS_RATIOS = (1.0, 1.1, 1.25, 1.5, 1.75, 2.0, 3.0, 4.0, 5.0, 10.0)
"""Radius ratios of YADE's capillary files M(r=1) ... M(r=10)."""

FIELDS = ("force", "volume", "delta1", "delta2", "nn11", "nn33")
"""Quantities stored at each node, last axis of `values`: F*, V*, delta1 and delta2 (degrees), nn11, nn33."""

TABLE_FORMAT = 1
"""Version of the table layout and solver, part of the cache key."""

NODE_TOLERANCE = 1e-6
"""Largest relative difference between a cached table's node and the exact solver's solution
of it (``spot_nodes``): nodes are solved by the same kernels, so a valid cache agrees to
round-off, and an edited or wrongly built one differs far more."""

SPOT_NODES = 6
"""Nodes of a cached table solved again when it is loaded (at least one per radius ratio): a
handful of exact solves, well under a second."""


def cache_directory():
    """Directory for cached tables: $PENDULAR_CACHE, else ~/.cache/pendular."""
    return Path(os.environ.get("PENDULAR_CACHE", Path.home() / ".cache" / "pendular"))


def save_atomically(table, path, identity=None):
    """table.save to path (atomic: concurrent runs never read a partial table), creating its
    folder; stamped (pendular.utils.integrity: checksum and ``identity``) before it appears when
    ``identity`` is given."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if identity is None:
        table.save(path)
        return
    with replacing(path) as temporary:
        table.save(temporary)
        stamp(temporary, identity)


def cache_key(kind, parameters):
    """Short hash of a table's kind and build parameters."""
    text = json.dumps({"kind": kind, "format": TABLE_FORMAT, **parameters}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def cache_identity(kind, parameters):
    """Identity stamped on a cached table: its kind, layout version, key and build parameters."""
    return {"kind": "table cache", "table": kind, "table_format": TABLE_FORMAT,
            "key": cache_key(kind, parameters), "parameters": parameters}


def cached_table(path, identity, load, check, build):
    """The table cached at ``path`` if it passes every check, else ``build()`` saved there.

    Checks: checksum and ``identity`` (pendular.utils.integrity.verify), ``load(path)``, then
    ``check(table)`` (ValueError when its nodes do not match the key, are not finite or differ
    from the exact solver at the spot-checked nodes: a checksum only proves the file unchanged
    since it was stamped). A file that fails is rebuilt, never used, with a one-line warning
    on stderr saying why; a build says on stderr what it builds and how long it took (seconds
    to minutes)."""
    path = Path(path)
    if path.exists():
        try:
            verify(path, identity, kind="table cache")
            with np.errstate(invalid="ignore", divide="ignore"):    # found by check below
                table = load(path)
            check(table)
            return table
        except (ValueError, OSError) as error:
            named = f"path = {str(path)!r}"
            reason = str(error).replace(f"{named}: ", "").replace(f"{named} ", "the file ")
            reason = " ".join(reason.split())
            print(f"warning: cached bridge table {path} not used, rebuilding it: {reason}",
                  file=sys.stderr)
    print(f"building bridge table {path.name} (cached for later runs) ...", file=sys.stderr,
          flush=True)
    started = time.perf_counter()
    table = build()
    save_atomically(table, path, identity)
    print(f"built {path.name} in {time.perf_counter() - started:.1f} s", file=sys.stderr)
    return table


def check_table_nodes(table, shapes, settings):
    """ValueError unless the table's arrays have the ``shapes`` (name -> tuple) and settings
    (name -> value) its cache key promises, and every lookup array (table.arrays()) is finite
    (no NaN, no logarithm of a non-positive node)."""
    for name, shape in shapes.items():
        found = tuple(getattr(table, name).shape)
        if found != tuple(shape):
            raise ValueError(f"{name} has shape {found}; the cache key says {tuple(shape)}")
    for name, value in settings.items():
        found = getattr(table, name)
        if not np.array_equal(np.asarray(found, dtype=np.float64), np.asarray(value, dtype=np.float64)):
            raise ValueError(f"{name} = {np.asarray(found).tolist()}; the cache key says "
                             f"{np.asarray(value).tolist()}")
    with np.errstate(invalid="ignore"):
        for index, array in enumerate(table.arrays()):
            if not np.isfinite(array).all():
                raise ValueError(f"lookup array {index} holds {int(np.sum(~np.isfinite(array)))} "
                                 "NaN or infinite nodes")


def spot_nodes(shape, count=SPOT_NODES):
    """Indices (i_r, i_axis, j) of the nodes of a grid of ``shape`` (n_r, n_axis, n_distance)
    that a cached table's check solves again: max(count, n_r) nodes, every radius ratio in
    turn, the other two indices spread over their axes (additive recurrences of irrational
    steps), duplicates dropped; the same nodes for the same shape."""
    n_r, n_axis, n_distance = shape
    nodes = []
    for m in range(max(count, n_r)):
        node = (m % n_r, int((0.5 + m * 0.6180339887498949) % 1.0 * n_axis),
                int((0.5 + m * 0.41421356237309515) % 1.0 * n_distance))
        if node not in nodes:
            nodes.append(node)
    return nodes


def compare_node(where, name, found, exact, scale=0.0):
    """ValueError unless the stored ``found`` agrees with the ``exact`` solution within
    NODE_TOLERANCE relative to max(|exact|, ``scale``); ``where`` names the node."""
    if not abs(found - exact) <= NODE_TOLERANCE * max(abs(exact), scale):
        raise ValueError(f"node {where}: {name} = {found:.10g} in the file, {exact:.10g} from "
                         f"the exact solver (valid: within a relative {NODE_TOLERANCE:g})")


def check_radius_ratios(radius_ratios):
    """The radius ratios of a table to build as a float64 array: each in [1,
    MAX_SOLVER_RADIUS_RATIO], at least one, strictly increasing."""
    radius_ratios = np.array([check_radius_ratio(r) for r in radius_ratios], dtype=np.float64)
    if radius_ratios.size == 0 or np.any(np.diff(radius_ratios) <= 0.0):
        raise ValueError(f"radius_ratios = {radius_ratios.tolist()} must be non-empty and strictly increasing")
    return radius_ratios


def check_node_count(name, n):
    """The number of nodes ``n`` of a table's axis as an int: an integer >= 2."""
    if int(n) != n or n < 2:
        raise ValueError(f"{name} = {n} is outside the valid range: an integer >= 2")
    return int(n)


class TabulatedBridges:
    """What the suction- and volume-controlled tables share: exact bridges for one contact angle
    on a grid (r, axis node, z), and the HDF5 file that holds them.

    contact_angle [deg]; radius_ratios (n_r,); distance_low and distance_rupture (n_r, n_axis),
    D/R2 at z = 1 and z = 0 of each axis node; values (n_r, n_axis, n_distance, 6) in the
    subclass's ``fields`` order. The file: root attributes kind, format (TABLE_FORMAT),
    contact_angle_deg, the subclass's ``file_scalars``, fields (joined by commas), then one
    dataset per name of ``file_arrays``; each scalar and array is the table's attribute and its
    constructor's argument of that name. In the cache directory the file is named
    ``{file_prefix}_{cache_key}.h5``; ``axis_nodes`` names the build parameter counting the
    axis nodes.
    """

    kind = ""
    description = ""
    fields = ()
    file_scalars = ()
    file_arrays = ()
    file_prefix = ""
    axis_nodes = ""

    def __init__(self, contact_angle, radius_ratios, distance_low, distance_rupture, values):
        self.contact_angle = float(contact_angle)
        self.radius_ratios = np.ascontiguousarray(radius_ratios, dtype=np.float64)
        self.distance_low = np.ascontiguousarray(distance_low, dtype=np.float64)
        self.distance_rupture = np.ascontiguousarray(distance_rupture, dtype=np.float64)
        self.values = np.ascontiguousarray(values, dtype=np.float64)
        self._log_distance_rupture = np.log(self.distance_rupture)

    @property
    def n_distance(self):
        return self.values.shape[2]

    @classmethod
    def array_shapes(cls, parameters):
        """Shapes (name -> tuple) of the arrays of the table of these build ``parameters``."""
        n_r, n_axis = len(parameters["radius_ratios"]), parameters[cls.axis_nodes]
        return {"values": (n_r, n_axis, parameters["n_distance"], len(cls.fields)),
                "distance_low": (n_r, n_axis), "distance_rupture": (n_r, n_axis)}

    @classmethod
    def from_cache(cls, parameters, directory, build):
        """The table of these build ``parameters`` (the cache key's content) cached in
        ``directory`` (default: cache_directory()), else ``build()`` saved there (cached_table).
        A cached table is used only with the array shapes and settings (contact angle, radius
        ratios, ``file_scalars``) of the key, and its ``check_nodes`` passed."""
        path = Path(directory or cache_directory()) / f"{cls.file_prefix}_{cache_key(cls.kind, parameters)}.h5"
        settings = ("contact_angle", "radius_ratios", *cls.file_scalars)

        def check(table):
            check_table_nodes(table, cls.array_shapes(parameters), {name: parameters[name] for name in settings})
            table.check_nodes()

        return cached_table(path, cache_identity(cls.kind, parameters), cls.load, check, build)

    def save(self, path):
        """Write the table to an HDF5 file, atomically (pendular.utils.atomic.replacing)."""
        with replacing(path) as temporary, h5py.File(temporary, "w") as h5:
            h5.attrs["kind"] = self.kind
            h5.attrs["format"] = TABLE_FORMAT
            h5.attrs["contact_angle_deg"] = self.contact_angle
            for name in self.file_scalars:
                h5.attrs[name] = getattr(self, name)
            h5.attrs["fields"] = ",".join(self.fields)
            for name in self.file_arrays:
                h5[name] = getattr(self, name)

    @classmethod
    def load(cls, path):
        """Read a table written by save()."""
        with reading(path, cls.description), h5py.File(path, "r") as h5:
            if h5.attrs.get("kind") != cls.kind or h5.attrs.get("format") != TABLE_FORMAT:
                raise ValueError(f"{path} is not a {cls.description} of format {TABLE_FORMAT}")
            return cls(contact_angle=h5.attrs["contact_angle_deg"],
                       **{name: h5.attrs[name] for name in cls.file_scalars},
                       **{name: h5[name][...] for name in cls.file_arrays})


@numba.njit(cache=True)
def write_bridge_fields(radius_ratio, theta, suction_star, delta1, out):
    """The exact bridge at delta1 [rad] (theta [rad]) into ``out`` in FIELDS order: F*, V*,
    delta1 and delta2 [deg], nn11, nn33."""
    _, volume, force, delta2, nn11, nn33 = bridge_kernel(radius_ratio, theta, suction_star, delta1)
    out[0] = force
    out[1] = volume
    out[2] = math.degrees(delta1)
    out[3] = math.degrees(delta2)
    out[4] = nn11
    out[5] = nn33


@numba.njit(cache=True, parallel=True)
def build_suction_grid(radius_ratios, theta, suction_nodes, n_distance):
    """Exact stable bridges on the (r, u*, z) grid; theta in rad.

    Returns (distance_low, distance_rupture) of shape (n_r, n_u) and values (n_r, n_u, n_distance, 6).
    """
    n_r = radius_ratios.size
    n_u = suction_nodes.size
    distance_low = np.empty((n_r, n_u))
    distance_rupture = np.empty((n_r, n_u))
    values = np.empty((n_r, n_u, n_distance, len(FIELDS)))
    largest = 0.5 * math.pi - theta
    for job in numba.prange(n_r * n_u):
        i = job // n_u
        k = job % n_u
        r = radius_ratios[i]
        u = suction_nodes[k]
        delta1_rupture, d_rupture = rupture_point(r, theta, u)
        d_low = max(0.0, bridge_kernel(r, theta, u, largest)[0])
        distance_low[i, k] = d_low
        distance_rupture[i, k] = d_rupture
        for j in range(n_distance):
            if j == 0:
                delta1 = delta1_rupture
            elif j == n_distance - 1 and d_low > 0.0:
                delta1 = largest
            else:
                d = d_low + (d_rupture - d_low) * distance_fraction(j / (n_distance - 1))
                delta1 = stable_filling_angle(r, theta, u, d, delta1_rupture, d_rupture)
            write_bridge_fields(r, theta, u, delta1, values[i, k, j])
    return distance_low, distance_rupture, values


@numba.njit(cache=True)
def radius_ratio_bracket(radius_ratios, radius_ratio):
    """(index i, weight t) with radius_ratio = (1 - t) r[i] + t r[i + 1]; raises outside the table."""
    n_r = radius_ratios.size
    if not (radius_ratios[0] <= radius_ratio <= radius_ratios[n_r - 1]):
        raise ValueError("radius_ratio is outside the range of the table's radius ratios")
    if n_r == 1:
        return 0, 0.0
    i = 0
    while i < n_r - 2 and radius_ratio > radius_ratios[i + 1]:
        i += 1
    return i, (radius_ratio - radius_ratios[i]) / (radius_ratios[i + 1] - radius_ratios[i])


@numba.njit(cache=True)
def grid_position(coordinate, step, n):
    """Cell index and fraction for a coordinate on a uniform grid 0, step, ..., (n - 1) step."""
    s = coordinate / step
    i = min(int(s), n - 2)
    return i, s - i


@numba.njit(cache=True)
def distance_coordinate(fraction):
    """Grid coordinate z in [0, 1] of a distance fraction (d - d_low)/(d_rupture - d_low), clamped to [0, 1].

    z = arccos(2 fraction - 1)/pi: z = 0 at rupture, 1 at d_low; uniform z clusters nodes at both
    ends, and quantities behaving like sqrt(d_rupture - d) near rupture are smooth in z.
    """
    return math.acos(2.0 * min(max(fraction, 0.0), 1.0) - 1.0) / math.pi


@numba.njit(cache=True)
def distance_fraction(coordinate):
    """Inverse of distance_coordinate: (d - d_low)/(d_rupture - d_low) = (1 + cos(pi z))/2."""
    return 0.5 * (1.0 + math.cos(math.pi * coordinate))


@numba.njit(cache=True)
def along_axis(array, i_r, i_a, t_a):
    """array[i_r, :] interpolated linearly at axis cell (i_a, t_a)."""
    return (1.0 - t_a) * array[i_r, i_a] + t_a * array[i_r, i_a + 1]


@numba.njit(cache=True)
def distance_cell(distance, distance_low, distance_rupture, n_z):
    """Cell (j, t) of the distance coordinate z for a gap D/R2, clamped to the tabulated range
    (rupture values beyond d_rupture, values at d_low below it)."""
    z = distance_coordinate((distance - distance_low) / (distance_rupture - distance_low))
    return grid_position(z, 1.0 / (n_z - 1), n_z)


@numba.njit(cache=True)
def bilinear(grid, i_r, i_a, t_a, j, t_z, field):
    """grid[i_r, :, :, field] interpolated bilinearly at axis cell (i_a, t_a) and distance cell (j, t_z)."""
    v00 = grid[i_r, i_a, j, field]
    v01 = grid[i_r, i_a, j + 1, field]
    v10 = grid[i_r, i_a + 1, j, field]
    v11 = grid[i_r, i_a + 1, j + 1, field]
    return (1.0 - t_a) * ((1.0 - t_z) * v00 + t_z * v01) + t_a * ((1.0 - t_z) * v10 + t_z * v11)


@numba.njit(cache=True)
def _interpolate_log(log_values, i_r, i_next, t_r, i_u, t_u, j, t_z, field):
    low = bilinear(log_values, i_r, i_u, t_u, j, t_z, field)
    high = bilinear(log_values, i_next, i_u, t_u, j, t_z, field)
    return math.exp((1.0 - t_r) * low + t_r * high)


@numba.njit(cache=True)
def _suction_cell(radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values,
                  radius_ratio, suction_star, distance_star):
    """Checked table cell of (r, u*, d*): (exists, i_r, i_next, t_r, i_u, t_u, j, t_z); exists
    is False beyond the rupture distance, and the cell is then the rupture node (z = 0)."""
    if not (math.isfinite(suction_star) and math.isfinite(distance_star) and math.isfinite(radius_ratio)):
        raise ValueError("lookup_suction: non-finite radius_ratio, suction_star or distance_star")
    suction_scale, suction_step, suction_max = suction_axis[0], suction_axis[1], suction_axis[2]
    if not 0.0 <= suction_star <= suction_max:
        raise ValueError("lookup_suction: suction_star is outside the table range [0, suction_max]")
    i_r, t_r = radius_ratio_bracket(radius_ratios, radius_ratio)
    i_next = i_r + 1 if t_r > 0.0 else i_r
    i_u, t_u = grid_position(math.log1p(suction_star / suction_scale), suction_step, log_values.shape[1])
    d_rupture = math.exp(
        (1.0 - t_r) * along_axis(log_distance_rupture, i_r, i_u, t_u)
        + t_r * along_axis(log_distance_rupture, i_next, i_u, t_u)
    )
    if distance_star > d_rupture:
        return False, i_r, i_next, t_r, i_u, t_u, 0, 0.0
    d_low = (1.0 - t_r) * along_axis(distance_low, i_r, i_u, t_u) + t_r * along_axis(distance_low, i_next, i_u, t_u)
    j, t_z = distance_cell(distance_star, d_low, d_rupture, log_values.shape[2])
    return True, i_r, i_next, t_r, i_u, t_u, j, t_z


@numba.njit(cache=True)
def lookup_suction(
    radius_ratios,
    suction_axis,
    distance_low,
    log_distance_rupture,
    log_values,
    radius_ratio,
    suction_star,
    distance_star,
):
    """Suction-controlled bridge from a BridgeTable's arrays(): r = R2/R1, u* = s R2/gamma, d* = D/R2.

    Returns (exists, F*, V*, delta1, delta2): F* = F/(2 pi gamma R2), V* = V/R2**3, filling angles
    in degrees (delta1 on the smaller sphere). exists is False beyond the rupture distance (then
    the other values are 0). Distances below the smallest tabulated one (contact, d* < 0) get the
    values there, as YADE does. Raises ValueError for r outside the table's radius ratios, u*
    outside [0, suction_max] or non-finite input. The rupture distance and the quantities are
    interpolated as logarithms (power laws in u* at high suction), linearly in (r, xi), and
    the distance coordinate z is taken relative to the interpolated rupture distance, so every
    radius ratio is read at the same stage of its family. The GPU's bridges read the table
    through this function and what it calls, compiled for the device from this source
    (pendular.gpu.cuda.device_twin; its checks there end the thread, the host checks first).
    """
    exists, i_r, i_next, t_r, i_u, t_u, j, t_z = _suction_cell(
        radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values, radius_ratio,
        suction_star, distance_star)
    if not exists:
        return False, 0.0, 0.0, 0.0, 0.0
    force = _interpolate_log(log_values, i_r, i_next, t_r, i_u, t_u, j, t_z, 0)
    volume = _interpolate_log(log_values, i_r, i_next, t_r, i_u, t_u, j, t_z, 1)
    delta1 = _interpolate_log(log_values, i_r, i_next, t_r, i_u, t_u, j, t_z, 2)
    delta2 = _interpolate_log(log_values, i_r, i_next, t_r, i_u, t_u, j, t_z, 3)
    return True, force, volume, delta1, delta2


@numba.njit(cache=True)
def lookup_interface(radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values,
                     radius_ratio, suction_star, distance_star):
    """The liquid-gas interface of a suction-controlled bridge (same arguments and cell as
    lookup_suction): (exists, nn11*, nn33*), nn_ii* = (1/R2^2) ∫_interface n_i n_i dS with axis
    3 along the bridge (pendular.capillary.meniscus.Bridge); beyond the rupture distance exists is False
    and the values are those at rupture (a volume-controlled bridge read at its own suction may
    sit a round-off beyond). Exact tables only (the toroidal table holds no interface: NaN)."""
    exists, i_r, i_next, t_r, i_u, t_u, j, t_z = _suction_cell(
        radius_ratios, suction_axis, distance_low, log_distance_rupture, log_values, radius_ratio,
        suction_star, distance_star)
    return (exists, _interpolate_log(log_values, i_r, i_next, t_r, i_u, t_u, j, t_z, 4),
            _interpolate_log(log_values, i_r, i_next, t_r, i_u, t_u, j, t_z, 5))


def suction_nodes(suction_scale, suction_max, n_suction):
    """u* at the nodes of the suction axis: suction_scale (exp(xi) - 1), xi uniform from 0."""
    xi = np.linspace(0.0, math.log1p(suction_max / suction_scale), n_suction)
    return suction_scale * np.expm1(xi)


class BridgeTable(TabulatedBridges):
    """Exact suction-controlled bridges tabulated over (r, u*, d*) for one contact angle.

    Build with BridgeTable.build(...) or, cached on disk, BridgeTable.cached(...). Inside Numba
    code call lookup_suction(*table.arrays(), radius_ratio, suction_star, distance_star).
    Covered range: u* in [0, suction_max]; d* from max(0, d* at delta1 = 90 - theta) to rupture.
    """

    kind = "suction"
    description = "suction-controlled bridge table"
    fields = FIELDS
    file_scalars = ("suction_scale", "suction_max")
    file_arrays = ("radius_ratios", "distance_low", "distance_rupture", "values")
    file_prefix = "bridge_table"
    axis_nodes = "n_suction"

    def __init__(
        self, contact_angle, radius_ratios, suction_scale, suction_max, distance_low, distance_rupture, values
    ):
        super().__init__(contact_angle, radius_ratios, distance_low, distance_rupture, values)
        self.suction_scale = float(suction_scale)
        self.suction_max = float(suction_max)
        self._log_values = np.log(self.values)

    @property
    def n_suction(self):
        return self.values.shape[1]

    @property
    def suction(self):
        """u* at the suction nodes."""
        return suction_nodes(self.suction_scale, self.suction_max, self.n_suction)

    def parameters(self):
        """Build parameters (the cache key's content)."""
        return self._parameters(
            self.contact_angle,
            self.radius_ratios,
            self.n_suction,
            self.n_distance,
            self.suction_max,
            self.suction_scale,
        )

    @staticmethod
    def _parameters(contact_angle, radius_ratios, n_suction, n_distance, suction_max, suction_scale):
        return {
            "contact_angle": float(contact_angle),
            "radius_ratios": [float(r) for r in radius_ratios],
            "suction_scale": float(suction_scale),
            "suction_max": float(suction_max),
            "n_suction": int(n_suction),
            "n_distance": int(n_distance),
        }

    @classmethod
    def build(
        cls,
        contact_angle=0.0,
        radius_ratios=YADE_RADIUS_RATIOS,
        n_suction=350,
        n_distance=80,
        suction_max=15000.0,
        suction_scale=0.1,
    ):
        """Solve every node exactly (parallel over radius ratio and suction; Numba threads).

        contact_angle in [0, 90) deg; radius_ratios sorted in [1, MAX_SOLVER_RADIUS_RATIO]; suction_max
        and suction_scale > 0 (u* units); n_suction, n_distance >= 2.
        """
        contact_angle = check_contact_angle(contact_angle)
        radius_ratios = check_radius_ratios(radius_ratios)
        suction_max = check_positive("suction_max", suction_max)
        suction_scale = check_positive("suction_scale", suction_scale)
        n_suction = check_node_count("n_suction", n_suction)
        n_distance = check_node_count("n_distance", n_distance)
        nodes = suction_nodes(suction_scale, suction_max, n_suction)
        distance_low, distance_rupture, values = build_suction_grid(
            radius_ratios, math.radians(contact_angle), nodes, n_distance
        )
        return cls(contact_angle, radius_ratios, suction_scale, suction_max, distance_low, distance_rupture, values)

    @classmethod
    def cached(cls, contact_angle=0.0, radius_ratios=YADE_RADIUS_RATIOS, n_suction=350, n_distance=80,
               suction_max=15000.0, suction_scale=0.1, directory=None):
        """Load the table with these parameters from the cache directory, building and saving it if
        absent; a cached file failing its checksum, identity or node checks is rebuilt (cached_table)."""
        parameters = cls._parameters(contact_angle, radius_ratios, n_suction, n_distance, suction_max, suction_scale)
        return cls.from_cache(parameters, directory, lambda: cls.build(contact_angle, radius_ratios, n_suction,
                                                                       n_distance, suction_max, suction_scale))

    def check_nodes(self, count=SPOT_NODES):
        """ValueError naming the first of the ``spot_nodes`` whose rupture distance, smallest
        distance or quantities differ from the exact solver's (pendular.capillary.suction_control:
        rupture_point, bridge_at_distance) beyond NODE_TOLERANCE. Exact tables only (a toroidal
        table holds the toroidal approximation)."""
        theta = math.radians(self.contact_angle)
        largest = 0.5 * math.pi - theta
        suction = self.suction
        n_distance = self.n_distance
        for i, k, j in spot_nodes(self.values.shape[:3], count):
            r, u = float(self.radius_ratios[i]), float(suction[k])
            delta1_rupture, d_rupture = rupture_point(r, theta, u)
            d_low = max(0.0, bridge_kernel(r, theta, u, largest)[0])
            where = f"r = {r:g}, u* = {u:.6g}, distance index {j} of {n_distance}"
            compare_node(where, "rupture distance d*", self.distance_rupture[i, k], d_rupture)
            compare_node(where, "smallest distance d*", self.distance_low[i, k], d_low, d_rupture)
            if j == 0:
                bridge = bridge_from_kernel(r, self.contact_angle, u, delta1_rupture)
            elif j == n_distance - 1 and d_low > 0.0:
                bridge = bridge_from_kernel(r, self.contact_angle, u, largest)
            else:
                distance = d_low + (d_rupture - d_low) * distance_fraction(j / (n_distance - 1))
                bridge = bridge_at_distance(r, self.contact_angle, u, distance)
            for field, found in zip(FIELDS, self.values[i, k, j]):
                compare_node(where, field, found, getattr(bridge, field))

    def arrays(self):
        """(radius_ratios, suction_axis = [suction_scale, xi step, suction_max], distance_low,
        ln distance_rupture, ln values): the contiguous float64 arguments of lookup_suction."""
        step = math.log1p(self.suction_max / self.suction_scale) / (self.n_suction - 1)
        suction_axis = np.array([self.suction_scale, step, self.suction_max])
        return self.radius_ratios, suction_axis, self.distance_low, self._log_distance_rupture, self._log_values

    def lookup(self, radius_ratio, suction_star, distance_star):
        """Python-side lookup_suction: (exists, F*, V*, delta1, delta2)."""
        return lookup_suction(*self.arrays(), float(radius_ratio), float(suction_star), float(distance_star))

    def lookup_interface(self, radius_ratio, suction_star, distance_star):
        """Python-side lookup_interface: (exists, nn11*, nn33*)."""
        return lookup_interface(*self.arrays(), float(radius_ratio), float(suction_star),
                                float(distance_star))
