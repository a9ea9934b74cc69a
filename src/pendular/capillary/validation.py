"""Input checks for the capillary package: each names the parameter, its value and the valid range."""

import math

from pendular.dem.contact_law import normal_stiffness
from pendular.utils.validate import check_positive, check_range, finite_number  # noqa: F401

MAX_SOLVER_RADIUS_RATIO = 20.0
"""Largest R2/R1 the exact solver accepts (its accuracy is verified up to this value)."""
MAX_CONTACT_ANGLE = 90.0
"""Wetting angles theta [deg] of a pendular bridge: [0, MAX_CONTACT_ANGLE) (a meniscus that
wets the grains: its filling angle lies in (0, 90 - theta])."""


def check_radius_ratio(radius_ratio, largest=MAX_SOLVER_RADIUS_RATIO):
    """r = R2/R1 in [1, largest]."""
    radius_ratio = finite_number("radius_ratio", radius_ratio, f"[1, {largest}]")
    if not 1.0 <= radius_ratio <= largest:
        raise ValueError(
            f"radius_ratio = {radius_ratio} is outside the valid range [1, {largest}] (R2/R1 with R2 >= R1)"
        )
    return radius_ratio


def check_contact_angle(contact_angle):
    """theta in [0, MAX_CONTACT_ANGLE) degrees."""
    return check_range("contact_angle", contact_angle, 0.0, MAX_CONTACT_ANGLE,
                       high_inclusive=False, unit="deg")


def check_suction(suction_star):
    """u* = s R2/gamma >= 0."""
    suction_star = finite_number("suction_star", suction_star, "[0, inf)")
    if suction_star < 0.0:
        raise ValueError(
            f"suction_star = {suction_star} is outside the valid range [0, inf) (matric suction s R2/gamma)"
        )
    return suction_star


def check_filling_angle(filling_angle, contact_angle):
    """delta1 in (0, 90 - theta] degrees."""
    filling_angle = finite_number("filling_angle", filling_angle, f"(0, {90.0 - contact_angle}] deg")
    if not 0.0 < filling_angle <= 90.0 - contact_angle:
        raise ValueError(
            f"filling_angle = {filling_angle} deg is outside the valid range (0, {90.0 - contact_angle}] deg "
            f"(0 < delta1 <= 90 - contact_angle)"
        )
    return filling_angle


def check_distance(distance_star):
    """A finite gap D/R2 (negative = overlap)."""
    return finite_number("distance_star", distance_star, "(-inf, inf), negative for overlaps")


#: Largest filling angle [deg] of a bridge at contact: the pendular limit of the loosest regular
#: packing (simple cubic, neighbours 90 deg apart: 45 deg; 30 deg for FCP, thesis Ch. 4). Beyond
#: it the menisci of neighbouring contacts merge in any packing: no longer the pendular regime.
PENDULAR_FILLING_ANGLE = 45.0

#: Largest overlap / radius that the force of one bridge at contact may cause (linear springs).
MAX_BRIDGE_OVERLAP = 0.05


def _widest_filling_angle(table, suction_star):
    """Largest filling angle [deg] of the table's bridges at contact, u* = s R/gamma with R the
    smallest radius: a pair of ratio r has R2 >= r R, so its u* = s R2/gamma >= r u* (every
    radius ratio of the table, each at its smallest u*; the filling angles fall as u* grows)."""
    return max(max(table.lookup(ratio, min(ratio * suction_star, table.suction_max), 0.0)[3:])
               for ratio in table.radius_ratios)


class NotPendular(ValueError):
    """A suction [Pa] below ``lowest`` [Pa], at which bridges at contact between spheres of
    ``radius`` [m] would have a filling angle ``angle`` [deg] above the pendular limit."""

    def __init__(self, message, suction, lowest, radius, angle):
        super().__init__(message)
        self.suction, self.lowest, self.radius, self.angle = suction, lowest, radius, angle


def check_pendular_suction(table, suction, radius, surface_tension):
    """NotPendular (a ValueError) naming ``suction`` [Pa] when a bridge at contact between
    spheres of radius >= ``radius`` [m] (surface_tension [N/m]) would have a filling angle
    above PENDULAR_FILLING_ANGLE; ``table``: the BridgeTable of the contact angle."""
    scale = radius / surface_tension
    angle = _widest_filling_angle(table, suction * scale)
    if angle <= PENDULAR_FILLING_ANGLE:
        return
    if math.isnan(angle):
        raise ValueError(f"contact_angle = {table.contact_angle:g} deg: the bridge table holds no "
                         f"bridge at contact at suction = {suction:g} Pa (a meniscus this close "
                         "to flat); valid: a smaller contact angle, e.g. up to 89 deg")
    # the filling angle falls as u* grows: bisect (in ln u*) for the lowest admissible suction
    low, high = max(suction * scale, 1e-9), table.suction_max
    for _ in range(60):
        middle = (low * high) ** 0.5
        low, high = (middle, high) if _widest_filling_angle(table, middle) > PENDULAR_FILLING_ANGLE \
            else (low, middle)
    raise NotPendular(
        f"suction = {suction:g} Pa is outside the valid range [{high / scale:.4g}, inf) Pa of the "
        f"pendular regime for radius = {radius:g} m (contact angle {table.contact_angle:g} deg): a "
        f"bridge at contact would have a filling angle of {angle:.1f} deg, above the pendular "
        f"limit of {PENDULAR_FILLING_ANGLE:g} deg where the menisci of neighbouring contacts merge",
        suction, high / scale, radius, angle)


def check_bridge_stiffness(young, radius, surface_tension):
    """ValueError naming ``young`` [Pa] and ``radius`` [m] when the force of a bridge at contact
    (at most 2 pi gamma R, surface_tension gamma [N/m]) would press spheres of normal stiffness
    kn = E R (pendular.dem.contact_law.normal_stiffness) together by more than MAX_BRIDGE_OVERLAP of
    their radius: overlap / R = 2 pi gamma R / (kn R)."""
    overlap = 2.0 * math.pi * surface_tension / normal_stiffness(young, radius, radius)
    if overlap > MAX_BRIDGE_OVERLAP:
        bound = 2.0 * math.pi * surface_tension / MAX_BRIDGE_OVERLAP
        raise ValueError(
            f"young = {young:g} Pa with radius = {radius:g} m is outside the valid range "
            f"young * radius >= {bound:g} N/m for bridges of surface_tension = "
            f"{surface_tension:g} N/m: a bridge at contact (force up to 2 pi gamma R) would "
            f"overlap the spheres by {overlap:.0%} of their radius (limit "
            f"{MAX_BRIDGE_OVERLAP:.0%})")
