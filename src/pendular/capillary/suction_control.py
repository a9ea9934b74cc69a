"""Suction-controlled bridges: the stable bridge at a given distance, and the rupture distance.

At fixed suction u* the bridges form a one-parameter family in the filling angle delta1: the
distance rises from 0 (delta1 -> 0) to a maximum, the rupture distance, then falls through
contact to overlap. Below the rupture distance two bridges exist; the one with the larger
filling angle (and volume) is stable (the criterion of YADE's capillary files: volume not below
the volume at rupture) and is the one returned. The family is limited to delta1 <= 90 deg - theta;
for large radius ratios at low suction that limit is reached before contact, at a positive
distance `lowest_distance`, and closer stable bridges lie outside the solver's range.
"""

import math

import numba
import numpy as np

from pendular.capillary.meniscus import bridge_from_kernel, bridge_kernel
from pendular.capillary.roots import brent_maximum, brent_root
from pendular.capillary.validation import (check_contact_angle, check_distance, check_radius_ratio,
    check_suction)

SMALLEST_FILLING_ANGLE = 1e-7
"""Lower end (rad) of the filling-angle search for the rupture point."""


@numba.njit(cache=True)
def _distance_at_log_filling_angle(log_delta1, args):
    radius_ratio, theta, suction_star = args
    return bridge_kernel(radius_ratio, theta, suction_star, math.exp(log_delta1))[0]


@numba.njit(cache=True)
def _distance_residual(delta1, args):
    radius_ratio, theta, suction_star, distance_star = args
    return bridge_kernel(radius_ratio, theta, suction_star, delta1)[0] - distance_star


@numba.njit(cache=True)
def rupture_point(radius_ratio, theta, suction_star):
    """(delta1 (rad), distance D/R2) at the largest distance of the family at suction u* >= 0."""
    log_delta1, distance = brent_maximum(
        _distance_at_log_filling_angle,
        (radius_ratio, theta, suction_star),
        math.log(SMALLEST_FILLING_ANGLE),
        math.log(0.5 * math.pi - theta),
        1e-12,
    )
    return math.exp(log_delta1), distance


@numba.njit(cache=True)
def stable_filling_angle(radius_ratio, theta, suction_star, distance_star, delta1_rupture, distance_rupture):
    """delta1 (rad) of the stable bridge at D/R2 = distance_star, given the rupture point.

    NaN beyond the rupture distance, or below the distance reached at delta1 = 90 deg - theta.
    """
    if distance_star > distance_rupture:
        return np.nan
    largest = 0.5 * math.pi - theta
    args = (radius_ratio, theta, suction_star, distance_star)
    residual_largest = _distance_residual(largest, args)
    if residual_largest > 0.0:
        return np.nan
    return brent_root(
        _distance_residual, args, delta1_rupture, largest, distance_rupture - distance_star, residual_largest, 1e-15
    )


@numba.njit(cache=True)
def contact_filling_angle(radius_ratio, theta, suction_star):
    """delta1 (rad) of the stable bridge at the smallest tabulated distance max(0, lowest distance)."""
    largest = 0.5 * math.pi - theta
    if bridge_kernel(radius_ratio, theta, suction_star, largest)[0] >= 0.0:
        return largest
    delta1_rupture, distance_rupture = rupture_point(radius_ratio, theta, suction_star)
    return stable_filling_angle(radius_ratio, theta, suction_star, 0.0, delta1_rupture, distance_rupture)


def rupture_distance(radius_ratio, contact_angle, suction_star):
    """Rupture distance D/R2 at suction u* = s R2/gamma: no bridge exists farther apart
    (docs/physics.md 'The bridge model').

    radius_ratio in [1, MAX_SOLVER_RADIUS_RATIO], contact_angle in [0, 90) deg, suction_star >= 0.
    """
    radius_ratio = check_radius_ratio(radius_ratio)
    contact_angle = check_contact_angle(contact_angle)
    suction_star = check_suction(suction_star)
    return rupture_point(radius_ratio, math.radians(contact_angle), suction_star)[1]


def lowest_distance(radius_ratio, contact_angle, suction_star):
    """Distance D/R2 of the stable bridge whose filling angle on the smaller sphere is 90 deg - theta.

    Negative (an overlap) in most cases; positive for large radius ratios at low suction, where
    stable bridges at closer distances are outside the solver's range.
    """
    radius_ratio = check_radius_ratio(radius_ratio)
    contact_angle = check_contact_angle(contact_angle)
    suction_star = check_suction(suction_star)
    theta = math.radians(contact_angle)
    return bridge_kernel(radius_ratio, theta, suction_star, 0.5 * math.pi - theta)[0]


def bridge_at_distance(radius_ratio, contact_angle, suction_star, distance_star):
    """Stable (larger filling angle) bridge at suction u* = s R2/gamma and gap D/R2 = distance_star.

    Raises ValueError beyond the rupture distance (no bridge exists there) and below
    `lowest_distance` (the stable bridge is outside the solver's range).
    """
    radius_ratio = check_radius_ratio(radius_ratio)
    contact_angle = check_contact_angle(contact_angle)
    suction_star = check_suction(suction_star)
    distance_star = check_distance(distance_star)
    theta = math.radians(contact_angle)
    delta1_rupture, distance_rupture = rupture_point(radius_ratio, theta, suction_star)
    delta1 = stable_filling_angle(radius_ratio, theta, suction_star, distance_star, delta1_rupture, distance_rupture)
    if math.isnan(delta1):
        low = bridge_kernel(radius_ratio, theta, suction_star, 0.5 * math.pi - theta)[0]
        if distance_star > distance_rupture:
            reason = f"no liquid bridge exists beyond the rupture distance {distance_rupture:.8g}"
        else:
            reason = f"the stable bridge would need a filling angle above 90 - contact_angle = {90 - contact_angle} deg"
        raise ValueError(
            f"distance_star = {distance_star} is outside the valid range [{low:.8g}, {distance_rupture:.8g}] "
            f"for radius_ratio = {radius_ratio}, contact_angle = {contact_angle} deg, "
            f"suction_star = {suction_star}: {reason}"
        )
    return bridge_from_kernel(radius_ratio, contact_angle, suction_star, delta1)
