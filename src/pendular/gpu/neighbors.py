"""Verlet neighbour list built on the device from a cell list, with per-pair state carried
across rebuilds by pair identity (pendular.dem.neighbors on the CPU).

Layout: rows of at most ``width`` pairs stored slot by slot (ELLPACK, so that the threads of
a warp, one per particle, read neighbouring words): pair k = s * N + p (N particles) is
particle p's s-th neighbour j > p within r_p + r_j + skin (``pair_j``, the row sorted by j;
``pair_count[p]`` of them); ``second_pair[s * N + p]``, s < ``second_count[p]``, are the pairs
in which p is the second member, sorted by their first member, the transposed index of the
CPU list, so that each particle sums its pairs in the CPU's order. Fixed widths need no
prefix sum on the host: the whole rebuild runs on the device, and its kernels do nothing
unless ``flags[0]`` asks for a rebuild (set by the integrator when a particle moved more than
skin / 2 since the last rebuild, by the walls' controls when a wall did; cleared by the next
pair-force pass).

The cells tile the walls' box, at least ``cell_size`` = 2 max(radius) + skin a side (as many
as the grid allocated holds), particles outside it counted in the nearest cell (as the CPU's
grid). A cell's members are appended by integer atomics in any order; the rows are sorted by
index as they are filled, so the list does not depend on that order. Overflow of a cell or a
row sets a bit of ``flags[1]`` (CELL_OVERFLOW, ROW_OVERFLOW), which the host reads at its
checks (pendular.gpu.simulation).
"""

import math
from collections import namedtuple

from pendular.dem.cell_list import _cell_coordinates, _sheared_cell, _within_reach, _wrap_cell
from pendular.dem.neighbors import NeighborList
from pendular.gpu.cuda import cuda, device, device_twin
from pendular.gpu.operations import DeviceSide, device_side

within_reach = device_twin(_within_reach)
cell_coordinates = device_twin(_cell_coordinates)

#: Bits of flags[1].
CELL_OVERFLOW = 1
ROW_OVERFLOW = 2

#: The cell grid: its cells' least edge [m], the most cells per axis allocated (3,), each
#: cell's member count and members (cells, ``cell_width``), each particle's cell.
Grid = namedtuple("Grid", "cell_size max_dims cell_count cell_members cell_width cell_of")
#: The rows (module docstring): slots per row, the list's rows (``pair_count``, ``pair_j``),
#: the rows a rebuild fills (``new_count``, ``new_pair_j``) and the pairs below each particle
#: it finds (``lower_count``, ``lower``).
Rows = namedtuple("Rows", "width pair_count pair_j new_count new_pair_j lower_count lower")
#: The per-pair state carried across a rebuild (pendular.gpu.state): the tangential spring,
#: normal, overlap, the bridges' and the rolling resistance's columns.
PairState = namedtuple("PairState", "shear_force normal overlap bridges rolling")


@device
def grid_dims(wall_position, cell_size, max_dims, axis):
    """Cells along ``axis``: as many of at least ``cell_size`` [m] as the box holds, within
    [1, max_dims[axis]] (1 for a box that is not finite or not open: a diverged run)."""
    cells = (wall_position[2 * axis + 1] - wall_position[2 * axis]) / cell_size
    if not cells >= 1.0:
        return 1
    if cells >= max_dims[axis]:
        return max_dims[axis]
    return int(cells)


@device
def grid_shape(wall_position, cell_size, max_dims):
    """(cells along x, y, z) of the grid in the walls' box now (grid_dims)."""
    return (grid_dims(wall_position, cell_size, max_dims, 0),
            grid_dims(wall_position, cell_size, max_dims, 1),
            grid_dims(wall_position, cell_size, max_dims, 2))


@device
def cell_coordinate(x, wall_position, dims, axis):
    """Cell index along ``axis`` of coordinate x [m], clamped into [0, dims) (0 for a
    coordinate or box that is not finite)."""
    cells = (x - wall_position[2 * axis]) / (wall_position[2 * axis + 1]
                                             - wall_position[2 * axis]) * dims
    if not cells > 0.0:
        return 0
    if cells >= dims:
        return dims - 1
    return int(cells)


