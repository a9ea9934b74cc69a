"""The liquid bridge at one contact of a regular packing: equal spheres at surface gap H/R.

Step 6 of Tables 4.2-4.4 finds the bridge (filling angle alpha, suction) holding a given volume.
Two methods, both in units of the sphere radius R (R2 = R: u* = s R/gamma, V* = V/R^3,
F* = F/(2 pi gamma R)):

- "exact": the axisymmetric Young-Laplace solution (capillary package). From a volume: the
  volume-controlled bridge at the gap (pendular.capillary.bridge_with_volume, the state reached from
  contact at constant volume). From a suction: the stable bridge, the one with the larger
  filling angle (pendular.capillary.bridge_at_distance); at H > 0 a suction below the largest one at
  this gap has two bridges, the smaller one being unstable under suction control. From a
  filling angle: at H = 0 a single bridge; at H > 0 the distance at fixed alpha first rises
  then falls with the suction and two bridges with the same alpha can span the gap: the one
  with the larger suction is taken (the stable one where it exists).
- "toroidal": thesis Appendix A (pendular.capillary.toroidal_bridge), parametrised by alpha. From a
  volume: the volume grows monotonically with alpha (root in alpha). From a suction: at H > 0
  the suction rises with alpha to a peak and falls again; the root on the falling side (larger
  alpha, larger bridge) is taken, as for the exact method.

Only positive suctions are accepted (thesis section 3.4.1: R1 < R2, water in tension).
"""

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from pendular import capillary
from pendular.capillary import BRIDGE_MODELS

_EXACT_SUCTION_GRID = np.concatenate([[0.0], np.geomspace(1e-4, 1e10, 141)])
"""u* scanned from the top for the largest-suction bridge with a given filling angle (10 per decade)."""

_ANGLE_STEP = 0.25
"""Filling-angle step [deg] of the scans of the toroidal family."""

_ANGLE_MARGIN = 1e-6
"""Distance [deg] kept from alpha + theta = 90 deg, where the toroidal meridian radius diverges."""


@dataclass(frozen=True)
class CellBridge:
    """Bridge between equal spheres: suction_star = s R/gamma, volume = V/R^3,
    force = F/(2 pi gamma R), filling_angle alpha [deg] (the same on both spheres)."""

    suction_star: float
    volume: float
    force: float
    filling_angle: float


def check_contact_angle(contact_angle):
    """The contact angle [deg], checked by the capillary package."""
    return capillary.validation.check_contact_angle(contact_angle)


def check_method(method):
    """method in BRIDGE_MODELS."""
    if method not in BRIDGE_MODELS:
        raise ValueError(f"method = {method!r} is not a bridge method; valid methods {BRIDGE_MODELS}")
    return method


def largest_filling_angle(method, contact_angle):
    """Largest alpha [deg] of the method's family: 90 - theta (toroidal: a margin below it)."""
    return 90.0 - contact_angle - (_ANGLE_MARGIN if method == "toroidal" else 0.0)


def _positive(bridge, method, contact_angle, separation):
    if not bridge.suction_star > 0.0:
        raise ValueError(
            f"the {method} bridge with filling_angle = {bridge.filling_angle:.6g} deg, contact_angle = "
            f"{contact_angle} deg, separation = {separation} has suction s R/gamma = {bridge.suction_star:.6g} "
            f"<= 0: only positive suction (water in tension) is within the model (thesis section 3.4.1)")
    return bridge


def _from_exact(bridge):
    return CellBridge(bridge.suction, bridge.volume, bridge.force, bridge.delta1)


def _toroidal(filling_angle, contact_angle, separation):
    bridge = capillary.toroidal_bridge(filling_angle, contact_angle, separation)
    return CellBridge(bridge.suction_star, bridge.volume, bridge.force, float(filling_angle))


def _toroidal_lowest_angle(contact_angle, separation):
    """Smallest alpha [deg] with a positive toroidal neck radius (Eq. A.2) at this gap."""
    def neck_ok(alpha):
        try:
            capillary.toroidal_bridge(alpha, contact_angle, separation)
            return True
        except ValueError:
            return False
    high = largest_filling_angle("toroidal", contact_angle)
    low = 1e-6
    if neck_ok(low):
        return low
    for _ in range(60):
        middle = 0.5 * (low + high)
        low, high = (low, middle) if neck_ok(middle) else (middle, high)
    return high


