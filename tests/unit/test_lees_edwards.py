"""The sheared periodic cell (Lees–Edwards, pendular.dem.cell): branch vectors and neighbour
lists against a brute-force search over a 5 x 5 x 5 block of sheared images, the list kept
complete while the cell shears, the relative velocity gamma_dot l_z of a pair through a z face,
the affine motion of particles and images, and the elastic shear of a simple cubic lattice
against its closed form."""

import numba
import numpy as np
import pytest

from conftest import DENSITY, RADIUS, YOUNG
from pendular.dem.cell import ConstantShearRate, PeriodicCell
from pendular.dem.contact_law import ContactForces, normal_stiffness
from pendular.dem.integrate import Integrator
from pendular.dem.neighbors import NeighborList, branch_vector, branch_vectors, build_contacts
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls

#: Edges of the cell [m], unequal so that an axis mixed up shows.
EDGES = np.array([7.0, 6.0, 8.0]) * 2 * RADIUS
#: Shear strains gamma = delta / Lz tried, beyond one Lx of offset and of either sign.
STRAINS = (0.0, 0.13, 0.5, -0.77, 2.31)


def sheared_cell(gamma, edges=EDGES):
    """A periodic cell of ``edges`` sheared by ``gamma`` (offset gamma Lz, brought into
    [-Lx/2, Lx/2) by a wrap)."""
    cell = PeriodicCell.box(np.zeros(3), edges)
    cell.shear_offset = gamma * edges[2]
    return cell


def images(cell):
    """(125, 3) shifts of the images (ix, iy, iz) in [-2, 2]^3 of ``cell``:
    (ix Lx + iz delta, iy Ly, iz Lz)."""
    index = np.array(np.meshgrid(*[np.arange(-2, 3)] * 3, indexing="ij")).reshape(3, -1).T
    lengths = cell.lengths()
    shift = index * lengths
    shift[:, 0] += index[:, 2] * cell.shear_offset
    return shift


def brute_force(position, radius, reach, cell):
    """{(i, j): branch vector} of the pairs i < j whose nearest image of j, over the 125
    images, lies within r_i + r_j + reach of i."""
    i, j = np.triu_indices(len(position), k=1)
    branch = (position[j] - position[i])[:, None, :] + images(cell)[None, :, :]
    distance = np.linalg.norm(branch, axis=2)
    nearest = np.argmin(distance, axis=1)
    rows = np.arange(len(i))
    within = distance[rows, nearest] < radius[i] + radius[j] + reach
    return {(int(a), int(b)): vector for a, b, vector in
            zip(i[within], j[within], branch[rows, nearest][within])}


@numba.njit(cache=True)
def kernel_branches(position, pair_i, pair_j, image, period):
    """branch_vector of every pair, as the compiled kernels see it."""
    out = np.empty((len(pair_i), 3))
    for k in range(len(pair_i)):
        out[k] = branch_vector(position, pair_i[k], pair_j[k], image, k, period)
    return out


def random_particles(count, seed, edges=EDGES):
    rng = np.random.default_rng(seed)
    radius = RADIUS * rng.uniform(0.6, 1.0, count)
    return Particles(rng.random((count, 3)) * edges, radius, DENSITY)


@pytest.mark.parametrize("gamma", STRAINS)
def test_branch_vectors_and_pairs_match_a_brute_force_search_of_the_sheared_images(gamma):
    """Random spheres (any overlap) in a cell sheared by gamma: the neighbour list holds
    exactly the pairs within reach of their nearest sheared image, and the branch vector of
    each (the compiled kernels' and the Python one) is that image's, after the offset is
    brought into [-Lx/2, Lx/2)."""
    particles = random_particles(300, seed=int(100 * abs(gamma)))
    cell = sheared_cell(gamma)
    cell.wrap(particles)
    assert -0.5 * EDGES[0] <= cell.shear_offset < 0.5 * EDGES[0]
    assert cell.sheared == (gamma != 0.0)
    reach = 0.4 * RADIUS
    c = build_contacts(particles.position, particles.radius, reach, period=cell.period)
    expected = brute_force(particles.position, particles.radius, reach, cell)
    listed = list(zip(c.pair_i.tolist(), c.pair_j.tolist()))
    assert set(listed) == set(expected) and len(listed) == len(expected) > 300
    want = np.array([expected[pair] for pair in listed])
    np.testing.assert_allclose(kernel_branches(particles.position, c.pair_i, c.pair_j, c.image,
                                               cell.period), want, rtol=0, atol=1e-15)
    np.testing.assert_allclose(branch_vectors(particles.position, c, cell.period), want,
                               rtol=0, atol=1e-15)
    if gamma != 0.0:        # pairs through the z faces, whose branches hold the offset
        assert np.count_nonzero(c.image[:, 2]) > 10


