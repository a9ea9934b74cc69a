"""Exact axisymmetric liquid bridge between two spheres (Young–Laplace).

Geometry (thesis section 3.4.1, docs/physics.md 'The bridge model'): spheres of radii R1 <= R2, r =
R2/R1, contact angle theta on both, filling angle delta1 on the smaller sphere. The meridian
of the liquid–gas surface has constant mean curvature fixed by the suction s:
with tangent angle phi to the bridge axis and arc length l,

    dphi/dl = cos(phi)/y + s/gamma                                (Young–Laplace)

and the axial force through any cross-section is invariant (docs/physics.md 'The bridge model'),

    F / (2 pi gamma) = y cos(phi) + (s / 2 gamma) y**2
                     = R1 sin(delta1) sin(delta1 + theta) + (s R1**2 / 2 gamma) sin(delta1)**2.

The invariant gives y(phi) in closed form, so the profile is a quadrature. For s >= 0, phi
increases monotonically along the meniscus and the variable is tau = artanh(sin phi)
(Gauss–Legendre on the two panels sphere 1 - neck - sphere 2). For s < 0 (reached only by
volume-controlled bridges) the meridian is an unduloid whose tangent angle can turn back at
inflection points; it is parametrised by its phase v (y = (1 - k cos v) R1 / a, a = -s R1/gamma,
k = sqrt(1 - 2 a f)) through tan(v/2) = eps sinh(sigma), which resolves thin necks. The
meniscus starts on sphere 1 at phi0 = delta1 + theta - 90 deg and ends at the first point past
the neck where it meets sphere 2 at the contact angle: phi_end = 90 deg - theta - delta2, height
R2 sin(delta2). That fixes delta2; the length of the profile fixes the gap.

All results are in YADE's dimensionless units (docs/units.md): distance D/R2,
volume V/R2**3, force F/(2 pi gamma R2), nn_ii = (1/R2**2) ∫ n_i n_i dS over the
liquid–gas surface (axis 3 along the bridge axis), suction s R2/gamma.
"""

from dataclasses import dataclass
import math

import numba
import numpy as np

from pendular.capillary.roots import brent_maximum, brent_root
from pendular.capillary.validation import (check_contact_angle, check_filling_angle,
    check_radius_ratio, check_suction)

GAUSS_ORDER = 32
"""Gauss–Legendre nodes on each of the two panels of the profile (sphere 1 to neck, neck to sphere 2)."""

_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(GAUSS_ORDER)


@dataclass(frozen=True)
class Bridge:
    """One liquid bridge in YADE's dimensionless units (docs/units.md); angles in degrees.

    radius_ratio: R2/R1 >= 1. contact_angle: theta. suction: s R2/gamma.
    distance: surface gap D/R2. volume: V/R2**3. force: F/(2 pi gamma R2), attractive.
    delta1, delta2: filling angles on the smaller (R1) and larger (R2) sphere.
    nn11, nn33: (1/R2**2) ∫ n_i n_i dS over the liquid–gas surface, axis 3 along the bridge.
    """

    radius_ratio: float
    contact_angle: float
    suction: float
    distance: float
    volume: float
    force: float
    delta1: float
    delta2: float
    nn11: float
    nn33: float

    @property
    def area(self):
        """Liquid–gas surface area / R2**2 (= 2 nn11 + nn33)."""
        return 2.0 * self.nn11 + self.nn33


@numba.njit(cache=True)
def profile_height(phi, force_invariant, suction1):
    """Meridian height y(phi) / R1 from the force invariant (stable form of the quadratic's root)."""
    c = math.cos(phi)
    return 2.0 * force_invariant / (c + math.sqrt(c * c + 2.0 * suction1 * force_invariant))


