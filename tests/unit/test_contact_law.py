"""Tests of the linear contact law: two bodies against closed forms, the pair loop's prefetch,
the one-thread kernels against the multi-thread pair loop and gathers."""

import numba
import numpy as np
import pytest

from conftest import RADIUS, YOUNG, two_body_scene
from pendular.dem.contact_law import (add_face_terms, gather_contact_forces,
    gather_contact_forces_virial, normal_stiffness, pair_forces, scatter_contact_forces,
    scattered_pair_forces)
from pendular.dem.neighbors import build_contacts
from pendular.dem.prefetch import PREFETCH_AHEAD, PREFETCH_MIN_PAIRS, prefetch_distance
from pendular.dem.state import Walls, period_layout
from pendular.dem.virial import SUM_BLOCKS


class CountContactSteps:
    """Test operation: count the steps during which the first pair overlaps."""

    steps = 0

    def apply(self, sim):
        self.steps += int(sim.contacts.overlap[0] > 0)


def test_head_on_collision_duration_and_restitution():
    """Undamped linear spring: contact lasts pi sqrt(m_eff / kn), restitution is exactly 1."""
    speed = 0.01
    sim = two_body_scene([[-1.001 * RADIUS, 0, 0], [1.001 * RADIUS, 0, 0]],
                         [[speed, 0, 0], [-speed, 0, 0]])
    mass = sim.particles.mass[0]
    kn = normal_stiffness(YOUNG, RADIUS, RADIUS)     # E R
    expected = np.pi * np.sqrt(0.5 * mass / kn)
    counter = CountContactSteps()
    sim.writers.append(counter)
    sim.run(int(3 * expected / sim.dt) + int(0.01 * RADIUS / (speed * sim.dt)))
    duration = counter.steps * sim.dt
    assert duration == pytest.approx(expected, rel=0.01)
    relative_after = sim.particles.velocity[1, 0] - sim.particles.velocity[0, 0]
    assert relative_after == pytest.approx(2 * speed, rel=1e-3)
    assert np.abs(sim.particles.angular_velocity).max() == 0.0


def test_damped_collision_loses_energy():
    """Cundall damping 0.2 must make the rebound slower than the impact."""
    speed = 0.01
    sim = two_body_scene([[-1.001 * RADIUS, 0, 0], [1.001 * RADIUS, 0, 0]],
                         [[speed, 0, 0], [-speed, 0, 0]], damping=0.2)
    sim.run(4000)
    rebound = sim.particles.velocity[1, 0] - sim.particles.velocity[0, 0]
    assert 0 < rebound < 2 * speed * 0.95


class PushOnSphere:
    """Test operation: constant external force on particle 1 (normal and tangential)."""

    def __init__(self, force):
        self.force = np.asarray(force, float)

    def apply(self, sim):
        sim.particles.force[1] += self.force


@pytest.mark.parametrize("ratio", [0.8, 1.5])
def test_sliding_at_the_coulomb_limit(ratio):
    """A sphere pressed on a far larger one (locally a plane) and pushed sideways, rotation
    blocked: it sticks with |Fs| = Ft below mu Fn, and slides at (Ft - mu Fn) / m above."""
    friction_deg = 20.0
    mu = np.tan(np.radians(friction_deg))
    big = 1e4 * RADIUS
    normal_push = 1e-3
    tangential = ratio * mu * normal_push
    kn = 2 * YOUNG * big * RADIUS / (big + RADIUS)
    overlap = normal_push / kn
    sliding = ratio > 1
    sim = two_body_scene([[0, 0, 0], [0, 0, big + RADIUS - overlap]], [[0, 0, 0], [0, 0, 0]],
                         radius=[big, RADIUS], friction_deg=friction_deg, box=10 * big,
                         damping=0.0 if sliding else 0.2,
                         extra=[PushOnSphere([tangential, 0.0, -normal_push])])
    sim.particles.inertia[:] *= 1e12   # no rotation: pure sliding
    sim.run(2000 if sliding else 40000)
    shear = np.linalg.norm(sim.contacts.shear_force[0])
    if not sliding:
        assert shear == pytest.approx(tangential, rel=1e-4)
        assert abs(sim.particles.velocity[1, 0]) < 1e-6 * np.sqrt(normal_push * overlap
                                                                  / sim.particles.mass[1])
        return
    x0, v0 = sim.particles.position[1, 0], sim.particles.velocity[1, 0]
    steps = 2000
    sim.run(steps)
    acceleration = (tangential - mu * normal_push) / sim.particles.mass[1]
    measured = (sim.particles.velocity[1, 0] - v0) / (steps * sim.dt)
    assert measured == pytest.approx(acceleration, rel=1e-3)
    assert sim.particles.position[1, 0] > x0
    shear = np.linalg.norm(sim.contacts.shear_force[0])
    assert shear == pytest.approx(mu * sim.contacts.normal_force[0], rel=1e-9)