def test_a_wrap_through_the_z_faces_shifts_x_by_the_offset_and_keeps_the_unwrapped_positions():
    """Particles placed outside the cell (above, below, beyond x) come back into it; a
    particle through the top face moves by -delta along x; the unwrapped positions, with the
    offset brought into range at the same time, are unchanged."""
    cell = sheared_cell(1.37)
    position = np.array([[0.5, 0.5, 1.2], [0.2, 0.5, -0.3], [1.4, 0.3, 2.6], [-0.6, 0.1, 0.5]])
    particles = Particles(position * EDGES, np.full(4, RADIUS), DENSITY)
    cell.wraps = np.zeros((4, 3), np.int64)
    before = cell.unwrapped(particles)
    offset = cell.shear_offset
    cell.wrap(particles)
    assert np.all((particles.position >= 0.0) & (particles.position < EDGES))
    np.testing.assert_array_equal(cell.wraps[:, 2], [1, -1, 2, 0])
    np.testing.assert_allclose(cell.unwrapped(particles), before, rtol=0, atol=1e-15)
    turns = round((offset - cell.shear_offset) / EDGES[0])    # 1.37 Lz = 1.57 Lx
    assert turns == 2 and abs(cell.shear_offset) <= 0.5 * EDGES[0]


def free_scene(particles, cell, rate, dt=1e-4, skin=0.3 * RADIUS, forces=()):
    """Particles in ``cell`` sheared at ``rate`` [1/s], forces ``forces`` (none: they fly)."""
    return Simulation(particles, cell, dt, neighbors=NeighborList(skin), forces=list(forces),
                      controls=[ConstantShearRate(rate)], integrator=Integrator(0.0), threads=1)


def test_the_list_stays_complete_while_the_cell_shears_through_several_periods():
    """Spheres riding the shear (own velocities small, so that the shear calls the rebuilds)
    while the offset sweeps four times across the cell: at every step the list holds every
    pair in contact with its nearest sheared image (brute force), with that image's branch
    vector, though the particles move Lz gamma_dot dt a step relative to each other across the
    height (a third of a radius). A rebuild criterion blind to the shear misses hundreds."""
    rng = np.random.default_rng(7)
    particles = random_particles(90, seed=7)
    particles.velocity[:] = rng.normal(0.0, 2e-4, (90, 3))
    cell = PeriodicCell.box(np.zeros(3), EDGES)
    dt = 2e-3
    rate = 4.0 * EDGES[0] / EDGES[2] / (200 * dt)       # delta crosses Lx four times
    sim = free_scene(particles, cell, rate, dt)
    checked = 0
    for _ in range(200):
        sim.run(1)
        sim.neighbors.apply(sim)        # the list the next step's forces see
        expected = brute_force(particles.position, particles.radius, 0.0, cell)
        c = sim.contacts
        listed = dict(zip(zip(c.pair_i.tolist(), c.pair_j.tolist()),
                          branch_vectors(particles.position, c, cell.period)))
        for pair, branch in expected.items():
            np.testing.assert_allclose(listed[pair], branch, rtol=0, atol=1e-12)
        checked += len(expected)
    assert checked > 200 and sim.neighbors.rebuilds > 20
    np.testing.assert_allclose(cell.shear_strain, rate * 200 * dt, rtol=1e-12)