@device
def append_to_cell(p, c, cell_of, cell_count, cell_members, cell_width, flags):
    """Record particle p in cell c (its slot taken atomically: the order within a cell is
    the launch's, which the rows' sort makes irrelevant), or flag the cell's overflow."""
    cell_of[p] = c
    slot = cuda.atomic.add(cell_count, c, 1)
    if slot < cell_width:
        cell_members[c * cell_width + slot] = p
    else:
        cuda.atomic.or_(flags, 1, CELL_OVERFLOW)


@cuda.jit
def bin_particles(position, wall_position, grid, flags):
    """Append each particle to its cell of the Grid ``grid`` (x-major numbering, as the CPU's
    grid)."""
    cell_size, max_dims, cell_count, cell_members, cell_width, cell_of = grid
    p = cuda.grid(1)
    if flags[0] == 0 or p >= position.shape[0]:
        return
    d0, d1, d2 = grid_shape(wall_position, cell_size, max_dims)
    c = ((cell_coordinate(position[p, 0], wall_position, d0, 0) * d1
          + cell_coordinate(position[p, 1], wall_position, d1, 1)) * d2
         + cell_coordinate(position[p, 2], wall_position, d2, 2))
    append_to_cell(p, c, cell_of, cell_count, cell_members, cell_width, flags)


@device
def shift_in(row, p, n, found, q):
    """Put q into particle p's sorted row of ``found`` entries (slots s * n + p; room checked
    by the caller), the entries above q moved up a slot; returns q's slot."""
    s = found
    while s > 0 and row[(s - 1) * n + p] > q:
        row[s * n + p] = row[(s - 1) * n + p]
        s -= 1
    row[s * n + p] = q
    return s


@device
def insert_sorted(row, p, n, found, width, q, flags):
    """Put q into particle p's row kept sorted (shift_in) if there is room, else flag the
    overflow; returns the new count."""
    if found >= width:
        cuda.atomic.or_(flags, 1, ROW_OVERFLOW)
    else:
        shift_in(row, p, n, found, q)
    return found + 1


@device
def carry(old, new, source, k, fill):
    """Row k of the (K, C) ``new`` from row ``source`` of ``old``, or ``fill`` (source -1)."""
    for c in range(new.shape[1]):
        new[k, c] = old[source, c] if source >= 0 else fill


@cuda.jit
def find_pairs(position, radius, skin, wall_position, grid, rows, carried, new, flags):
    """Particle p's neighbours within r_p + r_q + skin from the 27 cells around its own:
    those above p into its new row, those below into ``lower`` (both sorted); then the per-pair
    state of the new row from the same (p, j) pairs of the old one (the CPU's
    previous_pair_index and carry_pair_array): shear force, normal, overlap (-inf: never
    touched), the bridges' (K, C) values (state, volume, force, filling angles; zeros) and
    the rolling resistance's springs (K, C) (pendular.gpu.rolling; zeros): the bundles Grid,
    Rows and PairState (``carried`` the list's, ``new`` the new rows')."""
    cell_size, max_dims, cell_count, cell_members, cell_width, cell_of = grid
    width, pair_count, pair_j, new_count, new_pair_j, lower_count, lower = rows
    shear_force, normal, overlap, bridges, rolling = carried
    new_shear_force, new_normal, new_overlap, new_bridges, new_rolling = new
    p = cuda.grid(1)
    if flags[0] == 0 or p >= position.shape[0]:
        return
    d0, d1, d2 = grid_shape(wall_position, cell_size, max_dims)
    cx, cy, cz = cell_coordinates(cell_of[p], (d0, d1, d2))
    n = position.shape[0]
    above = 0
    below = 0
    for x in range(max(cx - 1, 0), min(cx + 2, d0)):
        for y in range(max(cy - 1, 0), min(cy + 2, d1)):
            for z in range(max(cz - 1, 0), min(cz + 2, d2)):
                c = (x * d1 + y) * d2 + z
                for slot in range(c * cell_width,
                                  c * cell_width + min(cell_count[c], cell_width)):
                    q = cell_members[slot]
                    if q == p:
                        continue
                    if within_reach(position, radius, skin, p, q):
                        if q > p:
                            above = insert_sorted(new_pair_j, p, n, above, width, q, flags)
                        else:
                            below = insert_sorted(lower, p, n, below, width, q, flags)
    carry_rows(p, n, min(above, width), min(below, width), new_count, lower_count, pair_count,
               pair_j, new_pair_j, shear_force, normal, overlap, bridges, rolling,
               new_shear_force, new_normal, new_overlap, new_bridges, new_rolling)


