"""Simple shear of a periodic cell through loading paths (pendular.procedures.loading: a Stage's
shear_rate, ending at a ShearStrain; pendular.procedures.simple_shear):

- a face-centred cubic lattice of frictionless spheres just touching, sheared at constant
  volume: a Bravais lattice follows the affine field exactly, and only the contacts along
  (1, 0, -1) close, each by gamma R, so that with N/V spheres per volume the Love–Weber stress
  (Eq. 3.41) is tau = sigma_xx = sigma_zz = (N/V) kn R^2 gamma, sigma_yy = 0;
- a random sample sheared at constant volume keeps its volume exactly and its stress is the
  pair-by-pair Love–Weber sum over the contacts with their nearest sheared images (brute
  force, independent of the cell's face terms); drained, the servo holds the normal stress
  while the height follows the dilatancy, x and y held;
- walls refuse a shear; a stage's shear is checked where it is declared."""

import copy
import math

import numpy as np
import pytest

from pendular.dem.cell import PeriodicCell
from pendular.dem.contact_law import normal_stiffness
from pendular.dem.state import Particles
from pendular.procedures.simple_shear import SimpleShearConfig
from pendular.procedures.loading import LoadingPath, ShearStrain, Stage, Static, Strain
from pendular.procedures.preparation import PrepareConfig, dry_simulation, prepare_sample
from pendular.procedures.simple_shear import (SHEAR_COLUMNS, simple_shear_stages,
    simple_shear_summary)

RADIUS, YOUNG, DENSITY = 1e-3, 1e6, 2650.0


def fcc_lattice(cells):
    """A periodic cell of ``cells``^3 face-centred cubic unit cells (edge a = 2 sqrt(2) R) of
    frictionless spheres just touching, and its scene."""
    edge = 2.0 * math.sqrt(2.0) * RADIUS
    basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]]) + 0.25
    position = np.array([(np.array(c) + b) * edge for c in np.ndindex(cells, cells, cells)
                         for b in basis])
    particles = Particles(position, np.full(len(position), RADIUS), DENSITY)
    cell = PeriodicCell.box(np.zeros(3), np.full(3, cells * edge))
    config = PrepareConfig(particles=len(position), radius=RADIUS, young=YOUNG,
                           friction_deg=0.0, periodic=True)
    dt = 0.2 * math.sqrt(particles.mass[0] / (YOUNG * RADIUS))
    return dry_simulation(particles, cell, config, dt, 0.1 * RADIUS, 0.0, [], threads=1)


def test_a_frictionless_fcc_lattice_sheared_at_constant_volume_has_the_closed_form_stress():
    sim = fcc_lattice(3)
    gamma, steps = 1e-3, 400
    rate = gamma / (steps * sim.dt)
    path = LoadingPath(sim, [Stage(strain_rate={"x": 0.0, "y": 0.0, "z": 0.0},
                                   shear_rate=rate, until=ShearStrain(gamma))],
                       records=10, columns=SHEAR_COLUMNS, guard=False)
    path.run(sim)
    sim.evaluate_forces()
    reached = sim.walls.shear_strain
    np.testing.assert_allclose(reached, rate * sim.dt * path.steps, rtol=1e-12)
    assert path.steps in (steps, steps + 1) and reached >= gamma
    density = len(sim.particles) / sim.walls.volume()
    expected = density * normal_stiffness(YOUNG, RADIUS, RADIUS) * RADIUS ** 2 * reached
    sigma = sim.walls.stress_tensor
    np.testing.assert_allclose(sim.walls.shear_stress(), expected, rtol=2e-3)
    np.testing.assert_allclose(np.diag(sigma), [expected, 0.0, expected], rtol=2e-3,
                               atol=1e-6 * expected)
    np.testing.assert_allclose(sigma, sigma.T, atol=1e-6 * expected)
    # the spheres followed the affine field: no velocity of their own
    assert np.abs(sim.particles.velocity).max() < 1e-9 * rate * RADIUS
    history = path.recorder.arrays()       # a record's stress: that of its step's start
    np.testing.assert_allclose(history["shear_stress"][-1],
                               expected * (1.0 - rate * sim.dt / reached), rtol=2e-3)
    assert np.all(np.diff(history["shear_stress"]) > 0.0)


@pytest.fixture(scope="module")
def periodic_sample():
    """A static periodic sample of 150 spheres at 750 Pa (its simulation)."""
    return prepare_sample(PrepareConfig(particles=150, periodic=True, seed=3),
                          progress=False)[0]


def nearest_image_stress(sim):
    """(1/V) sum over the touching pairs of l (x) f [Pa], l the branch vector to the nearest
    image of j among the 125 sheared images (ix Lx + iz delta, iy Ly, iz Lz), f the pair's
    contact force: the Love–Weber sum computed apart from the cell's face terms."""
    cell, c, position = sim.walls, sim.contacts, sim.particles.position
    index = np.array(np.meshgrid(*[np.arange(-2, 3)] * 3, indexing="ij")).reshape(3, -1).T
    shifts = index * cell.lengths()
    shifts[:, 0] += index[:, 2] * cell.shear_offset
    touching = np.flatnonzero(c.overlap > 0.0)
    branch = (position[c.pair_j[touching]] - position[c.pair_i[touching]])[:, None, :] + shifts
    nearest = np.argmin(np.linalg.norm(branch, axis=2), axis=1)
    branch = branch[np.arange(len(touching)), nearest]
    return np.einsum("ka,kb->ab", branch, c.force[touching]) / cell.volume()


