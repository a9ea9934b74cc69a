"""The closed liquid of the cluster model (pendular.capillary.closed_liquid): the suction found
from a liquid volume holds that volume to round-off, in the solver and in the DEM's own account,
and where no unit fills it is the pendular closed form (pendular.capillary.wetting's
formation suction)."""

import copy

import numpy as np
import pytest

from pendular.capillary import CapillaryBridges, formation_suction
from pendular.capillary.closed_liquid import HeldLiquid, solve_closed_liquid
from pendular.capillary.cluster_forces import (UnitForces, cluster_forces, cluster_stress,
                                               partial_forces)
from pendular.capillary.liquid_clusters import LiquidClusters
from pendular.capillary.pore_filling import FillingThresholds, filling_thresholds, unit_edges
from pendular.capillary.pores import decompose

GAMMA = 0.073


def closed(small_sample, suction=30000.0):
    """A copy of the sample with persisting suction-controlled bridges at ``suction`` and
    empty liquid clusters, its forces evaluated (bridges at contact)."""
    _, prepared, _ = small_sample
    sim = copy.deepcopy(prepared)
    bridges = CapillaryBridges(suction, GAMMA, persist=True)
    clusters = LiquidClusters(bridges, saturated=False)
    sim.forces += [bridges, clusters]
    sim.evaluate_forces()
    return sim, bridges, clusters


def touching_pairs(sim):
    """(pair_i, pair_j) of the touching pairs of ``sim``'s neighbour list."""
    touching = sim.contacts.overlap > 0.0
    return sim.contacts.pair_i[touching], sim.contacts.pair_j[touching]


def held_liquid(sim, bridges, thresholds=None):
    """HeldLiquid of the touching pairs of ``sim`` and its pore units, none filled so far."""
    particles = sim.particles
    units = decompose(particles.position, particles.radius)
    if thresholds is None:
        thresholds = filling_thresholds(units, particles.radius, GAMMA)
    pair_i, pair_j = touching_pairs(sim)
    larger = np.maximum(particles.radius[pair_i], particles.radius[pair_j])
    ratio = larger / np.minimum(particles.radius[pair_i], particles.radius[pair_j])
    edges = unit_edges(units)
    return HeldLiquid((larger, ratio, np.zeros(len(larger))), edges.of_pairs(pair_i, pair_j),
                      edges, units, thresholds, np.zeros(units.count, bool),
                      bridges.suction_table, GAMMA)


def test_where_no_unit_fills_the_suction_is_the_pendular_formation_suction(small_sample):
    sim, bridges, _ = closed(small_sample)
    never = held_liquid(sim, bridges)
    never.thresholds = FillingThresholds(throat_entry=never.thresholds.throat_entry,
                                         filling=np.zeros(never.pore_units.count))
    pair_i, pair_j = touching_pairs(sim)
    radius = sim.particles.radius
    volume = 0.02 * (sim.walls.volume() - sim.particles.solid_volume())
    liquid = solve_closed_liquid(volume, never)
    assert not liquid.filled.any() and liquid.front_fraction == 0.0 and liquid.clusters == 0.0
    pendular = formation_suction(bridges.suction_table, radius[pair_i], radius[pair_j], volume,
                                 GAMMA, tolerance=1e-12)
    assert liquid.suction == pytest.approx(pendular, rel=1e-9)
    assert liquid.bridges == pytest.approx(volume, rel=1e-12)
    assert abs(liquid.film) <= 1e-12 * volume


@pytest.mark.parametrize("saturation", [0.01, 0.05, 0.15])
def test_the_liquid_held_is_the_volume_to_round_off(small_sample, saturation):
    sim, bridges, _ = closed(small_sample)
    held = held_liquid(sim, bridges)
    volume = saturation * float(np.sum(held.pore_units.pore_volume))
    liquid = solve_closed_liquid(volume, held)
    assert liquid.total == pytest.approx(volume, rel=1e-14)
    assert abs(liquid.film) <= 1e-9 * volume            # no bridge breaks: only contacts
    assert 0.0 <= liquid.front_fraction <= 1.0
    assert not (liquid.front & liquid.filled).any()
    # the same parts from the weights alone, and monotone about the suction found
    bridges_part, units_part = held.parts(liquid.suction, liquid.weight)
    assert bridges_part + units_part + liquid.film == pytest.approx(volume, rel=1e-14)
    assert held.held(liquid.suction * 1.01) <= volume <= held.held(liquid.suction / 1.01)
    if saturation > 0.01:
        assert liquid.filled.any()


def test_hold_volume_conserves_the_liquid_in_the_dem_account(small_sample):
    sim, bridges, clusters = closed(small_sample)
    voids = sim.walls.volume() - sim.particles.solid_volume()
    for saturation in (0.02, 0.1, 0.06):                 # wetting, then drying back
        volume = saturation * voids
        liquid = clusters.hold_volume(sim, volume, max_gap=float(sim.particles.radius.mean()))
        assert bridges.suction == liquid.suction
        sim.evaluate_forces()                            # the bridges at the suction found
        account = clusters.account(sim)
        assert account.total == pytest.approx(volume, rel=1e-9)
        stats = clusters.statistics(sim)
        assert stats["saturation"] == pytest.approx(saturation, rel=1e-9)
        assert stats["liquid_in_bridges"] + stats["liquid_in_clusters"] <= 1.0 + 1e-12
        assert 0.0 <= stats["liquid_in_trimers"] <= stats["liquid_in_bridges"]
    assert clusters.filled.any()
    force = clusters._force
    assert np.abs(force.sum(axis=0)).max() < 1e-10 * np.abs(force).max()


def test_a_front_unit_filled_in_full_is_a_filled_unit(small_sample):
    """The front's forces, stress and absorbed shares in fraction f: at f = 1 those of the
    unit filled (superposition of the units' self-equilibrated sets)."""
    _, sim, _ = small_sample
    particles = sim.particles
    units = decompose(particles.position, particles.radius)
    forces = UnitForces(units.vertices, particles.radius[units.grains])
    filled = np.random.default_rng(3).random(units.count) < 0.4
    front = np.flatnonzero(~filled)[:5]
    more = filled.copy()
    more[front] = True
    suction, count = 20000.0, len(particles)
    assert np.allclose(cluster_forces(units, forces, filled, suction, count)
                       + partial_forces(units, forces, front, 1.0, suction, count),
                       cluster_forces(units, forces, more, suction, count),
                       rtol=0, atol=1e-12 * suction * particles.radius.max() ** 2)
    weight = filled + 0.3 * ~filled
    half = cluster_stress(units, forces, weight > 0, suction, 1.0, weight)
    assert np.allclose(half, 0.7 * cluster_stress(units, forces, filled, suction, 1.0)
                       + 0.3 * cluster_stress(units, forces, np.ones(units.count, bool),
                                              suction, 1.0), rtol=1e-12, atol=0)
    edges = unit_edges(units)
    assert np.array_equal(edges.share(filled.astype(float)), edges.filled_share(filled))
