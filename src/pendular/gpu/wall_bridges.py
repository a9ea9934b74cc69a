"""Sphere–wall bridges on the device (pendular.capillary.wall_bridges, a suction-controlled
bridge operation's ``walls``), run by the bridges' device side (pendular.gpu.bridges).

One thread per sphere runs the CPU's own body (pendular.capillary.wall_bridges._sphere_on_walls,
compiled by device_twin) among the forces' launches after the pairs' gather: its six walls in
order, its bridges' state (N, 6), its pull added to its force, its pull on each wall and that
pull's moment arm times the pull into (N, 6) buffers. After the walls' own sums
(pendular.gpu.walls.wall_sums), ``wall_bridge_partials`` sums the buffers per block of
REDUCE_CHUNK spheres in sphere order and ``wall_bridge_sums`` subtracts the pulls from the
walls' force and sets the bridges' moment on each wall, before the walls' controls read the
force: the CPU's sums, the force's in another order (round-off). The state lives on the device
during a run and comes back with the state (``to_host``).
"""

import numpy as np

from pendular.capillary.wall_bridges import _sphere_on_walls
from pendular.gpu.cuda import cuda, device_twin
from pendular.gpu.walls import REDUCE_CHUNK

sphere_on_walls = device_twin(_sphere_on_walls)

#: Quantities summed on each wall: the pulls [N], their moments [N m].
BRIDGE_SUMS = 2


@cuda.jit
def wall_bridges(position, radius, wall_position, suction, surface_tension, persist,
                 suction_axis, distance_low, log_distance_rupture, log_values, exists, volume,
                 force_magnitude, filling, force, moment):
    """Sphere p's bridges with the walls (pendular.capillary.wall_bridges.wall_bridge_forces'
    arguments, ``moment`` (N, 6) [N m]: row p its moments on the walls)."""
    p = cuda.grid(1)
    if p >= radius.shape[0]:
        return
    sphere_on_walls(p, position, radius, wall_position, suction, surface_tension, persist,
                    suction_axis, distance_low, log_distance_rupture, log_values, exists,
                    volume, force_magnitude, filling, force, moment[p])


@cuda.jit
def wall_bridge_partials(force_magnitude, moment, partial):
    """partial[b, w, q]: block b's sum over its spheres, in order, of their pulls on wall w
    (q 0) [N] and of those pulls' moments (q 1) [N m]."""
    b = cuda.grid(1)
    if b >= partial.shape[0]:
        return
    for w in range(6):
        f = 0.0
        m = 0.0
        for p in range(b * REDUCE_CHUNK, min((b + 1) * REDUCE_CHUNK, moment.shape[0])):
            f += force_magnitude[p, w]
            m += moment[p, w]
        partial[b, w, 0] = f
        partial[b, w, 1] = m


@cuda.jit
def wall_bridge_sums(partial, wall_force, bridge_moment):
    """One thread per wall and quantity: the blocks' pulls subtracted from the wall's force
    [N], their moments added in order into the bridges' ``bridge_moment`` (6,) [N m]."""
    t = cuda.grid(1)
    if t >= 6 * BRIDGE_SUMS:
        return
    w = t // BRIDGE_SUMS
    total = 0.0
    for b in range(partial.shape[0]):
        total += partial[b, w, t % BRIDGE_SUMS]
    if t % BRIDGE_SUMS == 0:
        wall_force[w] -= total
    else:
        bridge_moment[w] = total


class DeviceWallBridges:
    """The device's copy of a WallBridges ``walls`` (pendular.capillary.wall_bridges): its
    table, its per-sphere state and buffers, made at the first step's launches."""

    def __init__(self, walls):
        self.walls = walls
        self.table = None
        self._table_of = None
        self.state = None           # exists, volume, force, filling (N, 6)
        self.moment = self.partial = self.bridge_moment = None

    def _upload(self, count, blocks):
        """The host's state (zeros when it has none for these ``count`` spheres), the moment
        buffers and the blocks' partial sums into device memory."""
        walls = self.walls
        arrays = []
        for name, dtype in walls.ARRAYS.items():
            array = getattr(walls, name)
            if array.shape != (count, 6):
                array = np.zeros((count, 6), dtype)
            arrays.append(cuda.to_device(np.ascontiguousarray(array, dtype=dtype)))
        self.state = tuple(arrays)
        self.moment = cuda.to_device(np.zeros((count, 6)))
        self.partial = cuda.to_device(np.zeros((blocks, 6, BRIDGE_SUMS)))
        self.bridge_moment = cuda.to_device(np.ascontiguousarray(walls.moment, np.float64))

    def launches(self, state, op):
        """(kernel, items, arguments) of a step's bridges on the walls at the operation
        ``op``'s suction now (its table checked for the radii: WallBridges.load_table)."""
        s = state
        radius = s.radius.copy_to_host()
        self.walls.load_table(float(radius.min()), float(radius.max()))
        if self._table_of is not self.walls.table:
            self.table = tuple(cuda.to_device(np.ascontiguousarray(a))
                               for a in self.walls.table.arrays())
            self._table_of = self.walls.table
        if self.state is None:
            self._upload(s.count, s.partial.shape[0])
        return [(wall_bridges, s.count,
                 (s.position, s.radius, s.wall_position, op.suction, op.surface_tension,
                  op.persist, *self.table, *self.state, s.force, self.moment))]

    def wall_launches(self, state):
        """(kernel, items, arguments) of the pulls' sums on the walls, after the walls' own."""
        return [(wall_bridge_partials, self.partial.shape[0],
                 (self.state[2], self.moment, self.partial)),
                (wall_bridge_sums, 6 * BRIDGE_SUMS,
                 (self.partial, state.wall_force, self.bridge_moment))]

    def to_host(self):
        """The device's state and the bridges' moments into the host's WallBridges."""
        if self.state is None:
            return
        for name, array in zip(self.walls.ARRAYS, self.state):
            setattr(self.walls, name, array.copy_to_host())
        self.walls.moment = self.bridge_moment.copy_to_host()