@numba.njit(cache=True)
def end_tangent_angle(radius_ratio, theta, suction1, force_invariant):
    """Tangent angle phi_end (rad) where the meniscus meets sphere 2 at the contact angle, for u >= 0.

    Root of y(phi) = r cos(phi + theta) on [0, 90 deg - theta]: the left side increases and the
    right side decreases there, and at the neck (phi = 0) y <= sin(delta1) <= cos(theta) <=
    r cos(theta), so the root exists and is unique. First guess: the closed-form root of
    r sin(d2) sin(d2 + theta) + u r**2 sin(d2)**2 / 2 = f (the invariant on sphere 2); then
    safeguarded Newton to machine precision.
    """
    lo = 0.0
    hi = 0.5 * math.pi - theta
    p = 0.5 * math.cos(theta) + 0.25 * suction1 * radius_ratio
    q = 0.5 * math.sin(theta)
    cos_arg = (p - force_invariant / radius_ratio) / math.hypot(p, q)
    delta2 = 0.5 * (math.acos(max(-1.0, min(1.0, cos_arg))) - math.atan2(q, p))
    phi = min(max(0.5 * math.pi - theta - delta2, lo), hi)
    for _ in range(60):
        y = profile_height(phi, force_invariant, suction1)
        gap = y - radius_ratio * math.cos(phi + theta)
        if gap > 0.0:
            hi = phi
        else:
            lo = phi
        root = math.sqrt(math.cos(phi) ** 2 + 2.0 * suction1 * force_invariant)
        slope = radius_ratio * math.sin(phi + theta) + y * math.sin(phi) / root  # >= 0 on the bracket
        new_phi = phi - gap / slope if slope > 0.0 else 0.5 * (lo + hi)
        if not lo < new_phi < hi:
            new_phi = 0.5 * (lo + hi)
        if abs(new_phi - phi) <= 1e-15 * max(1.0, abs(phi)) or hi - lo <= 1e-16:
            return new_phi
        phi = new_phi
    return phi


@numba.njit(inline="always")
def _gauss_panel(integrands, a, b, args, nodes, weights):
    """Gauss–Legendre quadrature over [a, b] of the four profile integrals (R1 units): (axial
    length, ∫ pi y**2 dx, pi ∫ y cos(phi)**2 dl, 2 pi ∫ y sin(phi)**2 dl).

    integrands(x, w, args) returns the four integrands at x times the node's weight w (each
    parametrisation keeps its own order of operations). Inlined into its callers, as the
    root finders are (pendular.capillary.roots), so that they stay cacheable.
    """
    half = 0.5 * (b - a)
    mid = 0.5 * (b + a)
    length = 0.0
    volume = 0.0
    area11 = 0.0
    area33 = 0.0
    for k in range(nodes.size):
        d_length, d_volume, d_area11, d_area33 = integrands(mid + half * nodes[k], weights[k] * half, args)
        length += d_length
        volume += d_volume
        area11 += d_area11
        area33 += d_area33
    return length, volume, area11, area33


@numba.njit(cache=True)
def _tau_integrands(tau, w, args):
    """The weighted integrands of _gauss_panel at tau = artanh(sin phi), args = (f, u R1/gamma):
    cos(phi) = sech(tau), sin(phi) = tanh(tau), dphi/dtau = cos(phi), dl/dphi = y / S,
    S = sqrt(cos(phi)**2 + 2 u f)."""
    force_invariant, suction1 = args
    c = 1.0 / math.cosh(tau)
    s = math.tanh(tau)
    root = math.sqrt(c * c + 2.0 * suction1 * force_invariant)
    y = 2.0 * force_invariant / (c + root)
    dx = y * c * c / root
    return (w * dx, w * math.pi * y * y * dx, w * math.pi * y * y * c * c * c / root,
            w * 2.0 * math.pi * y * y * s * s * c / root)


@numba.njit(cache=True)
def _unduloid_point(sigma, suction_abs, force_invariant, k, one_minus_k, eps):
    """Profile at sigma for negative suction (unduloid), R1 units.

    With a = -s R1/gamma > 0: y = (1 - k cos v)/a, k = sqrt(1 - 2 a f), neck at v = 0,
    bulge at v = pi, tan(v/2) = eps sinh(sigma), eps = sqrt((1 - k)/(2 k)) (stretches the neck).
    Returns (y, cos phi, sin phi, dx/dsigma, dl/dsigma).
    """
    a = suction_abs
    tan_half = eps * math.sinh(sigma)
    denominator = 1.0 + tan_half * tan_half
    y = (one_minus_k + 2.0 * k * tan_half * tan_half / denominator) / a
    sin_v = 2.0 * tan_half / denominator
    p = y + force_invariant + 0.5 * a * y * y
    root = math.sqrt(0.5 * a * p)
    cos_phi = force_invariant / y + 0.5 * a * y
    sin_phi = root * (k / a) * sin_v / y
    dv = 2.0 * eps * math.cosh(sigma) / denominator
    return y, cos_phi, sin_phi, y * cos_phi / root * dv, y / root * dv


@numba.njit(cache=True)
def _unduloid_contact_gap(sigma, args):
    """y - r cos(phi + theta) at sigma: zero where the unduloid meets sphere 2 at the contact angle."""
    radius_ratio, theta, suction_abs, force_invariant, k, one_minus_k, eps = args
    y, cos_phi, sin_phi, _, _ = _unduloid_point(sigma, suction_abs, force_invariant, k, one_minus_k, eps)
    return y - radius_ratio * (cos_phi * math.cos(theta) - sin_phi * math.sin(theta))


