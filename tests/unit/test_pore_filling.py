"""Drainage, imbibition and the liquid's account on pore units (pendular.capillary.pore_filling)
and the forces of filled units (pendular.capillary.cluster_forces), against closed forms and
independent quadratures."""

import math

import numpy as np
import pytest

from pendular.capillary import cluster_forces, clusters, pore_filling, pores
from pendular.capillary.meniscus import bridge_kernel

RADIUS = 1.0e-4            # m
GAMMA = 0.073              # N/m


def touching_tetrahedron(radii):
    """Centres of four mutually touching spheres of ``radii``."""
    r1, r2, r3, r4 = radii
    c1 = np.zeros(3)
    c2 = np.array([r1 + r2, 0.0, 0.0])
    d13, d23 = r1 + r3, r2 + r3
    x = (d13 ** 2 - d23 ** 2 + c2[0] ** 2) / (2 * c2[0])
    c3 = np.array([x, math.sqrt(d13 ** 2 - x ** 2), 0.0])
    a = np.array([c2, c3])
    d = np.array([r1 + r4, r2 + r4, r3 + r4])
    # |c4 - ci| = d_i: linear in (x, y) from differences, then z
    rhs = 0.5 * (d[0] ** 2 - d[1:] ** 2 + np.sum(a * a, axis=1))
    xy = np.linalg.solve(a[:, :2], rhs)
    z = math.sqrt(d[0] ** 2 - xy @ xy)
    return np.array([c1, c2, c3, [xy[0], xy[1], z]])


@pytest.mark.parametrize("radii", [(1.0, 1.0, 1.0, 1.0), (1.0, 1.2, 0.8, 1.5)])
def test_pore_body_radius_is_the_soddy_sphere_of_touching_grains(radii):
    radii = np.array(radii) * RADIUS
    vertices = touching_tetrahedron(radii)[None]
    found = pore_filling.pore_body_radius(vertices, radii[None])[0]
    # Soddy-Gossett: (sum k)^2 = 3 sum k^2 over the five curvatures; the inner sphere's k
    k = 1.0 / radii
    b, c = -2.0 * k.sum(), 3.0 * np.sum(k * k) - k.sum() ** 2
    inner = (-b + math.sqrt(b * b - 8.0 * c)) / 4.0            # 2 k^2 + b k + c = 0, the larger
    assert found == pytest.approx(1.0 / inner, rel=1e-10)
    if np.ptp(radii) == 0:
        assert found == pytest.approx(RADIUS * (math.sqrt(1.5) - 1.0), rel=1e-12)


def test_a_flat_unit_has_no_pore_body():
    vertices = np.array([[[0, 0, 0], [2, 0, 0], [1, 1.7, 0], [1, 0.6, 0.05]]]) * RADIUS
    assert np.isnan(pore_filling.pore_body_radius(vertices, np.full((1, 4), RADIUS)))[0]


def random_packing(cells=5, seed=3):
    """A jittered cubic lattice of grains that do not touch: every throat open."""
    rng = np.random.default_rng(seed)
    grid = np.stack(np.meshgrid(*[np.arange(cells)] * 3, indexing="ij"), -1).reshape(-1, 3)
    centres = grid * 2.6 * RADIUS + rng.uniform(-0.25, 0.25, grid.shape) * RADIUS
    return centres, rng.uniform(0.9, 1.1, len(grid)) * RADIUS


@pytest.fixture(scope="module")
def packing():
    centres, radius = random_packing()
    units = pores.decompose(centres, radius)
    return centres, radius, units, pore_filling.filling_thresholds(units, radius, GAMMA)


def test_filling_is_never_above_the_entry_of_its_throats(packing):
    _, _, units, thresholds = packing
    entry = thresholds.throat_entry[units.throat_of]
    assert np.all(thresholds.filling <= entry.min(axis=1) * (1 + 1e-12))
    # a throat too wide for any meniscus (a flat hull face) opens at any suction
    wide = (thresholds.throat_entry[units.throat_of] == 0).any(axis=1)
    assert np.all(thresholds.filling[~wide] > 0) and np.all(thresholds.filling[wide] == 0)


