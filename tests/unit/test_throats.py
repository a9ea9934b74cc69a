"""The Mayer–Stowe–Princen entry suction of a throat of three spheres
(pendular.capillary.throats.mayer_stowe_princen_entry) against a closed form of the symmetric
throat, the closed form of wide throats and a grid count of the gas section's area and
boundary."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from pendular.capillary import CapillaryBridges, pore_filling, pores, throats
from pendular.capillary.liquid_clusters import LiquidClusters

RADIUS = 1.0e-4            # m
GAMMA = 0.073              # N/m


def triangle(sides):
    """(3, 3) centres with the distances ``sides`` (d01, d12, d20) [m], in the plane z = 0."""
    d01, d12, d20 = sides
    x = (d01 ** 2 + d20 ** 2 - d12 ** 2) / (2 * d01)
    return np.array([[0.0, 0.0, 0.0], [d01, 0.0, 0.0], [x, math.sqrt(d20 ** 2 - x ** 2), 0.0]])


def entry(centres, radii, angle=0.0):
    return throats.mayer_stowe_princen_entry(np.asarray(centres)[None], np.asarray(radii)[None],
                                           GAMMA, angle)[0]


def symmetric_balance(r, radius):
    """A_gas - r (L_gl + L_gs) of three equal touching spheres at theta = 0, in closed form:
    each corner arc's centre is R + r from two centres 2R apart, at phi = arccos(R / (R + r))
    from their side; a corner holds the triangle (c_i, p, c_j) less two grain sectors of angle
    phi and the arc's sector of angle pi - 2 phi."""
    phi = math.acos(radius / (radius + r))
    height = math.sqrt((radius + r) ** 2 - radius ** 2)
    corner = radius * height - phi * radius ** 2 - r * r * (math.pi - 2 * phi) / 2
    gas = math.sqrt(3) * radius ** 2 - math.pi * radius ** 2 / 2 - 3 * corner
    return gas - r * (3 * r * (math.pi - 2 * phi) + 3 * radius * (math.pi / 3 - 2 * phi))


@pytest.mark.parametrize("radii", [(1.0, 1.0, 1.0), (1.0, 2.0, 3.0), (0.5, 1.0, 2.5)])
def test_throat_radius_of_touching_spheres_follows_descartes(radii):
    """Three mutually touching circles: Descartes, k4 = k1 + k2 + k3 + 2 sqrt(k1 k2 + k2 k3 +
    k3 k1)."""
    r1, r2, r3 = (RADIUS * x for x in radii)
    # triangle of the centres from its sides r1 + r2, r1 + r3, r2 + r3
    a, b = r1 + r2, r1 + r3
    c = r2 + r3
    x3 = (a * a + b * b - c * c) / (2 * a)
    centres = np.array([[0, 0, 0], [a, 0, 0], [x3, math.sqrt(b * b - x3 * x3), 0]])
    k = [1 / r1, 1 / r2, 1 / r3]
    descartes = 1 / (sum(k) + 2 * math.sqrt(k[0] * k[1] + k[1] * k[2] + k[2] * k[0]))
    radius = throats.throat_radius(centres[None], np.array([[r1, r2, r3]]))[0]
    assert radius == pytest.approx(descartes, rel=1e-12)


def test_throat_radius_of_a_gap_and_a_closed_throat():
    # equilateral triangle of side d: the circle through the centre, radius d / sqrt 3 - R
    for side, expected in ((2.4 * RADIUS, 2.4 * RADIUS / math.sqrt(3) - RADIUS),
                           (1.6 * RADIUS, 1.6 * RADIUS / math.sqrt(3) - RADIUS)):
        centres = np.array([[0, 0, 0], [side, 0, 0], [side / 2, side * math.sqrt(3) / 2, 0]])
        radius = throats.throat_radius(centres[None], np.full((1, 3), RADIUS))[0]
        assert radius == pytest.approx(expected, rel=1e-12)
    assert expected < 0  # three overlapping grains close the throat
    assert throats.entry_suction(expected, 0.072) == math.inf


def test_entry_suction_is_young_laplace_through_the_inscribed_circle():
    r = RADIUS * (2 / math.sqrt(3) - 1)
    assert throats.entry_suction(r, 0.072) == pytest.approx(2 * 0.072 / r, rel=1e-14)
    assert throats.entry_suction(r, 0.072, 60.0) == pytest.approx(0.072 / r, rel=1e-12)
    with pytest.raises(ValueError, match=r"contact_angle = 95.0 deg is outside the valid range"):
        throats.entry_suction(r, 0.072, 95.0)
    with pytest.raises(ValueError, match="surface_tension"):
        throats.entry_suction(r, -1.0)