def test_wall_contact_stiffness_is_young_times_radius():
    """A sphere resting with overlap d on a wall feels E R d and the wall records it."""
    overlap = 1e-6
    sim = two_body_scene([[0, 0, -1.0 + RADIUS - overlap]], [[0, 0, 0]])
    sim.advance()
    expected = YOUNG * RADIUS * overlap
    assert sim.walls.force[4] == pytest.approx(expected, rel=1e-9)
    assert sim.walls.stiffness[4] == pytest.approx(YOUNG * RADIUS)
    assert np.count_nonzero(sim.walls.force) == 1


def test_normal_stiffness_of_unequal_spheres():
    """Spheres of radii R and 2 R overlapping by d push each other apart with
    kn d = 2 E R1 R2 / (R1 + R2) d = 4/3 E R d."""
    overlap = 1e-6
    sim = two_body_scene([[0, 0, 0], [3 * RADIUS - overlap, 0, 0]], np.zeros((2, 3)),
                         radius=[RADIUS, 2 * RADIUS])
    sim.advance()
    expected = 4.0 / 3.0 * YOUNG * RADIUS * overlap
    assert normal_stiffness(YOUNG, RADIUS, 2 * RADIUS) == pytest.approx(4.0 / 3.0 * YOUNG * RADIUS)
    assert sim.contacts.normal_force[0] == pytest.approx(expected, rel=1e-6)
    assert sim.particles.force[1, 0] == pytest.approx(expected, rel=1e-6)


def test_contact_torques_act_at_the_middle_of_the_overlap():
    """Spheres of radii R and 2 R overlapping by d with a shear force Fs (along y, normal along
    x): the force acts at the middle of the overlap, so the torque on each is
    -(r - d / 2) n x Fs, and the pair's moments about the origin cancel."""
    overlap, shear = 1e-6, 1e-4
    radius = np.array([RADIUS, 2 * RADIUS])
    sim = two_body_scene([[0, 0, 0], [3 * RADIUS - overlap, 0, 0]], np.zeros((2, 3)),
                         radius=radius, friction_deg=60.0)
    sim.evaluate_forces()                       # the pair's normal is now current
    sim.contacts.shear_force[0] = [0.0, shear, 0.0]
    sim.evaluate_forces()
    p = sim.particles
    for member in (0, 1):
        expected = -(radius[member] - 0.5 * overlap) * np.cross([1.0, 0, 0], [0, shear, 0])
        np.testing.assert_allclose(p.torque[member], expected, rtol=1e-12, atol=0)
    moment = p.torque.sum(axis=0) + np.cross(p.position, p.force).sum(axis=0)
    assert np.abs(moment).max() < 1e-12 * RADIUS * shear


def jammed_cloud(count=2000, seed=7):
    """``count`` spheres on a lattice of spacing 1.9 R jiggled by 0.05 R, radii R (1 +- 0.05),
    random velocities and spins: (position, radius, velocity, spin, lattice period (3,) [m])."""
    rng = np.random.default_rng(seed)
    side = round(count ** (1 / 3)) + 1
    lattice = np.stack(np.meshgrid(*[np.arange(side)] * 3, indexing="ij"), -1).reshape(-1, 3)
    position = (lattice[:count] + 0.5) * 1.9 * RADIUS + rng.normal(0, 0.05 * RADIUS, (count, 3))
    radius = RADIUS * rng.uniform(0.95, 1.05, count)
    velocity = rng.normal(0, 1e-3, (count, 3))
    spin = rng.normal(0, 1.0, (count, 3))
    return position, radius, velocity, spin, period_layout(np.full(3, side * 1.9 * RADIUS))


def evaluate(kernel, position, velocity, spin, radius, contacts, period, *extra):
    """The pair kernel ``kernel`` on ``contacts``, with ``extra`` arguments after the common
    ones, after a first evaluation by pair_forces from a random shear history (so that the
    kernel rotates the history with the normals of that evaluation)."""
    c = contacts
    c.shear_force[:] = np.random.default_rng(3).normal(0, 1e-6, c.shear_force.shape)
    per_pair = (c.image, period, np.zeros(3), c.shear_force, c.normal, c.overlap,
                c.normal_force, c.force, YOUNG, 0.3, 0.3, 1e-6)
    pair_forces(position, velocity, spin, radius, c.pair_i, c.pair_j, *per_pair, 0)
    pairs = (c.pair_i if kernel is pair_forces else c.row_start, c.pair_j)  # rows: one thread
    kernel(position, velocity, spin, radius, *pairs, *per_pair, *extra)