def test_drainage_is_monotone_and_goes_from_the_gas(packing):
    _, _, units, thresholds = packing
    full = np.ones(units.count, bool)
    entry = thresholds.throat_entry
    finite = entry[np.isfinite(entry) & (entry > 0)]
    kept = pore_filling.drain(units, thresholds, full, 0.99 * finite.min())
    assert kept.sum() > 0.9 * units.count
    assert not pore_filling.drain(units, thresholds, full, 1.01 * finite.max()).any()
    previous = full
    for suction in np.geomspace(finite.min(), finite.max(), 12):
        now = pore_filling.drain(units, thresholds, full, suction)
        assert not (now & ~previous).any()
        previous = now
        # every emptied unit is joined to the hull through throats open at this suction
        gas = ~now
        first, second = units.throat_units.T
        opened = thresholds.throat_entry < suction
        reached = np.zeros(units.count, bool)
        reached[first[(second < 0) & opened & gas[first]]] = True
        for _ in range(units.count):
            step = reached.copy()
            inner = (second >= 0) & opened
            step[second[inner & reached[first]]] = True
            step[first[inner & reached[np.maximum(second, 0)]]] = True
            step &= gas
            if (step == reached).all():
                break
            reached = step
        assert (reached == gas).all()


def test_a_unit_behind_closed_throats_stays_filled(packing):
    _, _, units, thresholds = packing
    inner = np.flatnonzero((units.neighbours >= 0).all(axis=1))[0]
    entry = np.full(len(units.throat_units), 10.0)        # every throat closed at 5 Pa ...
    entry[units.throat_of[inner]] = 1.0                   # ... but the inner unit's own
    closed = pore_filling.FillingThresholds(entry, thresholds.filling)
    after = pore_filling.drain(units, closed, np.ones(units.count, bool), 5.0)
    assert after.all()
    entry[:] = 1.0                                        # all open: all empty
    assert not pore_filling.drain(units, closed, np.ones(units.count, bool), 5.0).any()


def test_wetting_holds_less_than_drying_at_each_suction(packing):
    _, _, units, thresholds = packing
    suctions = np.geomspace(0.5 * thresholds.filling[thresholds.filling > 0].min(), 2.0 * np.max(
        thresholds.throat_entry[np.isfinite(thresholds.throat_entry)]), 15)
    filled = np.ones(units.count, bool)
    drying = []
    for s in suctions:
        filled = pore_filling.drain(units, thresholds, pore_filling.imbibe(thresholds, filled, s),
                                    s)
        drying.append(filled)
    assert not filled.any()
    for s, dry in zip(suctions[::-1], drying[::-1]):
        filled = pore_filling.drain(units, thresholds, pore_filling.imbibe(thresholds, filled, s),
                                    s)
        assert not (filled & ~dry).any()
    assert filled[thresholds.filling > 0].all()           # back to saturation at the lowest
    assert any((d & ~w).any() for d, w in zip(drying, [
        pore_filling.imbibe(thresholds, np.zeros(units.count, bool), s) for s in suctions]))


