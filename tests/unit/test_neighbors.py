"""Verlet list against brute force; contact history survives rebuilds; the list reaches as
far as the forces ask (``reach(sim)``); the particles near the walls are every particle that
can touch one."""

import copy
import dataclasses

import numpy as np
import pytest

from conftest import RADIUS, YOUNG, two_body_scene
from pendular.dem.contact_law import pair_forces
from pendular.dem.cell_list import ROW_CAPACITY, spatial_order
from pendular.dem.neighbors import build_contacts, near_wall_particles
from pendular.procedures.preparation import PrepareConfig, prepare_sample, servoed_simulation
from pendular.dem.state import Walls
from pendular.dem.walls import ConstantStrainRate, StressServo
from pendular.procedures.config import BridgeConfig


def brute_force_pairs(position, radius, skin):
    delta = position[None, :, :] - position[:, None, :]
    distance = np.linalg.norm(delta, axis=2)
    reach = radius[:, None] + radius[None, :] + skin
    i, j = np.nonzero(np.triu(distance < reach, k=1))
    return set(zip(i.tolist(), j.tolist()))


def test_pairs_match_brute_force_with_mixed_radii():
    rng = np.random.default_rng(3)
    position = rng.random((400, 3)) * [1.0, 0.5, 0.7]
    radius = rng.uniform(0.01, 0.04, 400)
    skin = 0.01
    contacts = build_contacts(position, radius, skin)
    found = set(zip(contacts.pair_i.tolist(), contacts.pair_j.tolist()))
    assert found == brute_force_pairs(position, radius, skin)
    assert np.all(contacts.pair_i < contacts.pair_j)
    for i in range(len(radius)):   # rows sorted by j (history lookup relies on it)
        row = contacts.pair_j[contacts.row_start[i]:contacts.row_start[i + 1]]
        assert np.all(np.diff(row) > 0)
    # the transposed index lists, for each particle, exactly the pairs where it is second, in
    # pair order (the order of the gathers' sums)
    for j in range(len(radius)):
        slots = contacts.second_pair[contacts.second_start[j]:contacts.second_start[j + 1]]
        assert slots.tolist() == np.nonzero(contacts.pair_j == j)[0].tolist()


