"""The device's copy of a scene: particles, the neighbour list with its per-pair state, the
cell grid, the walls (or a periodic cell: its faces, rate, stress, stiffness, the particles'
wraps and the pairs' images) and their controls' memory, copied in from a CPU Simulation once
and out when the host asks (pendular.gpu.simulation).

Per-pair arrays follow the device list's layout (pendular.gpu.neighbors: pair k = s * N + p);
the bridges' per-pair state is one (K, BRIDGE_COLUMNS) float64 array whose columns are
BridgeState's fields (``state``, ``volume``, ``force``, ``filling_i``, ``filling_j``,
``suction``: 0 under suction control). Bridges that persist across gaps (``persist``: suction
control's option, volume control always) also keep their force on j from i,
``bridge_pair_force`` (K, 3) [N], written for every pair each step (the CPU's
CapillaryBridges.pair_force), and the list reaches ``reach`` [m] beyond touching besides the
skin (their rupture range, the CPU's interaction_range). Volume control's liquid
(pendular.capillary.bridge_kernels.LiquidExchange): ``film`` (N,) [m^3] on each grain, per
pair ``released`` [m^3] and ``events`` (int8, cleared by each step's exchange: not carried
across rebuilds, as the CPU's fresh arrays after one), ``marked`` (1,) the events of the step,
``liquid_lost`` (1,) [m^3]. A rolling resistance's springs (``rolling``: the per-pair state
of pendular.dem.rolling, carried as the bridges' columns) and its pair moments
(pendular.gpu.rolling).
"""

import math

import numpy as np

from pendular.capillary.bridge_state import FIELDS, OWNER
from pendular.dem.cell_list import build_pairs, build_periodic_pairs
from pendular.dem.neighbors import Contacts, second_index
from pendular.dem.protocols import pair_key
from pendular.gpu.cell import CELL_SUMS
from pendular.gpu import rolling as device_rolling
from pendular.gpu.cuda import cuda
from pendular.gpu.forces import Images, Pairs, Transposed
from pendular.gpu.integrate import Motion
from pendular.gpu.neighbors import Grid, PairState, Rows
from pendular.gpu.walls import REDUCE_CHUNK, WALL_SUMS, Program

#: BridgeState fields kept on the device, in the columns of ``bridges``.
BRIDGE_COLUMNS = tuple(field.name for field in FIELDS)
#: Room left in each row beyond the longest row of the first list (neighbours come and go).
ROW_ROOM = 1.5
#: Fewest slots of a row.
MIN_WIDTH = 16
#: Cells per axis allocated for each cell the box holds now (room for the box to grow).
GRID_ROOM = 2
#: Densest packing of spheres (fcc) bounding how many fit a cell.
DENSEST = 0.7405


def row_width(position, radius, skin, contacts=None, period=None):
    """Slots per row [-]: ROW_ROOM times the most neighbours one particle has above or below it
    in the CPU's list (``contacts``, or one built here with ``skin`` [m]; through the images of
    a periodic cell of edges ``period`` (3,) [m] unless None), at least MIN_WIDTH."""
    if contacts is None and period is not None:
        row_start, pair_j, _ = build_periodic_pairs(np.mod(position, period), radius, skin,
                                                    np.asarray(period, dtype=np.float64))
    elif contacts is None:
        row_start, pair_j = build_pairs(position, radius, skin)
    else:
        row_start, pair_j = contacts.row_start, contacts.pair_j
    above = np.diff(row_start)
    below = np.bincount(pair_j, minlength=len(radius))
    longest = int(max(above.max(initial=0), below.max(initial=0)))
    return max(MIN_WIDTH, math.ceil(ROW_ROOM * longest))


def cell_capacity(radius, cell_size):
    """Most spheres of these radii [m] that fit a cell of edge below 2 ``cell_size`` [m] (the
    largest a grid of at least ``cell_size`` has), at the densest packing, plus a few."""
    smallest = 4.0 / 3.0 * math.pi * float(radius.min()) ** 3
    return math.ceil(DENSEST * (2.0 * cell_size) ** 3 / smallest) + 8


def _to_ell(values, slots, count, width, fill):
    """Per-pair ``values`` in CSR order (K, ...) laid out as device rows (width * count, ...)."""
    out = np.full((width * count,) + values.shape[1:], fill, dtype=values.dtype)
    out[slots] = values
    return out