def test_a_pair_through_the_z_face_follows_the_affine_shear_exactly():
    """Two spheres at rest in the shear's frame, one below the top face and one above the
    bottom face (a pair through the z face), and a pair inside the cell: over 500 steps each
    branch vector grows by gamma_dot l_z t along x, as the velocity field says, the pair
    through the face as the one inside (the image offset follows the particles)."""
    edges = np.array([8.0, 8.0, 8.0]) * 2 * RADIUS
    cell = PeriodicCell.box(np.zeros(3), edges)
    gap = 2.5 * RADIUS                                # apart: no forces anyway
    position = np.array([[5 * RADIUS, 4 * RADIUS, edges[2] - 0.4 * gap],
                         [6 * RADIUS, 4 * RADIUS, 0.6 * gap],
                         [5 * RADIUS, 9 * RADIUS, 6 * RADIUS],
                         [6 * RADIUS, 9 * RADIUS, 6 * RADIUS + gap]])
    particles = Particles(position, np.full(4, RADIUS), DENSITY)
    rate, dt, steps = 3.0, 1e-4, 500
    sim = free_scene(particles, cell, rate, dt, skin=RADIUS)
    sim.run(steps)
    grown = rate * gap * steps * dt
    np.testing.assert_allclose(cell.shear_offset, rate * edges[2] * steps * dt, rtol=1e-12)
    np.testing.assert_allclose(particles.position[3] - particles.position[2],
                               [RADIUS + grown, 0.0, gap], atol=1e-14)
    c = sim.contacts
    k = int(np.flatnonzero((c.pair_i == 0) & (c.pair_j == 1))[0])
    np.testing.assert_allclose(branch_vectors(particles.position, c, cell.period)[k],
                               [RADIUS + grown, 0.0, gap], atol=1e-14)


@pytest.mark.parametrize("through_face", [False, True])
def test_a_contact_feels_the_relative_velocity_gamma_dot_l_z(through_face):
    """Two touching spheres at rest in the shear's frame, placed inside the cell or across
    its z faces (and, then, with an offset making the image shift along x): one evaluation
    under gamma_dot gives the shear spring -ks (v - (v.n) n) dt of the relative velocity
    v = (gamma_dot l_z, 0, 0), l the branch vector through the image."""
    edges = np.array([8.0, 8.0, 8.0]) * 2 * RADIUS
    cell = PeriodicCell.box(np.zeros(3), edges)
    branch = np.array([0.6, 0.1, 1.8]) * RADIUS                      # |l| < 2R: touching
    first = np.array([3 * RADIUS, 5 * RADIUS, edges[2] - 0.5 * RADIUS])
    if not through_face:
        first[2] = 3 * RADIUS
    cell.shear_offset = 0.3 * edges[0] if through_face else 0.0
    second = first + branch
    if through_face:            # into the cell: down by Lz, back along x by the offset
        second = second - [cell.shear_offset, 0.0, edges[2]]
    particles = Particles(np.array([first, second]), np.full(2, RADIUS), DENSITY)
    rate, dt = 5.0, 1e-5
    contacts = ContactForces(YOUNG, 0.3, 30.0)
    sim = Simulation(particles, cell, dt, neighbors=NeighborList(0.2 * RADIUS),
                     forces=[contacts], integrator=Integrator(0.0), threads=1)
    cell.shear_rate = rate
    sim.evaluate_forces()
    c = sim.contacts
    assert len(c) == 1 and bool(c.image[0, 2]) == through_face
    normal = branch / np.linalg.norm(branch)
    velocity = np.array([rate * branch[2], 0.0, 0.0])
    ks = 0.3 * normal_stiffness(YOUNG, RADIUS, RADIUS)
    expected = -ks * (velocity - velocity @ normal * normal) * dt
    np.testing.assert_allclose(c.normal[0], normal, rtol=1e-12)
    np.testing.assert_allclose(c.shear_force[0], expected, rtol=1e-9)
    assert cell.shear_rate == 0.0           # until a control sets it again


