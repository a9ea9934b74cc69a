"""The sphere–wall bridges' share of the homogenised capillary stresses (docs/capillary.md
'Sphere–wall bridges').

Eqs. 3.44-3.46 sum, over the wetted caps of the particles in V, the water pressure on each cap
(A) and the surface tension along its contact line (B'), and add the water's own volume. A
sphere–wall bridge wets one particle cap (the sphere's; the wall is the boundary of V, not a
grain of it) and holds liquid in V, so it adds

    chi  += (V_b I + Rot A(R, delta1)) / V,      B += Rot B'(R, delta1) / V,
    psi  += chi_b s + B_b,                       I += (gamma / V) ∫_interface (I - n n) dS,

with the bridge axis along the wall's normal; its force on the wall is a boundary force, which
the wall stress sigma_wall (the walls' forces) measures, as the walls' contact forces. In the
Love–Weber stress of the capillary forces (on_the_fly.capillary_force_stress) a wall bridge adds
its l f, l from the sphere's centre to the wall, as a wall contact adds its own to the contact
stress: in static equilibrium sigma_wall = sigma_contact + sigma_capillary still holds.
"""

import dataclasses

from pendular.homogenize.bridge_tensors import (capillary_stress, capillary_stress_anisotropy,
    effective_stress_parameter, interface_stress, surface_tension_stress)


def with_wall_bridges(stress, sim, walls, suction, contact_angle, surface_tension, volume):
    """``stress`` (a BridgeStress of the sphere–sphere bridges over ``volume`` [m^3]) with the
    sphere–wall bridges ``walls`` (pendular.capillary.wall_bridges.WallBridges) of ``sim``
    added (module docstring): water volume, chi, B, psi at the ``suction`` [Pa] and, when
    ``stress`` has it, the interface term; a_psi of the new psi. The bridge count and fabric
    stay the sphere–sphere bridges'."""
    _, _, axis, radius, filling, interfaces = walls.bridges_of(sim)
    if len(radius) == 0:
        return stress
    water = walls.water_volume()
    caps = (axis, radius, radius, filling, 0.0)
    chi = effective_stress_parameter(*caps, water, volume)
    tension = surface_tension_stress(*caps, contact_angle, surface_tension, volume)
    psi = stress.psi + capillary_stress(chi, tension, suction)
    interface = stress.interface
    if interface is not None:
        interface = interface + interface_stress(axis, interfaces[:, 0], interfaces[:, 1],
                                                 surface_tension, volume)
    return dataclasses.replace(stress, water_volume=stress.water_volume + water,
                               chi=stress.chi + chi, B=stress.B + tension, psi=psi,
                               a_psi=capillary_stress_anisotropy(psi), interface=interface)

