"""Pore units of sphere packings (pendular.capillary.pores) against closed forms and Monte Carlo."""

import math

import numpy as np
import pytest
from scipy.spatial import ConvexHull, Delaunay, cKDTree

from pendular.capillary import pores

RADIUS = 1.0e-4  # m: sand-sized grains, so that SI magnitudes are exercised


def regular_tetrahedron(edge):
    """(4, 3) vertices of a regular tetrahedron of edge ``edge`` centred at the origin."""
    return np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float) * edge / math.sqrt(8)


def random_spheres(count, box, radius_range, overlap, seed):
    """Random sequential addition of ``count`` spheres in ``box`` (3,) [m], centres at least a
    radius from the faces, pairs overlapping by at most ``overlap`` times the smaller radius."""
    rng = np.random.default_rng(seed)
    centres, radii = [], []
    while len(centres) < count:
        r = rng.uniform(*radius_range)
        c = rng.uniform(r, np.asarray(box) - r)
        if centres:
            gap = np.linalg.norm(np.array(centres) - c, axis=1) - np.array(radii) - r
            if (gap < -overlap * np.minimum(np.array(radii), r)).any():
                continue
        centres.append(c)
        radii.append(r)
    return np.array(centres), np.array(radii)


def sample_in_tetrahedron(vertices, count, rng):
    """``count`` points uniform in the tetrahedron ``vertices`` (4, 3) (Dirichlet barycentrics)."""
    return rng.dirichlet(np.ones(4), count) @ vertices


def mc_tolerance(fraction, count, volume):
    """Five standard deviations of a Monte Carlo volume estimate of ``fraction`` of ``volume``
    from ``count`` uniform points (binomial variance)."""
    return 5.0 * volume * math.sqrt(fraction * (1.0 - fraction) / count)


def test_regular_tetrahedron_of_touching_spheres_matches_its_closed_form():
    edge = 2 * RADIUS
    units = pores.decompose(regular_tetrahedron(edge), np.full(4, RADIUS))
    volume = edge ** 3 / (6 * math.sqrt(2))
    # solid angle at a vertex of a regular tetrahedron: 3 dihedral angles - pi = arccos(23/27)
    omega = 3 * math.acos(1 / 3) - math.pi
    assert units.count == 1
    assert units.volume[0] == pytest.approx(volume, rel=1e-13)
    np.testing.assert_allclose(units.solid_angle[0], math.acos(23 / 27), rtol=1e-13)
    np.testing.assert_allclose(units.solid_angle[0], omega, rtol=1e-13)
    assert units.pore_volume[0] == pytest.approx(volume - 4 * omega * RADIUS ** 3 / 3, rel=1e-12)
    np.testing.assert_allclose(units.grain_area[0], omega * RADIUS ** 2, rtol=1e-13)
    np.testing.assert_allclose(units.throat_radius[0], RADIUS * (2 / math.sqrt(3) - 1), rtol=1e-12)
    assert not units.protrudes[0]
    assert (units.neighbours == -1).all() and len(units.throat_units) == 4


def test_overlapping_tetrahedron_pore_volume_against_monte_carlo():
    """Lenses: a regular tetrahedron of edge 1.8 R (pairwise overlaps, no triple point since
    the face's circumradius 1.8 R / sqrt 3 > R)."""
    vertices = regular_tetrahedron(1.8 * RADIUS)
    units = pores.decompose(vertices, np.full(4, RADIUS))
    count = 400_000
    points = sample_in_tetrahedron(vertices, count, np.random.default_rng(7))
    solid = (np.linalg.norm(points[:, None] - vertices[None], axis=2) < RADIUS).any(axis=1)
    void = 1.0 - solid.mean()
    expected = void * units.volume[0]
    assert units.pore_volume[0] == pytest.approx(
        expected, abs=mc_tolerance(void, count, units.volume[0]))
    # the lenses matter here: without them the estimate would be far off
    sectors = units.volume[0] - units.solid_angle[0].sum() * RADIUS ** 3 / 3
    assert abs(sectors - expected) > 10 * mc_tolerance(void, count, units.volume[0])


def test_lens_volume_closed_forms():
    r = RADIUS
    assert pores.lens_volume(2 * r, r, r) == 0.0
    assert pores.lens_volume(0.0, r, r) == pytest.approx(4 / 3 * math.pi * r ** 3)
    # two equal balls at distance d: pi (4 r + d)(2 r - d)^2 / 12
    d = 1.3 * r
    lens = math.pi * (4 * r + d) * (2 * r - d) ** 2 / 12
    assert pores.lens_volume(d, r, r) == pytest.approx(lens, rel=1e-13)
    assert pores.lens_volume(0.5 * r, r, 3 * r) == pytest.approx(4 / 3 * math.pi * r ** 3)


