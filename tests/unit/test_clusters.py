"""Liquid clusters of filled pore units (pendular.capillary.clusters) on hand-made fillings."""

import math

import numpy as np
import pytest

from pendular.capillary import clusters, pores

RADIUS = 1.0e-4  # m
SPACING = 2.0 * RADIUS  # simple cubic lattice of touching grains


def cubic_lattice(cells):
    """Centres of a simple cubic lattice of ``cells``^3 grains, off the cell's faces."""
    grid = np.stack(np.meshgrid(*[np.arange(cells)] * 3, indexing="ij"), -1).reshape(-1, 3)
    return (grid + 0.125) * SPACING


def test_two_units_sharing_a_throat():
    # a triangular bipyramid: two tetrahedra on one face
    centres = np.array([[0, 0, 0], [2, 0, 0], [1, math.sqrt(3), 0],
                        [1, 1 / math.sqrt(3), 1.6], [1, 1 / math.sqrt(3), -1.6]]) * RADIUS
    units = pores.decompose(centres, np.full(5, RADIUS))
    assert units.count == 2
    both = clusters.find_clusters(units, np.array([True, True]))
    assert both.count == 1 and both.units.tolist() == [2]
    assert both.volume[0] == pytest.approx(units.pore_volume.sum(), rel=1e-14)
    one = clusters.find_clusters(units, np.array([False, True]))
    assert one.count == 1 and one.label.tolist() == [-1, 0] and one.largest == 0
    none = clusters.find_clusters(units, np.array([False, False]))
    assert none.count == 0 and none.largest == -1 and not none.percolates.any()


def test_separate_clusters_and_the_largest_between_walls():
    cells = 4
    centres = cubic_lattice(cells)
    units = pores.decompose(centres, np.full(len(centres), RADIUS))
    centroid = units.vertices.mean(axis=1) / SPACING
    low = centroid[:, 0] < 1.0           # a slab at the low x wall
    high = centroid[:, 0] > 2.0          # a thicker slab at the high x wall
    found = clusters.find_clusters(units, low | high)
    assert found.count == 2
    assert sorted(found.units.tolist()) == sorted([low.sum(), high.sum()])
    assert found.volume[found.largest] == pytest.approx(units.pore_volume[high].sum(), rel=1e-12)
    assert found.percolates.tolist() == [False, True, True]
    everything = clusters.find_clusters(units, np.ones(units.count, bool))
    assert everything.count == 1 and everything.percolates.all()
    assert everything.volume[0] == pytest.approx(units.pore_volume.sum(), rel=1e-12)


def test_percolation_in_a_periodic_cell_is_wrapping():
    cells = 4
    centres = cubic_lattice(cells)
    period = np.full(3, cells * SPACING)
    units = pores.decompose(centres, np.full(len(centres), RADIUS), period=period)
    centroid = units.vertices.mean(axis=1) / SPACING
    slab = centroid[:, 2] < 1.0
    # the units of one column of the lattice's cubes (cube centres at i + 0.625 spacings)
    column = (np.abs(centroid[:, 0] - 2.625) < 0.5) & (np.abs(centroid[:, 1] - 2.625) < 0.5)
    half_slab = slab & (centroid[:, 0] < 2.0)   # crosses no x face: does not wrap along x
    for filled, expected in ((slab, [True, True, False]), (column, [False, False, True]),
                             (half_slab, [False, True, False]),
                             (np.ones(units.count, bool), [True, True, True])):
        found = clusters.find_clusters(units, filled)
        assert found.count == 1
        assert found.percolates.tolist() == expected
    # a slab touching the cell's low z face and its image at the high face are one cluster
    split = (centroid[:, 2] < 0.5) | (centroid[:, 2] > 3.5)
    assert clusters.find_clusters(units, split).count == 1


def test_percolation_in_a_sheared_cell_counts_its_images_shifted_along_x():
    """Lees–Edwards images (the image above in z shifted by delta along x): a slab of half the
    cell across x climbs through the z faces as a staircase (it wraps along y and z, not x),
    whatever the offset."""
    cells = 4
    centres = cubic_lattice(cells)
    for offset in (0.5, 1.3, -1.7):
        period = np.array([*[cells * SPACING] * 3, offset * SPACING])
        units = pores.decompose(centres, np.full(len(centres), RADIUS), period=period)
        centroid = pores.into_cell(units.vertices.mean(axis=1), period) / SPACING
        for filled, expected in ((centroid[:, 2] < 1.0, [True, True, False]),
                                 (centroid[:, 0] < 2.0, [False, True, True]),
                                 (centroid[:, 1] < 2.0, [True, False, True]),
                                 (np.ones(units.count, bool), [True, True, True])):
            found = clusters.find_clusters(units, filled)
            assert found.count == 1
            assert found.percolates.tolist() == expected, offset
        one = clusters.find_clusters(units, np.arange(units.count) == 0)
        assert one.count == 1 and not one.percolates.any()


def test_filled_must_be_one_bool_per_unit():
    centres = cubic_lattice(2)
    units = pores.decompose(centres, np.full(len(centres), RADIUS))
    with pytest.raises(ValueError, match=r"filled must be a bool array of shape \(\d+,\)"):
        clusters.find_clusters(units, np.ones(units.count + 1, bool))
