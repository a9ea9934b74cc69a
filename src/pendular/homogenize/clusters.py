"""Effective-stress parameter of a wet sample whose liquid is in bridges and clusters
(docs/liquid_clusters.md 'Stress').

The bridges keep Eq. 3.44 each, weighted by the share of their liquid outside the filled pore
units (``LiquidClusters.pair_share``): chi_b = (1/V) [sum w V_b I + sum w (Rot A_i + Rot A_j)],
w = 1 - share. A cluster's pressure and menisci are lumped by the meniscus closure
(pendular.capillary.cluster_forces), so that its stress is not split into a pressure part
(chi) and a tension part (B): its share of the complete capillary stress, psi_c
(``LiquidClusters.stress``), counts as chi_c s. Then chi = chi_b + psi_c / s and
psi = chi_b s + B_b + psi_c (B_b of the bridges, weighted alike).
"""

import numpy as np

from pendular.capillary.bridge_state import BridgeState
from pendular.dem.neighbors import branch_vectors
from pendular.homogenize.bridge_tensors import wetted_caps_sum


def chi_with_clusters(sim, clusters, psi_clusters=None):
    """(3, 3) chi of the bridges' shares outside the filled units and of the clusters of
    ``clusters`` (pendular.capillary.liquid_clusters.LiquidClusters) of ``sim``, over the box
    or the periodic cell (module docstring); ``psi_clusters``: ``clusters.stress(sim)`` if
    already measured."""
    sim.fetch("contacts")           # all of a device run's state (Simulation.fetch)
    contacts, particles = sim.contacts, sim.particles
    state = BridgeState.of(contacts)
    index = np.flatnonzero(state.mask())
    volume = sim.walls.volume()
    weight = 1.0 - clusters.pair_share(contacts)[index]
    branch = branch_vectors(particles.position, contacts, sim.walls.period, index)
    normal = branch / np.linalg.norm(branch, axis=1, keepdims=True)
    caps = wetted_caps_sum(normal, particles.radius[contacts.pair_i[index]],
                           particles.radius[contacts.pair_j[index]], state.filling_i[index],
                           state.filling_j[index], weight=weight)
    bridges = (float(np.sum(weight * state.volume[index])) * np.eye(3) + caps) / volume
    if psi_clusters is None:
        psi_clusters = clusters.stress(sim)
    return bridges + psi_clusters / clusters.suction


def cluster_force_stress(sim, clusters):
    """(3, 3) [Pa] Love–Weber stress of the forces ``clusters`` add to the grains of ``sim``
    (LiquidClusters.grain_forces: theirs, less the bridges' shares they absorb), (1/V) sum
    x (x) F (LiquidClusters.virial: each unit's forces at the positions, or the periodic
    images, where they were last computed; the shares over their pairs' branch vectors), with
    the sign of the bridges' sigma_capillary (tension negative): in static equilibrium
    sigma_wall = sigma_contact + sigma_capillary + this; in a periodic cell, this is the
    clusters' part of the cell's stress."""
    return clusters.virial(sim) / sim.walls.volume()
