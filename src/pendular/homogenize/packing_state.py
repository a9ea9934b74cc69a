"""Wet state of a regular packing: SWCC, chi_ij, B_ij and psi_ij (thesis Tables 4.2-4.4).

One bridge per contact, all alike (the contacts of these packings are equivalent); the water
volume V_w = V n Sr of the unit cell is shared equally by its N_LB bridges (docs/physics.md
'Regular packings'). The bridge follows from one state input (pendular.homogenize.cell_bridge,
method "exact" or "toroidal"); chi, B and psi are the discrete sums of Eqs. 3.44-3.46 over the
bridges of the cell (pendular.homogenize.bridge_tensors), a_psi is Eq. 4.5. Water content is
gravimetric, w = Sr e / Gs (docs/physics.md 'Errata'). SI units (m, N/m, Pa), stresses
compression positive, angles in degrees; saturation and water content as fractions (not per
cent).

A state whose filling angle exceeds the packing's pendular limit (max_filling_angle: wetted
caps of neighbouring bridges on a particle would overlap, docs/physics.md 'The bridge
model') raises ValueError.
"""

from dataclasses import dataclass
import math

import numpy as np

from pendular.utils.validate import check_positive, finite_number
from pendular.homogenize import cell_bridge
from pendular.homogenize.bridge_tensors import (capillary_stress, capillary_stress_anisotropy,
    effective_stress_parameter, surface_tension_stress)
from pendular.homogenize.regular_packing import RegularPacking

STATE_INPUTS = ("saturation", "suction", "water_content", "filling_angle")


@dataclass(frozen=True)
class PackingState:
    """A regular packing in the pendular regime, one bridge per contact.

    suction: s = u_a - u_w [Pa]; suction_star = s R / gamma. saturation: Sr (fraction).
    water_content: w = Sr e / Gs (gravimetric, fraction). filling_angle: alpha [deg].
    bridge_volume [m^3] and bridge_force [N] (attractive, docs/physics.md 'The bridge model')
    of each bridge.
    chi: chi_ij (3, 3), dimensionless (Eq. 3.44). B: B_ij (3, 3) [Pa] (Eq. 3.45).
    psi: psi_ij = chi_ij s + B_ij (3, 3) [Pa] (Eq. 3.46). a_psi: Eq. 4.5.
    """

    packing: RegularPacking
    method: str
    radius: float
    contact_angle: float
    surface_tension: float
    specific_gravity: float
    suction: float
    suction_star: float
    saturation: float
    water_content: float
    filling_angle: float
    bridge_volume: float
    bridge_force: float
    chi: np.ndarray
    B: np.ndarray
    psi: np.ndarray
    a_psi: float


def _state_input(saturation, suction, water_content, filling_angle):
    """(name, value) of the one state input given."""
    given = {name: value for name, value in zip(STATE_INPUTS, (saturation, suction, water_content, filling_angle))
             if value is not None}
    if len(given) != 1:
        raise ValueError(
            f"give exactly one of {', '.join(STATE_INPUTS)}; got "
            f"{', '.join(f'{k} = {v}' for k, v in given.items()) if given else 'none'}")
    ((name, value),) = given.items()
    if name == "saturation":
        value = finite_number(name, value, "(0, 1]")
        if not 0.0 < value <= 1.0:
            raise ValueError(f"saturation = {value} is outside the valid range (0, 1] (a fraction, not per cent)")
    elif name == "filling_angle":
        value = finite_number(name, value, "(0, 90) deg")
        if not 0.0 < value < 90.0:
            raise ValueError(f"filling_angle = {value} deg is outside the valid range (0, 90) deg")
    else:
        value = check_positive(name, value)
    return name, value


def _limit_angle(packing, method, contact_angle):
    """Largest filling angle [deg]: the pendular limit or the end of the method's family."""
    return min(packing.max_filling_angle, cell_bridge.largest_filling_angle(method, contact_angle))


def _beyond_limit(packing, method, contact_angle, detail):
    limit = _limit_angle(packing, method, contact_angle)
    cause = ("the pendular limit of this packing (neighbouring menisci on a particle would overlap)"
             if limit == packing.max_filling_angle else
             f"the largest filling angle of the {method} bridge, 90 - contact_angle")
    return ValueError(f"{detail} is beyond {cause}: filling_angle <= {limit:.6g} deg "
                      f"for kind = {packing.kind!r}, l_prime = {packing.l_prime}, separation = "
                      f"{packing.separation}, contact_angle = {contact_angle} deg")


