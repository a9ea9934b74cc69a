"""A suction that changes during a run (issue 14 item 1): suction-controlled bridges follow it
(bridges at contact looked up again, across gaps ruptured where the new rupture distance is
shorter), new bridges form at contact only, so drying and wetting differ."""

import numpy as np
import pytest

from pendular import capillary
from pendular.capillary import BridgeState, CapillaryBridges
from conftest import RADIUS, Still, two_body_scene
from pendular.dem.neighbors import NeighborList

GAMMA = capillary.SURFACE_TENSION


def force_star(bridges, suction, gap_star=0.0):
    """Table force F* of equal spheres at ``suction`` [Pa] and gap D/R (0 if none)."""
    exists, force, *_ = bridges.suction_table.lookup(1.0, suction * RADIUS / GAMMA, gap_star)
    return force if exists else 0.0


def pair(gap_star, suction, **options):
    """Two still spheres of RADIUS apart by gap_star R (negative: overlapping), wet at
    ``suction``; (sim, bridges)."""
    bridges = CapillaryBridges(suction, GAMMA, **options)
    sim = two_body_scene([[0, 0, 0], [(2 + gap_star) * RADIUS, 0, 0]], np.zeros((2, 3)),
                         extra=[bridges])
    sim.integrator = Still()
    sim.advance()
    return sim, bridges


def pull(sim):
    """Attraction on sphere 1 along -x, in units of 2 pi gamma R."""
    return -sim.particles.force[1, 0] / (2 * np.pi * GAMMA * RADIUS)


def test_bridge_at_contact_follows_the_suction_both_ways():
    sim, bridges = pair(-1e-6, 1000.0)
    spring = pull(sim) - force_star(bridges, 1000.0)          # the contact's repulsion
    for suction in (30000.0, 300000.0, 3000.0, 1000.0):
        bridges.set_suction(suction)
        sim.advance()
        assert pull(sim) - spring == pytest.approx(force_star(bridges, suction), rel=1e-12)
        state = BridgeState.of(sim.contacts)
        expected = bridges.suction_table.lookup(1.0, suction * RADIUS / GAMMA, 0.0)
        assert state.volume[0] == pytest.approx(expected[2] * RADIUS ** 3, rel=1e-12)


def test_drying_ruptures_a_bridge_across_a_gap_and_wetting_does_not_bring_it_back():
    """A bridge across a gap (formed at wetting, persisting) ruptures when the suction rises
    until the rupture distance falls below its gap; back at the low suction it stays broken
    (it would form again only at contact): the hysteresis of the path."""
    gap_star = 0.05
    low = 1000.0
    sim, bridges = pair(gap_star, low, persist=True)
    assert bridges.form_across_gaps(sim, 0.1 * RADIUS) == 1
    sim.advance()
    assert pull(sim) == pytest.approx(force_star(bridges, low, gap_star), rel=1e-12)
    rupture_star = [capillary.rupture_distance(1.0, 0.0, s * RADIUS / GAMMA)
                    for s in (low, 10000.0, 100000.0)]
    assert rupture_star[0] > gap_star > rupture_star[2]
    for suction in (10000.0, 100000.0):
        bridges.set_suction(suction)
        sim.advance()
        assert pull(sim) == pytest.approx(force_star(bridges, suction, gap_star), rel=1e-12)
    assert BridgeState.of(sim.contacts).count() == 0 and pull(sim) == 0.0   # ruptured
    for suction in (10000.0, low):
        bridges.set_suction(suction)
        sim.advance()
        assert BridgeState.of(sim.contacts).count() == 0 and pull(sim) == 0.0


def test_the_reach_follows_the_lowest_suction_imposed():
    sim, bridges = pair(0.3, 30000.0, persist=True)
    reach_30 = bridges.reach(sim)
    bridges.set_suction(3000.0)
    sim.advance()
    assert bridges.reach(sim) > reach_30
    assert sim.operation(NeighborList).interaction_range == bridges.reach(sim)
    widest = bridges.reach(sim)
    bridges.set_suction(300000.0)
    sim.advance()
    assert bridges.reach(sim) == widest       # never shrinks: no persisting bridge leaves


def test_set_suction_checks_its_input():
    sim, bridges = pair(-1e-6, 30000.0)
    with pytest.raises(ValueError, match="suction = -1.0 Pa is outside the valid range"):
        bridges.set_suction(-1.0)
    with pytest.raises(ValueError, match="suction = 1e\\+12 Pa is outside the valid range"):
        bridges.set_suction(1e12)
    with pytest.raises(ValueError, match="pendular"):
        bridges.set_suction(1.0)
    assert bridges.suction == 30000.0          # a refused value changes nothing
    _, volume = pair(-1e-6, 30000.0, control="volume")
    with pytest.raises(ValueError, match="set_suction needs control = 'suction'"):
        volume.set_suction(1000.0)