def lattice(kind, cells, spacing):
    """Centres of a simple cubic or face-centred cubic lattice of ``cells``^3 cubes of side
    ``spacing``, shifted off the cell's faces."""
    grid = np.stack(np.meshgrid(*[np.arange(cells)] * 3, indexing="ij"), -1).reshape(-1, 3)
    if kind == "fcc":
        basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]])
        grid = (grid[:, None, :] + basis[None]).reshape(-1, 3)
    return (grid + 0.125) * spacing


@pytest.mark.parametrize("kind, spacing, porosity", [
    ("sc", 2.0, 1 - math.pi / 6),                                   # 0.4764
    ("fcc", 2 * math.sqrt(2), 1 - math.pi / (3 * math.sqrt(2)))])  # 0.2595
def test_regular_packings_have_their_porosity(kind, spacing, porosity):
    cells = 3
    centres = lattice(kind, cells, spacing * RADIUS)
    period = np.full(3, cells * spacing * RADIUS)
    units = pores.decompose(centres, np.full(len(centres), RADIUS), period=period)
    cell_volume = np.prod(period)
    assert units.volume.sum() == pytest.approx(cell_volume, rel=1e-12)
    assert units.pore_volume.sum() / cell_volume == pytest.approx(porosity, rel=1e-12)
    np.testing.assert_allclose(units.grain_solid_angle(len(centres)), 4 * math.pi, rtol=1e-12)
    assert (units.neighbours >= 0).all()


def check_throats(units):
    """Each throat joins two units sharing exactly the three grains of its face, and both see
    the same throat."""
    inner = units.throat_units[:, 1] >= 0
    for u, v in units.throat_units[inner]:
        assert len(np.intersect1d(units.grains[u], units.grains[v])) == 3
    rows = np.repeat(np.arange(units.count), 4)
    throat = units.throat_of.ravel()
    assert ((units.throat_units[throat, 0] == rows) | (units.throat_units[throat, 1] == rows)).all()
    assert np.bincount(throat).max() == 2
    one_side = np.empty(len(units.throat_units))
    one_side[throat] = units.throat_radius.ravel()
    np.testing.assert_allclose(units.throat_radius, one_side[units.throat_of], rtol=1e-9)


def solid_fraction(points, centres, radii, box=None):
    """Fraction of ``points`` inside any ball (periodic in ``box`` if given)."""
    tree = cKDTree(points, boxsize=box)
    solid = np.zeros(len(points), bool)
    for inside in tree.query_ball_point(centres, radii):
        solid[inside] = True
    return solid.mean()


def test_random_periodic_packing_against_monte_carlo():
    box = np.full(3, 12 * RADIUS)
    centres, radii = random_spheres(150, box, (0.6 * RADIUS, 1.2 * RADIUS), 0.2, seed=3)
    centres = np.mod(centres + 0.37 * box, box)  # grains straddle the cell's faces
    units = pores.decompose(centres, radii, period=box)
    cell_volume = np.prod(box)
    assert units.volume.sum() == pytest.approx(cell_volume, rel=1e-12)
    np.testing.assert_allclose(units.grain_solid_angle(len(centres)), 4 * math.pi, rtol=1e-10)
    assert (units.neighbours >= 0).all()
    check_throats(units)
    # the void of the cell, counted independently
    count = 400_000
    points = np.random.default_rng(11).uniform(0, box, (count, 3))
    void = 1.0 - solid_fraction(points, centres, radii, box)
    assert units.pore_volume.sum() == pytest.approx(
        void * cell_volume, abs=mc_tolerance(void, count, cell_volume))


