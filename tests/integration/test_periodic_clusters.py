"""Liquid clusters in a periodic cell (pendular.capillary.liquid_clusters; Lees–Edwards images,
pendular.dem.cell): a filled pore unit across the sheared cell's faces pulls on its grains with
forces that sum to zero; the cell's stress is their Love–Weber sum over the grains' unwrapped
positions (the clusters' -V psi_c, LiquidClusters.stress), as where the same unit lies inside
the cell; forces and stress follow the grains through a face."""

import numpy as np
import pytest

from pendular.capillary import CapillaryBridges
from pendular.capillary.liquid_clusters import LiquidClusters
from pendular.capillary.pore_filling import filling_thresholds
from pendular.capillary.pores import into_cell
from pendular.dem.cell import PeriodicCell
from pendular.dem.contact_law import ContactForces
from pendular.dem.integrate import Integrator
from pendular.dem.neighbors import NeighborList
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles
from pendular.homogenize.clusters import cluster_force_stress

RADIUS, GAMMA, DENSITY, YOUNG = 1e-4, 0.073, 2650.0, 1e8
BOX = np.array([12.0, 13.0, 11.0]) * RADIUS
#: A sheared cell: the image above in z is shifted by 0.3 Lx along x.
PERIOD = np.array([*BOX, 0.3 * BOX[0]])
#: A tight tetrahedron of grains (gaps of 0.05 R) about the cell's low x and z faces, its
#: smallest pore: at its filling suction the one unit that fills.
TIGHT = (np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
         * 2.05 * RADIUS / np.sqrt(8.0) + [0.1 * RADIUS, 6.0 * RADIUS, 0.2 * RADIUS])


def sparse_grains():
    """Grains on a jittered grid, at least 3 R from the tight tetrahedron and its images."""
    rng = np.random.default_rng(7)
    grid = np.stack(np.meshgrid(*[np.arange(4)] * 3, indexing="ij"), -1).reshape(-1, 3)
    centres = (grid + 0.5) * BOX / 4 + rng.uniform(-0.3, 0.3, grid.shape) * RADIUS
    images = np.array([[i, j, k] for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)])
    tight = (TIGHT[:, None] + images * BOX + images[:, 2:] * [PERIOD[3], 0, 0]).reshape(-1, 3)
    far = np.min(np.linalg.norm(centres[:, None] - tight[None], axis=2), axis=1) > 3 * RADIUS
    return centres[far]


def scene(shift):
    """(sim, clusters, unwrapped centres): the tight tetrahedron and the sparse grains moved by
    ``shift`` [m] in the sheared cell, the tight unit filled alone (no grains touch: no bridge,
    no contact)."""
    unwrapped = np.vstack([TIGHT, sparse_grains()]) + shift
    particles = Particles(into_cell(unwrapped, PERIOD), np.full(len(unwrapped), RADIUS),
                          DENSITY)
    cell = PeriodicCell.box(np.zeros(3), BOX)
    cell.shear_offset = PERIOD[3]
    sim = Simulation(particles, cell, 1e-7, neighbors=NeighborList(0.5 * RADIUS),
                     forces=[ContactForces(YOUNG, 0.3, 30.0)], integrator=Integrator(0.0))
    bridges = CapillaryBridges(1e7, GAMMA, persist=True)
    clusters = LiquidClusters(bridges, saturated=False)
    sim.forces += [bridges, clusters]
    sim.evaluate_forces()
    clusters.set_suction(sim, 1e7)                      # nothing fills
    suction = filling_thresholds(clusters.units, particles.radius, GAMMA).filling.max()
    bridges.set_suction(suction)
    clusters.set_suction(sim, suction)
    sim.evaluate_forces()
    return sim, clusters, unwrapped


def test_a_unit_across_the_sheared_cells_faces_balances_and_stresses_the_cell():
    sim, clusters, unwrapped = scene(np.zeros(3))
    assert np.count_nonzero(clusters.filled) == 1
    unit = int(np.flatnonzero(clusters.filled)[0])
    assert sorted(clusters.units.grains[unit]) == [0, 1, 2, 3]
    # the unit crosses the cell's faces: its grains' positions are not all its vertices
    assert not np.allclose(sim.particles.position[:4], unwrapped[:4])
    force = clusters.grain_forces(sim)
    assert np.abs(force[4:]).max() == 0.0 and np.abs(force[:4]).min() > 0.0
    np.testing.assert_allclose(force.sum(axis=0), 0.0, atol=1e-12 * np.abs(force).max())
    np.testing.assert_array_equal(sim.particles.force, force)       # no other force
    # the cell's stress: (1/V) sum x (x) F over the unwrapped positions
    expected = np.einsum("ki,kj->ij", unwrapped[:4], force[:4]) / np.prod(BOX)
    scale = np.abs(expected).max()
    assert np.trace(expected) < 0.0                      # the unit pulls its grains together
    np.testing.assert_allclose(sim.walls.stress_tensor, expected, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(sim.walls.stress_tensor, -clusters.stress(sim), rtol=0,
                               atol=1e-12 * scale)
    np.testing.assert_allclose(cluster_force_stress(sim, clusters), expected, rtol=0,
                               atol=1e-12 * scale)
    # the same unit inside the cell: the same forces and stress
    inside, inside_clusters, _ = scene(np.array([3.0, 2.0, 3.0]) * RADIUS)
    assert np.allclose(inside.particles.position[:4] - [3 * RADIUS, 2 * RADIUS, 3 * RADIUS],
                       unwrapped[:4], rtol=0, atol=1e-12 * RADIUS)
    np.testing.assert_allclose(inside_clusters.grain_forces(inside), force, rtol=0,
                               atol=1e-12 * np.abs(force).max())
    np.testing.assert_allclose(inside.walls.stress_tensor, expected, rtol=0,
                               atol=1e-12 * scale)


def test_the_forces_and_the_stress_follow_the_grains_through_a_face():
    """The packing moved across the cell's faces between two updates
    (LiquidClusters.follow_packing): the unit's forces and the cell's stress stay as they
    were, the grains wrapped by the cell at the next neighbour list."""
    sim, clusters, _ = scene(np.zeros(3))
    force, stress = clusters.grain_forces(sim), sim.walls.stress_tensor.copy()
    sim.particles.position += np.array([0.0, 0.0, 0.6]) * RADIUS
    sim.walls.wrap(sim.particles)
    assert sim.walls.wraps[:4, 2].any()          # through the z face, the unit still across x
    # followed, then decomposed again where the grains now are: the same unit, filled, the
    # same forces and stress
    for update in (clusters.follow_packing, lambda s: clusters.set_suction(s, clusters.suction)):
        update(sim)
        sim.evaluate_forces()
        assert np.count_nonzero(clusters.filled) == 1
        np.testing.assert_allclose(clusters.grain_forces(sim), force, rtol=0,
                                   atol=1e-10 * np.abs(force).max())
        np.testing.assert_allclose(sim.walls.stress_tensor, stress, rtol=0,
                                   atol=1e-10 * np.abs(stress).max())
