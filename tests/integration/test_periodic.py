"""Periodic cell (pendular.dem.cell): pairs through the faces, the cell's stress and servo, affine
stretching, conservation, determinism, samples, and the triaxial and tension commands."""

import copy
import json

import numba
import numpy as np
import pytest

from pendular.capillary import CapillaryBridges
from pendular.capillary.bridge_state import ACROSS_GAP, BridgeState
from pendular.dem.cell import PeriodicCell, pair_virial
from pendular.dem.contact_law import ContactForces, gather_contact_forces, normal_stiffness
from pendular.dem.integrate import Integrator
from pendular.dem.neighbors import NeighborList, build_contacts, gather_pair_forces
from pendular.dem.cloud import random_cloud
from pendular.procedures.preparation import PrepareConfig, prepare_sample
from pendular.dem.sample import load_sample, save_sample
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles
from pendular.dem.walls import ConstantStrainRate, StressServo
from pendular import TriaxialConfig, TriaxialTest
from pendular.procedures.config import BridgeConfig, ShearConfig

from conftest import DENSITY, RADIUS, YOUNG, requires


def periodic_scene(position, radius, edge, velocity=None, forces=None, dt=1e-5, skin=0.3,
                   controls=(), damping=0.0, threads=1):
    """Spheres in a periodic cell [0, edge]^3 with linear contacts (friction 30 deg)."""
    particles = Particles(np.array(position, float), np.broadcast_to(radius, (len(position),)),
                          DENSITY, velocity=None if velocity is None else np.array(velocity))
    cell = PeriodicCell.box(np.zeros(3), np.full(3, edge))
    return Simulation(particles, cell, dt, neighbors=NeighborList(skin * RADIUS),
                      forces=forces or [ContactForces(YOUNG, 0.3, 30.0)],
                      controls=list(controls), integrator=Integrator(damping), threads=threads)


def test_a_pair_through_a_face_moves_as_the_same_pair_inside_the_cell():
    """Two spheres colliding obliquely, sliding and rolling on each other: placed across the x
    face, they follow the trajectory (relative position, forces, spins) of the same pair in the
    middle of the cell, step by step through the whole collision."""
    edge = 20 * RADIUS
    gap = 1.999 * RADIUS
    velocity = [[0.05, 0.02, -0.01], [-0.05, -0.02, 0.01]]
    inside = periodic_scene([[9 * RADIUS, 5 * RADIUS, 5 * RADIUS],
                             [9 * RADIUS + gap, 5 * RADIUS, 5 * RADIUS]], RADIUS, edge, velocity)
    across = periodic_scene([[edge - 0.5 * gap, 5 * RADIUS, 5 * RADIUS],
                             [0.5 * gap, 5 * RADIUS, 5 * RADIUS]], RADIUS, edge, velocity)
    across.particles.angular_velocity[0] = inside.particles.angular_velocity[0] = [3.0, 0, 0]
    touched = 0
    for _ in range(40):
        inside.run(1)
        across.run(1)
        assert np.any(across.contacts.image != 0)
        touched += inside.contacts.overlap[0] > 0.0
        relative = []
        for sim in (inside, across):
            unwrapped = sim.walls.unwrapped(sim.particles)
            branch = unwrapped[1] - unwrapped[0]
            relative.append(branch - edge * np.round(branch / edge))
        np.testing.assert_allclose(relative[1], relative[0], rtol=0, atol=1e-12 * RADIUS)
        np.testing.assert_allclose(across.contacts.force, inside.contacts.force, rtol=1e-9,
                                   atol=1e-12)
        np.testing.assert_allclose(across.particles.angular_velocity,
                                   inside.particles.angular_velocity, rtol=1e-9, atol=1e-12)
    assert touched >= 10 and np.linalg.norm(inside.particles.angular_velocity[1]) > 0.0


