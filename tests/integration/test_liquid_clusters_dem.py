"""Liquid clusters in the DEM (pendular.capillary.liquid_clusters): below the filling suction of
every pore unit they are the pendular bridges bit for bit; a saturated sample's clusters pull
on its grains with forces that balance, and hand over their bridges' liquid; their state, taken
back, gives the same forces and stress bit for bit, then and as the grains move on."""

import copy

import numpy as np
import pytest

from pendular.capillary import CapillaryBridges
from pendular.capillary.liquid_clusters import LiquidClusters
from pendular.dem.checkpoint import load_checkpoint, save_checkpoint
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
    # trimers: around throats of empty units only, their liquid a part of the bridges'
    trimers = clusters.trimers(sim)
    assert stats["trimers"] == trimers.count
    assert 0.0 <= stats["liquid_in_trimers"] <= stats["liquid_in_bridges"]
    assert not clusters.filled[clusters.units.throat_units[trimers.throats]].any()
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


def restored(sim, path):
    """A copy of ``sim`` whose clusters are built afresh, then given ``sim``'s checkpoint
    ``path`` (pendular.dem.checkpoint): (copy, its clusters)."""
    save_checkpoint(path, sim)
    copied = copy.deepcopy(sim)
    index = copied.forces.index(copied.operation(LiquidClusters))
    copied.forces[index] = LiquidClusters(copied.operation(CapillaryBridges))
    load_checkpoint(path, copied)
    return copied, copied.forces[index]


def assert_same(sim, clusters, other_sim, other):
    assert np.array_equal(clusters._force, other._force)
    assert np.array_equal(clusters.stress(sim), other.stress(other_sim))
    assert np.array_equal(clusters.grain_forces(sim), other.grain_forces(other_sim))
    assert clusters.statistics(sim) == other.statistics(other_sim)


@pytest.mark.parametrize("closed", [False, True])
def test_the_clusters_resume_from_a_checkpoint_bit_for_bit(small_sample, closed, tmp_path):
    """At an imposed suction and with a closed liquid (its front partly filled), saved right
    after a step of the model and after their forces followed the grains: the restored
    clusters pull as the saved ones, and the run goes on the same, the forces following the
    grains."""
    sim, bridges, clusters = wetted(small_sample, 3000.0, "clusters", saturated=True)
    if closed:
        clusters.hold_volume(sim, 0.9 * clusters.account(sim).total)
        assert 0.0 < clusters.liquid.front_fraction < 1.0
    assert_same(sim, clusters, *restored(sim, tmp_path / "updated.h5"))
    sim.run(50)
    clusters.follow_packing(sim)
    other_sim, other = restored(sim, tmp_path / "followed.h5")
    assert_same(sim, clusters, other_sim, other)
    for each, its in ((sim, clusters), (other_sim, other)):
        each.run(50)
        its.follow_packing(each)
    assert np.array_equal(sim.particles.position, other_sim.particles.position)
    assert_same(sim, clusters, other_sim, other)


def test_an_empty_clusters_state_is_taken_back_empty(small_sample):
    _, _, clusters = wetted(small_sample, 3000.0, "clusters")
    fresh = LiquidClusters(clusters.bridges)
    fresh.load_state(LiquidClusters(clusters.bridges).state_dict())
    assert fresh.units is None and fresh.suction is None


@pytest.mark.parametrize("change, words", [
    (lambda s: s["units"].update(grains=s["units"]["grains"] + len(s["radius"])),
     ["units/grains", "valid range [0, 300)"]),
    (lambda s: s["units"].update(vertices=s["units"]["vertices"][:-1]), ["units/vertices"]),
    (lambda s: s.update(filled=s["filled"][:-1]), ["filled", "shape"]),
    (lambda s: s.update(suction=None), ["suction"]),
])
def test_a_clusters_state_that_does_not_fit_is_refused_naming_it(small_sample, change, words):
    sim, _, clusters = wetted(small_sample, 3000.0, "clusters", saturated=True)
    state = clusters.state_dict()
    state["units"] = dict(state["units"])
    change(state)
    fresh = LiquidClusters(clusters.bridges)
    with pytest.raises(ValueError) as error:
        fresh.load_state(state)
    for word in words:
        assert word in str(error.value), (word, str(error.value))
    assert fresh.units is None
