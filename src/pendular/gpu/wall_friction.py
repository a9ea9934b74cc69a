"""Sphere–wall contacts with tangential springs on the device: wall friction of the linear law
(pendular.dem.wall_friction.FrictionalWallForces) and the damped laws' walls
(pendular.dem.hertz_mindlin.ViscoelasticWallForces, Hertz–Mindlin's among them).

One thread per particle runs the CPU's own body (pendular.dem.hertz_mindlin._sphere_on_walls,
compiled by device_twin): its six walls in order, its force, torque and springs, after the
gather of the pair forces (whose wall springs are then off: ``wall_young`` 0). Its
contributions to each wall's force, stiffness and moment go to (N, 6) buffers, which
``wall_partials`` sums per block of REDUCE_CHUNK particles in particle order for the walls'
own ``wall_sums`` (pendular.gpu.walls): for up to REDUCE_CHUNK particles the CPU's sums in the
CPU's order. The CPU adds the wall forces where the wall operation stands among the forces;
the device right after the gather, the same sum in another order (round-off) when the walls
precede the operation that gathers the pairs (bridges at contact, listed last).

The springs ``wall_shear`` (N, 6, 3) [N] live on the device during a run: uploaded from the
host's operation when a GpuSimulation is made, brought back by ``to_host`` (the
GpuSimulation's copy_back), so that a checkpoint and the CPU go on from them.
"""

import numpy as np

from pendular.dem.hertz_mindlin import ViscoelasticWallForces, _sphere_on_walls
from pendular.dem.walls import WallForces
from pendular.gpu.cuda import cuda, device_twin
from pendular.gpu.walls import REDUCE_CHUNK

sphere_on_walls = device_twin(_sphere_on_walls)


@cuda.jit
def wall_contacts(position, velocity, angular_velocity, radius, mass, wall_position,
                  wall_velocity, hertz, modulus, tangential, damping, tan_friction, dt,
                  wall_shear, force, torque, contact_force, contact_stiffness, contact_moment):
    """Particle p's contacts with the walls (pendular.dem.hertz_mindlin
    .viscoelastic_wall_forces' body and arguments): added to its force and torque, its springs
    updated, its share of each wall's force [N], stiffness [N/m] and moment [N m] written to
    row p of the (N, 6) ``contact_*`` buffers."""
    p = cuda.grid(1)
    if p >= radius.shape[0]:
        return
    for w in range(6):
        contact_force[p, w] = 0.0
        contact_stiffness[p, w] = 0.0
        contact_moment[p, w] = 0.0
    sphere_on_walls(p, position, velocity, angular_velocity, radius, mass, wall_position,
                    wall_velocity, hertz, modulus, tangential, damping, tan_friction, dt,
                    wall_shear, force, torque, contact_force[p], contact_stiffness[p],
                    contact_moment[p])


@cuda.jit
def wall_partials(contact_force, contact_stiffness, contact_moment, partial):
    """partial[b, w, q]: block b's sum over its particles, in order, of their shares of wall
    w's force, stiffness and moment (q 0, 1, 2: pendular.gpu.walls.WALL_SUMS)."""
    b = cuda.grid(1)
    if b >= partial.shape[0]:
        return
    for w in range(6):
        f = 0.0
        k = 0.0
        m = 0.0
        for p in range(b * REDUCE_CHUNK, min((b + 1) * REDUCE_CHUNK, contact_force.shape[0])):
            f += contact_force[p, w]
            k += contact_stiffness[p, w]
            m += contact_moment[p, w]
        partial[b, w, 0] = f
        partial[b, w, 1] = k
        partial[b, w, 2] = m


class DeviceSpringWalls:
    """The device side of a scene's sphere–wall operation with springs (``wall``: a
    ViscoelasticWallForces or FrictionalWallForces) over ``count`` particles: its springs and
    buffers on the device, its launches, its springs back to the host."""

    def __init__(self, wall, count):
        self.wall = wall
        shear = wall.wall_shear if wall.wall_shear.shape == (count, 6, 3) else \
            np.zeros((count, 6, 3))
        self.wall_shear = cuda.to_device(np.ascontiguousarray(shear, dtype=np.float64))
        self.contacts = tuple(cuda.to_device(np.zeros((count, 6))) for _ in range(3))

    @classmethod
    def of(cls, forces, count):
        """The device side of the one wall operation with springs among ``forces`` (a scene's
        list), None when it has none."""
        found = [op for op in forces if isinstance(op, (ViscoelasticWallForces, WallForces))]
        if len(found) > 1:
            raise ValueError(f"device='gpu' runs at most one sphere-wall operation; found "
                             f"{', '.join(type(op).__name__ for op in found)}")
        found = [op for op in found if isinstance(op, ViscoelasticWallForces)]
        return cls(found[0], count) if found else None

    def launches(self, state, dt):
        """(kernel, items, arguments) of a step's wall contacts and their partial sums, to run
        right after the gather (``state`` a DeviceState; the operation's parameters now)."""
        s = state
        w = self.wall
        return [(wall_contacts, s.count,
                 (s.position, s.velocity, s.angular_velocity, s.radius, s.mass,
                  s.wall_position, s.wall_velocity, w.hertz, w.modulus, w.tangential,
                  w.damping, w._tan_friction, dt, self.wall_shear, s.force, s.torque,
                  *self.contacts)),
                (wall_partials, s.partial.shape[0], (*self.contacts, s.partial))]

    def to_host(self):
        """The device's springs into the host's operation (``wall_shear``)."""
        self.wall.wall_shear = self.wall_shear.copy_to_host()