def test_a_bridge_through_a_face_pulls_as_inside():
    """A liquid bridge across a gap pulls the pair through the face as it does inside."""
    edge = 20 * RADIUS
    gap = 2.02 * RADIUS
    forces = {}
    for name, x in (("inside", (9 * RADIUS, 9 * RADIUS + gap)),
                    ("across", (edge - 0.5 * gap, 0.5 * gap))):
        bridges = CapillaryBridges(3000.0, persist=True)
        sim = periodic_scene([[x[0], 5 * RADIUS, 5 * RADIUS], [x[1], 5 * RADIUS, 5 * RADIUS]],
                             RADIUS, edge, forces=[ContactForces(YOUNG, 0.3, 30.0), bridges])
        sim.evaluate_forces()
        BridgeState.of(sim.contacts).state[:] = ACROSS_GAP     # a bridge that formed before
        sim.evaluate_forces()
        forces[name] = sim.particles.force.copy()
    assert forces["inside"][0, 0] > 0.0                          # attractive: 0 pulled to +x
    np.testing.assert_allclose(forces["across"], forces["inside"], rtol=1e-12)


@pytest.mark.parametrize("overlap", [0.01, 0.05])
def test_simple_cubic_lattice_has_the_stress_of_the_hand_computation(overlap):
    """A periodic simple-cubic lattice of spacing a = 2R (1 - overlap / 2): every sphere has 6
    contacts of force kn delta, so sigma = kn delta / a^2 on every axis, no shear, zero force
    on every sphere, and the cell stiffness S = kn / a (Eq. 3.41 over the cell)."""
    spacing = 2.0 * RADIUS * (1.0 - 0.5 * overlap)
    n = 4
    grid = (np.arange(n) + 0.5) * spacing
    position = np.array(np.meshgrid(grid, grid, grid, indexing="ij")).reshape(3, -1).T
    sim = periodic_scene(position, RADIUS, n * spacing)
    sim.evaluate_forces()
    sim.walls.update_stiffness(sim)
    kn = normal_stiffness(YOUNG, RADIUS, RADIUS)
    delta = 2.0 * RADIUS - spacing
    assert np.count_nonzero(sim.contacts.overlap > 0) == 3 * n ** 3
    np.testing.assert_allclose(sim.walls.stress_tensor, kn * delta / spacing ** 2 * np.eye(3),
                               rtol=1e-10, atol=1e-9 * kn * delta / spacing ** 2)
    np.testing.assert_allclose(sim.walls.stiffness, kn / spacing, rtol=1e-10)
    np.testing.assert_allclose(sim.particles.force, 0.0, atol=1e-12 * kn * delta)


def test_the_servo_holds_an_isotropic_lattice_at_its_target():
    """The lattice compressed past the target relaxes, through the cell servo alone, to the
    spacing whose hand-computed stress is the target, within 1 %."""
    spacing = 2.0 * RADIUS * 0.99
    n = 4
    grid = (np.arange(n) + 0.5) * spacing
    position = np.array(np.meshgrid(grid, grid, grid, indexing="ij")).reshape(3, -1).T
    target = 0.4 * normal_stiffness(YOUNG, RADIUS, RADIUS) * 0.02 * RADIUS / spacing ** 2
    servo = StressServo("xyz", target, max_velocity=1e-3)
    sim = periodic_scene(position, RADIUS, n * spacing, controls=[servo], damping=0.2)
    sim.run(3000)
    np.testing.assert_allclose(sim.walls.stress(), target, rtol=0.01)
    a = sim.walls.lengths()[0] / n
    kn = normal_stiffness(YOUNG, RADIUS, RADIUS)
    np.testing.assert_allclose(kn * (2 * RADIUS - a) / a ** 2, target, rtol=0.01)