def test_random_packing_between_walls_against_monte_carlo():
    """The units fill the hull of the centres: a random packing inside a cube with a grain at
    each corner, every other grain a radius away from the faces, so the solid inside the hull
    is the inner grains and an octant of each corner grain."""
    side = 10 * RADIUS
    box = np.full(3, side)
    corners = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], float) * side
    inner, inner_radii = random_spheres(120, box, (0.6 * RADIUS, 1.1 * RADIUS), 0.2, seed=5)
    far = np.min(np.linalg.norm(inner[:, None] - corners[None], axis=2), axis=1) > 2.5 * RADIUS
    centres = np.vstack([corners, inner[far]])
    radii = np.concatenate([np.full(8, RADIUS), inner_radii[far]])
    units = pores.decompose(centres, radii)
    assert units.volume.sum() == pytest.approx(ConvexHull(centres).volume, rel=1e-12)
    omega = units.grain_solid_angle(len(centres))
    np.testing.assert_allclose(omega[:8], math.pi / 2, rtol=1e-10)   # an octant at a corner
    np.testing.assert_allclose(omega[8:], 4 * math.pi, rtol=1e-10)
    check_throats(units)
    count = 400_000
    points = np.random.default_rng(13).uniform(0, box, (count, 3))
    void = 1.0 - solid_fraction(points, centres, radii)
    assert units.pore_volume.sum() == pytest.approx(
        void * side ** 3, abs=mc_tolerance(void, count, side ** 3))


def test_bad_input_is_refused_by_name():
    centres = regular_tetrahedron(2 * RADIUS)
    with pytest.raises(ValueError, match="at least 4"):
        pores.decompose(centres[:3], np.full(3, RADIUS))
    with pytest.raises(ValueError, match=r"radius\[1\]"):
        pores.decompose(centres, np.array([RADIUS, -RADIUS, RADIUS, RADIUS]))
    with pytest.raises(ValueError, match="coincides"):
        pores.decompose(np.vstack([centres, centres[:1]]), np.full(5, RADIUS))
    with pytest.raises(ValueError, match=r"position\[\d, \d\] = .* outside the periodic cell"):
        pores.decompose(centres, np.full(4, RADIUS), period=np.full(3, 10 * RADIUS))


def test_beyond_face_volume_is_the_cap_when_the_triangle_holds_its_disk():
    triangle = np.array([[[-10, -10, 0], [10, -10, 0], [0, 10, 0]]], float) * RADIUS
    for h in (0.05, 0.5, 0.95):
        apex = np.array([[0.3, -1.0, h]]) * RADIUS
        cap = math.pi * (RADIUS - h * RADIUS) ** 2 * (2 * RADIUS + h * RADIUS) / 3
        assert pores.beyond_face_volume(apex, np.array([RADIUS]), triangle)[0] == \
            pytest.approx(cap, rel=1e-12)
    far = np.array([[0.0, 0.0, 1.2 * RADIUS]])
    assert pores.beyond_face_volume(far, np.array([RADIUS]), triangle)[0] == 0.0


def test_ball_tetrahedron_volume_against_closed_forms_and_monte_carlo():
    tetrahedron = regular_tetrahedron(6 * RADIUS)[None]
    inscribed = 6 * RADIUS / math.sqrt(24)       # inradius of a regular tetrahedron
    volume = pores.ball_tetrahedron_volume
    # a ball inside, a ball outside, a ball holding the tetrahedron
    assert volume(np.zeros((1, 3)), np.array([0.9 * inscribed]), tetrahedron)[0] == \
        pytest.approx(4 / 3 * math.pi * (0.9 * inscribed) ** 3, rel=1e-12)
    assert volume(np.array([[20 * RADIUS, 0, 0]]), np.array([RADIUS]), tetrahedron)[0] == \
        pytest.approx(0.0, abs=1e-12 * RADIUS ** 3)
    assert volume(np.zeros((1, 3)), np.array([10 * RADIUS]), tetrahedron)[0] == \
        pytest.approx(pores.tetrahedron_volume(tetrahedron)[0], rel=1e-12)
    # balls across faces, edges and corners, inside and outside the tetrahedron
    rng = np.random.default_rng(17)
    centres = rng.uniform(-3 * RADIUS, 3 * RADIUS, (6, 3))
    radii = rng.uniform(1.0, 2.5, 6) * RADIUS
    exact = volume(centres, radii, np.repeat(tetrahedron, 6, axis=0))
    count = 200_000
    points = sample_in_tetrahedron(tetrahedron[0], count, rng)
    tet_volume = pores.tetrahedron_volume(tetrahedron)[0]
    for centre, radius, value in zip(centres, radii, exact):
        fraction = (np.linalg.norm(points - centre, axis=1) < radius).mean()
        assert value == pytest.approx(fraction * tet_volume,
                                      abs=mc_tolerance(fraction, count, tet_volume) + 1e-15)


