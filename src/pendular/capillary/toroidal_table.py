"""Suction-controlled table of the toroidal approximation (thesis Appendix A), equal spheres.

The table has the layout of pendular.capillary.table.BridgeTable with the single radius ratio r = 1, so
that the DEM's lookup kernel (pendular.capillary.lookup_suction) serves the exact and the toroidal model
alike. At fixed suction the toroidal family is explicit in the filling angle alpha: with
S = sin(alpha), c = 1 - sin(alpha + theta), Eq. A.2 gives the neck R2 = S - c R1 and Eq. 3.47
u* = 1/R1 - 1/R2, a quadratic in the meridian radius R1,

    u* c R1^2 - (u* S + c + 1) R1 + S = 0,

whose root with R2 > 0 is R1 = 2 S / (b + sqrt(b^2 - 4 u* c S)), b = u* S + c + 1; then
Eqs. A.1 and A.3 give the gap H/R = 2 (R1 cos(alpha + theta) - 1 + cos(alpha)). As for the exact
bridge, H rises from 0 (alpha -> 0) to the rupture distance and falls through contact; the
stable branch is the one of larger alpha. Volume and force at each node come from
pendular.capillary.toroidal_bridge (Eq. A.7 with the erratum in docs/physics.md 'Errata', force at
the contact line). Units as docs/units.md with R2 = R the sphere radius; nn11, nn33 are not defined
(NaN).
"""

import math

import numpy as np

from pendular.capillary.table import BridgeTable, distance_fraction, suction_nodes
from pendular.capillary.toroidal import toroidal_bridge
from pendular.capillary.validation import check_contact_angle, check_positive

_GOLDEN = 0.5 * (math.sqrt(5.0) - 1.0)


def toroidal_gap(filling_angle, contact_angle, suction_star):
    """Gap H/R of the toroidal bridge of filling angle alpha [rad] at suction u* (theta in rad);
    numpy-vectorised over its arguments."""
    sine = np.sin(filling_angle)
    c = 1.0 - np.sin(filling_angle + contact_angle)
    b = suction_star * sine + c + 1.0
    meridian = 2.0 * sine / (b + np.sqrt(b * b - 4.0 * suction_star * c * sine))
    return 2.0 * (meridian * np.cos(filling_angle + contact_angle) - 1.0 + np.cos(filling_angle))


def _rupture(theta, suction, largest):
    """(alpha_rupture, H_rupture) per suction: maximum of toroidal_gap over (0, largest)."""
    grid = np.linspace(0.0, largest, 2002)[1:-1]
    gaps = toroidal_gap(grid[None, :], theta, suction[:, None])
    best = np.argmax(gaps, axis=1)
    step = grid[1] - grid[0]
    low = np.maximum(grid[best] - step, 1e-12)
    high = np.minimum(grid[best] + step, largest * (1.0 - 1e-12))
    for _ in range(80):  # golden-section search, vectorised over the suctions
        left = high - _GOLDEN * (high - low)
        right = low + _GOLDEN * (high - low)
        keep_left = toroidal_gap(left, theta, suction) > toroidal_gap(right, theta, suction)
        high = np.where(keep_left, right, high)
        low = np.where(keep_left, low, left)
    alpha = 0.5 * (low + high)
    return alpha, toroidal_gap(alpha, theta, suction)


def _stable_filling_angle(theta, suction, gap, alpha_rupture, largest):
    """alpha on the stable branch (alpha >= alpha_rupture) with toroidal_gap = gap (bisection)."""
    low = alpha_rupture.copy()
    high = np.full_like(low, largest)
    for _ in range(100):
        middle = 0.5 * (low + high)
        above = toroidal_gap(middle, theta, suction) > gap
        low = np.where(above, middle, low)
        high = np.where(above, high, middle)
    return 0.5 * (low + high)


def toroidal_table(contact_angle=0.0, suction_max=15000.0, n_suction=64, n_distance=80, suction_scale=0.1):
    """BridgeTable (r = 1 only) of toroidal bridges over u* in [0, suction_max] and the gap.

    contact_angle in [0, 90) deg. Nodes follow BridgeTable's layout (xi = ln(1 + u*/scale)
    uniform, distance coordinate z from rupture to contact). Checks every node's suction from
    pendular.capillary.toroidal_bridge against the one it was solved for.
    """
    contact_angle = check_contact_angle(contact_angle)
    suction_max = check_positive("suction_max", suction_max)
    theta = math.radians(contact_angle)
    largest = 0.5 * math.pi - theta
    suction = suction_nodes(suction_scale, suction_max, int(n_suction))
    alpha_rupture, distance_rupture = _rupture(theta, suction, largest)
    distance_low = np.maximum(0.0, toroidal_gap(largest, theta, suction))
    values = np.full((1, len(suction), int(n_distance), 6), np.nan)
    for j in range(int(n_distance)):
        if j == 0:
            alpha = alpha_rupture
            gap = distance_rupture
        else:
            gap = distance_low + (distance_rupture - distance_low) * distance_fraction(j / (n_distance - 1))
            alpha = _stable_filling_angle(theta, suction, gap, alpha_rupture, largest)
        for k, (u, a, h) in enumerate(zip(suction, alpha, gap)):
            bridge = toroidal_bridge(math.degrees(a), contact_angle, max(h, 0.0))
            if not math.isclose(bridge.suction_star, u, rel_tol=1e-6, abs_tol=1e-7):
                raise RuntimeError(f"toroidal table: node u* = {u} solved to u* = {bridge.suction_star}")
            values[0, k, j, :4] = (bridge.force, bridge.volume, math.degrees(a), math.degrees(a))
    return BridgeTable(
        contact_angle, [1.0], suction_scale, suction_max, distance_low[None, :], distance_rupture[None, :], values
    )
