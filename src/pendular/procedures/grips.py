"""Direct tension: grips that move with a wall, the tensile stress, and wetting to a water content.

A wall only pushes, so a tension test (Kim 2001, thesis §4.4.1.2 and Table 4.5) grips the
sample at its ends: the particles whose centre lies within ``depth`` of a wall when the pull
starts (``grip_members``) move rigidly with that wall (``Grip``, the engine's control
pendular.dem.grips), as a sample glued to a rough platen. The force of
the specimen on a grip is ``Grip.pull`` [N], positive in tension; dividing by the
cross-section gives the tensile stress, the opposite of the compression-positive axial stress
(``tensile_stress``).
"""

import math

import numba
import numpy as np

from pendular.utils.validate import check_positive, check_range


def grip_members(position, radius, walls, wall, depth):
    """Indices of the particles whose centre lies within ``depth`` [m] of wall ``wall`` (0..5,
    pendular.dem.state.WALL_NAMES). ``depth`` must reach every particle touching the wall (>= max R)."""
    check_range("grip depth", depth, float(np.max(radius)), unit="m")
    axis = wall // 2
    distance = np.abs(position[:, axis] - walls.position[wall])
    return np.flatnonzero(distance <= depth)


def grip_reach(radius, grip_depth, radii):
    """Distance from a wall [m] within which a grip holds particle centres: the spheres whose
    surface lies within ``grip_depth`` mean diameters of the wall (``radius`` [m] the mean),
    and at least every sphere touching it (the largest of ``radii`` [m], which the
    preparation grew): grip_depth 0 grips the layer on the wall."""
    return max(radius * (1.0 + 2.0 * grip_depth), float(np.max(radii)))


def tensile_stress(grips, walls):
    """Mean pull of the grips over the cross-section normal to their axis [Pa], positive in
    tension (the axial stress, compression positive, is its opposite)."""
    area = walls.areas()[grips[0].wall]
    return float(np.mean([grip.pull for grip in grips])) / area


@numba.njit(cache=True)
def _solid_points(position, radius, lo, spacing, counts):
    """Number of the nodes lo + (k + 1/2) spacing (k < counts) inside at least one sphere."""
    inside = np.zeros((counts[0], counts[1], counts[2]), np.bool_)
    first = np.empty(3, np.int64)
    last = np.empty(3, np.int64)
    for p in range(position.shape[0]):
        r = radius[p]
        for a in range(3):
            first[a] = max(0, int(math.ceil((position[p, a] - r - lo[a]) / spacing[a] - 0.5)))
            last[a] = min(counts[a] - 1, int(math.floor((position[p, a] + r - lo[a])
                                                         / spacing[a] - 0.5)))
        for i in range(first[0], last[0] + 1):
            dx = lo[0] + (i + 0.5) * spacing[0] - position[p, 0]
            for j in range(first[1], last[1] + 1):
                dy = lo[1] + (j + 0.5) * spacing[1] - position[p, 1]
                for k in range(first[2], last[2] + 1):
                    dz = lo[2] + (k + 0.5) * spacing[2] - position[p, 2]
                    if dx * dx + dy * dy + dz * dz <= r * r:
                        inside[i, j, k] = True
    return np.count_nonzero(inside)


def core_void_ratio(particles, walls, margin, spacing):
    """Void ratio e = n / (1 - n) of the box shrunk by ``margin`` [m] on every side, away from
    the looser layers along the walls, by counting the nodes of a grid of ``spacing`` [m]
    inside the spheres (error about spacing / R / 100 for spacing <= R / 8)."""
    margin = check_range("core margin", margin, 0.0, unit="m")
    spacing = check_positive("core grid spacing", spacing, "m")
    lo = walls.lo + margin
    extent = walls.hi - margin - lo
    if (extent <= 0.0).any():
        raise ValueError(f"core margin = {margin:g} m leaves no core in a box of edges "
                         f"{walls.lengths().tolist()} m")
    counts = np.maximum(1, np.round(extent / spacing)).astype(np.int64)
    solid = _solid_points(particles.position, particles.radius, lo, extent / counts, counts)
    porosity = 1.0 - solid / float(np.prod(counts))
    return porosity / (1.0 - porosity)