@device
def carry_rows(p, n, above, below, new_count, lower_count, pair_count, pair_j, new_pair_j,
               shear_force, normal, overlap, bridges, rolling, new_shear_force, new_normal,
               new_overlap, new_bridges, new_rolling):
    """Close particle p's new rows: ``above`` pairs j > p and ``below`` j < p listed (counts
    within the rows' width), and the per-pair state of the new row from the same (p, j) pairs
    of its old one (find_pairs)."""
    new_count[p] = above
    lower_count[p] = below
    old = 0
    for s in range(new_count[p]):
        k = s * n + p
        j = new_pair_j[k]
        while old < pair_count[p] and pair_j[old * n + p] < j:
            old += 1
        source = old * n + p if old < pair_count[p] and pair_j[old * n + p] == j else -1
        carry(shear_force, new_shear_force, source, k, 0.0)
        carry(normal, new_normal, source, k, 0.0)
        new_overlap[k] = overlap[source] if source >= 0 else -math.inf
        if bridges.shape[0] == overlap.shape[0]:        # a wet scene
            carry(bridges, new_bridges, source, k, 0.0)
        if rolling.shape[0] == overlap.shape[0]:        # a rolling resistance
            carry(rolling, new_rolling, source, k, 0.0)


@device
def copy_row(new, current, k):
    """Row k of the (K, C) ``new`` into ``current``."""
    for c in range(new.shape[1]):
        current[k, c] = new[k, c]


@cuda.jit
def finish_rebuild(position, rows, new, second_count, second_pair, carried, normal_force,
                   force, reference_position, wall_position, reference_walls, grid, flags,
                   rebuilds):
    """Make the new rows the list: counts, neighbours and carried state (force and normal
    force zero, as a new CPU list's), the transposed index (for each q below p, the slot of p
    in q's row), the reference positions and walls of the displacement test; empty the cells
    used (the bundles Rows, Grid and PairState: ``new`` the new rows', ``carried`` the
    list's)."""
    _, pair_count, pair_j, new_count, new_pair_j, lower_count, lower = rows
    new_shear_force, new_normal, new_overlap, new_bridges, new_rolling = new
    shear_force, normal, overlap, bridges, rolling = carried
    cell_count, cell_of = grid.cell_count, grid.cell_of
    p = cuda.grid(1)
    if flags[0] == 0 or p >= position.shape[0]:
        return
    n = position.shape[0]
    pair_count[p] = new_count[p]
    for s in range(new_count[p]):
        k = s * n + p
        pair_j[k] = new_pair_j[k]
        overlap[k] = new_overlap[k]
        normal_force[k] = 0.0
        for c in range(3):
            force[k, c] = 0.0
        copy_row(new_shear_force, shear_force, k)
        copy_row(new_normal, normal, k)
        if bridges.shape[0] == overlap.shape[0]:
            copy_row(new_bridges, bridges, k)
        if rolling.shape[0] == overlap.shape[0]:
            copy_row(new_rolling, rolling, k)
    second_count[p] = lower_count[p]
    for s in range(lower_count[p]):
        q = lower[s * n + p]
        slot = 0
        while slot < new_count[q] - 1 and new_pair_j[slot * n + q] != p:
            slot += 1
        second_pair[s * n + p] = slot * n + q
    for c in range(3):
        reference_position[p, c] = position[p, c]
    cell_count[cell_of[p]] = 0
    if p == 0:
        for w in range(6):
            reference_walls[w] = wall_position[w]
        rebuilds[0] += 1


# ---------------------------------------------------------------- a periodic cell
# The cells tile the periodic cell [0, L) (pendular.dem.cell.PeriodicCell; its faces in
# ``cell_position``, as a Walls' position), int(L / cell_size) a side as the CPU's grid
# (pendular.dem.cell_list._periodic_grid, at most the grid allocated); a pair's image (K, 3)
# int8 is stored with it (Contacts.image). A cell narrower than 3 cells a side sets NARROW_CELL
# (the CPU refuses to build such a list: a pair would have more than one image in reach).
# A sheared cell (``period`` (4,), its offset delta last: pendular.gpu.cell) wraps its
# particles through the z faces with x shifted by -+ delta and searches the rows of cells
# through a z face around x less their offset (Lees–Edwards), with the offset brought into
# [-Lx/2, Lx/2) at the rebuild (reduced_offset, stored by shear_rebuilt after the search).

