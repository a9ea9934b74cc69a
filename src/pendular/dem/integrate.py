"""Leapfrog integration with Cundall's non-viscous local damping (the time step: pendular.dem.timestep)."""

import numba

from pendular.dem import HOT_KERNEL_FASTMATH
from pendular.utils.validate import check_range


@numba.njit(cache=True, inline="always")
def _damped(force, velocity, acceleration_dt, damping):
    """Cundall local damping of one degree of freedom: F (1 - lambda sign(F v)).

    As YADE's NewtonIntegrator, v is the on-step velocity estimate v(t - dt/2) + a dt / 2.
    Written without branches: the signs of F v are random, and mispredicted branches would
    dominate the cost of the whole integration (the comparisons as floats, which the GPU's
    twin and Numba's CUDA simulator take too).
    """
    product = force * (velocity + 0.5 * acceleration_dt)
    sign = (product > 0.0) * 1.0 - (product < 0.0) * 1.0
    return force * (1.0 - damping * sign)


@numba.njit(cache=True, parallel=True, fastmath=HOT_KERNEL_FASTMATH)
def leapfrog(position, velocity, angular_velocity, force, torque, mass, inertia, damping,
             affine_rate, dt):
    """Advance velocities to t + dt/2 and positions to t + dt (spheres: no orientation needed).

    affine_rate (3,) [1/s]: a periodic cell's homogeneous stretching (pendular.dem.cell), the velocity
    affine_rate * x carrying every particle on top of its own; zeros inside walls. A sheared
    cell's (4,) adds its shear rate gamma_dot: the velocity gamma_dot * z along x, z at the
    step's start (as the cell's offset follows, PeriodicCell.follow)."""
    stretched = affine_rate[0] != 0.0 or affine_rate[1] != 0.0 or affine_rate[2] != 0.0
    for p in numba.prange(position.shape[0]):
        _advance(p, position, velocity, angular_velocity, force, torque, mass, inertia, damping,
                 affine_rate, stretched, dt)


@numba.njit(cache=True, fastmath=HOT_KERNEL_FASTMATH, _nrt=False)
def serial_leapfrog(position, velocity, angular_velocity, force, torque, mass, inertia, damping,
                    affine_rate, dt):
    """leapfrog on one thread, without the parallel launch (2-3 us a call; same results)."""
    stretched = affine_rate[0] != 0.0 or affine_rate[1] != 0.0 or affine_rate[2] != 0.0
    for p in range(position.shape[0]):
        _advance(p, position, velocity, angular_velocity, force, torque, mass, inertia, damping,
                 affine_rate, stretched, dt)


@numba.njit(cache=True, inline="always")
def _advance(p, position, velocity, angular_velocity, force, torque, mass, inertia, damping,
             affine_rate, stretched, dt):
    """Particle p's leapfrog step (leapfrog)."""
    dt_mass = dt / mass[p]          # [s/kg], once a particle, not a product per component
    dt_inertia = dt / inertia[p]
    height = position[p, 2]
    for c in range(3):
        f = _damped(force[p, c], velocity[p, c], force[p, c] * dt_mass, damping)
        velocity[p, c] += f * dt_mass
        if stretched:
            position[p, c] += (velocity[p, c] + affine_rate[c] * position[p, c]) * dt
        else:
            position[p, c] += velocity[p, c] * dt
        t = _damped(torque[p, c], angular_velocity[p, c], torque[p, c] * dt_inertia, damping)
        angular_velocity[p, c] += t * dt_inertia
    if len(affine_rate) > 3:        # simple shear (a test on the array's shape: hoisted)
        position[p, 0] += affine_rate[3] * height * dt


class Integrator:
    """Leapfrog with Cundall local damping ``damping`` (YADE NewtonIntegrator, default 0.2)."""

    stateless = True

    def __init__(self, damping=0.2):
        self.damping = check_range("damping", damping, 0.0, 1.0, high_inclusive=False)

    def apply(self, sim):
        p = sim.particles
        step = leapfrog if numba.get_num_threads() > 1 else serial_leapfrog
        step(p.position, p.velocity, p.angular_velocity, p.force, p.torque, p.mass, p.inertia,
             self.damping, sim.walls.affine_rate, sim.dt)
        sim.walls.follow(sim.dt)
