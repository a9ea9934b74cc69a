"""Liquid clusters in the DEM (pendular.capillary.liquid_clusters): below the filling suction of
every pore unit they are the pendular bridges bit for bit; a saturated sample's clusters pull
on its grains with forces that balance, and hand over their bridges' liquid."""

import copy

import numpy as np
import pytest

from pendular.capillary import CapillaryBridges
from pendular.capillary.liquid_clusters import LiquidClusters
from pendular.homogenize.clusters import chi_with_clusters
from pendular.homogenize.on_the_fly import CapillaryHomogenization

GAMMA = 0.073


def wetted(small_sample, suction, regime, saturated=False):
    _, prepared, _ = small_sample
    sim = copy.deepcopy(prepared)
    bridges = CapillaryBridges(suction, GAMMA, persist=True)
    sim.forces.append(bridges)
    clusters = None
    if regime == "clusters":
        clusters = LiquidClusters(bridges, saturated=saturated)
        sim.forces.append(clusters)
    sim.evaluate_forces()
    if clusters is not None:
        clusters.set_suction(sim, suction)
    return sim, bridges, clusters


def test_clusters_below_every_filling_suction_are_the_pendular_bridges(small_sample):
    runs = []
    for regime in ("pendular", "clusters"):
        sim, bridges, clusters = wetted(small_sample, 300000.0, regime)
        if clusters is not None:
            assert not clusters.filled.any() and clusters.found.count == 0
        sim.run(300)
        runs.append((sim, bridges, clusters))
    (pendular, bridges, _), (clustered, _, clusters) = runs
    assert np.array_equal(pendular.particles.position, clustered.particles.position)
    assert np.array_equal(pendular.particles.force, clustered.particles.force)
    account = clusters.account(clustered)
    assert account.clusters == 0.0 and account.absorbed == 0.0
    assert clusters.saturation(clustered) == bridges.saturation(pendular)
    assert np.allclose(chi_with_clusters(clustered, clusters),
                       CapillaryHomogenization(bridges).chi(pendular), rtol=1e-12, atol=0)


def test_a_saturated_sample_drains_and_its_cluster_forces_balance(small_sample):
    sim, bridges, clusters = wetted(small_sample, 3000.0, "clusters", saturated=True)
    filled = np.count_nonzero(clusters.filled)
    assert 0 < filled < clusters.units.count             # the gas entered from the hull
    stats = clusters.statistics(sim)
    assert stats["clusters"] >= 1 and stats["filled_units"] == filled
    assert stats["liquid_in_bridges"] + stats["liquid_in_clusters"] == pytest.approx(1.0)
    assert 0 < stats["liquid_in_largest_cluster"] <= stats["liquid_in_clusters"]
    assert 0 < stats["saturation"] < stats["saturation_pore_units"]
    # the clusters' share of chi: positive, below the saturated sample's
    chi = np.trace(chi_with_clusters(sim, clusters)) / 3
    bridges_alone = np.trace(CapillaryHomogenization(bridges).chi(sim)) / 3
    assert 0 < chi < 1.5 and chi != bridges_alone
    assert np.abs(clusters._force.sum(axis=0)).max() < 1e-10 * np.abs(clusters._force).max()
    # the account: a filled unit's pore volume, a bridge's share outside the filled units
    account = clusters.account(sim)
    assert account.clusters == pytest.approx(clusters.units.pore_volume[clusters.filled].sum(),
                                             rel=1e-12)
    assert account.bridges + account.absorbed == pytest.approx(
        bridges.saturation(sim) * (sim.walls.volume() - sim.particles.solid_volume()),
        rel=1e-12)
    sim.run(200)
    assert np.isfinite(sim.particles.position).all()
    # drying on: fewer filled units, carried over the new decomposition
    bridges.set_suction(30000.0)
    clusters.set_suction(sim, 30000.0)
    assert np.count_nonzero(clusters.filled) < filled
    state = clusters.state_dict()
    assert state["filled_units"].shape == (np.count_nonzero(clusters.filled), 4)


def test_the_clusters_forces_follow_their_grains(small_sample):
    """LiquidClusters.follow_packing: at the decomposition's positions the same forces bit for
    bit; as the grains move, the forces of the same filled units, still summing to zero."""
    sim, _, clusters = wetted(small_sample, 3000.0, "clusters", saturated=True)
    held = clusters._force.copy()
    clusters.follow_packing(sim)
    assert np.array_equal(clusters._force, held)
    filled = clusters.filled.copy()
    sim.run(100)
    clusters.follow_packing(sim)
    assert np.array_equal(clusters.filled, filled) and not np.array_equal(clusters._force, held)
    assert np.abs(clusters._force.sum(axis=0)).max() < 1e-10 * np.abs(clusters._force).max()