def test_three_equal_touching_spheres_against_the_closed_form():
    centres = triangle([2 * RADIUS] * 3)
    found = entry(centres, [RADIUS] * 3)
    r = brentq(symmetric_balance, 1e-3 * RADIUS, 0.15 * RADIUS, args=(RADIUS,), xtol=1e-16)
    assert found == pytest.approx(GAMMA / r, rel=1e-9)
    inscribed = throats.entry_suction(throats.throat_radius(centres[None], np.full((1, 3), RADIUS)),
                                    GAMMA)[0]
    assert found < inscribed                   # s R / gamma 11.32 against 12.93


@pytest.mark.parametrize("angle", [0.0, 40.0])
def test_a_wide_throat_opens_where_its_side_bridges_break(angle):
    """Equal spheres a gap g >= R apart: the gas enters once the arc of a side has no neck,
    r = ((R + g/2)^2 - R^2) / (2 R cos theta), the balance holding there without corners
    (A_void >= r cos theta pi R for any g of equal spheres)."""
    gap = 2.0 * RADIUS
    centres = triangle([2 * RADIUS + gap] * 3)
    cosine = math.cos(math.radians(angle))
    r = ((RADIUS + gap / 2) ** 2 - RADIUS ** 2) / (2 * RADIUS * cosine)
    assert entry(centres, [RADIUS] * 3, angle) == pytest.approx(GAMMA / r, rel=1e-9)


def test_the_entry_vanishes_as_the_liquid_stops_wetting():
    centres = triangle([2 * RADIUS] * 3)
    angles = [0.0, 30.0, 60.0, 85.0, 89.0, 89.99]
    found = [entry(centres, [RADIUS] * 3, a) for a in angles]
    assert all(b < a for a, b in zip(found, found[1:]))
    # near 90 deg the corners empty: s -> gamma cos(theta) L_solid / A_void
    void = (math.sqrt(3) - math.pi / 2) * RADIUS ** 2
    limit = GAMMA * math.cos(math.radians(89.99)) * math.pi * RADIUS / void
    assert found[-1] == pytest.approx(limit, rel=1e-3)


def test_closed_and_vectorised():
    centres = np.stack([triangle([1.7 * RADIUS] * 3), triangle([2 * RADIUS] * 3),
                        triangle([2.3 * RADIUS, 2.0 * RADIUS, 2.1 * RADIUS])])
    radii = np.array([[RADIUS] * 3, [RADIUS] * 3, [1.1 * RADIUS, 0.8 * RADIUS, RADIUS]])
    together = throats.mayer_stowe_princen_entry(centres, radii, GAMMA, 20.0)
    assert together[0] == math.inf             # three overlapping grains close the throat
    for k in range(3):
        assert together[k] == entry(centres[k], radii[k], 20.0)
    with pytest.raises(ValueError, match="contact_angle"):
        entry(centres[1], radii[1], 90.0)


