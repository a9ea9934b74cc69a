"""Grips on the device: particles that move rigidly with a wall (pendular.dem.grips.Grip), held
after the walls' controls and before the leapfrog, as the CPU runs them.

Each step ``grip_partials`` sums the members' force along their grip's axis, GRIP_CHUNK
members a thread in the members' order, then ``grip_hold`` adds each grip's chunks in order
into its pull (one thread per grip: a fixed order, no float atomics) and holds every member on
its wall's motion (one thread per member: force, torque and spin zero, the wall's velocity
along the axis). The pulls stay in a small device array (``DeviceGrips.pull``) that the host
reads with the walls (``to_host``), the particles left on the device: the pull of a grip is a
force on its wall's rigid body.

The sum is the CPU's terms in another order (the CPU's np.sum adds pairwise): the pulls agree
to round-off, the motion bit for bit for the same forces.
"""

import numpy as np

from pendular.dem.grips import Grip
from pendular.gpu.cuda import cuda
from pendular.gpu.operations import ControlSide, device_side
from pendular.gpu.walls import GRIP

#: Members summed by one thread of grip_partials.
GRIP_CHUNK = 16


def check_grips(scene, count):
    """ValueError naming what of the grips among ``scene``'s controls (sides,
    pendular.gpu.operations.Scene) the device does not run: a grip before a wall control (the
    device holds the grips after every wall control, which the CPU's order then matches),
    members outside the ``count`` particles, a particle in two grips (the CPU holds it by the
    later one, which a reduction of all grips at once would not match)."""
    controls = scene.controls
    rows = [c for c, side in enumerate(controls) if side.role == GRIP]
    if not rows:
        return
    late = [side.name for side in controls[rows[0]:] if side.role != GRIP]
    if late:
        raise ValueError(f"device='gpu' runs the grips after every wall control; the control "
                         f"{late[0]} comes after a Grip (put the grips last)")
    members = np.concatenate([controls[c].op.members for c in rows])
    if members.size and (members.min() < 0 or members.max() >= count):
        raise ValueError(f"a Grip's members lie outside the valid range [0, {count - 1}]")
    if len(np.unique(members)) != len(members):
        raise ValueError("device='gpu' runs grips whose members are distinct; a particle is "
                         "in two grips")


@device_side(Grip)
class GripRow(ControlSide):
    """A Grip's row (GRIP): no wall control; the grips' own launches (DeviceGrips) hold their
    members after every wall control. Inside walls only."""

    role = GRIP
    in_cell = False

    def check(self, scene):
        """The grips of the scene together (check_grips), once, at the first grip."""
        if scene.controls_of(GRIP)[0] is self:
            check_grips(scene, len(scene.sim.peek("particles")))


@cuda.jit
def grip_partials(force, members, chunk_first, chunk_axis, partial):
    """partial[c] [N]: chunk c's members (members[chunk_first[c]:chunk_first[c + 1]]) summed in
    order, their force along their grip's axis ``chunk_axis[c]``."""
    c = cuda.grid(1)
    if c >= partial.shape[0]:
        return
    axis = chunk_axis[c]
    total = 0.0
    for k in range(chunk_first[c], chunk_first[c + 1]):
        total += force[members[k], axis]
    partial[c] = total


@cuda.jit
def grip_hold(force, torque, velocity, angular_velocity, members, member_grip, grip_chunks,
              grip_wall, partial, wall_force, wall_velocity, pull):
    """Thread g < grips: grip g's pull [N], the unit inward times its chunks' sums added in
    order less its wall's force (Grip.apply); thread k < members: member k held on its grip's
    wall: force, torque and angular velocity zero, velocity the wall's along its axis."""
    t = cuda.grid(1)
    if t < pull.shape[0]:
        wall = grip_wall[t]
        inward = 1.0 if wall % 2 == 0 else -1.0
        total = 0.0
        for c in range(grip_chunks[t], grip_chunks[t + 1]):
            total += partial[c]
        pull[t] = inward * total - wall_force[wall]
    if t < members.shape[0]:
        p = members[t]
        wall = grip_wall[member_grip[t]]
        inward = 1.0 if wall % 2 == 0 else -1.0
        for a in range(3):
            force[p, a] = 0.0
            torque[p, a] = 0.0
            angular_velocity[p, a] = 0.0
            velocity[p, a] = 0.0
        velocity[p, wall // 2] = -inward * wall_velocity[wall]


class DeviceGrips:
    """The grips ``grips`` (Grip, the scene's order) on the device: their members in chunks
    (copied once) and their pulls ``pull`` (G,) [N], which ``to_host`` writes into the grips."""

    def __init__(self, grips):
        self.grips = tuple(grips)
        counts = [len(grip.members) for grip in self.grips]
        chunk_first, chunk_axis, grip_chunks = [], [], [0]
        start = 0
        for grip, count in zip(self.grips, counts):
            firsts = list(range(start, start + count, GRIP_CHUNK))
            chunk_first += firsts
            chunk_axis += [grip.axis] * len(firsts)
            grip_chunks.append(len(chunk_first))
            start += count
        to = cuda.to_device
        self.members = to(np.concatenate([grip.members for grip in self.grips]))
        self.member_grip = to(np.repeat(np.arange(len(self.grips), dtype=np.int64), counts))
        self.chunk_first = to(np.array(chunk_first + [start], np.int64))
        self.chunk_axis = to(np.array(chunk_axis, np.int64))
        self.grip_chunks = to(np.array(grip_chunks, np.int64))
        self.grip_wall = to(np.array([grip.wall for grip in self.grips], np.int64))
        self.partial = to(np.zeros(len(chunk_axis)))
        self.pull = to(np.array([float(grip.pull) for grip in self.grips]))
        self.member_count = start

    @classmethod
    def of(cls, scene):
        """The DeviceGrips of the grips among ``scene``'s controls (sides,
        pendular.gpu.operations.Scene), None when there are none."""
        grips = [side.op for side in scene.controls_of(GRIP)]
        return cls(grips) if grips else None

    def launches(self, state):
        """(kernel, items, arguments) of the grips' step on the device state ``state``."""
        s = state
        return [
            (grip_partials, self.partial.shape[0],
             (s.force, self.members, self.chunk_first, self.chunk_axis, self.partial)),
            (grip_hold, max(self.member_count, len(self.grips)),
             (s.force, s.torque, s.velocity, s.angular_velocity, self.members,
              self.member_grip, self.grip_chunks, self.grip_wall, self.partial, s.wall_force,
              s.wall_velocity, self.pull)),
        ]

    def to_host(self):
        """The device's pulls into the grips' ``pull`` [N]."""
        for grip, pull in zip(self.grips, self.pull.copy_to_host()):
            grip.pull = float(pull)