@numba.njit(cache=True)
def _unduloid_contact_gap_at_v(v, args):
    """_unduloid_contact_gap at the unduloid angle v (0 at the neck, pi at the bulge)."""
    return _unduloid_contact_gap(math.asinh(math.tan(0.5 * v) / args[6]), args)


@numba.njit(cache=True)
def _unduloid_integrands(sigma, w, args):
    """The weighted integrands of _gauss_panel at sigma of the unduloid, args = (a, f, k, 1 - k, eps)."""
    y, cos_phi, sin_phi, dx, dl = _unduloid_point(sigma, *args)
    return (w * dx, w * math.pi * y * y * dx, w * math.pi * y * cos_phi * cos_phi * dl,
            w * 2.0 * math.pi * y * sin_phi * sin_phi * dl)


@numba.njit(cache=True)
def _unduloid_profile(radius_ratio, theta, suction1, force_invariant, delta1):
    """(phi_end, length, ∫ pi y**2 dx, area11, area33) in R1 units for negative suction, or NaNs.

    The end is the first point past the neck where the profile meets sphere 2 at the contact
    angle; NaNs if there is none before the bulge, or if the invariant admits no unduloid.
    """
    nan = np.nan
    a = -suction1
    two_af = 2.0 * a * force_invariant
    if not 0.0 < two_af < 1.0:
        return nan, nan, nan, nan, nan
    k = math.sqrt(1.0 - two_af)
    one_minus_k = two_af / (1.0 + k)
    eps = math.sqrt(one_minus_k / (2.0 * k))
    # start on sphere 1: cos v and sin v from the exact height and tangent angle there
    y0 = math.sin(delta1)
    phi0 = delta1 + theta - 0.5 * math.pi
    cos_v0 = (1.0 - a * y0) / k
    sin_v0 = math.sin(phi0) * y0 * a / (k * math.sqrt(0.5 * a * (y0 + force_invariant + 0.5 * a * y0 * y0)))
    if cos_v0 >= 0.0:
        tan_half0 = sin_v0 / (1.0 + cos_v0)
    elif sin_v0 < 0.0:
        tan_half0 = (1.0 - cos_v0) / sin_v0
    else:
        return nan, nan, nan, nan, nan
    sigma0 = math.asinh(tan_half0 / eps)
    args = (radius_ratio, theta, a, force_invariant, k, one_minus_k, eps)
    # first crossing past the neck (v = 0, where the gap is <= 0): the gap rises to a peak before
    # the bulge (v = pi); the crossing, if any, lies on the rising part
    v_peak, gap_peak = brent_maximum(_unduloid_contact_gap_at_v, args, 0.0, math.pi * (1.0 - 1e-12), 1e-13)
    if gap_peak < 0.0:
        return nan, nan, nan, nan, nan
    v_end = brent_root(
        _unduloid_contact_gap_at_v, args, 0.0, v_peak, _unduloid_contact_gap_at_v(0.0, args), gap_peak, 1e-15
    )
    sigma_end = math.asinh(math.tan(0.5 * v_end) / eps)
    _, cos_phi, sin_phi, _, _ = _unduloid_point(sigma_end, a, force_invariant, k, one_minus_k, eps)
    phi_end = math.atan2(sin_phi, cos_phi)
    shape = (a, force_invariant, k, one_minus_k, eps)
    l1, v1, a1, b1 = _gauss_panel(_unduloid_integrands, sigma0, 0.0, shape, _GAUSS_NODES, _GAUSS_WEIGHTS)
    l2, v2, a2, b2 = _gauss_panel(_unduloid_integrands, 0.0, sigma_end, shape, _GAUSS_NODES, _GAUSS_WEIGHTS)
    return phi_end, l1 + l2, v1 + v2, a1 + a2, b1 + b2


