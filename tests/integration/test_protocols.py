"""The operation contracts (pendular.dem.protocols): a new force plugs into a Simulation by
implementing them, and the neighbour list serves what it declares (its reach, its per-pair
state). These are also the recipe of docs/architecture.md, "Adding a force"."""

import numpy as np
import pytest

from conftest import RADIUS, two_body_scene
from pendular.dem.protocols import PairField, pair_arrays
from pendular.dem.simulation import Simulation


class Gravity:
    """A body force: g [m/s^2] along -z on every particle (a force needs only apply)."""

    def __init__(self, g):
        self.g = g

    def apply(self, sim):
        sim.particles.force[:, 2] -= sim.particles.mass * self.g


class PairCounter:
    """A force acting up to ``gap`` [m] between surfaces that keeps, per pair, the steps the
    pair has been within that gap (declared per-pair state, carried across rebuilds)."""

    pair_state = (PairField("steps_near", np.int64, "1", "steps within the gap"),)

    def __init__(self, gap):
        self.gap = gap

    def reach(self, sim):
        return self.gap

    def apply(self, sim):
        contacts = sim.contacts
        steps = pair_arrays(contacts, "counter", self.pair_state)["steps_near"]
        steps[contacts.overlap > -self.gap] += 1


def test_a_body_force_plugs_in_and_falls_as_the_leapfrog_says():
    """Free fall from rest: the leapfrog (v += g dt, then x += v dt) puts a sphere at
    x0 - g dt^2 n (n + 1) / 2 after n steps."""
    sim = two_body_scene([[0.0, 0.0, 0.0]], [[0.0, 0.0, 0.0]], extra=[Gravity(9.81)])
    steps = 200
    sim.run(steps)
    expected = -9.81 * sim.dt ** 2 * steps * (steps + 1) / 2.0
    assert sim.particles.position[0, 2] == pytest.approx(expected, rel=1e-12)


def test_a_reaching_force_gets_its_pairs_and_keeps_its_state_across_rebuilds():
    """Two spheres 0.3 R apart at rest, the counter reaching 0.5 R: their pair is listed
    although the skin (0.2 R) alone would not reach it, and its count survives rebuilds that
    a third, moving sphere forces."""
    gap = 0.3 * RADIUS
    positions = [[0.0, 0.0, 0.0], [2 * RADIUS + gap, 0.0, 0.0], [0.0, 0.5, 0.0]]
    velocities = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 5.0]]     # 0.5 R in 100 steps
    sim = two_body_scene(positions, velocities, extra=[PairCounter(0.5 * RADIUS)])
    sim.run(1)
    first = sim.contacts
    sim.run(99)
    contacts = sim.contacts
    pair = int(np.flatnonzero((contacts.pair_i == 0) & (contacts.pair_j == 1))[0])
    assert contacts.extra["counter.steps_near"][pair] == 100
    assert contacts is not first                  # the moving sphere made the list rebuild


def test_per_pair_state_that_does_not_match_its_declaration_is_refused():
    sim = two_body_scene([[0.0, 0.0, 0.0], [2.1 * RADIUS, 0.0, 0.0]], [[0.0] * 3] * 2)
    sim.run(1)
    field = PairField("steps_near", np.int64, "1", "steps within the gap")
    sim.contacts.extra["counter.steps_near"] = np.zeros(len(sim.contacts))     # float64
    with pytest.raises(ValueError, match="counter.steps_near holds float64"):
        pair_arrays(sim.contacts, "counter", [field])


def test_an_object_without_apply_is_not_an_operation():
    sim = two_body_scene([[0.0, 0.0, 0.0]], [[0.0, 0.0, 0.0]])
    with pytest.raises(TypeError, match="no apply"):
        Simulation(sim.particles, sim.walls, sim.dt, neighbors=sim.neighbors,
                   forces=[object()], integrator=sim.integrator)
