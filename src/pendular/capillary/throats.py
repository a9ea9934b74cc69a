"""The throat between three grains, the face of a pore unit (pendular.capillary.pores): its
inscribed radius and its entry suction, the suction at which gas passes it
(docs/liquid_clusters.md 'Filling criterion and entry suction'): through the inscribed circle
(``entry_suction``) or by the Mayer–Stowe–Princen balance over the throat's section
(``mayer_stowe_princen_entry``); ENTRY_ESTIMATES names them.
"""

import math

import numpy as np

from pendular.capillary.validation import check_contact_angle
from pendular.utils.validate import check_range


def throat_radius(centres, radii):
    """(..., ) [m] radius of the circle in the plane of three sphere centres ``centres`` (..., 3,
    3) [m] tangent to the three great circles of radii ``radii`` (..., 3) [m] from outside
    (Apollonius' problem): the inscribed circle of the throat between three grains, R (2/sqrt 3
    - 1) for three touching equal spheres. Negative where the three grains close the throat.

    With p the circle's centre and r its radius, |p - c_i| = R_i + r; differences of two of
    these are linear in p, which leaves a quadratic in r. Of its roots with R_i + r >= 0 for
    all i (a circle outside every grain) the smaller is the throat."""
    c1, c2, c3 = centres[..., 0, :], centres[..., 1, :], centres[..., 2, :]
    r1, r2, r3 = radii[..., 0], radii[..., 1], radii[..., 2]
    u = c2 - c1
    d12 = np.linalg.norm(u, axis=-1)
    e1 = u / d12[..., None]
    w = c3 - c1
    x3 = np.sum(w * e1, axis=-1)
    y3 = np.linalg.norm(w - x3[..., None] * e1, axis=-1)
    # x = ax + bx r, y = ay + by r in the face's frame (c1 at the origin, c2 on the x axis)
    ax = (d12 ** 2 - r2 ** 2 + r1 ** 2) / (2 * d12)
    bx = -(r2 - r1) / d12
    ay = (x3 ** 2 + y3 ** 2 - r3 ** 2 + r1 ** 2 - 2 * x3 * ax) / (2 * y3)
    by = (-(r3 - r1) - x3 * bx) / y3
    qa = bx ** 2 + by ** 2 - 1.0
    qb = ax * bx + ay * by - r1
    qc = ax ** 2 + ay ** 2 - r1 ** 2
    root = np.sqrt(np.maximum(qb * qb - qa * qc, 0.0))
    q = -(qb + np.copysign(root, qb))
    with np.errstate(divide="ignore", invalid="ignore"):
        roots = np.stack([q / qa, qc / q])
    lowest = -np.minimum(np.minimum(r1, r2), r3)
    valid = np.isfinite(roots) & (roots >= lowest - 1e-12 * np.abs(lowest))
    return np.where(valid, roots, np.inf).min(axis=0)


def entry_suction(throat_radius, surface_tension, contact_angle=0.0):
    """[Pa] suction at which a meniscus passes a throat of inscribed radius ``throat_radius``
    [m]: Young–Laplace for a spherical cap through the inscribed circle, 2 gamma cos(theta) / r
    (``surface_tension`` gamma [N/m], ``contact_angle`` theta [deg]); inf for a closed throat."""
    gamma = check_range("surface_tension", surface_tension, 0.0, math.inf, low_inclusive=False,
                        unit="N/m")
    theta = check_contact_angle(contact_angle)
    r = np.asarray(throat_radius, dtype=float)
    with np.errstate(divide="ignore"):
        return np.where(r > 0, 2.0 * gamma * math.cos(math.radians(theta)) / r, np.inf)


#: Throat entry estimates (``filling_thresholds``'s ``entry``): the inscribed circle's
#: 2 gamma cos(theta) / r_t, or the Mayer–Stowe–Princen balance over the throat's section.
ENTRY_ESTIMATES = ("inscribed", "mayer-stowe-princen")
#: The radii of curvature a Mayer–Stowe–Princen entry is looked for among, scanned from the
#: largest: _MSP_NODES log-spaced from _MSP_HIGHEST r_t / cos(theta) down to _MSP_LOWEST r_t,
#: r_t the inscribed radius; then bisected _MSP_BISECTIONS times between the two nodes that
#: bracket the entry.
_MSP_HIGHEST, _MSP_LOWEST, _MSP_NODES, _MSP_BISECTIONS = 10.0, 1e-3, 41, 40
#: The three sides (i, j) of a throat's triangle, counter-clockwise; the third grain is k.
_SIDES = ((0, 1, 2), (1, 2, 0), (2, 0, 1))


def check_entry_estimate(entry):
    """``entry`` if it is one of ENTRY_ESTIMATES, else ValueError naming them."""
    if entry not in ENTRY_ESTIMATES:
        raise ValueError(f"entry = {entry!r} is not a throat entry estimate; valid: "
                         f"{', '.join(ENTRY_ESTIMATES)}")
    return entry


