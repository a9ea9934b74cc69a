"""Trimers: three pendular bridges around a throat whose menisci have merged into one liquid
body around it (Scheel et al. 2008, Nature Materials 7, 189), the state between the bridges
and the filled pore units (docs/liquid_clusters.md 'Trimers').

On a grain, a bridge's contact line is the circle at its filling angle delta around the
direction to the other grain: the rim of a cap of half-angle delta. Two caps on one sphere meet
when the angle between their axes is at most the sum of their half-angles. So the menisci of a
throat of grains (a, b, c) whose three edges hold bridges have merged when, on each grain,

    angle(b - a, c - a) <= delta_ab(a) + delta_ac(a)

(delta_ab(a) the filling angle on a of the bridge a-b, BridgeState's filling_i or filling_j),
the test of the pendular limit (bridge_kernels.pendular_overlap_counts) on the three grains
of one throat together. A throat of a unit that holds liquid (filled, or a closed liquid's
front) is not a trimer: its liquid is the cluster's.

A trimer is counted, not modelled: its pressure–volume law (Melnikov et al. 2015's
energy-minimised fits) is not known here, so its liquid and forces stay those of its three
bridges until one of its units fills.
"""

from dataclasses import dataclass

import numpy as np

from pendular.capillary.pores import FACES, throat_sides


def contact_lines_meet(vertices, filling):
    """(F,) bool: the contact lines of the two bridges on each of the three grains of each
    triangle meet (module docstring). ``vertices`` (F, 3, 3) [m]: the grains' centres;
    ``filling`` (F, 3, 2) [deg]: on grain k, the filling angles of its bridges to grain
    (k + 1) % 3 and to grain (k + 2) % 3 (NaN: no bridge, which never meets)."""
    meet = np.ones(len(vertices), bool)
    for k in range(3):
        to_next = vertices[:, (k + 1) % 3] - vertices[:, k]
        to_previous = vertices[:, (k + 2) % 3] - vertices[:, k]
        cosine = np.sum(to_next * to_previous, axis=1) / (
            np.linalg.norm(to_next, axis=1) * np.linalg.norm(to_previous, axis=1))
        angle = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))
        with np.errstate(invalid="ignore"):
            meet &= angle <= filling[:, k, 0] + filling[:, k, 1]
    return meet


@dataclass(frozen=True)
class Trimers:
    """The trimers of a packing: ``throats`` (T,) bool, the throats of the pore units that
    are trimers; ``bridges`` (K,) bool, the pairs of the neighbour list whose bridge borders
    one or more of them."""

    throats: np.ndarray
    bridges: np.ndarray

    @property
    def count(self):
        """Number of trimers."""
        return int(np.count_nonzero(self.throats))

    def liquid(self, volume, absorbed_share):
        """[m^3] the liquid of the trimers: the volumes ``volume`` (K,) [m^3] of their
        bridges less the shares ``absorbed_share`` (K,) [-] that filled units hold, each
        bridge once however many trimers it borders."""
        return float(np.sum(volume[self.bridges] * (1.0 - absorbed_share[self.bridges])))


def find_trimers(pore_units, edges, held, bridges, pair_i, pair_j, pair_edge):
    """Trimers of ``pore_units`` (pendular.capillary.pores.PoreUnits; each throat once, on its
    first unit's side, where the face's vertices are the images that unit sees) whose units
    ``held`` (M,) bool hold no liquid, with the ``bridges`` (BridgeState) of the neighbour
    list's pairs ``pair_i`` < ``pair_j`` (K,) on the units' edges ``pair_edge`` (K,)
    (``edges``, pendular.capillary.pore_filling.UnitEdges; -1: not an edge)."""
    unit, face = throat_sides(pore_units)
    corners = FACES[face]                                       # (T, 3)
    grains = pore_units.grains[unit[:, None], corners]
    vertices = pore_units.vertices[unit[:, None], corners]
    present = bridges.mask() & (pair_edge >= 0)
    edge_pair = np.full(len(edges.pair), -1)
    edge_pair[pair_edge[present]] = np.flatnonzero(present)
    pairs = np.full((len(unit), 3, 2), -1)
    filling = np.full((len(unit), 3, 2), np.nan)
    for k in range(3):
        for side in range(2):
            mine, other = grains[:, k], grains[:, (k + 1 + side) % 3]
            edge = edges.of_pairs(np.minimum(mine, other), np.maximum(mine, other))
            pair = np.where(edge >= 0, edge_pair[np.maximum(edge, 0)], -1)
            row = np.maximum(pair, 0)
            angle = np.where(pair_i[row] == mine, bridges.filling_i[row], bridges.filling_j[row])
            pairs[:, k, side] = pair
            filling[:, k, side] = np.where(pair >= 0, angle, np.nan)
    first, second = pore_units.throat_units.T
    dry = ~held[first] & ((second < 0) | ~held[np.maximum(second, 0)])
    throats = dry & contact_lines_meet(vertices, filling)
    bordering = np.zeros(len(pair_i), bool)
    bordering[pairs[throats].ravel()] = True
    return Trimers(throats=throats, bridges=bordering)