@pytest.mark.parametrize("periodic", [False, True])
def test_a_row_longer_than_the_search_buffer_is_complete(periodic):
    """A large sphere (index 0) ringed by 3 * ROW_CAPACITY small ones on its surface: its row
    overflows the search's buffer and is searched again; the list is brute force's. In a
    periodic cell the cluster straddles a corner, so the row's pairs cross the faces."""
    rng = np.random.default_rng(11)
    count = 3 * ROW_CAPACITY
    direction = rng.normal(size=(count, 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    radius = np.concatenate([[0.1], np.full(count, 0.01)])
    position = np.concatenate([[[0.0, 0.0, 0.0]], 0.111 * direction])
    skin = 0.005
    if periodic:
        edge = 1.0
        position = np.mod(position, edge)
        contacts = build_contacts(position, radius, skin, period=np.full(3, edge))
        delta = position[None, :, :] - position[:, None, :]
        delta -= edge * np.round(delta / edge)              # minimum image
        reach = radius[:, None] + radius[None, :] + skin
        expected = set(zip(*[a.tolist() for a in np.nonzero(
            np.triu(np.linalg.norm(delta, axis=2) < reach, k=1))]))
        assert contacts.image[contacts.pair_i == 0].any()
    else:
        contacts = build_contacts(position, radius, skin)
        expected = brute_force_pairs(position, radius, skin)
    assert contacts.row_start[1] - contacts.row_start[0] == count > ROW_CAPACITY
    assert set(zip(contacts.pair_i.tolist(), contacts.pair_j.tolist())) == expected
    assert np.all(np.diff(contacts.pair_j[:count]) > 0)


def test_near_wall_particles_match_brute_force():
    rng = np.random.default_rng(5)
    lo, hi = np.array([0.0, -0.2, 0.1]), np.array([1.0, 0.3, 0.8])
    position = lo + rng.random((500, 3)) * (hi - lo)
    radius = rng.uniform(0.01, 0.04, 500)
    margin = 0.02
    gap = np.minimum(position - lo, hi - position).min(axis=1) - radius
    walls = np.array([lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]])
    near = near_wall_particles(position, radius, walls, margin)
    assert near.tolist() == np.flatnonzero(gap < margin).tolist()
    assert 0 < len(near) < 500
    contacts = build_contacts(position, radius, margin, walls=walls, wall_margin=margin)
    assert np.array_equal(contacts.near_wall, near)
    assert np.array_equal(build_contacts(position, radius, margin).near_wall, np.arange(500))


def test_a_wall_moved_beyond_half_the_skin_rebuilds_the_list():
    """A sphere at rest 0.3 R off the x+ wall is not near it (skin 0.2 R); the wall pushed
    0.4 R inward (more than skin / 2) rebuilds the list, and the sphere feels the wall: kn = E R
    times the overlap 0.1 R. A move of skin / 2 or less keeps the list."""
    sim = two_body_scene([[1.0 - 1.3 * RADIUS, 0.0, 0.0]], np.zeros((1, 3)))
    sim.evaluate_forces()
    assert sim.contacts.near_wall.tolist() == [] and sim.particles.force[0, 0] == 0.0
    rebuilds = sim.neighbors.rebuilds
    sim.walls.position[1] -= 0.1 * RADIUS
    sim.evaluate_forces()
    assert sim.neighbors.rebuilds == rebuilds and sim.particles.force[0, 0] == 0.0
    sim.walls.position[1] -= 0.3 * RADIUS
    sim.evaluate_forces()
    assert sim.neighbors.rebuilds == rebuilds + 1
    assert sim.contacts.near_wall.tolist() == [0]
    assert sim.particles.force[0, 0] == pytest.approx(-YOUNG * RADIUS * 0.1 * RADIUS, rel=1e-9)


def test_a_list_without_wall_reference_rebuilds():
    """A neighbour list restored from a checkpoint written before the walls' reference was
    kept (its state without ``_reference_walls``) rebuilds at its next step instead of failing."""
    sim = two_body_scene([[0.0, 0.0, 0.0], [3 * RADIUS, 0.0, 0.0]], np.zeros((2, 3)))
    sim.advance()
    rebuilds = sim.neighbors.rebuilds
    sim.neighbors._reference_walls = None
    sim.advance()
    assert sim.neighbors.rebuilds == rebuilds + 1
    sim.advance()
    assert sim.neighbors.rebuilds == rebuilds + 1


def test_history_is_carried_to_the_same_pair_after_a_rebuild():
    rng = np.random.default_rng(4)
    position = rng.random((300, 3))
    radius = np.full(300, 0.04)
    old = build_contacts(position, radius, 0.01)
    old.shear_force[:] = rng.random((len(old), 3))
    old.normal[:] = rng.random((len(old), 3))
    moved = position + rng.normal(scale=0.005, size=position.shape)
    new = build_contacts(moved, radius, 0.01, previous=old)
    old_rows = {(i, j): k for k, (i, j) in enumerate(zip(old.pair_i, old.pair_j))}
    kept = 0
    for k, (i, j) in enumerate(zip(new.pair_i, new.pair_j)):
        if (i, j) in old_rows:
            kept += 1
            assert np.array_equal(new.shear_force[k], old.shear_force[old_rows[i, j]])
            assert np.array_equal(new.normal[k], old.normal[old_rows[i, j]])
        else:
            assert not new.shear_force[k].any()
    assert kept > 0.5 * len(new)


class Reaching:
    """Test force: no force, needs pairs up to ``gap`` [m] apart (the reach interface)."""

    def __init__(self, gap):
        self.gap = gap

    def reach(self, sim):
        return self.gap

    def apply(self, sim):
        pass


def pairs(sim):
    return set(zip(sim.contacts.pair_i.tolist(), sim.contacts.pair_j.tolist()))


def test_the_list_reaches_as_far_as_the_forces_ask():
    """Two spheres at a gap of 0.5 R, skin 0.2 R: paired only while a force reaches that far;
    a change of the largest reach rebuilds the list, an unchanged one does not."""
    gap = 0.5 * RADIUS
    sim = two_body_scene([[0, 0, 0], [2 * RADIUS + gap, 0, 0]], np.zeros((2, 3)))
    sim.advance()
    neighbors = sim.neighbors
    assert pairs(sim) == set() and neighbors.interaction_range == 0.0
    rebuilds = neighbors.rebuilds
    reaching = Reaching(0.6 * RADIUS)
    sim.forces += [reaching, Reaching(0.1 * RADIUS)]
    sim.advance()
    assert pairs(sim) == {(0, 1)}
    assert neighbors.interaction_range == 0.6 * RADIUS
    assert neighbors.rebuilds == rebuilds + 1
    sim.advance()
    assert neighbors.rebuilds == rebuilds + 1
    reaching.gap = 0.0
    sim.advance()
    assert pairs(sim) == set() and neighbors.interaction_range == 0.1 * RADIUS
    sim.forces[2:] = []
    sim.advance()
    assert neighbors.interaction_range == 0.0 and neighbors.rebuilds == rebuilds + 3


def test_a_negative_reach_is_refused_naming_the_force():
    sim = two_body_scene([[0, 0, 0]], np.zeros((1, 3)), extra=[Reaching(-1e-6)])
    with pytest.raises(ValueError, match="Reaching.reach"):
        sim.advance()


def test_spatial_order_walks_the_cells_along_the_z_curve():
    """Eight points, one per cell of a 2 x 2 x 2 grid, listed in reverse: the order is the
    Morton order (x the fastest bit), and points sharing a cell keep their index order."""
    cells = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
    position = (cells[::-1] + 0.5) * RADIUS
    assert spatial_order(position, RADIUS).tolist() == [7, 6, 5, 4, 3, 2, 1, 0]
    twice = np.concatenate([position, position])
    assert spatial_order(twice, RADIUS).tolist()[:4] == [7, 15, 6, 14]


def test_a_prepared_sample_is_numbered_near_neighbours_near_in_memory(small_sample):
    """The preparation numbers particles along the curve: the pairs' mean index distance is
    under 40 % of the same packing's numbered at random (the 300-sphere sample shared with
    other tests)."""
    _, sim, _ = small_sample
    i, j = sim.contacts.pair_i, sim.contacts.pair_j
    shuffled = np.random.default_rng(0).permutation(len(sim.particles))
    assert np.mean(np.abs(j - i)) < 0.4 * np.mean(np.abs(shuffled[j] - shuffled[i]))


def test_a_contact_lost_on_a_rebuild_step_forgets_its_shear_spring():
    """The first evaluation after a rebuild knows which pairs were touching: one found apart
    there drops its shear force, as it would on any other step (it once kept it, and started
    its next contact from a stale spring)."""
    radius = np.full(2, RADIUS)
    touching = np.array([[0.0, 0, 0], [1.999 * RADIUS, 0, 0]])
    contacts = build_contacts(touching, radius, 0.5 * RADIUS)
    still = np.zeros((2, 3))
    walls = Walls.box([-1.0] * 3, [1.0] * 3)

    def evaluate(position, c):
        pair_forces(position, still, still, radius, c.pair_i, c.pair_j, c.image, walls.period,
                    np.zeros(3), c.shear_force, c.normal, c.overlap, c.normal_force, c.force,
                    1e6, 0.3, 0.3, 1e-7, 0)

    evaluate(touching, contacts)
    contacts.shear_force[0] = [0.0, 1e-6, 0.0]           # a loaded spring
    apart = touching.copy()
    apart[1, 0] = 2.001 * RADIUS
    rebuilt = build_contacts(apart, radius, 0.5 * RADIUS, previous=contacts)
    assert rebuilt.overlap[0] > 0.0                      # carried: touching at the last step
    evaluate(apart, rebuilt)
    assert np.all(rebuilt.shear_force[0] == 0.0) and rebuilt.overlap[0] < 0.0


@pytest.mark.parametrize("suction", [0.0, 30000.0])
def test_a_shear_does_not_depend_on_the_skin(suction, small_sample):
    """The skin only decides when the list is rebuilt: contacts open and close (and bridges
    form and break) on rebuild steps as on any other, so a shear with a thin and a thick skin
    is the same to the bit, dry or wet (of the 300-sphere sample shared with other tests)."""
    config, sample, _ = small_sample
    runs = []
    for skin_factor in (0.05, 0.6):
        sim = servoed_simulation(copy.deepcopy(sample.particles), copy.deepcopy(sample.walls),
                                 dataclasses.replace(config, skin_factor=skin_factor), 750.0)
        if suction:
            sim.forces.append(BridgeConfig(suction).build())
        sim.controls = [StressServo("xy", 750.0, sim.controls[0].max_velocity),
                        ConstantStrainRate("z", 0.02 / (3000 * sim.dt), sim.walls.lengths()[2])]
        sim.run(3000)                                    # to 2 % axial strain
        runs.append((sim.particles.position.copy(), sim.neighbors.rebuilds))
    (thin, thin_rebuilds), (thick, thick_rebuilds) = runs
    assert thin_rebuilds > 3 * thick_rebuilds
    assert np.array_equal(thin, thick)


def test_a_preparation_does_not_depend_on_the_skin():
    """The radius growth sets its time step at each rebuild (GrowthTimeStep), so it keeps a
    skin of its own; the later phases run with the test's skin, whose rebuilds change nothing:
    a thin and a thick skin prepare the same sample to the bit (when the growth took the
    thicker of the two, its step changed at other steps and the samples ended a radius apart)."""
    samples = []
    for skin_factor in (0.05, 0.6):
        sim, _ = prepare_sample(PrepareConfig(particles=80, skin_factor=skin_factor),
                                progress=False)
        samples.append((sim.particles.position, sim.walls.position, sim.neighbors.rebuilds))
    (thin, thin_walls, thin_rebuilds), (thick, thick_walls, thick_rebuilds) = samples
    assert thin_rebuilds > thick_rebuilds
    assert np.array_equal(thin, thick) and np.array_equal(thin_walls, thick_walls)


def test_a_thicker_skin_takes_effect_at_the_next_step():
    """Two spheres 0.3 R apart are off a list of skin 0.2 R; the skin raised to 0.5 R rebuilds
    the list at the next step (a list kept from the thinner skin would miss the pair until a
    particle had moved 0.25 R), which then holds the pair."""
    sim = two_body_scene([[0.0, 0.0, 0.0], [2.3 * RADIUS, 0.0, 0.0]], np.zeros((2, 3)))
    sim.evaluate_forces()
    assert len(sim.contacts) == 0
    rebuilds = sim.neighbors.rebuilds
    sim.neighbors.skin = 0.5 * RADIUS
    sim.evaluate_forces()
    assert sim.neighbors.rebuilds == rebuilds + 1
    assert sim.contacts.pair_i.tolist() == [0] and sim.contacts.pair_j.tolist() == [1]
