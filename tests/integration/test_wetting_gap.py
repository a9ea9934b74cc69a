"""Wetting where the liquid would be (issue 13): volume-controlled bridges formed across gaps at
the formation suction, against the exact Young–Laplace solver, and the formation suction of a
water volume shared over contacts and gaps."""

import numpy as np
import pytest

from pendular import capillary
from pendular.capillary import BridgeState, BridgeTable, CapillaryBridges, formation_suction
from conftest import Still, two_body_scene
from pendular.dem.simulation import Simulation

GAMMA = capillary.SURFACE_TENSION
RADIUS = 1e-3                     # the larger sphere R2 [m]
SUCTION_STAR = 5.0                # u* = s R2 / gamma at formation


def wetted_pair(ratio, gap_star, max_gap_star, roughness=0.0):
    """(sim, bridges, number formed) of two spheres R2 / ratio and R2 a gap d* R2 apart,
    wetted across gaps up to max_gap_star R2 at u* = SUCTION_STAR."""
    radii = [RADIUS / ratio, RADIUS]
    bridges = CapillaryBridges(SUCTION_STAR * GAMMA / RADIUS, GAMMA, control="volume",
                               roughness=roughness)
    sim = two_body_scene([[0, 0, 0], [sum(radii) + gap_star * RADIUS, 0, 0]], np.zeros((2, 3)),
                         radius=radii, extra=[bridges])
    sim.integrator = Still()
    sim.evaluate_forces()
    formed = bridges.form_across_gaps(sim, max_gap_star * RADIUS)
    return sim, bridges, formed


@pytest.mark.parametrize("ratio", [1.0, 2.0])
def test_a_pair_across_a_gap_gets_the_exact_bridge_of_the_formation_suction(ratio):
    gap_star = 0.05
    sim, bridges, formed = wetted_pair(ratio, gap_star, 0.1)
    exact = capillary.bridge_at_distance(ratio, 0.0, SUCTION_STAR, gap_star)
    state = BridgeState.of(sim.contacts)
    assert formed == 1 and state.count() == 1
    assert state.volume[0] == pytest.approx(exact.volume * RADIUS ** 3, rel=2e-3)
    sim.evaluate_forces()          # the bridge pulls the spheres together with the exact force
    force = sim.particles.force[1, 0]
    assert force == pytest.approx(-exact.force * 2 * np.pi * GAMMA * RADIUS, rel=5e-3)


def test_no_bridge_forms_beyond_the_rupture_distance_or_the_formation_gap():
    rupture = capillary.rupture_distance(1.0, 0.0, SUCTION_STAR)
    assert wetted_pair(1.0, 1.05 * rupture, 2.0)[2] == 0            # beyond rupture
    assert wetted_pair(1.0, 0.05, 0.04)[2] == 0                     # beyond the formation gap
    assert wetted_pair(1.0, 0.95 * rupture, 2.0)[2] == 1


def test_gap_bridges_need_volume_control_or_persisting_bridges():
    bridges = CapillaryBridges(1000.0, GAMMA)
    sim = two_body_scene([[0, 0, 0], [2.1 * RADIUS, 0, 0]], np.zeros((2, 3)), radius=RADIUS,
                         extra=[bridges])
    with pytest.raises(ValueError, match="persist = False"):
        bridges.form_across_gaps(sim, 0.1 * RADIUS)


def test_the_formation_suction_shares_the_water_over_contacts_and_gaps():
    table = BridgeTable.cached(0.0, radius_ratios=(1.0, 2.0))
    rng = np.random.default_rng(1)
    count = 200
    radius_i = rng.choice([0.5e-3, 1e-3], count)
    radius_j = np.full(count, 1e-3)
    gap = np.where(rng.random(count) < 0.5, 0.0, rng.uniform(0.0, 0.3e-3, count))
    water = 0.5 * sum(table.lookup(1e-3 / ri, 2.0, d / 1e-3)[2] * 1e-9
                      for ri, d in zip(radius_i, gap))
    suction = formation_suction(table, radius_i, radius_j, water, GAMMA, gap=gap)
    held = 0.0
    for ri, rj, d in zip(radius_i, radius_j, gap):
        big = max(ri, rj)
        exists, _, volume, _, _ = table.lookup(big / min(ri, rj), suction * big / GAMMA, d / big)
        held += volume * big ** 3 if exists else 0.0
    assert held == pytest.approx(water, rel=1e-4)
    touching = gap == 0.0
    contacts_only = formation_suction(table, radius_i[touching], radius_j[touching], water,
                                      GAMMA)
    assert contacts_only < suction       # fewer pairs hold the water: wetter bridges


def test_wetting_without_a_gap_wets_the_contacts_only(tmp_path):
    from pendular.procedures.preparation import PrepareConfig, prepare_sample
    from pendular.procedures.tension_pull import wetted_pairs

    sim, _ = prepare_sample(PrepareConfig(particles=150, confining=750.0, unload_steps=400),
                            progress=False)
    assert isinstance(sim, Simulation)
    i, j, gap = wetted_pairs(sim, 0.0)
    touching = sim.contacts.overlap > 0.0
    assert gap is None and np.array_equal(i, sim.contacts.pair_i[touching])
    i, j, gap = wetted_pairs(sim, 0.1 * 2.4e-5)
    assert len(i) > touching.sum() and np.all(gap <= 0.1 * 2.4e-5)
    # across gaps the pairs are found afresh from the positions (after the last step's move)
    c, x, r = sim.contacts, sim.particles.position, sim.particles.radius
    now = np.linalg.norm(x[c.pair_j] - x[c.pair_i], axis=1) < r[c.pair_i] + r[c.pair_j]
    assert np.count_nonzero(gap == 0.0) == now.sum()


def test_a_formation_gap_out_of_range_is_refused_naming_it():
    from pendular.procedures.tension import TensionConfig

    with pytest.raises(ValueError, match="^form_gap = 1.5 is outside"):
        TensionConfig(form_gap=1.5)