def mayer_stowe_princen_entry(centres, radii, surface_tension, contact_angle=0.0):
    """(T,) [Pa] Mayer–Stowe–Princen entry suction of throats between three spheres with
    centres ``centres`` (T, 3, 3) [m] and radii ``radii`` (T, 3) [m] (any radii, gaps or
    overlaps; ``surface_tension`` gamma [N/m], ``contact_angle`` theta [deg]); inf for a
    throat its grains close.

    In the plane of the centres the gas that enters the throat is bounded by the grains' great
    circles and by arcs of radius r = gamma / s meeting two grains at the angle theta (the
    liquid left in the corners; a side whose gap is too wide for such an arc, whose neck
    would close, has none, and the gas meets the neighbouring throat across it). The entry is
    the balance of the work of the gas pressure with the surface energy of a meniscus that
    advances through the throat as through a prism (Mayer & Stowe 1965; Princen 1969; Mason &
    Mellor 1995):

        s A_gas = gamma (L_gas-liquid + cos(theta) L_gas-solid),

    at the largest r (the lowest suction) where it holds, the corner arcs not crossing (a
    circular throat of radius a gives 2 gamma / a). Where the triangle of the centres does not
    hold the throat's opening (the inscribed circle's centre outside it, or a grain across
    the side opposite it: flat and obtuse faces, whose opening lies across a side), or no
    balance is found among the radii looked at, the inscribed estimate ``entry_suction``
    stands; a throat the gas enters at the widest radius looked at gets the suction there, an
    upper bound (docs/liquid_clusters.md)."""
    gamma = check_range("surface_tension", surface_tension, 0.0, math.inf, low_inclusive=False,
                        unit="N/m")
    cosine = math.cos(math.radians(check_contact_angle(contact_angle)))
    centres = np.asarray(centres, dtype=float).reshape(-1, 3, 3)
    radii = np.asarray(radii, dtype=float).reshape(-1, 3)
    inscribed = throat_radius(centres, radii)
    suction = entry_suction(inscribed, gamma, contact_angle)
    open_ = np.flatnonzero((inscribed > 0) & np.isfinite(inscribed))
    corner = _plane_triangles(centres[open_])
    posed = _holds_its_opening(corner, radii[open_], inscribed[open_])
    open_ = open_[posed]
    if len(open_) == 0:
        return suction
    throat = _ThroatSection(corner[posed], radii[open_], cosine)
    scale = np.log(inscribed[open_])
    nodes = np.linspace(math.log(_MSP_HIGHEST / cosine), math.log(_MSP_LOWEST), _MSP_NODES)
    low = np.full(len(open_), np.nan)         # the largest node where the gas enters
    for node in nodes:
        free = np.flatnonzero(np.isnan(low))
        if len(free) == 0:
            break
        enters = throat.enters(np.exp(scale[free] + node), free)
        low[free[enters]] = node
    found = np.flatnonzero(np.isfinite(low))
    low = low[found]
    high = np.where(low == nodes[0], low, low + (nodes[0] - nodes[1]))   # at most the widest
    for _ in range(_MSP_BISECTIONS):
        middle = 0.5 * (low + high)
        enters = throat.enters(np.exp(scale[found] + middle), found)
        low, high = np.where(enters, middle, low), np.where(enters, high, middle)
    suction[open_[found]] = gamma / np.exp(scale[found] + 0.5 * (low + high))
    return suction


def _plane_triangles(centres):
    """(T, 3, 2) [m] the triangles of ``centres`` (T, 3, 3) in their planes, counter-clockwise,
    centred on their centroids."""
    u = centres[:, 1] - centres[:, 0]
    length = np.linalg.norm(u, axis=1)
    ex = u / length[:, None]
    w = centres[:, 2] - centres[:, 0]
    x3 = np.sum(w * ex, axis=1)
    y3 = np.linalg.norm(w - x3[:, None] * ex, axis=1)
    corner = np.zeros((len(centres), 3, 2))
    corner[:, 1, 0] = length
    corner[:, 2, 0], corner[:, 2, 1] = x3, y3
    return corner - corner.mean(axis=1, keepdims=True)


def _holds_its_opening(corner, radii, inscribed):
    """(T,) whether the triangles ``corner`` (T, 3, 2) [m] hold the circle of radius
    ``inscribed`` (T,) [m] tangent to their grains of ``radii`` (T, 3) [m] (its centre inside)
    and no grain crosses the side opposite it."""
    reach = radii + inscribed[:, None]
    rows = 2.0 * (corner[:, 1:] - corner[:, :1])                 # |p - c_i| = R_i + r
    rhs = (np.sum(corner[:, 1:] ** 2, axis=2) - np.sum(corner[:, :1] ** 2, axis=2)
           - reach[:, 1:] ** 2 + reach[:, :1] ** 2)
    centre = np.linalg.solve(rows, rhs[..., None])[..., 0]
    holds = np.ones(len(corner), bool)
    for i, j, k in _SIDES:
        side = corner[:, j] - corner[:, i]
        length = np.linalg.norm(side, axis=1)
        holds &= _cross(side, centre - corner[:, i]) >= 0.0
        holds &= _cross(side, corner[:, k] - corner[:, i]) >= radii[:, k] * length
    return holds