def test_stretching_the_cell_carries_the_particles_affinely():
    """Without contacts, a cell stretched at a constant rate carries every particle with it:
    the fractional coordinates x / L stay fixed while L changes by 10 %."""
    edge = 40 * RADIUS
    position = random_cloud(20, RADIUS, np.zeros(3), np.full(3, edge), seed=2)
    sim = periodic_scene(position, RADIUS, edge, skin=0.5)
    fractions = sim.particles.position / sim.walls.lengths()
    rate = ConstantStrainRate("z", 1.0, edge)
    sim.controls = [rate]
    sim.run(rate.steps_to(0.1, sim.dt))
    assert sim.walls.lengths()[2] == pytest.approx(0.9 * edge, rel=1e-9)
    np.testing.assert_allclose(sim.particles.position / sim.walls.lengths(), fractions,
                               atol=1e-12)


def _touching_pairs(position, radius, lengths):
    """Pairs (i < j) of spheres overlapping through their nearest images, by brute force."""
    delta = position[None, :, :] - position[:, None, :]
    delta -= lengths * np.round(delta / lengths)
    gap = np.linalg.norm(delta, axis=2) - radius[:, None] - radius[None, :]
    i, j = np.nonzero(np.triu(gap < 0.0, k=1))
    return set(zip(i.tolist(), j.tolist()))


def test_the_list_follows_a_stretched_cell_without_missing_a_pair():
    """Spheres flying about (colliding, crossing faces) in a cell squeezed by 20 % along z and
    stretched along x: at every step every touching pair is in the list. Displacements are
    measured from the cell's stretching, so a pure stretch of 10 % needs no rebuild at all."""
    edge = 10 * RADIUS
    position = random_cloud(40, RADIUS, np.zeros(3), np.full(3, edge), seed=3)
    velocity = np.random.default_rng(3).normal(0.0, 30 * RADIUS, (40, 3))
    sim = periodic_scene(position, RADIUS, edge, velocity=velocity, skin=0.3)
    squeeze, stretch = ConstantStrainRate("z", 10.0, edge), ConstantStrainRate("x", -5.0, edge)
    sim.controls = [squeeze, stretch]
    radius = sim.particles.radius
    touched = 0
    for _ in range(squeeze.steps_to(0.2, sim.dt)):
        sim.run(1)
        listed = set(zip(sim.contacts.pair_i.tolist(), sim.contacts.pair_j.tolist()))
        touching = _touching_pairs(sim.particles.position, radius, sim.walls.lengths())
        assert touching <= listed
        touched += len(touching)
    assert touched > 100 and sim.operation(NeighborList).rebuilds > 5

    grid = (np.arange(2) + 0.5) * 0.5 * edge                      # no two ever touch
    lattice = np.array(np.meshgrid(grid, grid, grid, indexing="ij")).reshape(3, -1).T
    still = periodic_scene(lattice, RADIUS, edge, skin=0.3)
    squeeze = ConstantStrainRate("z", 10.0, edge)
    still.controls = [squeeze]
    still.run(squeeze.steps_to(0.1, still.dt))
    assert not still.particles.velocity.any()
    assert still.operation(NeighborList).rebuilds == 1       # the first build only


def test_momentum_is_conserved_while_particles_cross_the_faces():
    """No damping, no control: the total momentum of colliding spheres stays what it was
    (every pair force acts on both members, through the faces too) while they wrap."""
    rng = np.random.default_rng(3)
    edge = 14 * RADIUS
    position = random_cloud(120, RADIUS, np.zeros(3), np.full(3, edge), seed=4)
    velocity = rng.normal(0.0, 0.2, (120, 3))
    sim = periodic_scene(position, RADIUS, edge, velocity=velocity)
    p = sim.particles
    before = (p.mass[:, None] * p.velocity).sum(axis=0)
    sim.run(3000)
    after = (p.mass[:, None] * p.velocity).sum(axis=0)
    scale = np.sum(p.mass[:, None] * np.abs(velocity))
    assert np.abs(sim.walls.wraps).sum() > 20
    np.testing.assert_allclose(after, before, atol=1e-12 * scale)


def _periodic_prep(threads):
    config = PrepareConfig(particles=150, radius=RADIUS, confining=750.0, seed=5,
                           periodic=True, unload_steps=2000)
    numba.set_num_threads(threads)
    sim, report = prepare_sample(config, progress=False, threads=threads)
    sim.run(500)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    return sim, report