@numba.njit(cache=True)
def _tau_profile(radius_ratio, theta, suction1, force_invariant, delta1):
    """(phi_end, length, ∫ pi y**2 dx, area11, area33) in R1 units for suction >= 0."""
    phi_end = end_tangent_angle(radius_ratio, theta, suction1, force_invariant)
    delta2 = 0.5 * math.pi - theta - phi_end
    # tau = artanh(sin phi) = ln tan((phi + 90 deg)/2) at both ends of the profile
    tau_start = math.log(math.tan(0.5 * (delta1 + theta)))
    tau_end = -math.log(math.tan(0.5 * (delta2 + theta)))
    shape = (force_invariant, suction1)
    l1, v1, a1, b1 = _gauss_panel(_tau_integrands, tau_start, 0.0, shape, _GAUSS_NODES, _GAUSS_WEIGHTS)
    l2, v2, a2, b2 = _gauss_panel(_tau_integrands, 0.0, tau_end, shape, _GAUSS_NODES, _GAUSS_WEIGHTS)
    return phi_end, l1 + l2, v1 + v2, a1 + a2, b1 + b2


@numba.njit(cache=True)
def bridge_kernel(radius_ratio, theta, suction_star, delta1):
    """Exact bridge for r = R2/R1, theta (rad), u* = s R2/gamma (any sign), delta1 (rad).

    Returns (distance D/R2, volume V/R2**3, force F/(2 pi gamma R2), delta2 (rad), nn11, nn33),
    all NaN where no such meniscus exists (negative suction strong enough to make the force
    repulsive or the profile miss sphere 2). Force: docs/physics.md 'The bridge model';
    volume: ∫ pi y**2 dx minus the two wetted caps. Negative suction (liquid pressure above the
    gas pressure) is only reached by volume-controlled bridges.
    """
    nan = np.nan
    suction1 = suction_star / radius_ratio  # s R1 / gamma
    sin1 = math.sin(delta1)
    force_invariant = sin1 * (math.sin(delta1 + theta) + 0.5 * suction1 * sin1)
    if not force_invariant > 0.0:
        return nan, nan, nan, nan, nan, nan
    if suction1 >= 0.0:
        phi_end, length, integral_y2, area11, area33 = _tau_profile(
            radius_ratio, theta, suction1, force_invariant, delta1
        )
    else:
        phi_end, length, integral_y2, area11, area33 = _unduloid_profile(
            radius_ratio, theta, suction1, force_invariant, delta1
        )
    if not phi_end == phi_end:
        return nan, nan, nan, nan, nan, nan
    r = radius_ratio
    delta2 = 0.5 * math.pi - theta - phi_end
    versine1 = 2.0 * math.sin(0.5 * delta1) ** 2  # 1 - cos(delta1)
    versine2 = 2.0 * math.sin(0.5 * delta2) ** 2
    gap = length - versine1 - r * versine2
    caps = math.pi / 3.0 * (versine1 * versine1 * (3.0 - versine1) + r**3 * versine2 * versine2 * (3.0 - versine2))
    volume = integral_y2 - caps
    return gap / r, volume / r**3, force_invariant / r, delta2, area11 / r**2, area33 / r**2


def solve_bridge(radius_ratio, contact_angle, suction_star, filling_angle):
    """Exact bridge from its filling angle on the smaller sphere (docs/units.md; docs/physics.md
    'The bridge model').

    radius_ratio: r = R2/R1 in [1, MAX_SOLVER_RADIUS_RATIO]; contact_angle: theta in [0, 90) deg;
    suction_star: u* = s R2/gamma >= 0; filling_angle: delta1 on R1 in (0, 90 - theta] deg.
    Returns a Bridge (dimensionless, angles in degrees). The distance may come out negative
    (the spheres would overlap) on the large-filling-angle end of the family.
    """
    radius_ratio = check_radius_ratio(radius_ratio)
    contact_angle = check_contact_angle(contact_angle)
    suction_star = check_suction(suction_star)
    filling_angle = check_filling_angle(filling_angle, contact_angle)
    return bridge_from_kernel(radius_ratio, contact_angle, suction_star, math.radians(filling_angle),
                              filling_angle)


def bridge_from_kernel(radius_ratio, contact_angle, suction_star, delta1, filling_angle=None):
    """Bridge record of the exact kernel (bridge_kernel) at delta1 [rad], input already checked.

    contact_angle [deg]; suction_star: u* = s R2/gamma, any sign; filling_angle: delta1 in
    degrees as the caller was given it, recorded as is (default: math.degrees(delta1)).
    """
    distance, volume, force, delta2, nn11, nn33 = bridge_kernel(
        radius_ratio, math.radians(contact_angle), suction_star, delta1
    )
    return Bridge(
        radius_ratio=radius_ratio,
        contact_angle=contact_angle,
        suction=suction_star,
        distance=distance,
        volume=volume,
        force=force,
        delta1=math.degrees(delta1) if filling_angle is None else filling_angle,
        delta2=math.degrees(delta2),
        nn11=nn11,
        nn33=nn33,
    )