def packing_state(packing, *, radius, contact_angle, surface_tension, saturation=None, suction=None,
                  water_content=None, filling_angle=None, method="exact", specific_gravity=2.65):
    """State of `packing` (a RegularPacking) wetted by one bridge per contact.

    radius R [m] > 0; contact_angle theta in [0, 90) deg; surface_tension gamma [N/m] > 0;
    exactly one of saturation Sr in (0, 1], suction s [Pa] > 0, water_content w > 0
    (gravimetric fraction, w = Sr e / Gs) or filling_angle alpha in (0, 90) deg;
    method "exact" (Young-Laplace) or "toroidal" (Appendix A); specific_gravity Gs > 0.
    At a gap H > 0 a suction is held by two bridges: the larger (stable) one is taken
    (pendular.homogenize.cell_bridge). Raises ValueError beyond the pendular limit.
    """
    if not isinstance(packing, RegularPacking):
        raise ValueError(f"packing = {packing!r} is not a RegularPacking; build one with pendular.homogenize.regular_packing")
    radius = check_positive("radius", radius)
    surface_tension = check_positive("surface_tension", surface_tension)
    specific_gravity = check_positive("specific_gravity", specific_gravity)
    contact_angle = cell_bridge.check_contact_angle(contact_angle)
    method = cell_bridge.check_method(method)
    name, value = _state_input(saturation, suction, water_content, filling_angle)

    bridges = packing.bridges_per_cell
    pore_volume = packing.porosity * packing.cell_volume  # [R^3]
    separation = packing.separation
    if name == "filling_angle":
        if value > _limit_angle(packing, method, contact_angle):
            raise _beyond_limit(packing, method, contact_angle, f"filling_angle = {value} deg")
        bridge = cell_bridge.bridge_from_filling_angle(method, value, contact_angle, separation)
    elif name == "suction":
        suction_star = value * radius / surface_tension
        bridge = _solve_or_explain(packing, method, contact_angle, f"suction = {value} Pa",
                                   lambda: cell_bridge.bridge_from_suction(method, suction_star, contact_angle,
                                                                           separation),
                                   lambda limit: suction_star < limit.suction_star)
    else:
        sr = value if name == "saturation" else value * specific_gravity / packing.void_ratio
        if sr > 1.0:
            raise ValueError(f"water_content = {value} gives saturation {sr:.6g} > 1 in this packing "
                             f"(void ratio {packing.void_ratio:.6g}, specific_gravity {specific_gravity})")
        detail = f"{name} = {value}" + ("" if name == "saturation" else f" (saturation {sr:.6g})")
        volume_star = sr * pore_volume / bridges
        bridge = _solve_or_explain(packing, method, contact_angle, detail,
                                   lambda: cell_bridge.bridge_from_volume(method, volume_star, contact_angle,
                                                                          separation),
                                   lambda limit: volume_star > limit.volume)
    if bridge.filling_angle > _limit_angle(packing, method, contact_angle) * (1.0 + 1e-12):
        raise _beyond_limit(packing, method, contact_angle,
                            f"{name} = {value} (filling_angle {bridge.filling_angle:.6g} deg)")

    saturation = bridges * bridge.volume / pore_volume
    suction = bridge.suction_star * surface_tension / radius
    volume = packing.cell_volume * radius**3
    caps = (packing.bridge_normals, radius, radius, bridge.filling_angle, bridge.filling_angle)
    chi = effective_stress_parameter(*caps, bridges * bridge.volume * radius**3, volume)
    tension = surface_tension_stress(*caps, contact_angle, surface_tension, volume)
    psi = capillary_stress(chi, tension, suction)
    return PackingState(
        packing=packing,
        method=method,
        radius=radius,
        contact_angle=contact_angle,
        surface_tension=surface_tension,
        specific_gravity=specific_gravity,
        suction=suction,
        suction_star=bridge.suction_star,
        saturation=saturation,
        water_content=saturation * packing.void_ratio / specific_gravity,
        filling_angle=bridge.filling_angle,
        bridge_volume=bridge.volume * radius**3,
        bridge_force=2.0 * math.pi * surface_tension * radius * bridge.force,
        chi=chi,
        B=tension,
        psi=psi,
        a_psi=capillary_stress_anisotropy(psi),
    )


def _solve_or_explain(packing, method, contact_angle, detail, solve, beyond):
    """solve(); a failure where beyond(limit bridge) holds is reported as beyond the pendular limit."""
    try:
        return solve()
    except ValueError as error:
        try:
            limit = cell_bridge.bridge_from_filling_angle(
                method, _limit_angle(packing, method, contact_angle), contact_angle, packing.separation)
        except ValueError:
            raise error from None
        if not beyond(limit):
            raise
        raise _beyond_limit(packing, method, contact_angle,
                            f"{detail} (the limit state has s R/gamma = {limit.suction_star:.6g}, "
                            f"V/R^3 = {limit.volume:.6g} per bridge)") from error