@pytest.fixture(scope="module")
def periodic_prep():
    """The periodic 150-sphere preparation on one thread (its simulation and report), made
    once for the module; a test that changes the simulation takes a deep copy."""
    return _periodic_prep(1)


@requires("threads")
def test_a_periodic_preparation_is_deterministic_and_thread_independent(periodic_prep):
    one, report = periodic_prep
    two, _ = _periodic_prep(2)
    again, _ = _periodic_prep(1)
    for other in (two, again):
        np.testing.assert_array_equal(other.particles.position, one.particles.position)
        np.testing.assert_array_equal(other.walls.position, one.walls.position)
    assert report["periodic"] and 0.30 < report["porosity"] < 0.42
    np.testing.assert_allclose(report["sigma_wall"], 750.0, rtol=0.011)


@pytest.mark.parametrize("persist", [False, True])
def test_the_cell_stress_gathered_with_the_forces_is_the_pair_by_pair_sum(persist,
                                                                         periodic_prep):
    """The Love–Weber sum that the contact and bridge gathers add up (each particle's position
    times its resultant, plus the pairs through a face, pendular.dem.virial) is the sum of pair_virial
    (every pair's branch vector times its force) on a static packing and on one whose
    particles are off balance, with bridges at contacts and across gaps, on 1 and 2 threads
    alike."""
    sim = copy.deepcopy(periodic_prep[0])
    bridges = CapillaryBridges(3000.0, persist=persist)
    sim.forces.append(bridges)
    for shaken in (False, True):
        if shaken:
            sim.particles.position += np.random.default_rng(0).normal(0.0, 0.01 * RADIUS,
                                                                      (150, 3))
        stresses = []
        for threads in (2, 1):      # the same state each time (the shear springs move on)
            numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
            evaluated = copy.deepcopy(sim)
            evaluated.evaluate_forces()
            stresses.append(evaluated.walls.stress_tensor)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        sim, bridges = evaluated, evaluated.forces[-1]
        c, p = sim.contacts, sim.particles
        assert np.count_nonzero(c.image.any(axis=1) & (c.overlap > 0.0)) > 20
        assert np.count_nonzero(bridges.pair_forces(sim)[c.through_face].any(axis=1)) > 10
        by_pairs = sum(pair_virial(p.position, c.row_start, c.pair_j, c.image,
                                   sim.walls.period, op.pair_forces(sim)) for op in sim.forces)
        np.testing.assert_array_equal(stresses[1], stresses[0])
        np.testing.assert_allclose(stresses[0].ravel() * sim.walls.volume(), by_pairs,
                                   rtol=1e-9, atol=1e-9 * np.abs(by_pairs).max())
        # the periodic gathers add the walled ones' forces (torques bit for bit)
        force, torque = np.zeros_like(p.force), np.zeros_like(p.torque)
        gather_contact_forces(c.force, None, c.normal, c.overlap, p.radius,
                              c.row_start, c.second_start, c.second_pair, force, torque)
        gather_pair_forces(bridges.pair_forces(sim), c.row_start, c.second_start,
                           c.second_pair, force)
        np.testing.assert_allclose(p.force, force, rtol=0, atol=1e-12 * np.abs(force).max())
        np.testing.assert_array_equal(p.torque, torque)


class _NoForce:
    """A force operation that is not a pair force (as a body force would be), adding nothing."""

    def apply(self, sim):
        pass


def test_a_force_that_is_not_a_pair_force_sends_the_cell_stress_pair_by_pair(periodic_prep):
    """With a force that has no pair_forces among the scene's (its gather adds no virial), the
    cell sums pair by pair, and gets the same stress here as from the gathers."""
    sim = copy.deepcopy(periodic_prep[0])
    gathered = copy.deepcopy(sim)       # the same state each time (the shear springs move on)
    gathered.evaluate_forces()
    sim.forces.append(_NoForce())
    sim.evaluate_forces()
    np.testing.assert_allclose(sim.walls.stress_tensor, gathered.walls.stress_tensor, rtol=1e-9,
                               atol=1e-9 * np.abs(gathered.walls.stress_tensor).max())