#: Bit of flags[1]: the periodic cell is narrower than 3 cells of the grid on an axis.
NARROW_CELL = 4

wrap_cell = device_twin(_wrap_cell)
sheared_cell = device_twin(_sheared_cell)


@device
def reduced_offset(period):
    """(the offset period[3] [m] brought into [-Lx/2, Lx/2), the whole Lx taken out of it
    [-]) (PeriodicCell._wrap_sheared, a method: restated)."""
    turns = math.floor(period[3] / period[0] + 0.5)
    return period[3] - turns * period[0], turns


@device
def wrap_sheared(p, position, period, wraps):
    """PeriodicCell._wrap_sheared for particle p: its x wraps counted again with the whole Lx
    taken out of the offset (so that the unwrapped position is unchanged), then, through a z
    face, x shifted by -+ the reduced offset, z brought into [0, Lz) (clamped) and the z
    wraps counted."""
    offset, turns = reduced_offset(period)
    if turns != 0.0:
        wraps[p, 0] += int(turns) * wraps[p, 2]
    crossed = math.floor(position[p, 2] / period[2])
    if crossed != 0.0 and math.isfinite(crossed):       # diverged: the integrator flags it
        position[p, 0] -= crossed * offset
        z = position[p, 2] - crossed * period[2]
        position[p, 2] = min(max(z, 0.0), math.nextafter(period[2], 0.0))
        wraps[p, 2] += int(crossed)


@device
def wrap_particle(p, position, cell_position, wraps):
    """Bring particle p into [0, L) and count the periods it crossed in ``wraps`` (N, 3)
    (pendular.dem.cell.PeriodicCell.wrap of a cell not sheared: floor, subtract, clamp into
    [0, the largest number below L])."""
    crossed = False
    for axis in range(3):
        periods = math.floor(position[p, axis] / cell_position[2 * axis + 1])
        if not math.isfinite(periods):      # diverged: the integrator flags it
            return
        if periods != 0.0:
            crossed = True
    if not crossed:
        return
    for axis in range(3):
        length = cell_position[2 * axis + 1]
        periods = math.floor(position[p, axis] / length)
        x = position[p, axis] - periods * length
        x = min(x, math.nextafter(length, 0.0))
        position[p, axis] = max(x, 0.0)
        wraps[p, axis] += int(periods)


@cuda.jit
def bin_periodic(position, cell_position, period, wraps, grid, flags):
    """Wrap each particle into the cell (a sheared cell's ``period`` (4,): wrap_sheared first,
    as PeriodicCell.wrap; then wrap_particle), then append it to its cell of the periodic grid
    (x-major numbering, the CPU's _sort_into_cells over [0, L)) of the Grid ``grid``."""
    cell_size, max_dims, cell_count, cell_members, cell_width, cell_of = grid
    p = cuda.grid(1)
    if flags[0] == 0 or p >= position.shape[0]:
        return
    if period.shape[0] > 3:
        wrap_sheared(p, position, period, wraps)
    wrap_particle(p, position, cell_position, wraps)
    dims = grid_shape(cell_position, cell_size, max_dims)      # low faces at 0: int(L / size)
    if p == 0 and (dims[0] < 3 or dims[1] < 3 or dims[2] < 3):
        cuda.atomic.or_(flags, 1, NARROW_CELL)
    c = 0
    for axis in range(3):
        width = cell_position[2 * axis + 1] / dims[axis]
        index = int(position[p, axis] / width)
        index = min(max(index, 0), dims[axis] - 1)
        c = c * dims[axis] + index
    append_to_cell(p, c, cell_of, cell_count, cell_members, cell_width, flags)


