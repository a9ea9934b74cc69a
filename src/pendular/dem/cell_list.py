"""Candidate pairs within reach, found through a cell list, and the spatial order of particles.

``build_pairs`` (inside walls) and ``build_periodic_pairs`` (a periodic cell, sheared or not:
pairs through the nearest image) bin the particles into cells of at least the largest
diameter plus the reach and list, for each particle i, the particles j > i within reach:
CSR rows ``row_start`` [-] of the pairs' second members ``pair_j`` [-], sorted by j.
pendular.dem.neighbors builds its Contacts from them; the device compiles the same cell
kernels (pendular.gpu.neighbors). ``spatial_order`` lists particles along a Z-order curve.
"""

import numba
import numpy as np

from pendular.utils.validate import check_positive


#: Pairs of a row kept by the one search of build_pairs (a longer row is searched again): a
#: sphere of a packing has 2-6 neighbours j > i within a skin of 0.1 R.
ROW_CAPACITY = 16


@numba.njit(cache=True)
def group_members(group_of, group_count):
    """(group_start, members): the indices k of ``group_of`` (each one's group, in
    [0, group_count)) sorted by group in CSR order, group g holding
    members[group_start[g]:group_start[g + 1]] in index order (a counting sort)."""
    group_start = np.zeros(group_count + 1, np.int64)
    for k in range(len(group_of)):
        group_start[group_of[k] + 1] += 1
    for g in range(group_count):
        group_start[g + 1] += group_start[g]
    fill = group_start[:-1].copy()
    members = np.empty(len(group_of), np.int64)
    for k in range(len(group_of)):
        members[fill[group_of[k]]] = k
        fill[group_of[k]] += 1
    return group_start, members


@numba.njit(cache=True)
def _sort_into_cells(position, lo, hi, dims):
    """(dims, cell_of, cell_start, cell_particles) of the ``dims`` grid of cells spanning
    [lo, hi): each particle's cell (x-major numbering) and the particles of each cell in CSR
    order, in index order within a cell."""
    count = position.shape[0]
    cell_of = np.empty(count, np.int64)
    for p in range(count):
        index = 0
        for axis in range(3):
            width = (hi[axis] - lo[axis]) / dims[axis]
            c = int((position[p, axis] - lo[axis]) / width)
            c = min(max(c, 0), dims[axis] - 1)
            index = index * dims[axis] + c
        cell_of[p] = index
    cell_start, cell_particles = group_members(cell_of, dims[0] * dims[1] * dims[2])
    return dims, cell_of, cell_start, cell_particles


@numba.njit(cache=True)
def _cell_grid(position, cell_size):
    """Sort particles into a regular grid of cells of at least ``cell_size`` covering them.

    The grid spans the particles' bounding box and holds at most about 4 cells per particle,
    so a sparse scene in a large box costs no more memory than a dense one.
    """
    count = position.shape[0]
    lo = np.empty(3)
    hi = np.empty(3)
    for axis in range(3):
        lo[axis] = position[:, axis].min()
        hi[axis] = position[:, axis].max() + 1e-12 * cell_size
    dims = np.empty(3, np.int64)
    while True:
        for axis in range(3):
            dims[axis] = max(1, int((hi[axis] - lo[axis]) / cell_size))
        if dims[0] * dims[1] * dims[2] <= 4 * count + 27:
            break
        cell_size *= 1.25
    return _sort_into_cells(position, lo, hi, dims)


@numba.njit(cache=True, inline="always")
def _cell_coordinates(cell, dims):
    """(x, y, z) coordinates of the cell numbered ``cell`` in the ``dims`` grid (x-major
    numbering, as _sort_into_cells)."""
    return cell // (dims[1] * dims[2]), (cell // dims[2]) % dims[1], cell % dims[2]


@numba.njit(cache=True, inline="always")
def _within_reach(position, radius, skin, p, q):
    """Whether particles p and q are closer than r_p + r_q + ``skin`` [m] (centre to centre,
    no periodic image): the Verlet list's test, the GPU's too (pendular.gpu.neighbors)."""
    reach = radius[p] + radius[q] + skin
    d0 = position[q, 0] - position[p, 0]
    d1 = position[q, 1] - position[p, 1]
    d2 = position[q, 2] - position[p, 2]
    return d0 * d0 + d1 * d1 + d2 * d2 < reach * reach


