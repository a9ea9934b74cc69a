"""Volume-controlled bridges: the bridge of given volume at a given distance, and its rupture distance.

A bridge of fixed volume V* (it keeps the water it formed with: docs/physics.md 'The bridge
model') is followed from contact as the spheres separate. Its states form the contour V(u*,
delta1) = V* of the exact solution (pendular.capillary.meniscus); along it the distance first
grows, reaches a maximum, the volume-controlled rupture distance (Lian et al. 1993 estimate it
as (1 + theta/2) V*^(1/3)), then falls again on the unstable part. The stable part is the one
connected to contact. It goes well past the suction-controlled rupture point, and for larger
volumes or contact angles the suction turns negative (liquid pressure above the gas pressure,
convex menisci) before rupture, so `suction` may come out negative here. The contour is traced
by pseudo-arclength continuation in (asinh(u*/r), delta1). Its contact end is the stable
suction-controlled bridge at contact (or at delta1 = 90 deg - theta where that comes first,
large radius ratios), so the volumes covered are those of bridges formed at contact with a
suction in [0, CONTACT_SUCTION_MAX].
"""

from dataclasses import dataclass
import functools
import math

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from pendular.capillary.meniscus import bridge_from_kernel, bridge_kernel
from pendular.capillary.suction_control import contact_filling_angle
from pendular.capillary.validation import (check_contact_angle, check_distance, check_positive,
    check_radius_ratio)

CONTACT_SUCTION_MAX = 15000.0
"""Largest u* at contact of the volume-controlled family (smallest volume covered)."""

_STEP_FIRST, _STEP_MAX, _STEP_MIN = 0.01, 0.1, 1e-6
_MAX_POINTS = 3000
_GRADIENT_STEP = 1e-6


@dataclass(frozen=True)
class VolumeContour:
    """States of one volume-controlled bridge from contact to rupture (contact_angle in degrees).

    points: (n, 2) array of (asinh(u*/r), delta1 in rad) along the contour, distance increasing;
    tangents, steps: points[k] is the projection onto the contour of points[k-1] + steps[k] tangents[k-1];
    distances: d* at the points (the last one is taken as the rupture distance);
    ends_at_peak: True when the distance peaked on the contour; False when the contour ends
    before, where the solver's family stops (delta1 reaching 90 - theta for large radius
    ratios, or, for theta > 0 at strongly negative suction, where the meniscus meets sphere 2
    tangentially and the first-contact solution changes branch); the last distance is then a
    lower bound of the rupture distance (docs/capillary.md gives its size).
    """

    radius_ratio: float
    contact_angle: float
    volume: float
    points: np.ndarray
    tangents: np.ndarray
    steps: np.ndarray
    distances: np.ndarray
    ends_at_peak: bool

    @property
    def contact_distance(self):
        return float(self.distances[0])

    @property
    def rupture_distance(self):
        return float(self.distances[-1])


def suction_at(radius_ratio, nu):
    """u* at the contour coordinate nu = asinh(u*/r)."""
    return radius_ratio * math.sinh(nu)


def _state(radius_ratio, theta, point):
    """Kernel output (d*, V*, F*, delta2, nn11, nn33) at point = (nu, delta1); NaNs outside the range."""
    nu, delta1 = point
    if not 0.0 < delta1 <= 0.5 * math.pi - theta:
        return (math.nan,) * 6
    return bridge_kernel(radius_ratio, theta, suction_at(radius_ratio, nu), delta1)


def _gradients(radius_ratio, theta, point):
    """Central-difference gradients of (d*, V*) with respect to (nu, delta1): a 2x2 array, rows d and V."""
    gradient = np.empty((2, 2))
    for axis in range(2):
        step = np.zeros(2)
        step[axis] = _GRADIENT_STEP
        plus = np.array(_state(radius_ratio, theta, point + step)[:2])
        minus = np.array(_state(radius_ratio, theta, point - step)[:2])
        span = 2.0 * _GRADIENT_STEP
        if np.isnan(plus[0]) or np.isnan(minus[0]):  # one-sided at the edge of the range
            centre = np.array(_state(radius_ratio, theta, point)[:2])
            span = _GRADIENT_STEP
            if np.isnan(plus[0]):
                plus = centre
            else:
                minus = centre
        gradient[:, axis] = (plus - minus) / span
    return gradient


