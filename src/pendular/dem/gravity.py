"""Gravity: the weight m g of every particle along -z, a body force (docs/physics.md 'Gravity').

It is added to the particles' forces before the integrator, so Cundall's local damping acts on
it as on any force: a static packing carries its weight undamped (the damping acts on the
unbalanced force, zero at equilibrium), but a particle in free fall under damping λ accelerates
at (1 - λ) g, not g (pendular.dem.integrate). Walls only: a periodic cell has no floor to hold
the weight.
"""

import numba

from pendular.utils.validate import check_range

#: Largest gravity [m/s^2]: 100 g, a geotechnical centrifuge's range.
MAX_GRAVITY = 1000.0


@numba.njit(cache=True, inline="always")
def _add_particle_weight(p, force, mass, gravity):
    """Subtract particle p's weight m g [N] from the z component of its ``force`` (N, 3)
    (the body of add_weight and of the device's, pendular.gpu.gravity)."""
    force[p, 2] -= mass[p] * gravity


@numba.njit(cache=True)
def add_weight(force, mass, gravity):
    """Subtract m g [N] from the z component of each particle's ``force`` (N, 3); ``mass``
    (N,) [kg], ``gravity`` [m/s^2]."""
    for p in range(len(mass)):
        _add_particle_weight(p, force, mass, gravity)


class Gravity:
    """The particles' weight along -z, ``acceleration`` g [m/s^2] in (0, MAX_GRAVITY]."""

    stateless = True

    def __init__(self, acceleration):
        self.acceleration = check_range("gravity", acceleration, 0.0, MAX_GRAVITY,
                                        low_inclusive=False, unit="m/s^2")

    def apply(self, sim):
        if sim.walls.periodic:
            raise ValueError("gravity acts in a box of walls only: a periodic cell has no "
                             "floor to carry the weight")
        add_weight(sim.particles.force, sim.particles.mass, self.acceleration)
