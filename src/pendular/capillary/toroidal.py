"""Toroidal approximation of a liquid bridge between two equal spheres (thesis Appendix A).

The meridian is a circle arc of radius R1 (Eq. A.1) and the neck radius is R2 (Eq. A.2),
both in units of the sphere radius R; the suction follows from Young–Laplace with these two
radii (Eq. 3.47, docs/physics.md 'Errata': s = gamma (1/R1 - 1/R2)) and the volume from Eq. A.7
with the erratum in docs/physics.md 'Errata' (its last term is the wetted-cap volume (N - H/2)**2
(3 - N + H/2)/3). The force is evaluated at the contact line (docs/physics.md 'The bridge model')
with that suction. Valid while alpha + theta < 90 deg and R2 > 0.
"""

from dataclasses import dataclass
import math

from pendular.capillary.validation import check_contact_angle, check_distance, finite_number


@dataclass(frozen=True)
class ToroidalBridge:
    """Toroidal bridge in the units of docs/units.md (R = sphere radius): suction_star = s R/gamma,
    volume = V/R**3, force = F/(2 pi gamma R), meridian_radius = R1/R, neck_radius = R2/R."""

    suction_star: float
    volume: float
    force: float
    meridian_radius: float
    neck_radius: float


def toroidal_bridge(filling_angle, contact_angle, separation):
    """Toroidal bridge for half filling angle alpha (deg), contact angle theta (deg) and gap H/R >= 0.

    Eqs. A.1-A.3 give R1, R2 and N = H/2 + 1 - cos(alpha); Eq. 3.47 the suction; Eq. A.7
    (V/(2 pi R**3)) the volume. Raises ValueError unless 0 < alpha, alpha + theta < 90 deg,
    0 <= theta < 90 deg, H >= 0 and R2 > 0.
    """
    contact_angle = check_contact_angle(contact_angle)
    separation = check_distance(separation)
    alpha_deg = finite_number("filling_angle", filling_angle, f"(0, {90.0 - contact_angle}) deg")
    if not 0.0 < alpha_deg < 90.0 - contact_angle:
        raise ValueError(
            f"filling_angle = {alpha_deg} deg is outside the toroidal approximation's range "
            f"(0, {90.0 - contact_angle}) deg (alpha + contact_angle < 90 deg)"
        )
    if separation < 0.0:
        raise ValueError(f"separation = {separation} is outside the valid range [0, inf) (H/R)")
    alpha = math.radians(alpha_deg)
    theta = math.radians(contact_angle)
    half_gap = 0.5 * separation
    n = half_gap + 1.0 - math.cos(alpha)  # Eq. A.3
    meridian = n / math.cos(alpha + theta)  # Eq. A.1
    neck = math.sin(alpha) + meridian * (math.sin(alpha + theta) - 1.0)  # Eq. A.2
    if neck <= 0.0:
        raise ValueError(
            f"the toroidal neck radius R2/R = {neck:.6g} is not positive for filling_angle = {alpha_deg} deg, "
            f"contact_angle = {contact_angle} deg, separation = {separation}: the approximation needs R2 > 0"
        )
    suction_star = 1.0 / meridian - 1.0 / neck  # Eq. 3.47
    outer = meridian + neck
    volume_reduced = (  # Eq. A.7, V / (2 pi R**3)
        (outer * outer + meridian * meridian) * n
        - n**3 / 3.0
        - outer * (n * math.sqrt(meridian * meridian - n * n) + meridian * meridian * math.asin(n / meridian))
        - (n - half_gap) ** 2 * (3.0 - n + half_gap) / 3.0
    )
    force = math.sin(alpha) * math.sin(alpha + theta) + 0.5 * suction_star * math.sin(alpha) ** 2
    return ToroidalBridge(
        suction_star=suction_star,
        volume=2.0 * math.pi * volume_reduced,
        force=force,
        meridian_radius=meridian,
        neck_radius=neck,
    )