def test_bridge_shares_and_the_liquid_account(packing):
    _, radius, units, _ = packing
    edges = pore_filling.unit_edges(units)
    everything = np.ones(units.count, bool)
    share = edges.filled_share(everything)
    # the units around an inner edge fill 2 pi
    inner_grain = np.setdiff1d(np.arange(len(radius)),
                               units.grains[(units.neighbours < 0).any(axis=1)].ravel())
    inner = np.isin(edges.pair, inner_grain).all(axis=1)
    assert np.allclose(share[inner], 1.0, atol=1e-12)
    pair_edge = edges.of_pairs(edges.pair[:, 0], edges.pair[:, 1])
    assert (pair_edge == np.arange(len(edges.pair))).all()
    assert edges.of_pairs(np.array([0]), np.array([0]))[0] == -1
    beyond = int(edges.pair.max()) + 1               # a grain on no edge: none found
    assert (edges.of_pairs(np.array([0, 1]), np.array([beyond, beyond + 5])) == -1).all()
    volume = np.full(len(edges.pair), 1e-15)
    half = np.zeros(units.count, bool)
    half[::2] = True
    found = clusters.find_clusters(units, half)
    account = pore_filling.liquid_account(units, edges, found, volume, pair_edge)
    assert account.clusters == pytest.approx(units.pore_volume[half].sum(), rel=1e-12)
    assert account.bridges + account.absorbed == pytest.approx(volume.sum(), rel=1e-12)
    assert account.absorbed == pytest.approx(np.sum(volume * edges.filled_share(half)),
                                             rel=1e-12)
    empty = pore_filling.liquid_account(units, edges, clusters.find_clusters(
        units, np.zeros(units.count, bool)), volume, pair_edge)
    assert empty.bridges == volume.sum() and empty.clusters == 0 and empty.absorbed == 0


def test_cap_force_is_the_exact_bridge_force():
    # the bridge solver's force (thesis Eq. 3.48) on sphere 1 of a bridge of equal spheres
    for theta, suction_star, delta in ((0.0, 2.0, 0.3), (0.4, 10.0, 0.15), (0.2, 0.5, 0.6)):
        force_star = bridge_kernel(1.0, theta, suction_star, delta)[2]
        exact = force_star * 2 * math.pi * GAMMA * RADIUS
        suction = suction_star * GAMMA / RADIUS
        assert cluster_forces.cap_force(suction, GAMMA, theta, RADIUS, delta) == \
            pytest.approx(exact, rel=1e-12)