def test_a_periodic_sample_round_trips_and_is_refused_for_walls(tmp_path, periodic_prep):
    sim, _ = periodic_prep
    path = tmp_path / "sample.h5"
    save_sample(path, sim)
    particles, cell, _, _ = load_sample(path, expected={"periodic": True})
    assert isinstance(cell, PeriodicCell)
    np.testing.assert_array_equal(cell.position, sim.walls.position)
    np.testing.assert_allclose(particles.position, np.mod(sim.particles.position,
                                                          sim.walls.lengths()))
    with pytest.raises(ValueError, match="periodic cell.*six walls"):
        load_sample(path, expected={"periodic": False})


def test_a_cell_too_narrow_for_its_neighbours_is_refused():
    with pytest.raises(ValueError, match="periodic cell edges"):
        build_contacts(np.zeros((2, 3)) + 1e-3, np.full(2, 1e-3), 3e-4, period=np.full(3, 5e-3))


@pytest.fixture(scope="module")
def periodic_wet_triaxial(tmp_path_factory):
    out = tmp_path_factory.mktemp("periodic") / "wet"
    config = TriaxialConfig(
        sample=PrepareConfig(particles=300, confining=750.0, seed=1, periodic=True),
        shear=ShearConfig(max_strain=0.03, records=60), bridges=BridgeConfig(30000.0),
        vtk_every=2000)
    summary = TriaxialTest(config).run(str(out), progress=False)
    return out, summary


def test_periodic_wet_triaxial_holds_the_lateral_stress_and_balances(periodic_wet_triaxial):
    """The cell's lateral stress stays within 4 % of 750 Pa (a 300-sphere wet sample has
    collapse events, single records 1-3 % off; 2,000 spheres stay within 0.7 %,
    docs/periodic.md) and within 0.2 % on average; the Love–Weber stress of the contacts and
    bridges recorded beside it is the cell's stress."""
    import pendular

    out, summary = periodic_wet_triaxial
    history = pendular.read_history(str(out))
    lateral = history["sigma_wall"].values[3:, :2]
    assert np.max(np.abs(lateral - 750.0)) < 30.0
    assert np.mean(np.abs(lateral - 750.0)) < 1.5
    assert summary["stress_balance_error"] < 1e-3
    assert summary["peak_q"] > 3000.0 and 0.0 < summary["saturation_at_peak"] < 0.1


@requires("meshio")
def test_periodic_paraview_frames_show_the_cell_and_wrapped_particles(periodic_wet_triaxial):
    import meshio

    out, _ = periodic_wet_triaxial
    summary = json.loads((out / "summary.json").read_text())
    frames = sorted((out / "vtk").glob("particles_*.vtu"))
    last = meshio.read(frames[-1])
    walls = meshio.read(sorted((out / "vtk").glob("walls_*.vtu"))[-1])
    hi = walls.points.max(axis=0)
    assert np.all(last.points >= 0.0) and np.all(last.points < hi)
    stress = walls.cell_data["normal_stress"][0]
    assert stress[0] == pytest.approx(750.0, rel=0.02)
    assert summary["completed"]


def test_periodic_direct_tension_pulls_the_cell(tmp_path):
    """`pendular tension --periodic`: no grips, the cell pulled along z at zero lateral
    stress, a positive tensile strength."""
    from pendular.cli import main

    out = tmp_path / "tension"
    assert main(["tension", "--periodic", "--particles", "150", "--void-ratio", "0.58",
                 "--water-content", "1.04", "--vtk-frames", "0", "--quiet",
                 "--out", str(out)]) == 0
    case = json.loads((out / "tension.json").read_text())["cases"][0]
    assert case["tensile_strength_pa"] > 50.0 and case["grip_particles"] == []