def sheared(sample, stages):
    """A copy of the static ``sample`` (a simulation) run along ``stages``: (simulation,
    path, history)."""
    sim = copy.deepcopy(sample)
    path = LoadingPath(sim, stages, record_every=200, columns=SHEAR_COLUMNS)
    path.run(sim)
    return sim, path, path.recorder.arrays()


def test_a_constant_volume_shear_keeps_the_volume_and_the_love_weber_stress(periodic_sample):
    rate = 2e-5 / periodic_sample.dt              # gamma 0.02 in 1,000 steps
    sim, path, history = sheared(periodic_sample, [
        Stage(strain_rate={"x": 0.0, "y": 0.0, "z": 0.0}, shear_rate=rate,
              until=ShearStrain(0.02))])
    lengths = periodic_sample.walls.lengths()
    np.testing.assert_array_equal(sim.walls.lengths(), lengths)
    assert np.all(history["volumetric_strain"] == 0.0)
    np.testing.assert_allclose(history["shear_strain"][-1], 0.02, rtol=1e-9)
    assert history["shear_stress"][-1] > 0.1 * history["normal_stress"][-1] > 0.0
    sim.evaluate_forces()
    np.testing.assert_allclose(sim.walls.stress_tensor, nearest_image_stress(sim), rtol=1e-9,
                               atol=1e-9 * np.abs(sim.walls.stress_tensor).max())
    assert np.count_nonzero((sim.contacts.image[:, 2] != 0) & (sim.contacts.overlap > 0)) > 10
    summary = simple_shear_summary(history, constant_volume=True)
    assert summary["max_volume_change"] == 0.0
    assert 0.0 < summary["peak_stress_ratio"] < 1.0


def test_a_drained_shear_holds_the_normal_stress_as_the_sample_dilates(periodic_sample):
    sample = periodic_sample
    normal = float(sample.walls.stress()[2])
    config = SimpleShearConfig(sample=PrepareConfig(particles=150, periodic=True, seed=3),
                               normal_stress=750.0, strain_rate=2e-5 / sample.dt,
                               max_strain=0.03)
    stages = simple_shear_stages(config, config.rate())
    assert len(stages) == 1 and stages[0].stress == {"z": 750.0}
    sim, path, history = sheared(periodic_sample, stages)
    np.testing.assert_array_equal(sim.walls.lengths()[:2], sample.walls.lengths()[:2])
    assert sim.walls.lengths()[2] != sample.walls.lengths()[2]
    sigma_n = history["normal_stress"][len(history["step"]) // 2:]
    assert abs(np.mean(sigma_n) / 750.0 - 1.0) < 0.02 and abs(normal / 750.0 - 1.0) < 0.02
    summary = simple_shear_summary(history, constant_volume=False)
    assert summary["max_dilatancy"] is not None and 0.0 < summary["peak_stress_ratio"] < 1.0
    assert path.shear_strain(sim) == pytest.approx(0.03, rel=1e-9)


def test_walls_refuse_a_shear_and_a_stage_checks_its_shear():
    sample = prepare_sample(PrepareConfig(particles=60, seed=1), progress=False)[0]
    with pytest.raises(ValueError, match=r"shear_rate = 1 1/s needs a periodic cell"):
        LoadingPath(sample, [Stage(strain_rate={"x": 0.0, "y": 0.0, "z": 0.0},
                                   shear_rate=1.0, until=ShearStrain(0.1))], record_every=10)
    with pytest.raises(ValueError, match="until static needs every axis"):
        Stage(stress={"x": 1.0, "y": 1.0, "z": 1.0}, shear_rate=1.0, until=Static())
    with pytest.raises(ValueError, match="until shear strain 0.1 needs a shear_rate of its"):
        Stage(strain_rate={"x": 0.0, "y": 0.0, "z": 0.0}, until=ShearStrain(0.1))
    with pytest.raises(ValueError, match="until shear strain"):
        ShearStrain(11.0)
    stage = Stage(stress={"z": 750.0}, strain_rate={"x": 0.0, "y": 0.0}, shear_rate=2.0,
                  until=ShearStrain(0.2))
    assert stage.describe() == ("z 750 Pa; x 0 1/s; y 0 1/s; shear xz 2 1/s; until shear "
                                "strain 0.2")
    assert Stage(strain_rate={"x": 0.0, "y": 0.0, "z": 1.0}, until=Strain(0.1)).describe() == (
        "x 0 1/s; y 0 1/s; z 1 1/s; until z strain 0.1")
    with pytest.raises(ValueError, match="periodic = False: a simple shear needs a periodic"):
        SimpleShearConfig(sample=PrepareConfig(particles=60))