def bridge_from_filling_angle(method, filling_angle, contact_angle, separation):
    """CellBridge with filling angle alpha [deg] spanning the gap H/R = separation."""
    check_method(method)
    if method == "toroidal":
        return _positive(_toroidal(filling_angle, contact_angle, separation), method, contact_angle, separation)
    contact_angle = capillary.validation.check_contact_angle(contact_angle)
    filling_angle = capillary.validation.check_filling_angle(filling_angle, contact_angle)

    def gap_excess(suction_star):
        return capillary.solve_bridge(1.0, contact_angle, suction_star, filling_angle).distance - separation

    excess = np.array([gap_excess(u) for u in _EXACT_SUCTION_GRID])
    spanning = np.flatnonzero(excess > 0.0)
    if len(spanning) == 0:
        raise ValueError(
            f"no exact bridge with filling_angle = {filling_angle} deg and contact_angle = {contact_angle} deg "
            f"spans separation = {separation} at a positive suction")
    last = spanning[-1]
    if last == len(_EXACT_SUCTION_GRID) - 1:
        raise ValueError(f"filling_angle = {filling_angle} deg is too small: the bridge needs s R/gamma > "
                         f"{_EXACT_SUCTION_GRID[-1]:.3g}")
    suction_star = brentq(gap_excess, _EXACT_SUCTION_GRID[last], _EXACT_SUCTION_GRID[last + 1],
                          xtol=1e-14, rtol=1e-13)
    return _from_exact(capillary.solve_bridge(1.0, contact_angle, suction_star, filling_angle))


def bridge_from_suction(method, suction_star, contact_angle, separation):
    """CellBridge at suction u* = s R/gamma > 0 spanning the gap: the larger bridge."""
    check_method(method)
    if method == "exact":
        return _from_exact(capillary.bridge_at_distance(1.0, contact_angle, suction_star, separation))
    largest = largest_filling_angle(method, contact_angle)
    if _toroidal(largest, contact_angle, separation).suction_star >= suction_star:
        raise ValueError(
            f"suction_star = {suction_star} is below the toroidal suction at the largest filling angle "
            f"{largest:.6g} deg (contact_angle = {contact_angle} deg, separation = {separation}): "
            f"the bridge would be outside the approximation's range")
    lowest = _toroidal_lowest_angle(contact_angle, separation)
    angles = np.arange(largest, lowest, -_ANGLE_STEP)
    for high, low in zip(angles[:-1], angles[1:]):
        if _toroidal(low, contact_angle, separation).suction_star >= suction_star:
            alpha = brentq(lambda a: _toroidal(a, contact_angle, separation).suction_star - suction_star,
                           low, high, xtol=1e-12)
            return _toroidal(alpha, contact_angle, separation)
    raise ValueError(
        f"suction_star = {suction_star} is above the largest toroidal suction at contact_angle = "
        f"{contact_angle} deg, separation = {separation}: no bridge spans the gap at this suction")


def bridge_from_volume(method, volume_star, contact_angle, separation):
    """CellBridge holding V* = V/R^3 > 0 at the gap (exact: volume-controlled; toroidal: root in alpha)."""
    check_method(method)
    if method == "exact":
        bridge = _from_exact(capillary.bridge_with_volume(1.0, contact_angle, volume_star, separation))
        return _positive(bridge, method, contact_angle, separation)
    lowest = _toroidal_lowest_angle(contact_angle, separation)
    largest = largest_filling_angle(method, contact_angle)
    low_volume = _toroidal(lowest, contact_angle, separation).volume
    high_volume = _toroidal(largest, contact_angle, separation).volume
    if not low_volume <= volume_star <= high_volume:
        raise ValueError(
            f"volume_star = {volume_star} is outside the toroidal family's range [{low_volume:.6g}, "
            f"{high_volume:.6g}] at contact_angle = {contact_angle} deg, separation = {separation}")
    alpha = brentq(lambda a: _toroidal(a, contact_angle, separation).volume - volume_star,
                   lowest, largest, xtol=1e-12)
    return _positive(_toroidal(alpha, contact_angle, separation), method, contact_angle, separation)
