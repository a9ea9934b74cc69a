"""The closed liquid of the cluster model: the suction at which a fixed volume of liquid is held
by the bridges and the filled pore units of a packing (docs/liquid_clusters.md 'The closed
liquid').

In the quasi-static model (pendular.capillary.pore_filling) every liquid body is at one suction
s [Pa]. With the liquid closed (a water content) s is not imposed but found: the liquid held at
s by the packing as it stands,

    L(s) = sum_k V_k(s) (1 - a_k) + sum_{filled u} V_u,

V_k(s) the suction-controlled bridge of pair k at its gap (0 beyond its rupture distance), a_k
the share of its liquid inside filled units (absorbed by them: UnitEdges.filled_share), V_u a
filled unit's pore volume, equals the volume V. The units filled at s are those the history
leaves filled (``carried``) and those whose filling suction is at least s, less those the
Haines jumps at s empty (pore_filling.imbibe, then drain): the branch the state is on, wetting
where the suction falls from the carried state, drying where it rises. L falls as s rises (the
bridges shrink and break, fewer units fill, more drain), so s is a one-dimensional monotone
root, found by bisection in ln s down to adjacent floating-point numbers. L jumps where units
fill or drain (one or a cascade of Haines jumps at one throat's entry suction) and where a
bridge breaks at its rupture distance: when V falls in a jump of units, those units (the
front) hold the fraction of their pore volume that makes L = V, and their forces and absorbed
shares are taken in that fraction; what is left at a bridge's rupture (no unit at the front)
stays on the grains as film, without force, until the next solution. The liquid held, film
included, equals V to round-off.

With no unit filled at any s (units whose filling suction lies below the suctions reached) L is
the bridges' alone and s the formation suction of pendular.capillary.wetting: the pendular
closed form.
"""

import math
from dataclasses import dataclass

import numba
import numpy as np

from pendular.capillary.pore_filling import drain, imbibe
from pendular.capillary.table import lookup_suction
from pendular.utils.validate import check_positive


@numba.njit(cache=True)
def bridge_volumes(larger, ratio, distance_star, suction, surface_tension, arrays,
                   suction_max, out):
    """Fill ``out`` (K,) [m^3] with the volume of the suction-controlled bridge of each pair
    (larger radius R2 [m], ratio R2/R1, d* = gap / R2) at ``suction`` [Pa], 0 beyond its
    rupture distance; u* kept within the table's ``suction_max``."""
    for k in range(len(larger)):
        exists, _, volume_star, _, _ = lookup_suction(
            arrays[0], arrays[1], arrays[2], arrays[3], arrays[4], ratio[k],
            min(suction * larger[k] / surface_tension, suction_max), distance_star[k])
        out[k] = volume_star * larger[k] ** 3 if exists else 0.0


@dataclass(frozen=True)
class ClosedLiquid:
    """The closed liquid's state at its suction.

    suction [Pa]; filled (M,) bool, the units full of liquid; front (M,) bool, the units partly
    filled (the jump V fell in), each holding ``front_fraction`` of its pore volume; weight
    (M,) [-] the share of each unit's pore volume that is liquid (1 filled, front_fraction at
    the front, 0 empty); bridges [m^3] the bridges' liquid outside the units' liquid; clusters
    [m^3] the units' liquid; film [m^3] what is left on the grains (round-off, or a bridge
    broken at the suction found).
    """

    suction: float
    filled: np.ndarray
    front: np.ndarray
    front_fraction: float
    weight: np.ndarray
    bridges: float
    clusters: float
    film: float

    @property
    def total(self):
        """The liquid held [m^3]: bridges, units and film."""
        return self.bridges + self.clusters + self.film


