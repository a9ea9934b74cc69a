"""Trimers (pendular.capillary.trimers): the contact lines of two bridges on a grain meet
when the angle between their axes is at most the sum of their filling angles; against the
angles of closed-form triangles, and over a random packing against a loop over its faces."""

import math

import numpy as np
import pytest

from pendular.capillary import pore_filling, pores
from pendular.capillary.bridge_state import AT_CONTACT, NO_BRIDGE, BridgeState
from pendular.capillary.trimers import contact_lines_meet, find_trimers

RADIUS = 1.0e-4            # m


def touching_triangle(radii):
    """Centres (3, 3) [m] of three mutually touching spheres of ``radii`` [m] in a plane."""
    r1, r2, r3 = radii
    d12, d13, d23 = r1 + r2, r1 + r3, r2 + r3
    x = (d12 ** 2 + d13 ** 2 - d23 ** 2) / (2.0 * d12)
    return np.array([[0.0, 0.0, 0.0], [d12, 0.0, 0.0], [x, math.sqrt(d13 ** 2 - x ** 2), 0.0]])


def uniform(angle):
    """(1, 3, 2) [deg] the filling angle ``angle`` of every bridge on every grain."""
    return np.full((1, 3, 2), angle)


def test_equal_touching_spheres_meet_at_thirty_degrees():
    # equilateral: 60 deg between the directions on each grain, met by 30 + 30 deg
    vertices = touching_triangle([RADIUS] * 3)[None]
    assert not contact_lines_meet(vertices, uniform(29.9))[0]
    assert contact_lines_meet(vertices, uniform(30.1))[0]
    short = uniform(30.1)
    short[0, 2] = (29.9, 30.05)                 # 59.95 deg on one grain: not merged there
    assert not contact_lines_meet(vertices, short)[0]
    missing = uniform(80.0)
    missing[0, 1, 0] = np.nan                   # no bridge between grains 1 and 2
    assert not contact_lines_meet(vertices, missing)[0]


@pytest.mark.parametrize("scale", [1.0, 1.0e-3])
def test_a_three_four_five_triangle(scale):
    # radii 1, 2, 3 touching: sides 3, 4, 5, so 90 deg on grain 0, atan(4/3) on grain 1 and
    # atan(3/4) on grain 2
    vertices = touching_triangle(np.array([1.0, 2.0, 3.0]) * scale * RADIUS)
    angles = np.degrees([math.pi / 2.0, math.atan2(4.0, 3.0), math.atan2(3.0, 4.0)])
    for grain in range(3):
        for margin, meets in ((-1e-6, False), (1e-6, True)):
            filling = np.repeat((angles / 2.0 + 1.0)[:, None], 2, axis=1)[None]
            filling[0, grain] = (0.3 * angles[grain], 0.7 * angles[grain] + margin)
            assert contact_lines_meet(vertices[None], filling)[0] == meets


def test_contact_lines_meet_where_their_circles_touch():
    # the caps of two bridges on one grain, sampled: the rim of one comes within the other's
    # half-angle exactly when the axes are within the sum of the half-angles
    rng = np.random.default_rng(5)
    vertices = rng.normal(size=(300, 3, 3))
    filling = rng.uniform(5.0, 80.0, (300, 3, 2))
    meet = contact_lines_meet(vertices, filling)
    phi = np.linspace(0.0, 2.0 * math.pi, 2000, endpoint=False)
    for f in range(len(vertices)):
        expected = True
        for k in range(3):
            a = vertices[f, (k + 1) % 3] - vertices[f, k]
            b = vertices[f, (k + 2) % 3] - vertices[f, k]
            a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
            side = np.cross(a, b)
            side /= np.linalg.norm(side)
            other = np.cross(side, a)             # in the plane of a and b, towards b
            half = math.radians(filling[f, k, 0])
            rim = (math.cos(half) * a[:, None] + math.sin(half)
                   * (other[:, None] * np.cos(phi) + side[:, None] * np.sin(phi)))
            nearest = np.degrees(np.arccos(np.clip(b @ rim, -1.0, 1.0)).min())
            inside = math.degrees(math.acos(np.clip(a @ b, -1, 1))) <= filling[f, k, 0]
            expected &= bool(inside or nearest <= filling[f, k, 1] + 1e-3)
        if abs(_margin(vertices[f], filling[f])) > 1e-2:
            assert meet[f] == expected, f