def _project(radius_ratio, theta, volume, guess):
    """Point of the contour V* = volume near guess, moving along the volume gradient.

    Chord Newton (gradient at the guess), then full Newton if that stalls; None if neither converges.
    """
    for refresh in (False, True):
        point = guess.copy()
        gradient = _gradients(radius_ratio, theta, point)[1]
        for _ in range(12):
            residual = _state(radius_ratio, theta, point)[1] - volume
            if not math.isfinite(residual):
                break
            if abs(residual) <= 1e-11 * volume:  # the kernel resolves V* to ~1e-13 relative
                return point
            if refresh:
                gradient = _gradients(radius_ratio, theta, point)[1]
            norm2 = gradient @ gradient
            if not norm2 > 0.0:
                break
            point = point - residual * gradient / norm2
    return None


def _tangent(radius_ratio, theta, point, previous=None):
    """Unit tangent of the volume contour, oriented along previous (or toward growing distance)."""
    gradient = _gradients(radius_ratio, theta, point)
    tangent = np.array([-gradient[1, 1], gradient[1, 0]])
    tangent /= np.hypot(*tangent)
    reference = previous if previous is not None else gradient[0]
    return tangent if tangent @ reference > 0.0 else -tangent, gradient[0]


def _contact_point(radius_ratio, theta, volume):
    """(nu, delta1) of the contact end: the stable bridge at contact holding this volume."""

    def contact_volume(nu):
        suction = suction_at(radius_ratio, nu)
        return bridge_kernel(radius_ratio, theta, suction, contact_filling_angle(radius_ratio, theta, suction))[1]

    nu_max = math.asinh(CONTACT_SUCTION_MAX / radius_ratio)
    largest, smallest = contact_volume(0.0), contact_volume(nu_max)
    if not smallest <= volume <= largest:
        raise ValueError(
            f"volume_star = {volume} is outside the valid range [{smallest:.6g}, {largest:.6g}] for radius_ratio = "
            f"{radius_ratio}, contact_angle = {math.degrees(theta)} deg: volumes of bridges formed at contact with "
            f"suction_star in [0, {CONTACT_SUCTION_MAX}]"
        )
    nu = brentq(lambda x: contact_volume(x) - volume, 0.0, nu_max, xtol=1e-14, rtol=1e-14)
    return np.array([nu, contact_filling_angle(radius_ratio, theta, suction_at(radius_ratio, nu))])


def volume_contour(radius_ratio, contact_angle, volume_star):
    """VolumeContour of the bridge of volume V* = V/R2**3 (contact_angle in degrees; ranges as in
    rupture_distance_for_volume)."""
    radius_ratio = check_radius_ratio(radius_ratio)
    contact_angle = check_contact_angle(contact_angle)
    volume_star = check_positive("volume_star", volume_star)
    return trace_contour(radius_ratio, contact_angle, volume_star)


@functools.lru_cache(maxsize=256)
def trace_contour(radius_ratio, contact_angle, volume):
    """Trace the volume-controlled bridge from contact to rupture (validated input); see VolumeContour."""
    theta = math.radians(contact_angle)
    point = _contact_point(radius_ratio, theta, volume)
    tangent = _tangent(radius_ratio, theta, point)[0]
    points, tangents, steps = [point], [tangent], [0.0]
    distances = [_state(radius_ratio, theta, point)[0]]

    def contour(ends_at_peak):
        return VolumeContour(radius_ratio, contact_angle, volume, np.array(points), np.array(tangents),
                             np.array(steps), np.array(distances), ends_at_peak)

    step = _STEP_FIRST
    while True:
        candidate = _project(radius_ratio, theta, volume, point + step * tangent)
        if candidate is not None:
            new_tangent, new_distance_gradient = _tangent(radius_ratio, theta, candidate, tangent)
            turn = math.acos(min(1.0, new_tangent @ tangent))
        if candidate is None or turn > 0.1:
            step *= 0.5
            if step < _STEP_MIN:  # a kink or the edge of the range: the family ends here
                return contour(False)
            continue
        if new_distance_gradient @ new_tangent <= 0.0:  # the distance peaked within this step
            break
        point, tangent = candidate, new_tangent
        points.append(point)
        tangents.append(tangent)
        steps.append(step)
        distances.append(_state(radius_ratio, theta, point)[0])
        step = min(1.5 * step, _STEP_MAX)
        if len(points) == _MAX_POINTS:
            return contour(False)

    # the rupture: largest distance on the contour between point and candidate
    def negative_distance(s):
        projected = _project(radius_ratio, theta, volume, point + s * tangent)
        return -_state(radius_ratio, theta, projected)[0] if projected is not None else 1.0  # d* > -1 on the contour

    best = minimize_scalar(negative_distance, bounds=(0.0, step), method="bounded", options={"xatol": 1e-12})
    rupture = _project(radius_ratio, theta, volume, point + best.x * tangent)
    points.append(rupture)
    tangents.append(_tangent(radius_ratio, theta, rupture, tangent)[0])
    steps.append(best.x)
    distances.append(_state(radius_ratio, theta, rupture)[0])
    return contour(True)