def cubic_lattice(n, overlap):
    """n^3 spheres on a simple cubic lattice of spacing a = 2R (1 - overlap / 2) filling a
    periodic cell of edge n a: (positions, a)."""
    spacing = 2.0 * RADIUS * (1.0 - 0.5 * overlap)
    grid = (np.arange(n) + 0.5) * spacing
    return np.array(np.meshgrid(grid, grid, grid, indexing="ij")).reshape(3, -1).T, spacing


class AffineShear:
    """Replaces the integrator: every sphere follows the homogeneous simple shear exactly, no
    motion or spin of its own (the cell's offset follows as the integrator makes it)."""

    def apply(self, sim):
        p, cell = sim.particles, sim.walls
        p.velocity[:] = 0.0
        p.angular_velocity[:] = 0.0
        p.position[:, 0] += cell.shear_rate * p.position[:, 2] * sim.dt
        cell.follow(sim.dt)


def test_the_affine_simple_shear_of_a_cubic_lattice_has_the_stress_of_the_closed_form():
    """A simple cubic lattice (spacing a, contact force fn = kn (2R - a)) sheared affinely to
    gamma without spins: the z contacts tilt by gamma and their springs load by ks gamma a
    along -x, the x and y contacts do not move. Over the cell (a^3 a sphere, one contact of
    each direction), sigma_xz = gamma fn / a^2 and sigma_zx = gamma (fn - ks a) / a^2
    (Eq. 3.41), so tau = -(sigma_xz + sigma_zx) / 2 = gamma (ks a - 2 fn) / (2 a^2); the
    normal stresses stay fn / a^2. The z contacts lie on the top and bottom faces' pairs
    too: their branch vectors hold the offset."""
    n, overlap = 4, 0.02
    position, spacing = cubic_lattice(n, overlap)
    particles = Particles(position, np.full(len(position), RADIUS), DENSITY)
    cell = PeriodicCell.box(np.zeros(3), np.full(3, n * spacing))
    gamma, steps = 1e-4, 100
    dt = 1e-4
    sim = Simulation(particles, cell, dt, neighbors=NeighborList(0.2 * RADIUS),
                     forces=[ContactForces(YOUNG, 0.3, 89.0)],
                     controls=[ConstantShearRate(gamma / (steps * dt))],
                     integrator=AffineShear(), threads=1)
    sim.run(steps)
    sim.evaluate_forces()           # the springs of the last step's motion
    np.testing.assert_allclose(cell.shear_strain, gamma, rtol=1e-12)
    np.testing.assert_allclose(cell.shear_offset, gamma * n * spacing, rtol=1e-12)
    kn = normal_stiffness(YOUNG, RADIUS, RADIUS)
    ks, fn, a = 0.3 * kn, kn * (2 * RADIUS - spacing), spacing
    sigma = cell.stress_tensor
    np.testing.assert_allclose(np.diag(sigma), fn / a ** 2, rtol=1e-6)
    np.testing.assert_allclose([sigma[0, 2], sigma[2, 0]],
                               [gamma * fn / a ** 2, gamma * (fn - ks * a) / a ** 2], rtol=1e-3)
    np.testing.assert_allclose(sigma[[0, 1, 1, 2], [1, 0, 2, 1]], 0.0,
                               atol=1e-12 * fn / a ** 2)
    np.testing.assert_allclose(cell.shear_stress(), gamma * (ks * a - 2 * fn) / (2 * a ** 2),
                               rtol=1e-3)
    c = sim.contacts
    assert np.count_nonzero((c.image[:, 2] != 0) & (c.overlap > 0)) == n * n


def test_walls_refuse_a_shear_rate_in_one_line():
    particles = Particles(np.array([[0.5, 0.5, 0.5]]), np.full(1, 0.1), DENSITY)
    sim = Simulation(particles, Walls.box(np.zeros(3), np.ones(3)), 1e-4,
                     neighbors=NeighborList(0.01), integrator=Integrator(),
                     controls=[ConstantShearRate(1.0)])
    with pytest.raises(ValueError, match="shear_rate = 1 1/s needs a periodic cell"):
        sim.run(1)
    with pytest.raises(ValueError, match="shear_rate"):
        ConstantShearRate(float("nan"))
