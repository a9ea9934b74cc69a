"""Rolling and twisting resistance on the walls on the device
(pendular.dem.wall_rolling.WallRollingResistance).

One thread per particle runs the CPU's own body (pendular.dem.wall_rolling._sphere_wall_moments,
compiled by device_twin): its six walls in order, its springs, its moments added to its
torque, among the forces' own launches after the gather (in the scene's order: after the
walls' springs when listed after them, as the CPU). Each thread writes its own particle's
row only: the CPU's sums for any launch.

The springs ``wall_rolling_moment`` (N, 6, 3) and ``wall_twisting_moment`` (N, 6) [N m] live
on the device during a run: uploaded from the host's operation at the GpuSimulation's first
run, brought back with the state (its copy_back), so that a checkpoint and the CPU go on from
them.
"""

import numpy as np

from pendular.dem.wall_rolling import WallRollingResistance, _sphere_wall_moments
from pendular.gpu.cuda import cuda, device_twin
from pendular.gpu.operations import DeviceSide, device_side

sphere_wall_moments = device_twin(_sphere_wall_moments)


@cuda.jit
def wall_moments(position, angular_velocity, radius, mass, inertia, wall_position, hertz,
                 modulus, coefficients, dt, rolling_moment, twisting_moment, torque):
    """Particle p's rolling and twisting moments on the walls (pendular.dem.wall_rolling
    .wall_moments' body and arguments; ``coefficients`` the operation's (rolling, twisting,
    damping_ratio)): its springs updated, its moments added to its torque."""
    p = cuda.grid(1)
    if p >= radius.shape[0]:
        return
    rolling, twisting, damping_ratio = coefficients
    sphere_wall_moments(p, position, angular_velocity, radius, mass, inertia, wall_position,
                        hertz, modulus, rolling, twisting, damping_ratio, dt, rolling_moment,
                        twisting_moment, torque)


@device_side(WallRollingResistance)
class WallResistance(DeviceSide):
    """A WallRollingResistance's side: its launch after the gather, inside walls only; its
    springs up at the first step's launches and back with the state (``pairs_to_host``)."""

    family = "force"
    role = "wall rolling"
    in_cell = False

    def __init__(self, op):
        super().__init__(op)
        self.springs = None

    def _upload(self, count):
        """The springs (zeros when the host has none for these ``count`` particles) into
        device memory."""
        rolling = self.op.wall_rolling_moment
        twisting = self.op.wall_twisting_moment
        if rolling.shape != (count, 6, 3) or twisting.shape != (count, 6):
            rolling, twisting = np.zeros((count, 6, 3)), np.zeros((count, 6))
        self.springs = tuple(cuda.to_device(np.ascontiguousarray(a, dtype=np.float64))
                             for a in (rolling, twisting))

    def launches(self, state, dt):
        """(kernel, items, arguments) of a step's moments on the walls (``state`` a
        DeviceState; the operation's coefficients now), to run after the gather."""
        s = state
        if self.springs is None:
            self._upload(s.count)
        op = self.op
        return [(wall_moments, s.count,
                 (s.position, s.angular_velocity, s.radius, s.mass, s.inertia,
                  s.wall_position, op.hertz, op.modulus,
                  (op.rolling, op.twisting, op.damping_ratio), dt, *self.springs, s.torque))]

    def pairs_to_host(self, sim, state, index):
        """The device's springs into the host's operation (per particle)."""
        if self.springs is not None:
            rolling, twisting = self.springs
            self.op.wall_rolling_moment = rolling.copy_to_host()
            self.op.wall_twisting_moment = twisting.copy_to_host()