def test_cone_area_vector_against_a_quadrature(packing):
    _, radius, units, _ = packing
    forces = cluster_forces.UnitForces(units.vertices, radius[units.grains])
    rng = np.random.default_rng(7)
    direction = rng.normal(size=(400000, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    for u in rng.choice(np.flatnonzero(~units.protrudes), 3, replace=False):
        for k in range(2):
            others = units.vertices[u, pores.FACES[k]] - units.vertices[u, k]
            weights = np.linalg.solve(others.T, direction.T).T
            inside = (weights >= 0).all(axis=1)
            area = 4 * math.pi * np.mean(direction * inside[:, None], axis=0)   # ∫ n dOmega
            expected = area * radius[units.grains[u, k]] ** 2
            error = np.linalg.norm(forces.cone[u, k] - expected)
            noise = 4 * math.pi / math.sqrt(len(direction)) * radius.max() ** 2
            assert error < 5 * noise


def test_moved_unit_forces_are_those_of_the_units_at_their_new_positions(packing):
    """UnitForces.moved (the forces following the grains) recomputes the units given, their
    faces keeping their sides, exactly as the coefficients of all units at the new
    positions; the other units keep theirs."""
    _, radius, units, _ = packing
    radii = radius[units.grains]
    forces = cluster_forces.UnitForces(units.vertices, radii)
    shifted = units.vertices + np.random.default_rng(3).normal(0.0, 0.02 * RADIUS,
                                                               units.vertices.shape)
    every = cluster_forces.UnitForces(shifted, radii, forces.sides)
    moved_units = np.flatnonzero(np.arange(units.count) % 3 == 0)
    moved = forces.moved(moved_units, shifted[moved_units], radii[moved_units])
    kept = np.setdiff1d(np.arange(units.count), moved_units)
    for name in ("sides", "open_area", "cone", "meniscus"):
        assert np.array_equal(getattr(moved, name)[moved_units],
                              getattr(every, name)[moved_units]), name
        assert np.array_equal(getattr(moved, name)[kept], getattr(forces, name)[kept]), name


def test_a_filled_regular_tetrahedron_pulls_each_grain_to_its_centre():
    vertices = touching_tetrahedron(np.full(4, RADIUS))
    units = pores.decompose(vertices, np.full(4, RADIUS))
    forces = cluster_forces.UnitForces(units.vertices, np.full((1, 4), RADIUS))
    suction = 1000.0
    force = cluster_forces.cluster_forces(units, forces, np.array([True]), suction, 4)
    towards = vertices.mean(axis=0) - vertices
    towards /= np.linalg.norm(towards, axis=1, keepdims=True)
    # s [pi R^2/6 (the cone) + A/3 (a third of each of three menisci)], A = (sqrt 3 - pi/2) R^2
    magnitude = suction * RADIUS ** 2 / math.sqrt(3.0)
    assert np.allclose(force, magnitude * towards, rtol=0, atol=1e-12 * magnitude)


def test_cluster_forces_balance_and_vanish_inside(packing):
    centres, radius, units, _ = packing
    forces = cluster_forces.UnitForces(units.vertices, radius[units.grains])
    rng = np.random.default_rng(1)
    filled = rng.uniform(size=units.count) < 0.6
    found = clusters.find_clusters(units, filled)
    scale = 1e3 * RADIUS ** 2
    for cluster in range(found.count):
        one = found.label == cluster
        force = cluster_forces.cluster_forces(units, forces, one, 1e3, len(radius))
        assert np.abs(force.sum(axis=0)).max() < 1e-12 * scale
    everything = cluster_forces.cluster_forces(units, forces, np.ones(units.count, bool), 1e3,
                                               len(radius))
    inner = np.setdiff1d(np.arange(len(radius)),
                         units.grains[(units.neighbours < 0).any(axis=1)].ravel())
    assert len(inner) > 5
    assert np.abs(everything[inner]).max() < 1e-12 * scale
    stress = cluster_forces.cluster_stress(units, forces, filled, 1e3, 1e-9)
    assert np.isfinite(stress).all()
    # with the grains moved, the stress of the forces there is -(1/V) sum x (x) F over the
    # grains at their new positions (the forces balance, so the origin does not matter)
    moved = centres + np.random.default_rng(2).normal(0.0, 0.02 * RADIUS, centres.shape)
    at = moved[units.grains]
    followed = forces.moved(np.arange(units.count), at, radius[units.grains])
    grain_force = cluster_forces.cluster_forces(units, followed, filled, 1e3, len(radius))
    expected = -np.einsum("ki,kj->ij", moved, grain_force) / 1e-9
    found = cluster_forces.cluster_stress(units, followed, filled, 1e3, 1e-9, vertices=at)
    assert np.allclose(found, expected, rtol=0, atol=1e-9 * np.abs(expected).max())


def test_pore_units_coloured_by_cluster_for_paraview(packing, tmp_path):
    import meshio

    from pendular.io.vtk import pore_mesh, write_vtu

    _, _, units, _ = packing
    filled = np.zeros(units.count, bool)
    filled[: units.count // 3] = True
    found = clusters.find_clusters(units, filled)
    write_vtu(tmp_path / "pores.vtu", pore_mesh(units, found.label), field_data={"stage": 3})
    back = meshio.read(tmp_path / "pores.vtu")
    assert back.cells[0].type == "tetra" and len(back.cells[0].data) == units.count
    assert np.array_equal(back.cell_data["cluster"][0], found.label)
    corners = back.points[back.cells[0].data]
    assert np.allclose(corners, units.vertices)


def test_a_saturated_periodic_cell_drains_from_its_weakest_unit():
    centres, radius = random_packing(cells=4, seed=5)
    period = np.full(3, 4 * 2.6 * RADIUS)
    units = pores.decompose(np.mod(centres, period), radius, period=period)
    thresholds = pore_filling.filling_thresholds(units, radius, GAMMA)
    full = np.ones(units.count, bool)
    entry = thresholds.throat_entry
    assert pore_filling.drain(units, thresholds, full, 0.999 * entry.min()).all()
    assert not pore_filling.drain(units, thresholds, full, 1.001 * entry.max()).any()
    partly = pore_filling.drain(units, thresholds, full, np.median(entry))
    assert 0 < partly.sum() < units.count