@numba.njit(cache=True)
def _neighbors_of(p, position, radius, skin, dims, cell_of, cell_start, cell_particles, out):
    """Count the j > p within r_p + r_j + skin; return how many. While ``out`` has room they
    are written into it, sorted (all of them if it is long enough: compare the count)."""
    room = len(out)
    found = 0
    cx, cy, cz = _cell_coordinates(cell_of[p], dims)
    for dx in range(-1, 2):
        x = cx + dx
        if x < 0 or x >= dims[0]:
            continue
        for dy in range(-1, 2):
            y = cy + dy
            if y < 0 or y >= dims[1]:
                continue
            for dz in range(-1, 2):
                z = cz + dz
                if z < 0 or z >= dims[2]:
                    continue
                c = (x * dims[1] + y) * dims[2] + z
                for slot in range(cell_start[c], cell_start[c + 1]):
                    q = cell_particles[slot]
                    if q <= p:
                        continue
                    if _within_reach(position, radius, skin, p, q):
                        if found < room:        # insertion keeps the row sorted by j
                            k = found
                            while k > 0 and out[k - 1] > q:
                                out[k] = out[k - 1]
                                k -= 1
                            out[k] = q
                        found += 1
    return found


@numba.njit(cache=True, parallel=True)
def build_pairs(position, radius, skin):
    """Half Verlet list (i < j, |x_i - x_j| < r_i + r_j + skin) as CSR arrays (row_start, pair_j):
    one search keeps each row in a buffer of ROW_CAPACITY, then the rows are copied into the
    list; a longer row is searched again, into its place in the list."""
    count = position.shape[0]
    cell_size = 2.0 * radius.max() + skin
    dims, cell_of, cell_start, cell_particles = _cell_grid(position, cell_size)
    kept = np.empty((count, ROW_CAPACITY), np.int64)
    row_count = np.empty(count, np.int64)
    for p in numba.prange(count):     # p as int64 in both loops: one compiled _neighbors_of
        row_count[p] = _neighbors_of(np.int64(p), position, radius, skin, dims, cell_of,
                                     cell_start, cell_particles, kept[p])
    row_start = _row_starts(row_count)
    pair_j = np.empty(row_start[count], np.int64)
    for p in numba.prange(count):
        start, stop = row_start[p], row_start[p + 1]
        if stop - start <= ROW_CAPACITY:
            pair_j[start:stop] = kept[p, :stop - start]
        else:
            _neighbors_of(np.int64(p), position, radius, skin, dims, cell_of, cell_start,
                          cell_particles, pair_j[start:stop])
    return row_start, pair_j


@numba.njit(cache=True)
def _row_starts(row_count):
    """CSR row starts (N + 1,) of rows of ``row_count`` (N,) entries."""
    row_start = np.zeros(len(row_count) + 1, np.int64)
    for p in range(len(row_count)):
        row_start[p + 1] = row_start[p] + row_count[p]
    return row_start


@numba.njit(cache=True)
def _periodic_grid(position, cell_size, period):
    """Sort particles (wrapped into [0, period)) into cells of edge at least ``cell_size``
    tiling the periodic box (build_contacts makes sure of at least 3 a side, so that the 27
    cells around a cell are distinct)."""
    dims = np.empty(3, np.int64)
    for axis in range(3):
        dims[axis] = int(period[axis] / cell_size)
    # the period copied: contiguous, as _cell_grid's bounds (one compiled _sort_into_cells)
    return _sort_into_cells(position, np.zeros(3), period.copy(), dims)


@numba.njit(cache=True, inline="always")
def _wrap_cell(c, dim):
    """(cell index, image) of cell coordinate ``c`` in a periodic row of ``dim`` cells,
    c in [-1, dim]."""
    if c < 0:
        return c + dim, -1
    if c >= dim:
        return c - dim, 1
    return c, 0


@numba.njit(cache=True, inline="always")
def _sheared_cell(c, dim):
    """(cell index, image) of cell coordinate ``c`` (any integer) in a periodic row of ``dim``
    cells: c modulo dim and the periods it lies beyond the row."""
    index = c % dim
    return index, (c - index) // dim


