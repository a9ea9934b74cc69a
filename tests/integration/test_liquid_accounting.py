"""Liquid of volume-controlled bridges in a closed amount (issue 14 item 1): a ruptured bridge's
liquid shared among its grains' remaining bridges (or held as film, or lost), new bridges from
films, and bridges + films + lost = the liquid at closing to round-off."""

import numpy as np
import pytest

from pendular import capillary
from pendular.capillary import BridgeState, CapillaryBridges
from conftest import RADIUS, two_body_scene

GAMMA = capillary.SURFACE_TENSION


class Schedule:
    """Replaces the integrator: sphere positions along x from ``positions(step)`` (3,) [m]."""

    def __init__(self, positions):
        self.positions = positions

    def apply(self, sim):
        sim.particles.position[:, 0] = self.positions(sim.step + 1)
        sim.particles.velocity[:] = 0.0


def chain(liquid, pull_steps=400):
    """Spheres A, B, C in a row, touching; after wetting (reservoir) the liquid is closed and
    C is pulled away from B until their bridge ruptures, then pushed back into contact.
    Returns (sim, bridges, snapshots {name: (volumes by pair (a, b), film, lost)})."""
    touching = 2 * RADIUS * (1 - 1e-4)
    step = 2e-3 * RADIUS

    def positions(n):
        if n <= 5:
            gap = 0.0
        elif n <= 5 + pull_steps:
            gap = (n - 5) * step
        else:
            gap = max(pull_steps * step - (n - 5 - pull_steps) * 4 * step, 0.0)
        return np.array([0.0, touching, 2 * touching + gap])

    bridges = CapillaryBridges(30000.0, GAMMA, control="volume")
    sim = two_body_scene([[0, 0, 0], [touching, 0, 0], [2 * touching, 0, 0]], np.zeros((3, 3)),
                         radius=RADIUS, extra=[bridges])
    sim.integrator = Schedule(positions)
    snapshots = {}

    def snapshot(name):
        state = BridgeState.of(sim.contacts)
        volumes = {(int(i), int(j)): float(v) for i, j, v, s in zip(
            sim.contacts.pair_i, sim.contacts.pair_j, state.volume, state.state) if s}
        snapshots[name] = (volumes, bridges.film.copy(), bridges.liquid_lost,
                           bridges.liquid_balance(sim)[3])

    sim.run(5)
    bridges.close_liquid(sim, liquid)
    snapshot("wet")
    sim.run(pull_steps)
    snapshot("pulled")
    sim.run(pull_steps)
    snapshot("back")
    return sim, bridges, snapshots


def test_a_ruptured_bridge_shares_its_liquid_with_its_grains():
    _, bridges, snaps = chain("shared")
    wet, pulled, back = snaps["wet"], snaps["pulled"], snaps["back"]
    assert set(wet[0]) == {(0, 1), (1, 2)}
    v = wet[0][(1, 2)]
    assert set(pulled[0]) == {(0, 1)}                              # B-C ruptured
    # half to B, whose other bridge A-B takes it; half to C, which has none: film
    assert pulled[0][(0, 1)] == pytest.approx(wet[0][(0, 1)] + 0.5 * v, rel=1e-12)
    assert pulled[1].tolist() == pytest.approx([0.0, 0.0, 0.5 * v], rel=1e-12)
    assert pulled[2] == 0.0 and pulled[3] < 1e-12
    # back in contact: B-C forms again from the films of B and C (C's half)
    assert back[0][(1, 2)] == pytest.approx(0.5 * v, rel=1e-12)
    assert back[1].tolist() == [0.0, 0.0, 0.0]
    assert back[3] < 1e-12


def test_lost_liquid_is_counted():
    _, _, snaps = chain("lost")
    v = snaps["wet"][0][(1, 2)]
    volumes, film, lost, error = snaps["pulled"]
    assert volumes[(0, 1)] == snaps["wet"][0][(0, 1)] and not film.any()
    assert lost == pytest.approx(v, rel=1e-12) and error < 1e-12
    assert set(snaps["back"][0]) == {(0, 1)}                         # no liquid to form anew


def test_open_liquid_forms_from_the_reservoir_and_liquid_models_are_checked():
    sim, bridges, _ = chain("shared")
    assert bridges.liquid_initial > 0
    with pytest.raises(ValueError, match="liquid = 'dry' is not one of"):
        CapillaryBridges(30000.0, GAMMA, control="volume", liquid="dry")
    with pytest.raises(ValueError, match="needs control='volume'"):
        CapillaryBridges(30000.0, GAMMA, liquid="shared")
    suction = CapillaryBridges(30000.0, GAMMA)
    with pytest.raises(ValueError, match="needs control = 'volume'"):
        suction.close_liquid(sim)
