"""Leapfrog with Cundall's local damping on the device: the CPU's own particle step
(pendular.dem.integrate._advance, compiled for the device by device_twin), one thread per
particle, which also asks for a neighbour-list rebuild when the particle has moved more than
half the skin since the last one (pendular.dem.neighbors.moved_beyond) and flags a position
that is not finite (a diverged run, which the CPU catches at its next rebuild)."""

import math
from collections import namedtuple

from pendular.dem.integrate import Integrator, _advance
from pendular.gpu.cuda import cuda, device_twin
from pendular.gpu.operations import DeviceSide, device_side

advance = device_twin(_advance)

#: What the leapfrog moves: positions, velocities, angular velocities (N, 3) from forces and
#: torques (N, 3), masses and moments of inertia (N,) (pendular.gpu.state).
Motion = namedtuple("Motion", "position velocity angular_velocity force torque mass inertia")


@cuda.jit
def leapfrog(motion, damping, no_stretching, dt, reference_position, limit, flags):
    """Advance particle p's velocities to t + dt/2 and position to t + dt (the CPU's _advance
    inside walls: ``no_stretching`` zeros (3,)); set flags[0] when it is farther than
    ``limit`` [m] from its position at the last rebuild, flags[2] when its position is not
    finite (every thread that sets one writes the same 1). ``motion``: a Motion."""
    position, velocity, angular_velocity, force, torque, mass, inertia = motion
    p = cuda.grid(1)
    if p >= position.shape[0]:
        return
    advance(p, position, velocity, angular_velocity, force, torque, mass, inertia, damping,
            no_stretching, False, dt)
    d0 = position[p, 0] - reference_position[p, 0]
    d1 = position[p, 1] - reference_position[p, 1]
    d2 = position[p, 2] - reference_position[p, 2]
    if d0 * d0 + d1 * d1 + d2 * d2 > limit * limit:
        flags[0] = 1
    if not (math.isfinite(position[p, 0]) and math.isfinite(position[p, 1])
            and math.isfinite(position[p, 2])):
        flags[2] = 1


@cuda.jit
def cell_leapfrog(motion, damping, affine_rate, dt, reference_position, cell_position,
                  reference_cell, period, shear, limit, shortest_unlisted, flags):
    """leapfrog in a periodic cell (the CPU's _advance with stretching: the velocity
    ``affine_rate`` (3,) [1/s] * x carrying the particle on top of its own; a sheared cell's
    (4,) adds gamma_dot * z along x); the rebuild test is pendular.dem.neighbors.moved_beyond
    (an njit loop over every particle: restated per thread): the displacement from
    s x_ref + g z_ref along x, s = L / L_ref (cell faces ``cell_position`` now,
    ``reference_cell`` at the last rebuild) and, in a sheared cell (``period`` (4,), its
    offset delta now last; ``shear`` pendular.gpu.cell.SHEAR_FIELDS, delta at the last
    rebuild), g = (delta - s_x delta_ref) / Lz_ref (else 0), against ``limit`` [m] less
    (max|s - 1| + |g|) / 2 times ``shortest_unlisted`` [m]. ``motion``: a Motion."""
    position, velocity, angular_velocity, force, torque, mass, inertia = motion
    p = cuda.grid(1)
    if p >= position.shape[0]:
        return
    stretched = affine_rate[0] != 0.0 or affine_rate[1] != 0.0 or affine_rate[2] != 0.0
    advance(p, position, velocity, angular_velocity, force, torque, mass, inertia, damping,
            affine_rate, stretched, dt)
    s0 = cell_position[1] / reference_cell[1]
    s1 = cell_position[3] / reference_cell[3]
    s2 = cell_position[5] / reference_cell[5]
    shear_since = 0.0       # g (docstring)
    if period.shape[0] > 3:
        shear_since = (period[3] - s0 * shear[3]) / reference_cell[5]
    stretch = max(abs(s0 - 1.0), abs(s1 - 1.0), abs(s2 - 1.0)) + abs(shear_since)
    reach = limit - 0.5 * stretch * shortest_unlisted
    d0 = position[p, 0] - s0 * reference_position[p, 0]
    if shear_since != 0.0:
        d0 -= shear_since * reference_position[p, 2]
    d1 = position[p, 1] - s1 * reference_position[p, 1]
    d2 = position[p, 2] - s2 * reference_position[p, 2]
    if reach <= 0.0 or d0 * d0 + d1 * d1 + d2 * d2 > reach * reach:
        flags[0] = 1
    if not (math.isfinite(position[p, 0]) and math.isfinite(position[p, 1])
            and math.isfinite(position[p, 2])):
        flags[2] = 1


@device_side(Integrator)
class Leapfrog(DeviceSide):
    """The Integrator's side: the leapfrog launches (the box's steps) read its damping."""

    family = "integrator"

    @property
    def damping(self):
        """The numerical damping [-] now."""
        return self.op.damping