@device
def insert_with_image(row, image, p, n, found, width, q, sx, sy, sz, flags):
    """insert_sorted, the pair's image (sx, sy, sz) moving with q in ``image`` (K, 3)."""
    if found >= width:
        cuda.atomic.or_(flags, 1, ROW_OVERFLOW)
        return found + 1
    s = shift_in(row, p, n, found, q)
    for t in range(found, s, -1):           # the images of the entries that moved up
        for c in range(3):
            image[t * n + p, c] = image[(t - 1) * n + p, c]
    image[s * n + p, 0] = sx
    image[s * n + p, 1] = sy
    image[s * n + p, 2] = sz
    return found + 1


@cuda.jit
def find_periodic_pairs(position, radius, skin, cell_position, period, grid, rows, image,
                        carried, new, flags):
    """find_pairs in a periodic cell: particle p's neighbours through the nearest image from
    the 27 cells around its own, wrapped across the faces (the CPU's _periodic_neighbors_of:
    in a sheared cell, ``period`` (4,), the rows through a z face around p's x less their
    offset, with the offset reduced_offset), each with its image into ``image`` (written in
    place: the forces read it after this rebuild; lower rows hold no image); then the per-pair
    state carried as find_pairs (its bundles)."""
    cell_size, max_dims, cell_count, cell_members, cell_width, cell_of = grid
    width, pair_count, pair_j, new_count, new_pair_j, lower_count, lower = rows
    shear_force, normal, overlap, bridges, rolling = carried
    new_shear_force, new_normal, new_overlap, new_bridges, new_rolling = new
    p = cuda.grid(1)
    if flags[0] == 0 or p >= position.shape[0]:
        return
    dims = grid_shape(cell_position, cell_size, max_dims)      # low faces at 0: int(L / size)
    cx, cy, cz = cell_coordinates(cell_of[p], dims)
    shear = reduced_offset(period)[0] if period.shape[0] > 3 else 0.0
    along = cell_position[1] / dims[0]                         # a cell's width along x
    n = position.shape[0]
    above = 0
    below = 0
    for dx in range(-1, 2):
        for dy in range(-1, 2):
            y, sy = wrap_cell(cy + dy, dims[1])
            for dz in range(-1, 2):
                z, sz = wrap_cell(cz + dz, dims[2])
                offset = sz * shear
                if offset != 0.0:       # the images of that row sit offset along x
                    x, sx = sheared_cell(
                        int(math.floor((position[p, 0] - offset) / along)) + dx, dims[0])
                else:
                    x, sx = wrap_cell(cx + dx, dims[0])
                c = (x * dims[1] + y) * dims[2] + z
                for slot in range(c * cell_width,
                                  c * cell_width + min(cell_count[c], cell_width)):
                    q = cell_members[slot]
                    if q == p:
                        continue
                    reach = radius[p] + radius[q] + skin
                    d0 = position[q, 0] + sx * cell_position[1] + offset - position[p, 0]
                    d1 = position[q, 1] + sy * cell_position[3] - position[p, 1]
                    d2 = position[q, 2] + sz * cell_position[5] - position[p, 2]
                    if d0 * d0 + d1 * d1 + d2 * d2 < reach * reach:
                        if q > p:
                            above = insert_with_image(new_pair_j, image, p, n, above, width,
                                                      q, sx, sy, sz, flags)
                        else:
                            below = insert_sorted(lower, p, n, below, width, q, flags)
    carry_rows(p, n, min(above, width), min(below, width), new_count, lower_count, pair_count,
               pair_j, new_pair_j, shear_force, normal, overlap, bridges, rolling,
               new_shear_force, new_normal, new_overlap, new_bridges, new_rolling)


@cuda.jit
def shear_rebuilt(period, shear, flags):
    """After a rebuild (flags[0]) in a sheared cell: the offset the wrap and the search took
    (reduced_offset) stored in ``period`` [3] and ``shear`` (pendular.gpu.cell.SHEAR_FIELDS:
    the offset, and the rebuild test's reference). One thread."""
    if cuda.grid(1) != 0 or flags[0] == 0:
        return
    offset, _ = reduced_offset(period)
    period[3] = offset
    shear[0] = offset
    shear[3] = offset


@device_side(NeighborList)
class VerletList(DeviceSide):
    """The NeighborList's side: the rebuild's launches (the box's steps) and the device's
    grid read its skin; its ``rebuild`` makes the host's list when the state comes back."""

    family = "neighbor list"

    @property
    def skin(self):
        """The list's skin [m]."""
        return self.op.skin