def _margin(vertices, filling):
    """[deg] the least of sum of filling angles less the angle between the axes, over the
    three grains (how far from the boundary a triangle is)."""
    margins = []
    for k in range(3):
        a = vertices[(k + 1) % 3] - vertices[k]
        b = vertices[(k + 2) % 3] - vertices[k]
        angle = math.degrees(math.acos(a @ b / np.linalg.norm(a) / np.linalg.norm(b)))
        margins.append(filling[k].sum() - angle)
    return min(margins, key=abs)


def test_trimers_of_a_random_packing_against_a_loop_over_its_faces():
    rng = np.random.default_rng(11)
    grid = np.stack(np.meshgrid(*[np.arange(5)] * 3, indexing="ij"), -1).reshape(-1, 3)
    centres = grid * 2.2 * RADIUS + rng.uniform(-0.3, 0.3, grid.shape) * RADIUS
    radius = rng.uniform(0.9, 1.1, len(grid)) * RADIUS
    units = pores.decompose(centres, radius)
    edges = pore_filling.unit_edges(units)
    # the neighbour list: the units' edges and a few pairs that are none, shuffled
    extra = np.array([[0, 124], [3, 77], [10, 99]])
    pairs = np.concatenate([edges.pair, extra])[rng.permutation(len(edges.pair) + 3)]
    count = len(pairs)
    state = np.where(rng.random(count) < 0.9, AT_CONTACT, NO_BRIDGE).astype(np.int8)
    filling_i, filling_j = rng.uniform(20.0, 45.0, (2, count))
    bridges = BridgeState(state=state, volume=rng.uniform(1.0, 2.0, count) * 1e-15,
                          force=np.zeros(count), filling_i=filling_i, filling_j=filling_j,
                          suction=np.zeros(count))
    held = rng.random(units.count) < 0.1
    pair_edge = edges.of_pairs(pairs[:, 0], pairs[:, 1])
    found = find_trimers(units, edges, held, bridges, pairs[:, 0], pairs[:, 1], pair_edge)

    row = {(int(i), int(j)): n for n, (i, j) in enumerate(pairs)}
    wet = set()
    for u in range(units.count):
        if held[u]:
            wet.update(frozenset(units.grains[u, face]) for face in pores.FACES)
    expected, bordering = set(), set()
    for u in range(units.count):
        for face in pores.FACES:
            grains = [int(g) for g in units.grains[u, face]]
            if frozenset(grains) in wet:
                continue
            meets, rows = True, []
            for k in range(3):
                mine = grains[k]
                angle_sum = 0.0
                for other in (grains[(k + 1) % 3], grains[(k + 2) % 3]):
                    n = row[min(mine, other), max(mine, other)]
                    rows.append(n)
                    if state[n] == NO_BRIDGE:
                        angle_sum = -np.inf
                    angle_sum += filling_i[n] if pairs[n, 0] == mine else filling_j[n]
                a = centres[grains[(k + 1) % 3]] - centres[mine]
                b = centres[grains[(k + 2) % 3]] - centres[mine]
                angle = math.degrees(math.acos(a @ b / np.linalg.norm(a) / np.linalg.norm(b)))
                meets &= angle <= angle_sum
            if meets:
                expected.add(frozenset(grains))
                bordering.update(rows)
    unit, face = pores.throat_sides(units)
    throat_grains = units.grains[unit[:, None], pores.FACES[face]]
    got = {frozenset(int(g) for g in throat_grains[t]) for t in np.flatnonzero(found.throats)}
    assert len(expected) > 20 and got == expected and found.count == len(expected)
    assert set(np.flatnonzero(found.bridges)) == bordering
    # each bridge's liquid once, less what filled units hold
    share = rng.random(count)
    liquid = sum(bridges.volume[n] * (1.0 - share[n]) for n in bordering)
    assert found.liquid(bridges.volume, share) == pytest.approx(liquid, rel=1e-12)
