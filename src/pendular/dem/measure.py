"""Scalar measures of the packing state: porosity, coordination, unbalanced force, largest
overlap."""

import numba
import numpy as np

from pendular.dem.contact_law import normal_stiffness, wall_contact_stiffness


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


def largest_overlap(sim):
    """Largest overlap over the smaller radius [-] of the pairs of ``sim`` (as at its last
    force evaluation) and, inside walls, of the spheres with the walls; at most 0 when nothing
    touches, NaN when a position is not finite."""
    particles, contacts = sim.particles, sim.contacts
    radius = particles.radius
    overlaps = [np.zeros(1)]
    if contacts is not None:
        smaller = np.minimum(radius[contacts.pair_i], radius[contacts.pair_j])
        overlaps.append(contacts.overlap / smaller)
    if not sim.walls.periodic:
        inside = np.minimum(particles.position - sim.walls.lo, sim.walls.hi - particles.position)
        overlaps.append((1.0 - inside / radius[:, None]).ravel())
    return float(np.max(np.concatenate(overlaps)))


def kinetic_energy(particles):
    """Translational plus rotational kinetic energy [J]."""
    translation = 0.5 * np.sum(particles.mass * np.sum(particles.velocity ** 2, axis=1))
    rotation = 0.5 * np.sum(particles.inertia * np.sum(particles.angular_velocity ** 2, axis=1))
    return float(translation + rotation)


def elastic_energy(particles, contacts, walls, young, shear_ratio):
    """Energy stored in the linear springs [J]: pairs (normal and shear) and walls.

    Uses the overlaps and shear forces of the last force evaluation; kn = 2 E R1 R2 / (R1 + R2),
    ks = shear_ratio kn, wall kn = E R (docs/physics.md 'The contact law').
    """
    touching = contacts.overlap > 0.0
    ri = particles.radius[contacts.pair_i[touching]]
    rj = particles.radius[contacts.pair_j[touching]]
    kn = normal_stiffness(young, ri, rj)
    energy = 0.5 * np.sum(kn * contacts.overlap[touching] ** 2)
    if shear_ratio > 0.0:
        energy += 0.5 * np.sum(np.sum(contacts.shear_force[touching] ** 2, axis=1)
                               / (shear_ratio * kn))
    radius = particles.radius[:, None]
    wall_overlap = np.concatenate([radius - (particles.position - walls.lo),
                                   radius - (walls.hi - particles.position)], axis=1)
    wall_overlap = np.maximum(wall_overlap, 0.0)
    energy += 0.5 * np.sum(wall_contact_stiffness(young, radius) * wall_overlap ** 2)
    return float(energy)