class _ThroatSection:
    """The sections of T throats in the planes of their centres (``corner`` (T, 3, 2) [m],
    _plane_triangles; ``radii`` (T, 3) [m]; ``cosine`` of the contact angle), for
    mayer_stowe_princen_entry."""

    def __init__(self, corner, radii, cosine):
        self.corner, self.radii, self.cosine = corner, radii, cosine

    def enters(self, r, which):
        """(W,) whether the gas enters the throats ``which`` (W,) at the radii of curvature
        ``r`` (W,) [m]: the corner arcs leave it a section, and s A_gas >= gamma (L_gl +
        cos(theta) L_gs) there."""
        corner, radii, cosine = self.corner[which], self.radii[which], self.cosine
        count = len(r)
        # the arc of each side: its centre, contact angles on both grains, or none
        start = np.empty((count, 3))          # where each grain's gas boundary starts [rad]
        end = np.empty((count, 3))            # and where it ends (clockwise about the grain)
        area = np.zeros(count)                # 2 A_gas by Green's theorem
        liquid_length = np.zeros(count)
        for i, j, _ in _SIDES:
            ci, cj, ri, rj = corner[:, i], corner[:, j], radii[:, i], radii[:, j]
            side = cj - ci
            distance = np.linalg.norm(side, axis=1)
            along = side / distance[:, None]
            inward = np.stack([-along[:, 1], along[:, 0]], axis=1)
            rho_i = np.sqrt(ri * ri + r * r + 2.0 * ri * r * cosine)
            rho_j = np.sqrt(rj * rj + r * r + 2.0 * rj * r * cosine)
            foot = (distance ** 2 + rho_i ** 2 - rho_j ** 2) / (2.0 * distance)
            height = np.sqrt(np.maximum(rho_i ** 2 - foot ** 2, 0.0))
            centre = ci + foot[:, None] * along + height[:, None] * inward
            # the arc meets grain i at beta_i from the line c_i -> centre, towards the side
            beta_i = np.arccos(np.clip((ri * ri + rho_i ** 2 - r * r) / (2 * ri * rho_i), -1, 1))
            beta_j = np.arccos(np.clip((rj * rj + rho_j ** 2 - r * r) / (2 * rj * rho_j), -1, 1))
            to_i, to_j = centre - ci, centre - cj
            angle_i = np.arctan2(to_i[:, 1], to_i[:, 0]) - beta_i
            angle_j = np.arctan2(to_j[:, 1], to_j[:, 0]) + beta_j
            side_angle = np.arctan2(along[:, 1], along[:, 0])
            above_i = _wrap(angle_i - side_angle) >= 0.0
            above_j = _wrap(side_angle + math.pi - angle_j) >= 0.0
            arc = (rho_i ** 2 - foot ** 2 >= r * r) & above_i & above_j
            end[:, i] = np.where(arc, angle_i, side_angle)
            start[:, j] = np.where(arc, angle_j, side_angle + math.pi)
            point_i = ci + ri[:, None] * _unit(end[:, i])
            point_j = cj + rj[:, None] * _unit(start[:, j])
            from_, to = (np.arctan2(p[:, 1] - centre[:, 1], p[:, 0] - centre[:, 0])
                         for p in (point_i, point_j))
            sweep = np.mod(to - from_, 2.0 * math.pi)
            area += np.where(arc, _arc_area(centre, r, from_, sweep),
                             point_i[:, 0] * point_j[:, 1] - point_j[:, 0] * point_i[:, 1])
            liquid_length += np.where(arc, r * sweep, 0.0)
        span = _wrap(start - end)             # each grain's arc in contact with the gas
        solid_length = np.sum(radii * span, axis=1)
        for k in range(3):
            area += _arc_area(corner[:, k], radii[:, k], start[:, k], -span[:, k])
        valid = np.all(span >= 0.0, axis=1) & (area > 0.0)
        return valid & (0.5 * area >= r * (liquid_length + cosine * solid_length))


def _cross(u, v):
    """(T,) the z component of the cross products of the plane vectors ``u``, ``v`` (T, 2)."""
    return u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]


def _wrap(angle):
    """``angle`` [rad] in (-pi, pi]."""
    return math.pi - np.mod(math.pi - angle, 2.0 * math.pi)


def _unit(angle):
    """(T, 2) the unit vectors at ``angle`` (T,) [rad]."""
    return np.stack([np.cos(angle), np.sin(angle)], axis=1)


def _arc_area(centre, radius, start, sweep):
    """(T,) twice the Green's-theorem area (the integral of x dy - y dx) of arcs of circles
    ``centre`` (T, 2), ``radius`` from the angle ``start`` through ``sweep`` [rad]."""
    stop = start + sweep
    return (radius * radius * sweep
            + radius * centre[:, 0] * (np.sin(stop) - np.sin(start))
            - radius * centre[:, 1] * (np.cos(stop) - np.cos(start)))
