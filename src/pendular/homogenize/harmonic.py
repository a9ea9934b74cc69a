"""Continuous (harmonic) forms of chi_ij and B_ij (thesis Eqs. 3.50, 3.55-3.57).

The bridges of a volume V are described by a density of normals instead of a list:

    p(n) = (1 / 4 pi) [1 + a (3 cos^2 beta - 1)]                                    (Eq. 3.50)
    p'(n) = 2 N_LB p(n) / V, N_LB the number of bridges in V (Errata)              (Eq. 3.57)
    chi_ij = (V_w / V) delta_ij + ∫∫ M A M^T p'(n) sin beta dbeta dphi             (Eq. 3.55)
    B_ij   = ∫∫ M B' M^T p'(n) sin beta dbeta dphi                                  (Eq. 3.56)

with A, B' of one cap (Eqs. 3.48-3.49; all bridges alike) and M(beta, phi) of Eq. 3.26. As
printed, Eq. 3.26 sends the local z axis to azimuth phi + pi; p(n) does not depend on phi, so the
integrals are unchanged and M is used here as printed. "Errata": the errata of the thesis text
in docs/physics.md.

Relation to the discrete sums (pendular.homogenize.bridge_tensors): A and B' are diag(a, a, c), so a sum
of rotated caps depends on the normals only through their fabric F (sum = N (a I + (c - a) F)),
and p(n) has the fabric F_z = 1/3 + 4a/15, F_x = F_y = 1/3 - 2a/15. The continuous forms with
a = the packing's anisotropy therefore equal the discrete sums whenever the discrete fabric is
axisymmetric about z (all the packings of Chapter 4, isotropic or not) and all bridges are
alike; otherwise they differ by (2 N_LB / V)(c - a)(F_discrete - F_harmonic).
Integration: Gauss-Legendre in cos(beta) times the trapezoidal rule in phi, exact for these
polynomial integrands from order 4 on.
"""

import numpy as np

from pendular.utils.validate import finite_number
from pendular.homogenize.bridge_tensors import contact_line_integral, wetted_cap_integral

ANISOTROPY_RANGE = (-0.5, 1.0)
"""Values of a for which p(n) of Eq. 3.50 is nowhere negative."""

QUADRATURE_ORDER = 8
"""Gauss-Legendre nodes in cos(beta); 2 * order points in phi."""


def fabric_density(anisotropy, polar_angle):
    """p(n) of Eq. 3.50 at polar angle beta [deg] from z; integrates to 1 over the unit sphere."""
    cosine = np.cos(np.radians(polar_angle))
    return (1.0 + anisotropy * (3.0 * cosine**2 - 1.0)) / (4.0 * np.pi)


def thesis_rotation(polar_angle, azimuth):
    """M(beta, phi) of Eq. 3.26 as printed (angles in degrees); shape (..., 3, 3).

    M e_z points to polar angle beta and azimuth phi + pi (docs/physics.md 'Errata').
    """
    beta, phi = np.broadcast_arrays(np.radians(polar_angle), np.radians(azimuth))
    cb, sb, cp, sp = np.cos(beta), np.sin(beta), np.cos(phi), np.sin(phi)
    return np.stack([
        np.stack([sp**2 + (1.0 - sp**2) * cb, -sp * cp * (1.0 - cb), -cp * sb], axis=-1),
        np.stack([-sp * cp * (1.0 - cb), cp**2 + (1.0 - cp**2) * cb, -sp * sb], axis=-1),
        np.stack([cp * sb, sp * sb, cb], axis=-1),
    ], axis=-2)


def _check_anisotropy(anisotropy):
    anisotropy = finite_number("anisotropy", anisotropy, f"[{ANISOTROPY_RANGE[0]}, {ANISOTROPY_RANGE[1]}]")
    if not ANISOTROPY_RANGE[0] <= anisotropy <= ANISOTROPY_RANGE[1]:
        raise ValueError(f"anisotropy = {anisotropy} is outside the valid range [{ANISOTROPY_RANGE[0]}, "
                         f"{ANISOTROPY_RANGE[1]}] (p(n) of Eq. 3.50 would be negative)")
    return anisotropy


def _orientation_average(local_tensor, anisotropy):
    """∫∫ M X M^T p(n) sin beta dbeta dphi for one bridge-frame tensor X (3, 3)."""
    cosines, weights = np.polynomial.legendre.leggauss(QUADRATURE_ORDER)
    azimuths = np.linspace(0.0, 360.0, 2 * QUADRATURE_ORDER, endpoint=False)
    polar = np.degrees(np.arccos(cosines))
    rotation = thesis_rotation(polar[:, None], azimuths[None, :])
    density = fabric_density(anisotropy, polar)[:, None] * weights[:, None] * (2.0 * np.pi / len(azimuths))
    return np.einsum("pq,pqia,ab,pqjb->ij", np.broadcast_to(density, rotation.shape[:2]), rotation,
                     local_tensor, rotation, optimize=True)


def _check_counts(bridge_count, volume):
    bridge_count = finite_number("bridge_count", bridge_count, "[0, inf)")
    volume = finite_number("volume", volume, "(0, inf) m^3")
    if bridge_count < 0.0:
        raise ValueError(f"bridge_count = {bridge_count} is outside the valid range [0, inf)")
    if volume <= 0.0:
        raise ValueError(f"volume = {volume} is outside the valid range (0, inf) m^3")
    return bridge_count, volume


def harmonic_effective_stress_parameter(anisotropy, bridge_count, volume, radius, filling_angle, water_volume):
    """chi_ij (3, 3) of Eq. 3.55 with p' of Eq. 3.57.

    anisotropy: a of the bridge normals (Eqs. 3.52, 3.54), in [-1/2, 1]; bridge_count: N_LB in
    the volume V [m^3]; radius [m] and filling_angle [deg] of every cap; water_volume V_w [m^3].
    """
    anisotropy = _check_anisotropy(anisotropy)
    bridge_count, volume = _check_counts(bridge_count, volume)
    cap = wetted_cap_integral(radius, filling_angle)
    return (water_volume * np.eye(3) + 2.0 * bridge_count * _orientation_average(cap, anisotropy)) / volume


def harmonic_surface_tension_stress(anisotropy, bridge_count, volume, radius, filling_angle, contact_angle,
                                    surface_tension):
    """B_ij (3, 3) [Pa] of Eq. 3.56 with p' of Eq. 3.57; arguments as for the chi form,
    contact_angle [deg], surface_tension [N/m]."""
    anisotropy = _check_anisotropy(anisotropy)
    bridge_count, volume = _check_counts(bridge_count, volume)
    line = contact_line_integral(radius, filling_angle, contact_angle, surface_tension)
    return 2.0 * bridge_count * _orientation_average(line, anisotropy) / volume