def grid_balance(centres, radii, r, angle, pixels=1200, points=12000):
    """A_gas - r (L_gl + cos(theta) L_gs) counted on a grid: the gas is the triangle less the
    grains and the corners; a corner (c_i, t_i, t_j, c_j) holds what lies outside the grains
    and the arc of radius r meeting both grains at theta, where that arc has a neck."""
    c = centres[:, :2]
    cosine = math.cos(math.radians(angle))
    corners = []
    for i, j, k in [(0, 1, 2), (1, 2, 0), (2, 0, 1)]:
        d = np.linalg.norm(c[j] - c[i])
        e = (c[j] - c[i]) / d
        n = np.array([-e[1], e[0]])
        if np.dot(c[k] - c[i], n) < 0:
            n = -n
        rho = [math.sqrt(radii[m] ** 2 + r * r + 2 * radii[m] * r * cosine) for m in (i, j)]
        a = (d * d + rho[0] ** 2 - rho[1] ** 2) / (2 * d)
        if rho[0] ** 2 - a * a < r * r:
            continue                           # no neck: the side has no arc
        p = c[i] + a * e + math.sqrt(rho[0] ** 2 - a * a) * n
        touch = []
        for m, q in ((i, rho[0]), (j, rho[1])):
            # the intersection of grain m's circle and the arc's nearer to the side
            u = (p - c[m]) / q
            b = math.acos(min(1.0, (radii[m] ** 2 + q * q - r * r) / (2 * radii[m] * q)))
            options = [c[m] + radii[m] * np.array([math.cos(s) * u[0] - math.sin(s) * u[1],
                                                   math.sin(s) * u[0] + math.cos(s) * u[1]])
                       for s in (b, -b)]
            touch.append(min(options, key=lambda t: np.dot(t - c[i], n)))
        corners.append((np.array([c[i], touch[0], touch[1], c[j]]), p))

    def cross(u, v):
        return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]

    def in_polygon(x, poly):
        inside = np.ones(len(x), bool)
        sign = np.sign(cross(poly[1] - poly[0], poly[2] - poly[0]))
        for a, b in zip(poly, np.roll(poly, -1, axis=0)):
            inside &= sign * cross(b - a, x - a) >= 0
        return inside

    def liquid_or_solid(x):
        solid = np.zeros(len(x), bool)
        for m in range(3):
            solid |= np.linalg.norm(x - c[m], axis=1) < radii[m]
        liquid = np.zeros(len(x), bool)
        for poly, p in corners:
            liquid |= in_polygon(x, poly) & (np.linalg.norm(x - p, axis=1) > r)
        return solid | liquid

    low, high = c.min(axis=0), c.max(axis=0)
    step = (high - low) / pixels
    axes = [low[a] + (np.arange(pixels) + 0.5) * step[a] for a in range(2)]
    x = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 2)
    x = x[in_polygon(x, c)]
    area = np.count_nonzero(~liquid_or_solid(x)) * step[0] * step[1]
    # the boundary: points on each circle, just off it into the gas side
    solid_length = 0.0
    angles = (np.arange(points) + 0.5) * 2 * math.pi / points
    ring = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    for m in range(3):
        x = c[m] + (radii[m] * (1 + 1e-9)) * ring
        gas = in_polygon(x, c) & ~liquid_or_solid(x)
        solid_length += np.count_nonzero(gas) * 2 * math.pi * radii[m] / points
    liquid_length = 0.0
    for poly, p in corners:
        x = p + (r * (1 - 1e-9)) * ring
        edge = in_polygon(x, poly) & ~liquid_or_solid(x) & in_polygon(x, c)
        liquid_length += np.count_nonzero(edge) * 2 * math.pi * r / points
    return area - r * (liquid_length + cosine * solid_length), area


@pytest.mark.parametrize("angle", [0.0, 30.0])
def test_an_irregular_throat_against_a_grid_count(angle):
    """Unequal spheres, one pair overlapping, one touching, one a gap apart: the balance
    changes sign across the entry found (its grid count within a per mille of A_gas)."""
    radii = np.array([1.0, 0.7, 1.3]) * RADIUS
    centres = triangle([1.68 * RADIUS, 2.15 * RADIUS, 2.3 * RADIUS])
    r = GAMMA / entry(centres, radii, angle)
    above, area_above = grid_balance(centres, radii, 1.02 * r, angle)
    below, area_below = grid_balance(centres, radii, 0.98 * r, angle)
    assert above < 0 < below
    at, area = grid_balance(centres, radii, r, angle)
    assert abs(at) < 1e-3 * area


def test_entry_estimates_in_the_filling_thresholds():
    """On a random packing: the Mayer–Stowe–Princen entries of perfectly wetting water lie
    below the inscribed ones (at them on the faces whose opening lies across a side), the
    filling suctions stay at most every throat's entry."""
    rng = np.random.default_rng(3)
    grid = np.stack(np.meshgrid(*[np.arange(4)] * 3, indexing="ij"), -1).reshape(-1, 3)
    centres = grid * 2.3 * RADIUS + rng.uniform(-0.25, 0.25, grid.shape) * RADIUS
    radius = rng.uniform(0.9, 1.1, len(grid)) * RADIUS
    units = pores.decompose(centres, radius)
    inscribed = pore_filling.filling_thresholds(units, radius, GAMMA)
    msp = pore_filling.filling_thresholds(units, radius, GAMMA, entry="mayer-stowe-princen")
    finite = np.isfinite(inscribed.throat_entry)
    below = msp.throat_entry[finite] < inscribed.throat_entry[finite]
    assert (below | (msp.throat_entry[finite] == inscribed.throat_entry[finite])).all()
    assert np.count_nonzero(below) > len(below) / 2
    assert (msp.filling <= msp.throat_entry[units.throat_of].min(axis=1)).all()
    with pytest.raises(ValueError, match="entry"):
        pore_filling.filling_thresholds(units, radius, GAMMA, entry="circle")
    bridges = CapillaryBridges(2e4, GAMMA, 0.0, persist=True)
    assert LiquidClusters(bridges, entry="mayer-stowe-princen").entry == "mayer-stowe-princen"
    with pytest.raises(ValueError, match="inscribed, mayer-stowe-princen"):
        LiquidClusters(bridges, entry="circle")
