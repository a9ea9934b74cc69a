"""Wetting a sample at a water content: the formation suction of volume-controlled bridges.

Volume-controlled bridges (capillary.CapillaryBridges, control="volume") take the volume of the
suction-controlled bridge at contact at their formation suction; at a fixed gravimetric water
content w = V_w / (Gs V_s) the formation suction is the root of sum over touching pairs of
V(s) = V_w (``formation_suction``).
"""

import math

import numpy as np

from dem.validate import check_positive


def gravimetric_water_content(water_volume, solid_volume, specific_gravity):
    """w = (V_w rho_w) / (V_s Gs rho_w) = V_w / (Gs V_s) (fraction; volumes in m^3)."""
    return water_volume / (specific_gravity * solid_volume)


def formation_suction(table, radius_i, radius_j, water_volume, surface_tension,
                      roughness=0.0, tolerance=1e-6):
    """Suction [Pa] at which suction-controlled bridges at contact between the pairs of radii
    (radius_i, radius_j) [m] hold ``water_volume`` [m^3] in total (volume-controlled wetting at
    a fixed water content). Bisection on ln u*: V(u*) at contact falls monotonically with u*.
    roughness: the menisci's separation at contact / R2 (CapillaryBridges ``roughness``).

    table: a capillary.BridgeTable (``lookup(r, u*, d*)`` -> (exists, F*, V*, delta1, delta2),
    u* = s R2 / gamma, V = V* R2^3, R2 the larger radius of the pair).
    """
    water_volume = check_positive("water volume", water_volume, "m^3")
    surface_tension = check_positive("surface_tension", surface_tension, "N/m")
    larger = np.maximum(radius_i, radius_j)
    pairs = np.stack([larger, larger / np.minimum(radius_i, radius_j)], axis=1)
    if len(pairs) == 0:
        raise ValueError("no touching pair to hold the water: the sample has no contact")
    groups, multiplicity = np.unique(pairs, axis=0, return_counts=True)

    def held(suction):
        return sum(count * table.lookup(ratio, suction * big / surface_tension, roughness)[2]
                   * big ** 3
                   for (big, ratio), count in zip(groups, multiplicity))

    smallest_star = 1e-6
    low = smallest_star * surface_tension / groups[:, 0].max()
    high = table.suction_max * surface_tension / groups[:, 0].max()
    most, least = held(low), held(high)
    if not least <= water_volume <= most:
        raise ValueError(
            f"water volume = {water_volume:g} m^3 is outside the valid range [{least:g}, "
            f"{most:g}] m^3 that bridges at the {len(pairs)} contacts can hold (suction "
            f"{low:g} to {high:g} Pa)")
    while math.log(high / low) > tolerance:
        middle = math.sqrt(low * high)
        if held(middle) > water_volume:
            low = middle
        else:
            high = middle
    return math.sqrt(low * high)
