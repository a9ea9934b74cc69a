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
the device among the forces' own launches after the gather (pendular.gpu.operations), the
same sum in another order (round-off) when the walls precede the operation that gathers the
pairs (bridges at contact, listed last).

The springs ``wall_shear`` (N, 6, 3) [N] live on the device during a run: uploaded from the
host's operation at the GpuSimulation's first run, brought back with the state (its
copy_back), so that a checkpoint and the CPU go on from them.
"""

import numpy as np

from pendular.dem.hertz_mindlin import ViscoelasticWallForces, _sphere_on_walls
from pendular.dem.wall_friction import FrictionalWallForces
from pendular.gpu.cuda import cuda, device_twin
from pendular.gpu.operations import DeviceSide, device_side
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


@device_side(ViscoelasticWallForces, FrictionalWallForces)
class SpringWalls(DeviceSide):
    """The walls' side of a sphere–wall operation with springs (ViscoelasticWallForces,
    FrictionalWallForces; role "walls" as pendular.gpu.walls.WallSprings): the gather adds no
    wall springs (``young`` 0), ``wall_contacts`` runs among the forces' launches and
    ``partials`` sums its buffers for the walls' ``wall_sums``. Its springs and (N, 6) buffers
    go to the device at the first step's launches and come back with the state
    (``pairs_to_host``)."""

    family = "force"
    role = "walls"
    in_cell = False
    #: E [Pa] of the springs the pairs' gather adds: none, wall_contacts runs the walls.
    young = 0.0

    def __init__(self, op):
        super().__init__(op)
        self.wall_shear = None
        self.contacts = None

    def _upload(self, count):
        """The springs (zeros when the host has none for these ``count`` particles) and the
        buffers into device memory."""
        shear = self.op.wall_shear
        if shear.shape != (count, 6, 3):
            shear = np.zeros((count, 6, 3))
        self.wall_shear = cuda.to_device(np.ascontiguousarray(shear, dtype=np.float64))
        self.contacts = tuple(cuda.to_device(np.zeros((count, 6))) for _ in range(3))

    def launches(self, state, dt):
        """(kernel, items, arguments) of a step's wall contacts (``state`` a DeviceState; the
        operation's parameters now)."""
        s = state
        if self.wall_shear is None:
            self._upload(s.count)
        w = self.op
        return [(wall_contacts, s.count,
                 (s.position, s.velocity, s.angular_velocity, s.radius, s.mass,
                  s.wall_position, s.wall_velocity, w.hertz, w.modulus, w.tangential,
                  w.damping, w._tan_friction, dt, self.wall_shear, s.force, s.torque,
                  *self.contacts))]

    def partials(self, state):
        """(kernel, items, arguments) of each block's sums of the particles' shares on the
        walls (``wall_partials`` into ``state.partial``)."""
        return [(wall_partials, state.partial.shape[0], (*self.contacts, state.partial))]

    def pairs_to_host(self, sim, state, index):
        """The device's springs into the host's operation (``wall_shear``: per particle)."""
        if self.wall_shear is not None:
            self.op.wall_shear = self.wall_shear.copy_to_host()