class HeldLiquid:
    """L(s) of a packing as it stands (module docstring).

    pairs: (larger radius R2 [m], ratio R2/R1, d*) (K,) each, the pairs that may hold a bridge;
    pair_edge (K,): their edges among the units (UnitEdges.of_pairs, -1 for none); edges: the
    units' UnitEdges; pore_units, thresholds (pore_filling.FillingThresholds) and ``carried``
    (M,) bool, the units the history leaves filled; table: the BridgeTable of the bridges;
    surface_tension [N/m].
    """

    def __init__(self, pairs, pair_edge, edges, pore_units, thresholds, carried, table,
                 surface_tension):
        self.larger, self.ratio, self.distance_star = (np.ascontiguousarray(a, np.float64)
                                                       for a in pairs)
        self.pair_edge = np.asarray(pair_edge, np.int64)
        self.edges, self.pore_units, self.thresholds = edges, pore_units, thresholds
        self.carried = np.asarray(carried, bool)
        self.arrays, self.suction_max = table.arrays(), float(table.suction_max)
        self.surface_tension = check_positive("surface_tension", surface_tension, "N/m")
        self._volume = np.zeros(len(self.larger))

    def filled(self, suction):
        """(M,) bool: the units filled at ``suction`` [Pa] from the carried state."""
        filled = imbibe(self.thresholds, self.carried, suction)
        return drain(self.pore_units, self.thresholds, filled, suction)

    def parts(self, suction, weight):
        """(bridges, units) [m^3]: the bridges' liquid outside the units' and the units'
        liquid, at ``suction`` [Pa] with each unit's liquid share ``weight`` (M,) [-]."""
        bridge_volumes(self.larger, self.ratio, self.distance_star, suction,
                       self.surface_tension, self.arrays, self.suction_max, self._volume)
        absorbed = np.zeros(len(self._volume))
        edge = self.pair_edge >= 0
        absorbed[edge] = self.edges.share(weight)[self.pair_edge[edge]]
        return (float(np.sum(self._volume * (1.0 - absorbed))),
                float(np.dot(weight, self.pore_units.pore_volume)))

    def held(self, suction):
        """L(s) [m^3] at ``suction`` [Pa]."""
        return sum(self.parts(suction, self.filled(suction).astype(float)))

    def suction_range(self):
        """(low, high) [Pa]: the bracket of the search, u* from 1e-6 to the table's largest
        over the largest R2."""
        largest = float(self.larger.max()) if len(self.larger) else 1.0
        return (1e-6 * self.surface_tension / largest,
                self.suction_max * self.surface_tension / largest)


def solve_closed_liquid(volume, held):
    """ClosedLiquid holding ``volume`` [m^3] in ``held`` (HeldLiquid; module docstring).
    ValueError naming the volume outside what the packing holds over the table's suctions."""
    volume = check_positive("liquid volume", volume, "m^3")
    low, high = held.suction_range()
    most, least = held.held(low), held.held(high)
    if not least <= volume <= most:
        raise ValueError(f"liquid volume = {volume:g} m^3 is outside the valid range "
                         f"[{least:g}, {most:g}] m^3 that the bridges and pore units of this "
                         f"packing hold at suctions {low:g} to {high:g} Pa")
    while True:                       # L(low) >= volume >= L(high)
        middle = math.sqrt(low * high)
        if not low < middle < high:
            break
        if held.held(middle) >= volume:
            low = middle
        else:
            high = middle
    filled = held.filled(high)
    front = held.filled(low) & ~filled
    weight = filled.astype(float)
    bridges, units = held.parts(high, weight)
    fraction = 0.0
    if front.any():
        full_bridges, full_units = held.parts(high, weight + front)
        step = full_bridges + full_units - bridges - units
        if step > 0.0:
            fraction = min(max((volume - bridges - units) / step, 0.0), 1.0)
            weight = weight + fraction * front
            bridges, units = held.parts(high, weight)
    return ClosedLiquid(suction=high, filled=filled, front=front, front_fraction=fraction,
                        weight=weight, bridges=bridges, clusters=units,
                        film=volume - bridges - units)