def test_prefetching_pair_loop_gives_the_same_forces_bit_for_bit():
    """The prefetch hint of large samples (pendular.dem.prefetch) reads ahead and changes nothing: a jammed
    cloud of 2,000 spheres with random velocities and shear history, evaluated with and
    without it (1 and 16 pairs ahead: the look-ahead's end of the list included)."""
    position, radius, velocity, spin, _ = jammed_cloud()
    walls = Walls.box(position.min(0) - 2 * RADIUS, position.max(0) + 2 * RADIUS)
    results = []
    for ahead in (0, 1, PREFETCH_AHEAD):
        c = build_contacts(position, radius, 0.2 * RADIUS)
        evaluate(pair_forces, position, velocity, spin, radius, c, walls.period, ahead)
        results.append(np.concatenate([c.force, c.shear_force, c.normal,
                                       c.overlap[:, None], c.normal_force[:, None]], axis=1))
    assert (results[0][:, -1] > 0).sum() > len(radius)      # many touching pairs
    assert np.array_equal(results[0], results[1]) and np.array_equal(results[0], results[2])
    assert prefetch_distance(PREFETCH_MIN_PAIRS - 1) == 0
    assert prefetch_distance(PREFETCH_MIN_PAIRS) == PREFETCH_AHEAD


@pytest.mark.parametrize("periodic", [False, True], ids=["walls", "cell"])
def test_one_thread_kernels_give_the_gathers_sums_bit_for_bit(periodic):
    """On one thread the pair forces go straight to the particles: scattered_pair_forces (the
    pair loop and the gather in one) and scatter_contact_forces (the gather with a central
    attraction, as bridges at contact) add the same terms in the same order as the pair loop
    and the gather on every thread Numba has, so forces, torques and a cell's face terms of
    the virial are the same bit for bit (and results do not depend on the thread count). A
    jammed cloud of 2,000 spheres, in walls and in a periodic cell whose faces it presses
    through; each kernel prefetching (1 ahead) or not."""
    position, radius, velocity, spin, lattice = jammed_cloud()
    period = lattice if periodic else period_layout(np.zeros(3))
    count = len(radius)

    def contacts():
        return build_contacts(position, radius, 0.2 * RADIUS, period=lattice if periodic else None)

    def zeros():
        return np.zeros((count, 3)), np.zeros((count, 3)), np.zeros((SUM_BLOCKS, 9))

    def gathered(c, attraction):
        force, torque, virial = zeros()
        if periodic:
            gather_contact_forces_virial(c.force, attraction, c.normal, c.overlap, radius,
                                         c.row_start, c.second_start, c.second_pair, force,
                                         torque, c.image, c.through_face, c.face_start, period,
                                         virial)
        else:
            gather_contact_forces(c.force, attraction, c.normal, c.overlap, radius, c.row_start,
                                  c.second_start, c.second_pair, force, torque)
        return force, torque, virial

    def add_faces(c, virial, attraction):
        if periodic:
            add_face_terms(virial, c.through_face, c.face_start, c.image, period, c.force,
                           attraction, c.normal)

    def assert_same(sums, expected):
        for name, value, reference_value in zip(("force", "torque", "virial"), sums, expected):
            assert np.array_equal(value, reference_value), name

    caller_threads = numba.get_num_threads()
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)     # the gather on every thread
    try:
        reference = contacts()
        evaluate(pair_forces, position, velocity, spin, radius, reference, period, 0)
        attraction = np.random.default_rng(5).uniform(0, 1e-4, len(reference))  # bridges [N]
        expected_dry = gathered(reference, None)
        expected_wet = gathered(reference, attraction)
    finally:
        numba.set_num_threads(caller_threads)
    assert np.count_nonzero(reference.overlap > 0) > count
    assert not periodic or np.count_nonzero(reference.overlap[reference.through_face] > 0) > 100
    assert np.abs(expected_dry[1]).max() > 0 and not np.array_equal(expected_dry[0],
                                                                     expected_wet[0])
    for ahead in (0, 1):
        scattered = contacts()
        force, torque, virial = zeros()
        evaluate(scattered_pair_forces, position, velocity, spin, radius, scattered, period,
                 ahead, force, torque)
        add_faces(scattered, virial, None)
        assert np.array_equal(scattered.force, reference.force)
        assert_same((force, torque, virial), expected_dry)

        force, torque, virial = zeros()
        scatter_contact_forces(reference.force, attraction, reference.normal, reference.overlap,
                               radius, reference.row_start, reference.pair_j, force, torque, ahead)
        add_faces(reference, virial, attraction)
        assert_same((force, torque, virial), expected_wet)