def contour_point_at_distance(contour, distance_star):
    """(nu, delta1) on the contour where d* = distance_star, in [contact distance, rupture distance].

    Between traced points k-1 and k, the points projected from the predictor
    points[k-1] + s tangents[k-1], s in [0, steps[k]], are searched for the distance.
    """
    k = int(np.searchsorted(contour.distances, distance_star))
    k = min(max(k, 1), len(contour.distances) - 1)
    if distance_star <= contour.distances[k - 1]:
        return contour.points[k - 1]
    if distance_star >= contour.distances[k]:
        return contour.points[k]
    start, tangent = contour.points[k - 1], contour.tangents[k - 1]
    theta = math.radians(contour.contact_angle)

    def point_at(s):
        projected = _project(contour.radius_ratio, theta, contour.volume, start + s * tangent)
        if projected is None:
            raise ValueError(f"no volume-controlled bridge found near distance_star = {distance_star}")
        return projected

    def residual(s):
        return _state(contour.radius_ratio, theta, point_at(s))[0] - distance_star

    step = contour.steps[k]
    s = brentq(residual, 0.0, step, xtol=1e-15 * max(1.0, step), rtol=1e-14)
    return point_at(s)


def rupture_distance_for_volume(radius_ratio, contact_angle, volume_star):
    """Volume-controlled rupture distance D/R2 of a bridge of volume V* = V/R2**3.

    radius_ratio in [1, MAX_SOLVER_RADIUS_RATIO], contact_angle in [0, 90) deg, volume_star within the
    volumes of bridges formed at contact with u* in [0, CONTACT_SUCTION_MAX]. Where the traced
    family ends before its distance peaks (VolumeContour.ends_at_peak), its last distance.
    """
    return volume_contour(radius_ratio, contact_angle, volume_star).rupture_distance


def bridge_with_volume(radius_ratio, contact_angle, volume_star, distance_star):
    """Stable bridge of volume V* = V/R2**3 at gap D/R2 = distance_star (its suction is the unknown).

    Valid distances run from contact (or, for large radius ratios, the distance where the filling
    angle on the smaller sphere reaches 90 - theta) to the volume-controlled rupture distance;
    ValueError outside. The returned Bridge's suction may be negative (see module docstring).
    """
    distance_star = check_distance(distance_star)
    contour = volume_contour(radius_ratio, contact_angle, volume_star)
    if contour.contact_distance - 1e-12 <= distance_star < contour.contact_distance:
        distance_star = contour.contact_distance  # rounding of the contact distance (0 at contact)
    if not contour.contact_distance <= distance_star <= contour.rupture_distance:
        beyond = "beyond the rupture distance" if distance_star > contour.rupture_distance else "closer than contact"
        raise ValueError(
            f"distance_star = {distance_star} is outside the valid range [{contour.contact_distance:.8g}, "
            f"{contour.rupture_distance:.8g}] for radius_ratio = {radius_ratio}, contact_angle = {contact_angle} deg, "
            f"volume_star = {volume_star}: no volume-controlled bridge {beyond}"
        )
    nu, delta1 = contour_point_at_distance(contour, distance_star)
    suction = suction_at(contour.radius_ratio, nu)
    return bridge_from_kernel(contour.radius_ratio, contour.contact_angle, suction, delta1)
