"""Leapfrog with Cundall's local damping on the device (pendular.dem.integrate), one thread per
particle, which also asks for a neighbour-list rebuild when the particle has moved more than
half the skin since the last one (pendular.dem.neighbors.moved_beyond) and flags a position
that is not finite (a diverged run, which the CPU catches at its next rebuild)."""

import math

from pendular.gpu.cuda import cuda, device


@device
def damped(force, velocity, acceleration_dt, damping):
    """Cundall local damping F (1 - lambda sign(F v)), v the on-step velocity
    (pendular.dem.integrate._damped; the sign as a select, which the simulator's NumPy
    scalars take as the compiled code does)."""
    product = force * (velocity + 0.5 * acceleration_dt)
    sign = 1.0 if product > 0.0 else (-1.0 if product < 0.0 else 0.0)
    return force * (1.0 - damping * sign)


@cuda.jit
def leapfrog(position, velocity, angular_velocity, force, torque, mass, inertia, damping, dt,
             reference_position, limit, flags):
    """Advance particle p's velocities to t + dt/2 and position to t + dt (the CPU's _advance
    inside walls: no stretching); set flags[0] when it is farther than ``limit`` [m] from its
    position at the last rebuild, flags[2] when its position is not finite (every thread that
    sets one writes the same 1)."""
    p = cuda.grid(1)
    if p >= position.shape[0]:
        return
    dt_mass = dt / mass[p]
    dt_inertia = dt / inertia[p]
    for c in range(3):
        f = damped(force[p, c], velocity[p, c], force[p, c] * dt_mass, damping)
        velocity[p, c] += f * dt_mass
        position[p, c] += velocity[p, c] * dt
        t = damped(torque[p, c], angular_velocity[p, c], torque[p, c] * dt_inertia, damping)
        angular_velocity[p, c] += t * dt_inertia
    d0 = position[p, 0] - reference_position[p, 0]
    d1 = position[p, 1] - reference_position[p, 1]
    d2 = position[p, 2] - reference_position[p, 2]
    if d0 * d0 + d1 * d1 + d2 * d2 > limit * limit:
        flags[0] = 1
    if not (math.isfinite(position[p, 0]) and math.isfinite(position[p, 1])
            and math.isfinite(position[p, 2])):
        flags[2] = 1