class DeviceState:
    """Device arrays of a scene (attributes named as on the host; a periodic cell's faces in
    ``wall_position``, its other state in the ``cell_`` arrays, ``period``, ``affine_rate``,
    ``wraps`` and the pairs' ``image``: pendular.gpu.cell). ``to_host`` writes them back into
    the Simulation. ``resisting``: whether the pairs keep a rolling resistance's springs."""

    def __init__(self, sim, skin, wet, reach=0.0, persist=False, film=None, resisting=False):
        p = sim.particles
        walls = sim.walls
        count = len(p)
        self.count = count
        self.skin = skin
        self.wet = wet
        self.resisting = resisting
        self.persist = persist
        self.reach = reach
        self.periodic = walls.periodic
        self.cell_size = 2.0 * float(p.radius.max()) + skin + reach
        period = walls.position[1::2] if self.periodic else None
        self.width = row_width(p.position, p.radius, skin, sim.contacts, period)
        if reach > 0.0:     # the bridges' reach may have grown since the host's list was built
            self.width = max(self.width, row_width(p.position, p.radius, skin + reach,
                                                   None, period))
        self.cell_width = cell_capacity(p.radius, self.cell_size)
        lengths = walls.lengths()
        max_dims = np.array([max(1, int(GRID_ROOM * length / self.cell_size))
                             for length in lengths], dtype=np.int64)
        cells = int(np.prod(max_dims))
        pairs = self.width * count
        to = cuda.to_device
        for name in ("position", "velocity", "angular_velocity", "radius", "mass", "inertia"):
            setattr(self, name, to(np.ascontiguousarray(getattr(p, name))))
        self.force = to(np.zeros((count, 3)))
        self.torque = to(np.zeros((count, 3)))
        self.reference_position = to(np.ascontiguousarray(p.position))
        for name in ("position", "velocity", "force", "stiffness", "moment"):
            values = (getattr(walls, name) if name == "position" or not self.periodic
                      else np.zeros(6))       # a cell has no walls: unread
            setattr(self, f"wall_{name}", to(np.ascontiguousarray(values)))
        self.reference_walls = to(np.ascontiguousarray(walls.position))
        self._cell_from_host(walls, count)
        self.partial = to(np.zeros((max(1, -(-count // REDUCE_CHUNK)), 6, WALL_SUMS)))
        self.max_dims = to(max_dims)
        self.cell_count = to(np.zeros(cells, np.int32))
        self.cell_members = to(np.zeros(cells * self.cell_width, np.int32))
        self.cell_of = to(np.zeros(count, np.int32))
        # the list in use, filled from the host's if it has one; flags[0] = 1: rebuild first
        rows = self.host_rows(sim.contacts, count)
        self.pair_count = to(rows["pair_count"])
        self.pair_j = to(rows["pair_j"])
        self.shear_force = to(rows["shear_force"])
        self.normal = to(rows["normal"])
        self.overlap = to(rows["overlap"])
        self.bridges = to(rows["bridges"])
        self.rolling = to(rows["rolling"])
        self.image = to(rows["image"])
        # each slot's first member (k = s * N + p: p), which the CPU's bridge law reads as
        # pair_i when a bridge forms (pendular.gpu.forces.pair_forces); wet scenes only
        self.pair_i = to(np.tile(np.arange(count, dtype=np.int32), self.width) if wet
                         else np.zeros(1, np.int32))
        # the periodic image and period the CPU's contact law takes, not read inside walls;
        # zeros for every pair where the persisting bridges' branch vectors read them
        self.no_image = to(np.zeros((pairs if persist else 1, 3), np.int8))
        self.no_period = to(np.zeros(3))
        self.bridge_pair_force = to(np.zeros((pairs if persist else 1, 3)))
        # volume control's liquid (``film`` (N,) [m^3] given: module docstring)
        liquid = film is not None
        self.film = to(np.ascontiguousarray(film, dtype=np.float64) if liquid else np.zeros(1))
        self.released = to(np.zeros(pairs if liquid else 1))
        self.events = to(np.zeros(pairs if liquid else 1, np.int8))
        self.marked = to(np.zeros(1, np.int64))
        self.liquid_lost = to(np.zeros(1))
        self.normal_force = to(np.zeros(pairs))
        self.pair_force = to(np.zeros((pairs, 3)))
        self.pair_moment = to(np.zeros((pairs if resisting else 1, 3)))
        self.second_count = to(np.zeros(count, np.int32))
        self.second_pair = to(np.zeros(pairs, np.int32))
        # the list being built at a rebuild
        self.new_count = to(np.zeros(count, np.int32))
        self.new_pair_j = to(np.zeros(pairs, np.int32))
        self.lower_count = to(np.zeros(count, np.int32))
        self.lower = to(np.zeros(pairs, np.int32))
        self.new_shear_force = to(np.zeros((pairs, 3)))
        self.new_normal = to(np.zeros((pairs, 3)))
        self.new_overlap = to(np.zeros(pairs))
        self.new_bridges = to(np.zeros(rows["bridges"].shape))
        self.new_rolling = to(np.zeros(rows["rolling"].shape))
        self.flags = to(np.array([1, 0, 0], np.int32))
        self.rebuilds = to(np.zeros(1, np.int64))

    def _cell_from_host(self, cell, count):
        """A periodic cell's arrays (pendular.gpu.cell; one-entry stand-ins inside walls)."""
        to = cuda.to_device
        if not self.periodic:
            self.wraps = to(np.zeros((1, 3), np.int64))
            self.cell_partial = to(np.zeros((1, CELL_SUMS)))
            return
        self.cell_rate = to(np.ascontiguousarray(cell.rate))
        self.stress_tensor = to(np.ascontiguousarray(cell.stress_tensor))
        self.cell_stiffness = to(np.ascontiguousarray(cell.stiffness))
        self.period = to(np.ascontiguousarray(cell.position[1::2]))
        self.affine_rate = to(np.ascontiguousarray(cell.rate))
        wraps = cell.wraps if len(cell.wraps) == count else np.zeros((count, 3), np.int64)
        self.wraps = to(np.ascontiguousarray(wraps))
        self.cell_partial = to(np.zeros((max(1, -(-count // REDUCE_CHUNK)), CELL_SUMS)))

    def host_rows(self, contacts, count):
        """The host's list (or none) as device rows: counts, neighbours and per-pair state."""
        width = self.width
        bridge_rows = width * count if self.wet else 1
        rolling = np.zeros((width * count if self.resisting else 1, device_rolling.COLUMNS))
        if contacts is None or len(contacts) == 0:
            return {"pair_count": np.zeros(count, np.int32),
                    "pair_j": np.zeros(width * count, np.int32),
                    "shear_force": np.zeros((width * count, 3)),
                    "normal": np.zeros((width * count, 3)),
                    "overlap": np.full(width * count, -np.inf),
                    "bridges": np.zeros((bridge_rows, len(BRIDGE_COLUMNS))),
                    "rolling": rolling,
                    "image": np.zeros((width * count if self.periodic else 1, 3), np.int8)}
        counts = np.diff(contacts.row_start)
        slots = (np.arange(len(contacts)) - contacts.row_start[contacts.pair_i]) * count \
            + contacts.pair_i
        bridges = np.zeros((bridge_rows, len(BRIDGE_COLUMNS)))
        if self.wet and pair_key(OWNER, FIELDS[0]) in contacts.extra:
            columns = np.stack([contacts.extra[pair_key(OWNER, field)].astype(np.float64)
                                for field in FIELDS], axis=1)
            bridges = _to_ell(columns, slots, count, width, 0.0)
        if self.resisting:
            rolling = _to_ell(device_rolling.host_columns(contacts), slots, count, width, 0.0)
        return {"pair_count": counts.astype(np.int32),
                "pair_j": _to_ell(contacts.pair_j.astype(np.int32), slots, count, width, 0),
                "shear_force": _to_ell(contacts.shear_force, slots, count, width, 0.0),
                "normal": _to_ell(contacts.normal, slots, count, width, 0.0),
                "overlap": _to_ell(contacts.overlap, slots, count, width, -np.inf),
                "bridges": bridges,
                "rolling": rolling,
                "image": (_to_ell(contacts.image, slots, count, width, 0) if self.periodic
                          else np.zeros((1, 3), np.int8))}

    def grid(self):
        """The cell grid's bundle (pendular.gpu.neighbors.Grid)."""
        return Grid(self.cell_size, self.max_dims, self.cell_count, self.cell_members,
                    self.cell_width, self.cell_of)

    def rows(self):
        """The rows' bundle (pendular.gpu.neighbors.Rows)."""
        return Rows(self.width, self.pair_count, self.pair_j, self.new_count, self.new_pair_j,
                    self.lower_count, self.lower)

    def carried(self):
        """The list's per-pair state (pendular.gpu.neighbors.PairState)."""
        return PairState(self.shear_force, self.normal, self.overlap, self.bridges,
                         self.rolling)

    def new_carried(self):
        """The per-pair state of the rows a rebuild fills (pendular.gpu.neighbors.PairState)."""
        return PairState(self.new_shear_force, self.new_normal, self.new_overlap,
                         self.new_bridges, self.new_rolling)

    def pairs(self):
        """The pairs and their state as the pair kernels read them (pendular.gpu.forces
        .Pairs)."""
        return Pairs(self.pair_count, self.pair_i, self.pair_j, self.shear_force, self.normal,
                     self.overlap, self.normal_force, self.pair_force)

    def transposed(self):
        """The transposed pair index (pendular.gpu.forces.Transposed)."""
        return Transposed(self.second_count, self.second_pair)

    def images(self):
        """A periodic cell's images, period and stretching (pendular.gpu.forces.Images; inside
        walls the zeros that stand for them)."""
        if self.periodic:
            return Images(self.image, self.period, self.affine_rate)
        return Images(self.no_image, self.no_period, self.no_period)

    def motion(self):
        """What the leapfrog moves (pendular.gpu.integrate.Motion)."""
        return Motion(self.position, self.velocity, self.angular_velocity, self.force,
                      self.torque, self.mass, self.inertia)

    def program(self):
        """The controls' program (pendular.gpu.walls.Program), uploaded by GpuSimulation."""
        return Program(self.kinds, self.control_walls, self.wall_counts, self.parameters,
                       self.previous, self.stiffness, self.calls, self.control_step,
                       self.failure)

    def bridge_columns(self):
        """The columns of ``bridges`` (BRIDGE_COLUMNS) as the bridge law's arrays."""
        return tuple(self.bridges[:, c] for c in range(self.bridges.shape[1]))

    def flags_now(self):
        """(rebuild asked, overflow bits, not-finite flag) read from the device (a sync)."""
        return tuple(int(value) for value in self.flags.copy_to_host())

    def _slots(self):
        """(row_start, pair_i, slots): the device's list in CSR order, pair k of it in the
        device's slot slots[k]."""
        count = self.count
        pair_count = self.pair_count.copy_to_host().astype(np.int64)
        row_start = np.concatenate([[0], np.cumsum(pair_count)]).astype(np.int64)
        pair_i = np.repeat(np.arange(count, dtype=np.int64), pair_count)
        return row_start, pair_i, (np.arange(row_start[-1]) - row_start[pair_i]) * count + pair_i

    def bridge_pair_forces(self):
        """The persisting bridges' forces on j from i (K, 3) [N] of the device's list, in the
        order of ``contacts()``."""
        return self.bridge_pair_force.copy_to_host()[self._slots()[2]]

    def pair_moments(self):
        """The rolling resistance's pair moments (K, 3) [N m] of the device's list, in the
        order of ``contacts()``."""
        return self.pair_moment.copy_to_host()[self._slots()[2]]

    def contacts(self):
        """The device's neighbour list and per-pair state as a host Contacts (CSR order)."""
        count = self.count
        row_start, pair_i, slots = self._slots()
        pair_j = self.pair_j.copy_to_host()[slots].astype(np.int64)
        second_start, second_pair = second_index(row_start, pair_j, count)
        extra = {}
        if self.wet:
            bridges = self.bridges.copy_to_host()[slots]
            for column, field in enumerate(FIELDS):
                extra[pair_key(OWNER, field)] = bridges[:, column].astype(field.dtype)
        if self.resisting:
            extra.update(device_rolling.host_fields(self.rolling.copy_to_host()[slots]))
        return Contacts(pair_i=pair_i, pair_j=pair_j, row_start=row_start,
                        second_start=second_start, second_pair=second_pair,
                        shear_force=self.shear_force.copy_to_host()[slots],
                        normal=self.normal.copy_to_host()[slots],
                        overlap=self.overlap.copy_to_host()[slots],
                        normal_force=self.normal_force.copy_to_host()[slots],
                        force=self.pair_force.copy_to_host()[slots], extra=extra,
                        image=self.image.copy_to_host()[slots] if self.periodic else None)

    def walls_to_host(self, walls):
        """Write the walls' position, velocity, force, stiffness and moment into ``walls`` (a
        periodic cell's faces, rate, stress tensor and stiffness into the cell)."""
        if self.periodic:
            self.wall_position.copy_to_host(walls.position)
            self.cell_rate.copy_to_host(walls.rate)
            self.stress_tensor.copy_to_host(walls.stress_tensor)
            self.cell_stiffness.copy_to_host(walls.stiffness)
            return
        for name in ("position", "velocity", "force", "stiffness", "moment"):
            getattr(self, f"wall_{name}").copy_to_host(getattr(walls, name))

    def to_host(self, sim):
        """Write the particles, the walls and the neighbour list into ``sim`` (a copy each)."""
        p = sim.particles
        for name in ("position", "velocity", "angular_velocity", "force", "torque"):
            getattr(self, name).copy_to_host(getattr(p, name))
        self.walls_to_host(sim.walls)
        if self.periodic:
            sim.walls.wraps = self.wraps.copy_to_host()
        sim.contacts = self.contacts()
