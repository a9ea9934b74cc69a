"""Scalar measures of the packing state: porosity, coordination, unbalanced force."""

import numba
import numpy as np


def porosity(particles, walls):
    """1 - (solid volume / volume inside the walls). Spheres are assumed inside the box."""
    return 1.0 - particles.solid_volume() / walls.volume()


def coordination(contacts, count):
    """Mean number of sphere–sphere contacts per particle, 2 Nc / N."""
    return 2.0 * float(np.count_nonzero(contacts.overlap > 0.0)) / count


@numba.njit(cache=True)
def _unbalanced(force, pair_force, overlap):
    resultant = 0.0
    for p in range(force.shape[0]):
        resultant += np.sqrt(force[p, 0] ** 2 + force[p, 1] ** 2 + force[p, 2] ** 2)
    contact_sum = 0.0
    touching = 0
    for k in range(len(overlap)):
        if overlap[k] > 0.0:
            contact_sum += np.sqrt(pair_force[k, 0] ** 2 + pair_force[k, 1] ** 2
                                   + pair_force[k, 2] ** 2)
            touching += 1
    if touching == 0:
        return np.inf
    return (resultant / force.shape[0]) / (contact_sum / touching)


def unbalanced_force(particles, contacts):
    """Mean resultant force on particles / mean sphere–sphere contact force (YADE's measure).

    Reads the forces of the last step (call after the force operations); inf without contacts.
    """
    return float(_unbalanced(particles.force, contacts.force, contacts.overlap))
