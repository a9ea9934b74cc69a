"""Wetting a static sample to a gravimetric water content with volume-controlled bridges.

The formation suction of the bridges is the one at which suction-controlled bridges at the
wetted pairs hold the water (pendular.capillary.formation_suction); while the wetted sample settles, new
contacts form bridges of that suction from the reservoir, so the water held drifts from the
target: the formation suction is corrected and the wetting started again from the dry sample
until the water held is within WATER_TOLERANCE of the target (at most WETTINGS tries). Used by
the direct-tension test (pendular.procedures.tension) and the constant-water-content triaxial
(pendular.procedures.triaxial).
"""

from __future__ import annotations

import copy

from pendular.capillary import formation_suction

#: Largest relative difference between the water held after wetting and the target [-].
WATER_TOLERANCE = 0.01
#: Most wettings (formation suctions tried) to reach the target water volume.
WETTINGS = 4


def wet_to_water_volume(dry, target, table, pairs, build, settle, *, surface_tension,
                        roughness=0.0, max_gap=0.0):
    """(wetted copy of ``dry``, its bridges, the tries): bridges holding ``target`` [m^3] of
    water once static.

    table: the capillary.BridgeTable of the sample's radius ratios; pairs: (radius_i, radius_j,
    gap or None) [m] of the pairs that take water; build(suction): the bridge operation
    (volume control) of a formation suction [Pa]; settle(sim): runs the wetted sample to
    equilibrium, returns the steps; roughness: H/R2 of the bridges; max_gap [m]: bridges also
    form across gaps up to it (CapillaryBridges.form_across_gaps). Each try: {formation_suction_pa,
    steps, water_volume [m^3]}.
    """
    radius_i, radius_j, gap = pairs
    aimed = target
    tries = []
    for _ in range(WETTINGS):
        suction = formation_suction(table, radius_i, radius_j, aimed, surface_tension,
                                    roughness, gap=gap)
        sim = copy.deepcopy(dry)
        bridges = build(suction)
        sim.forces.append(bridges)
        if max_gap > 0.0:
            sim.evaluate_forces()          # the neighbour list at the bridges' reach
            bridges.form_across_gaps(sim, max_gap)
        steps = settle(sim)
        held = bridges.water_volume(sim.contacts)
        tries.append({"formation_suction_pa": suction, "steps": steps, "water_volume": held})
        if abs(held / target - 1.0) <= WATER_TOLERANCE:
            break
        aimed *= target / held
    return sim, bridges, tries