def test_each_unit_holds_its_own_void_even_where_grains_cross_its_faces():
    """Flat units of a random packing, where grains cross the face opposite them and grains of
    neighbouring units reach in, against a Monte Carlo count of the void in each tetrahedron."""
    box = np.full(3, 11 * RADIUS)
    centres, radii = random_spheres(80, box, (0.8 * RADIUS, 1.2 * RADIUS), 0.0, seed=23)
    units = pores.decompose(centres, radii)
    flat = np.flatnonzero(units.protrudes)
    assert len(flat) >= 10
    rng = np.random.default_rng(29)
    count = 20_000
    tree = cKDTree(centres)
    for unit in flat[:10]:
        points = sample_in_tetrahedron(units.vertices[unit], count, rng)
        distance, index = tree.query(points, k=8)
        void = 1.0 - (distance < radii[index]).any(axis=1).mean()
        assert units.pore_volume[unit] == pytest.approx(
            void * units.volume[unit], abs=mc_tolerance(void, count, units.volume[unit]))


def test_periodic_pore_volumes_of_separate_grains_sum_exactly():
    """Without overlaps, the units' pore volumes sum to the cell less the grains, to round-off:
    every part of every ball is counted once, in the unit it lies in."""
    box = np.full(3, 11 * RADIUS)
    centres, radii = random_spheres(80, box, (0.8 * RADIUS, 1.2 * RADIUS), 0.0, seed=31)
    centres = np.mod(centres + 0.5 * box, box)
    units = pores.decompose(centres, radii, period=box)
    assert units.protrudes.any()
    solid = np.sum(4 / 3 * math.pi * radii ** 3)
    assert units.pore_volume.sum() == pytest.approx(np.prod(box) - solid, rel=1e-12)


def sheared_images(centres, period, reach=2):
    """Every image of ``centres`` with shifts in [-reach, reach]^3 of the sheared cell ``period``
    (Lx, Ly, Lz, delta): x + (ix Lx + iz delta, iy Ly, iz Lz), and the grain of each."""
    lx, ly, lz, delta = period
    images, grain = [], []
    for ix in range(-reach, reach + 1):
        for iy in range(-reach, reach + 1):
            for iz in range(-reach, reach + 1):
                images.append(centres + [ix * lx + iz * delta, iy * ly, iz * lz])
                grain.append(np.arange(len(centres)))
    return np.vstack(images), np.concatenate(grain)


def test_a_sheared_cell_is_cut_from_the_triangulation_of_its_images():
    """Lees–Edwards images (pendular.dem.cell): the units are those of the Delaunay
    triangulation of the images whose centroid lies in the box, their throats' shifts the
    sheared lattice's, and without overlaps the pore volumes still sum to the cell less the
    grains."""
    box = np.array([11.0, 12.0, 10.0]) * RADIUS
    period = np.array([*box, 0.37 * box[0]])
    centres, radii = random_spheres(80, box, (0.8 * RADIUS, 1.2 * RADIUS), 0.0, seed=31)
    centres = pores.into_cell(centres + 0.5 * box + [0.0, 0.0, 0.2 * box[2]], period)
    units = pores.decompose(centres, radii, period=period)
    assert units.volume.sum() == pytest.approx(np.prod(box), rel=1e-12)
    solid = np.sum(4 / 3 * math.pi * radii ** 3)
    assert units.pore_volume.sum() == pytest.approx(np.prod(box) - solid, rel=1e-12)
    check_throats(units)
    # the images' triangulation, cut by the box
    images, grain = sheared_images(centres, period)
    triangulation = Delaunay(images)
    centroid = images[triangulation.simplices].mean(axis=1)
    inside = np.all((centroid >= 0) & (centroid < box), axis=1)
    expected = {tuple(np.round(np.sort(images[s].ravel()) / RADIUS, 9))
                for s in triangulation.simplices[inside]}
    found = {tuple(np.round(np.sort(v.ravel()) / RADIUS, 9)) for v in units.vertices}
    assert found == expected and units.count == len(expected)
    assert (sorted(map(tuple, np.sort(grain[triangulation.simplices[inside]], axis=1)))
            == sorted(map(tuple, np.sort(units.grains, axis=1))))
    # across each throat the second unit's face is the first's moved by its shift
    inner = np.flatnonzero(units.throat_units[:, 1] >= 0)

    def face_centre(side):
        unit = units.throat_units[inner, side]
        face = np.argmax(units.throat_of[unit] == inner[:, None], axis=1)
        return units.vertices[unit[:, None], pores.FACES[face]].mean(axis=1)

    move = pores.lattice_vectors(units.throat_shift[inner], period)
    assert np.abs(units.throat_shift[inner]).max() == 1
    np.testing.assert_allclose(face_centre(1), face_centre(0) + move, rtol=0,
                               atol=1e-9 * RADIUS)