@numba.njit(cache=True)
def _periodic_neighbors_of(p, position, radius, skin, period, shear, dims, cell_of, cell_start,
                           cell_particles, out, out_image):
    """As _neighbors_of in a periodic box: the j > p within r_p + r_j + skin of p through
    the nearest image, written sorted with that image into ``out`` and ``out_image`` while
    they have room; returns how many. In a sheared cell (``shear`` = delta [m], the offset
    along x of the images above in z, pendular.dem.cell) the rows of cells through a z face
    are searched around p's x less their offset sz * delta."""
    room = len(out)
    found = 0
    cx, cy, cz = _cell_coordinates(cell_of[p], dims)
    width = period[0] / dims[0]
    for dx in range(-1, 2):
        for dy in range(-1, 2):
            y, sy = _wrap_cell(cy + dy, dims[1])
            for dz in range(-1, 2):
                z, sz = _wrap_cell(cz + dz, dims[2])
                offset = sz * shear
                if offset != 0.0:   # the images of that row sit offset along x
                    x, sx = _sheared_cell(
                        int(np.floor((position[p, 0] - offset) / width)) + dx, dims[0])
                else:
                    x, sx = _wrap_cell(cx + dx, dims[0])
                c = (x * dims[1] + y) * dims[2] + z
                for slot in range(cell_start[c], cell_start[c + 1]):
                    q = cell_particles[slot]
                    if q <= p:
                        continue
                    reach = radius[p] + radius[q] + skin
                    d0 = position[q, 0] + sx * period[0] + offset - position[p, 0]
                    d1 = position[q, 1] + sy * period[1] - position[p, 1]
                    d2 = position[q, 2] + sz * period[2] - position[p, 2]
                    if d0 * d0 + d1 * d1 + d2 * d2 < reach * reach:
                        if found < room:
                            k = found
                            while k > 0 and out[k - 1] > q:
                                out[k] = out[k - 1]
                                out_image[k] = out_image[k - 1]
                                k -= 1
                            out[k] = q
                            out_image[k, 0] = sx
                            out_image[k, 1] = sy
                            out_image[k, 2] = sz
                        found += 1
    return found


@numba.njit(cache=True, parallel=True)
def build_periodic_pairs(position, radius, skin, period):
    """Half Verlet list of a periodic box (positions wrapped into [0, period)): CSR arrays
    (row_start, pair_j) and each pair's image (K, 3) int8 (branch_vector; ``period`` (4,) of a
    sheared cell: its images above in z offset along x). The box must be at least 3 cells of
    2 max(radius) + skin a side, so that a pair has one image in reach."""
    count = position.shape[0]
    cell_size = 2.0 * radius.max() + skin
    shear = period[3] if len(period) > 3 else 0.0
    dims, cell_of, cell_start, cell_particles = _periodic_grid(position, cell_size, period)
    kept = np.empty((count, ROW_CAPACITY), np.int64)
    kept_image = np.empty((count, ROW_CAPACITY, 3), np.int8)
    row_count = np.empty(count, np.int64)
    for p in numba.prange(count):     # p as int64 in both loops (build_pairs)
        row_count[p] = _periodic_neighbors_of(np.int64(p), position, radius, skin, period,
                                              shear, dims, cell_of, cell_start, cell_particles,
                                              kept[p], kept_image[p])
    row_start = _row_starts(row_count)
    pair_j = np.empty(row_start[count], np.int64)
    image = np.empty((row_start[count], 3), np.int8)
    for p in numba.prange(count):
        start, stop = row_start[p], row_start[p + 1]
        if stop - start <= ROW_CAPACITY:
            pair_j[start:stop] = kept[p, :stop - start]
            image[start:stop] = kept_image[p, :stop - start]
        else:
            _periodic_neighbors_of(np.int64(p), position, radius, skin, period, shear, dims,
                                   cell_of, cell_start, cell_particles, pair_j[start:stop],
                                   image[start:stop])
    return row_start, pair_j, image


def spatial_order(position, cell_size):
    """Permutation [-] that lists particles cell by cell along a Z-order (Morton) curve through a
    grid of cells of edge ``cell_size`` [m], in index order within a cell.

    Particles listed in this order keep near neighbours near in memory, so the pair loops and
    gathers read contiguous rows instead of jumping across the arrays (LAMMPS's atom_modify
    sort, JAX-MD's cell ordering). 21 bits per axis: grids of up to 2^21 cells a side.
    """
    position = np.asarray(position, dtype=np.float64)
    cell_size = check_positive("cell_size", cell_size, "m")
    cells = np.floor((position - position.min(axis=0)) / cell_size).astype(np.int64)
    cells = np.minimum(cells, 2 ** 21 - 1)
    code = np.zeros(len(position), np.int64)
    for bit in range(21):
        for axis in range(3):
            code |= ((cells[:, axis] >> bit) & 1) << (3 * bit + axis)
    return np.argsort(code, kind="stable")
