"""Wetting a sample at a water content: the formation suction of volume-controlled bridges.

Volume-controlled bridges (capillary.CapillaryBridges, control="volume") take the volume of the
suction-controlled bridge at their formation suction: at contact, and, when the wetting forms
bridges across gaps (CapillaryBridges.form_across_gaps), at each pair's own gap. The liquid is
shared as one suction would share it: every bridge is the one in equilibrium with the same
pressure deficit, the state a liquid film spread over the grains relaxes to before the menisci
separate. At a fixed gravimetric water content w = V_w / (Gs V_s) the formation suction is
the root of sum over the wetted pairs of V(s, gap) = V_w (``formation_suction``); a pair
whose gap exceeds the rupture distance at s holds nothing.
"""

import math

import numba
import numpy as np

from pendular.capillary.table import lookup_suction
from pendular.utils.validate import check_positive


def gravimetric_water_content(water_volume, solid_volume, specific_gravity):
    """w = (V_w rho_w) / (V_s Gs rho_w) = V_w / (Gs V_s) (fraction; volumes in m^3)."""
    return water_volume / (specific_gravity * solid_volume)


@numba.njit(cache=True)
def _held(larger, ratio, distance_star, multiplicity, cube, suction, surface_tension, arrays,
          suction_max):
    """Liquid [m^3] of the suction-controlled bridges at ``suction`` [Pa] of pair groups
    (larger radius R2 [m], ratio, d*, count, R2^3); pairs beyond rupture hold none. u* is
    kept within the table's ``suction_max`` (the bisection's upper end, up to round-off)."""
    total = 0.0
    for k in range(len(larger)):
        exists, _, volume_star, _, _ = lookup_suction(
            arrays[0], arrays[1], arrays[2], arrays[3], arrays[4], ratio[k],
            min(suction * larger[k] / surface_tension, suction_max), distance_star[k])
        if exists:
            total += multiplicity[k] * volume_star * cube[k]
    return total


def formation_suction(table, radius_i, radius_j, water_volume, surface_tension,
                      roughness=0.0, tolerance=1e-6, gap=None):
    """Suction [Pa] at which suction-controlled bridges between the pairs of radii
    (radius_i, radius_j) [m], at contact or across their ``gap`` [m] (None: all at contact),
    hold ``water_volume`` [m^3] in total (volume-controlled wetting at a fixed water content).
    Bisection on ln u*: V(u*) falls monotonically with u* at any gap, and a bridge across a gap
    exists only below a suction that falls with the gap.
    roughness: the menisci's separation at contact / R2 (CapillaryBridges ``roughness``):
    d* = roughness + gap / R2.

    table: a capillary.BridgeTable (u* = s R2 / gamma, V = V* R2^3, R2 the larger radius of
    the pair).
    """
    water_volume = check_positive("water volume", water_volume, "m^3")
    surface_tension = check_positive("surface_tension", surface_tension, "N/m")
    larger = np.maximum(radius_i, radius_j)
    gap = np.zeros_like(larger) if gap is None else np.maximum(np.asarray(gap, float), 0.0)
    pairs = np.stack([larger, larger / np.minimum(radius_i, radius_j),
                      roughness + gap / larger], axis=1)
    if len(pairs) == 0:
        raise ValueError("no touching pair to hold the water: the sample has no contact")
    groups, multiplicity = np.unique(pairs, axis=0, return_counts=True)
    columns = [np.ascontiguousarray(groups[:, n]) for n in range(3)]
    cube = np.array([float(big) ** 3 for big in columns[0]])
    arrays = table.arrays()

    def held(suction):
        return _held(*columns, multiplicity.astype(np.float64), cube, suction,
                     surface_tension, arrays, table.suction_max)

    smallest_star = 1e-6
    low = smallest_star * surface_tension / groups[:, 0].max()
    high = table.suction_max * surface_tension / groups[:, 0].max()
    most, least = held(low), held(high)
    if not least <= water_volume <= most:
        raise ValueError(
            f"water volume = {water_volume:g} m^3 is outside the valid range [{least:g}, "
            f"{most:g}] m^3 that bridges at the {len(pairs)} pairs can hold (suction "
            f"{low:g} to {high:g} Pa)")
    while math.log(high / low) > tolerance:
        middle = math.sqrt(low * high)
        if held(middle) > water_volume:
            low = middle
        else:
            high = middle
    return math.sqrt(low * high)
