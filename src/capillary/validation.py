"""Input checks for the capillary package: each names the parameter, its value and the valid range."""

from dem.validate import check_positive, finite_number  # noqa: F401  (shared checks)

MAX_RADIUS_RATIO = 20.0
"""Largest R2/R1 the exact solver accepts (its accuracy is verified up to this value)."""


def check_radius_ratio(radius_ratio, largest=MAX_RADIUS_RATIO):
    """r = R2/R1 in [1, largest]."""
    radius_ratio = finite_number("radius_ratio", radius_ratio, f"[1, {largest}]")
    if not 1.0 <= radius_ratio <= largest:
        raise ValueError(
            f"radius_ratio = {radius_ratio} is outside the valid range [1, {largest}] (R2/R1 with R2 >= R1)"
        )
    return radius_ratio


def check_contact_angle(contact_angle):
    """theta in [0, 90) degrees."""
    contact_angle = finite_number("contact_angle", contact_angle, "[0, 90) deg")
    if not 0.0 <= contact_angle < 90.0:
        raise ValueError(f"contact_angle = {contact_angle} deg is outside the valid range [0, 90) deg")
    return contact_angle


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
