"""Random clouds of non-overlapping spheres in a box: the starting positions of a preparation
(pendular.procedures.preparation), by cell-list insertion (equal spheres; pairwise insertion
for small counts that the cell list cannot place) or largest first (unequal spheres)."""

import numpy as np
import numba

from pendular.dem.state import Walls
from pendular.utils.validate import check_int, check_positive

#: Largest random seed (NumPy's legacy generator, used by the Numba kernels: 32 bits).
MAX_SEED = 2 ** 32 - 1


@numba.njit(cache=True, inline="always")
def _overlaps_placed(x, r, c, dims, head, following, position, radius):
    """Whether a sphere of radius ``r`` [m] centred at ``x`` overlaps a placed one in the 27
    cells around cell ``c`` of the ``dims`` grid (cells as linked lists: ``head`` per cell,
    ``following`` per sphere, -1 ending a list; cells at least 2 max(radius) wide)."""
    for dx in range(-1, 2):
        for dy in range(-1, 2):
            for dz in range(-1, 2):
                nx = c[0] + dx
                ny = c[1] + dy
                nz = c[2] + dz
                if nx < 0 or ny < 0 or nz < 0 or nx >= dims[0] or ny >= dims[1] \
                        or nz >= dims[2]:
                    continue
                q = head[(nx * dims[1] + ny) * dims[2] + nz]
                while q >= 0:
                    d = x - position[q]
                    reach = r + radius[q]
                    if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < reach * reach:
                        return True
                    q = following[q]
    return False


@numba.njit(cache=True)
def _random_cloud(count, radius, lo, hi, seed, max_attempts):
    """Random sequential insertion of ``count`` equal spheres in [lo, hi] without overlap."""
    np.random.seed(seed)
    cell = 2.0 * radius
    dims = np.empty(3, np.int64)
    for a in range(3):
        dims[a] = max(1, int((hi[a] - lo[a] - 2.0 * radius) / cell))
    # a cell admits one centre (random_cloud): one drawn in an occupied cell is refused, so
    # each cell's list holds one sphere at most
    occupant = -np.ones(dims[0] * dims[1] * dims[2], np.int64)
    following = -np.ones(count, np.int64)
    radii = np.full(count, radius)
    position = np.empty((count, 3))
    placed = 0
    attempts = 0
    while placed < count:
        attempts += 1
        if attempts > max_attempts:
            return position[:placed]
        x = np.empty(3)
        c = np.empty(3, np.int64)
        for a in range(3):
            x[a] = lo[a] + radius + np.random.random() * (hi[a] - lo[a] - 2.0 * radius)
            c[a] = min(int((x[a] - lo[a] - radius) / ((hi[a] - lo[a] - 2.0 * radius) / dims[a])),
                       dims[a] - 1)
        key = (c[0] * dims[1] + c[1]) * dims[2] + c[2]
        if occupant[key] < 0 and not _overlaps_placed(x, radius, c, dims, occupant, following,
                                                      position, radii):
            position[placed] = x
            occupant[key] = placed
            placed += 1
    return position


@numba.njit(cache=True)
def _random_cloud_pairwise(count, radius, lo, hi, seed, max_attempts):
    """Random sequential insertion testing every placed sphere (O(count^2), small counts)."""
    np.random.seed(seed)
    position = np.empty((count, 3))
    placed = 0
    for _ in range(max_attempts):
        x = np.empty(3)
        for a in range(3):
            x[a] = lo[a] + radius + np.random.random() * (hi[a] - lo[a] - 2.0 * radius)
        free = True
        for q in range(placed):
            d = x - position[q]
            if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < 4.0 * radius * radius:
                free = False
                break
        if free:
            position[placed] = x
            placed += 1
            if placed == count:
                break
    return position[:placed]


@numba.njit(cache=True)
def _random_cloud_graded(radius, lo, hi, seed, max_attempts):
    """Random sequential insertion of spheres of unequal ``radius`` in [lo, hi] without
    overlap, largest first (positions in the order of ``radius``; only those placed, in
    insertion order, if ``max_attempts`` ran out). Cells of edge 2 max(radius) hold any
    number of centres (linked lists), so a sphere is checked against the 27 cells around its
    own."""
    np.random.seed(seed)
    count = radius.size
    cell = 2.0 * radius.max()
    dims = np.empty(3, np.int64)
    for a in range(3):
        dims[a] = max(1, int((hi[a] - lo[a]) / cell))
    head = -np.ones(dims[0] * dims[1] * dims[2], np.int64)
    following = -np.ones(count, np.int64)
    position = np.empty((count, 3))
    order = np.argsort(-radius, kind="mergesort")
    placed = 0
    attempts = 0
    while placed < count:
        attempts += 1
        if attempts > max_attempts:
            return position[order[:placed]]
        i = order[placed]
        r = radius[i]
        x = np.empty(3)
        c = np.empty(3, np.int64)
        for a in range(3):
            x[a] = lo[a] + r + np.random.random() * (hi[a] - lo[a] - 2.0 * r)
            c[a] = min(int((x[a] - lo[a]) / ((hi[a] - lo[a]) / dims[a])), dims[a] - 1)
        if not _overlaps_placed(x, r, c, dims, head, following, position, radius):
            position[i] = x
            key = (c[0] * dims[1] + c[1]) * dims[2] + c[2]
            following[i] = head[key]
            head[key] = i
            placed += 1
    return position


#: Largest count for which random_cloud falls back to pairwise insertion.
PAIRWISE_CLOUD_MAX = 2000


def random_cloud(count, radius, lo, hi, seed):
    """``count`` non-overlapping spheres of ``radius`` [m] (one value, or one per sphere)
    uniformly placed in the box [lo, hi].

    Equal spheres: cell-list insertion admits one centre per cell, which in a box only a few
    diameters wide leaves room for fewer spheres than fit; small counts that it cannot place
    are placed by pairwise insertion instead (the cell-list result is kept whenever it
    succeeds). Unequal spheres: insertion largest first with any number of centres per cell."""
    count = check_int("particles", count, low=1)
    radii = np.ascontiguousarray(np.broadcast_to(np.asarray(radius, dtype=np.float64),
                                                 (count,)))
    for value in (radii.min(), radii.max()):
        check_positive("radius", value, "m")
    box = Walls.box(lo, hi)
    lo, hi = np.ascontiguousarray(box.lo), np.ascontiguousarray(box.hi)
    largest = float(radii.max())
    if np.any(hi - lo <= 2.0 * largest):
        raise ValueError(f"radius = {largest:g} m is outside the valid range (0, "
                         f"{0.5 * float(np.min(hi - lo)):g}] m for a box of edges "
                         f"{(hi - lo).tolist()} m")
    seed = check_int("seed", seed, high=MAX_SEED)
    if radii.min() < largest:
        position = _random_cloud_graded(radii, lo, hi, seed, 200 * count + 10000)
    else:
        position = _random_cloud(count, largest, lo, hi, seed, 200 * count + 10000)
        if len(position) < count and count <= PAIRWISE_CLOUD_MAX:
            position = _random_cloud_pairwise(count, largest, lo, hi, seed,
                                              200 * count + 10000)
    if len(position) < count:
        raise ValueError(f"particles = {count} is outside the valid range [1, {len(position)}] "
                         f"for spheres of radius up to {largest:g} m in this box: only "
                         f"{len(position)} could be placed without overlap; use a larger box "
                         "or a smaller radius")
    return position
