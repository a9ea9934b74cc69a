"""Love–Weber stress of contact forces (thesis Eq. 3.41).

Sign convention (docs/units.md; docs/physics.md 'Effective stress'): compression positive. For a
pair, l = x_j - x_i and f = force exerted by i on j, so a repulsive contact contributes l_i f_j
> 0. For a wall contact, l runs from the particle centre to the contact point on the wall plane
and f is the force the particle exerts on the wall; then, in static equilibrium, the contact
stress equals the wall stresses.
"""

import numba
import numpy as np

from pendular.dem.neighbors import branch_vector


@numba.njit(cache=True)
def pair_stress_sum(position, pair_i, pair_j, image, period, pair_force, mask):
    """Sum over the selected pairs of l (x) f [N m] (3x3), l = x_j - x_i (+ image * period in
    a periodic cell, pendular.dem.neighbors.branch_vector), f on j from i."""
    total = np.zeros((3, 3))
    for k in range(len(pair_i)):
        if not mask[k]:
            continue
        branch = branch_vector(position, pair_i[k], pair_j[k], image, k, period)
        for a in range(3):
            for b in range(3):
                total[a, b] += branch[a] * pair_force[k, b]
    return total


def contact_stress(particles, contacts, walls):
    """Love–Weber stress of the mechanical contact forces, Eq. 3.41 [Pa] (3x3, compression +).

    Sums sphere–sphere contacts (forces of the last step, current branch vectors) and the
    sphere–wall contacts' l f accumulated by the wall force kernel, over the box volume
    (``walls``: pendular.dem.state.Walls, or a periodic cell, which has no wall contacts).
    """
    touching = contacts.overlap > 0.0
    total = pair_stress_sum(particles.position, contacts.pair_i, contacts.pair_j,
                            contacts.image, walls.period, contacts.force, touching)
    if not walls.periodic:
        total[np.diag_indices(3)] += walls.moment[0::2] + walls.moment[1::2]
    return total / walls.volume()
