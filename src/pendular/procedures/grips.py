"""Direct tension: grips that move with a wall, the tensile stress, and wetting to a water content.

A wall only pushes, so a tension test (Kim 2001, thesis §4.4.1.2 and Table 4.5) grips the
sample at its ends: the particles whose centre lies within ``depth`` of a wall when the pull
starts move rigidly with that wall (``Grip``, a prescribed velocity, no rotation), as a sample
glued to a rough platen. The force the rig needs to hold a grip on its path is minus the
resultant on its particles; without the wall's own push on them (the wall and its grip are one
rigid body) that is the force of the specimen on the grip, ``Grip.pull`` [N], positive when the
specimen pulls the grip inward (tension). Dividing by the cross-section gives the tensile stress,
the opposite of the compression-positive axial stress (``tensile_stress``).
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


class Grip:
    """Particles ``members`` moving rigidly with wall ``wall`` (0..5): each step their force
    and torque are replaced by the prescribed motion (velocity = the wall's, along its axis;
    no spin). Runs after the force operations and the wall control, before the Integrator.

    ``pull`` [N]: force of the rest of the sample on the grip along the wall's axis, positive
    toward the sample (tension); the wall's push on the members (``walls.force[wall]``) is not
    part of it: all particles touching the wall must be members (``grip_members``).
    """

    def __init__(self, wall, members):
        if wall not in range(6):
            raise ValueError(f"wall = {wall!r} is outside the valid range 0..5")
        self.wall = wall
        self.axis = wall // 2
        self.inward = 1.0 if wall % 2 == 0 else -1.0   # unit direction from the wall into the box
        self.members = np.asarray(members, np.int64)
        if len(self.members) == 0:
            raise ValueError(f"grip of wall {wall} has no particles: increase the grip depth")
        self.pull = 0.0

    def apply(self, sim):
        p = sim.particles
        resultant = float(np.sum(p.force[self.members, self.axis]))
        self.pull = self.inward * resultant - sim.walls.force[self.wall]
        p.force[self.members] = 0.0
        p.torque[self.members] = 0.0
        p.angular_velocity[self.members] = 0.0
        p.velocity[self.members] = 0.0
        p.velocity[self.members, self.axis] = -self.inward * sim.walls.velocity[self.wall]


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
