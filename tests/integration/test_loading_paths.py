"""Loading paths through the library (pendular.procedures.loading) against closed forms on
regular packings of equal elastic spheres (kn = E R, ks = shear_ratio kn):

- oedometric loading of a simple cubic packing between walls: every contact force is axial,
  so K0 = 0, and the column of n spheres between the two z walls is n + 1 springs of
  stiffness E R in series over a height 2 R n carrying sigma (2 R)^2: M = E n / (2 (n + 1));
- oedometric loading of a periodic regular packing (the strain affine, every particle alike):
  a contact of normal n shortens by 2 R eps n_z^2, so with N/V particles per volume
  sigma_ij = (N/V) 2 R^2 eps sum over the neighbours of n_i n_z (kn n_z n_j + ks (delta_jz -
  n_z n_j)) (Love-Weber): frictionless, M = (N/V) 2 R^2 kn sum n_z^4 and
  K0 = sum n_x^2 n_z^2 / sum n_z^4 (1/2 for the face-centred packing); with elastic friction
  the Voigt bound with ks;
- an isotropic loading and unloading of the simple cubic packing between walls: each axis is
  the column above, and the unloading returns to the start;

and the mixed conditions (constant p, constant b) holding their targets through a shear."""

import copy
import math

import numpy as np
import pytest

from pendular.dem.cell import PeriodicCell
from pendular.dem.state import Particles, Walls
from pendular.homogenize import regular_packing
from pendular.procedures.config import ShearConfig
from pendular.procedures.loading import LoadingPath
from pendular.procedures.columns import k0, void_ratio
from pendular.procedures.isotropic import isotropic_stages, isotropic_summary
from pendular.procedures.triaxial import measured_b
from pendular.procedures.oedometer import oedometer_stages, oedometer_summary
from pendular.procedures.preparation import PrepareConfig, dry_simulation
from pendular.procedures.triaxial import TriaxialShear, summarize
from pendular.homogenize.invariants import mean_stress

RADIUS, YOUNG, DENSITY, SHEAR_RATIO = 1e-3, 1e6, 2650.0, 0.3
#: Strain per step of the loading: slow against the lattice's vibrations (quasi-static).
STRAIN_PER_STEP = 2e-7
COLUMNS = {"void_ratio": void_ratio, "k0": k0}


def lattice(kind, cells, periodic, friction=0.0):
    """(scene, packing): ``cells`` unit cells of the regular packing ``kind`` (equal spheres
    just touching), in a periodic cell or between six walls touching the outer spheres."""
    packing = regular_packing(kind)
    size = np.asarray(packing.cell_size) * RADIUS
    basis = [np.zeros(3)] if kind == "scp" else [np.zeros(3), 0.5 * size]
    position = np.array([np.array(c) * size + b for c in np.ndindex(*cells) for b in basis])
    extent = np.array(cells) * size
    if periodic:
        box = PeriodicCell.box(np.zeros(3), extent)
        position += 0.25 * size
    else:                                   # walls tangent to the outer spheres
        box = Walls.box(np.zeros(3), extent - size + 2.0 * RADIUS)
        position += RADIUS
    particles = Particles(position, np.full(len(position), RADIUS), DENSITY)
    config = PrepareConfig(particles=len(position), radius=RADIUS, young=YOUNG,
                           shear_ratio=SHEAR_RATIO, friction_deg=friction, periodic=periodic)
    dt = 0.2 * math.sqrt(particles.mass[0] / (YOUNG * RADIUS))
    sim = dry_simulation(particles, box, config, dt, 0.1 * RADIUS, friction, [], threads=1)
    return sim, packing


def oedometric(sim, stress, guard=True):
    """The oedometer_stages path of ``sim`` to the axial ``stress`` [Pa]; its summary."""
    path = LoadingPath(sim, oedometer_stages(stress, STRAIN_PER_STEP / sim.dt),
                       record_every=500, columns=COLUMNS, guard=guard)
    path.run(sim)
    return oedometer_summary(path.recorder.arrays(), stress)


def test_simple_cubic_packing_between_walls_gives_k0_zero_and_its_constrained_modulus():
    layers = 4
    sim, _ = lattice("scp", (3, 3, layers), periodic=False)
    summary = oedometric(sim, 1000.0)
    assert summary["k0"] == 0.0                 # no contact has a lateral component
    modulus = YOUNG * layers / (2.0 * (layers + 1))
    assert summary["constrained_modulus"] == pytest.approx(modulus, rel=1e-3)
    assert summary["axial_stress_at_load"] == pytest.approx(1000.0, rel=1e-3)


def affine_closed_form(packing, shear_ratio):
    """(M [Pa], K0 [-]) of a periodic regular packing in affine oedometric strain (module
    docstring), ks = shear_ratio kn (0: frictionless)."""
    n = packing.normals
    nx, nz = n[:, 0] ** 2, n[:, 2] ** 2
    density = packing.particles_per_cell / packing.cell_volume       # per R^3
    axial = np.sum(nz * nz) + shear_ratio * np.sum(nz - nz * nz)
    lateral = (1.0 - shear_ratio) * np.sum(nx * nz)
    return 2.0 * YOUNG * density * axial, lateral / axial


@pytest.mark.parametrize("kind, friction, shear_ratio", [
    ("scp", 0.0, 0.0), ("fcp", 0.0, 0.0), ("fcp", 30.0, SHEAR_RATIO)])
def test_periodic_regular_packing_gives_the_affine_k0_and_constrained_modulus(
        kind, friction, shear_ratio):
    """The face-centred packing: K0 = 1/2 frictionless; with friction 30 degrees every contact
    stays elastic (tangential / normal force 0.3 < tan 30) and the Voigt values hold."""
    sim, packing = lattice(kind, (4, 4, 4), periodic=True, friction=friction)
    summary = oedometric(sim, 500.0, guard=False)   # the densest packing: the guard's bound
    modulus, expected = affine_closed_form(packing, shear_ratio)
    # second order in the strain (5e-4 to 1e-3): the normals turn as the lattice shortens
    assert summary["constrained_modulus"] == pytest.approx(modulus, rel=3e-3)
    assert summary["k0"] == pytest.approx(expected, abs=3e-3)


def test_isotropic_path_on_a_regular_packing_returns_to_its_start_on_unloading():
    layers = 4
    sim, _ = lattice("scp", (layers, layers, layers), periodic=False)
    start = sim.walls.lengths().copy()
    stresses = [500.0, 2000.0, 500.0]
    path = LoadingPath(sim, isotropic_stages(stresses, STRAIN_PER_STEP / sim.dt,
                                             max_steps=200000, unbalanced=1e-3,
                                             tolerance=1e-3),
                       record_every=500, columns={"void_ratio": void_ratio})
    path.run(sim)
    history = path.recorder.arrays()
    summary = isotropic_summary(history, stresses)
    first, top, last = summary["stages"]
    assert last["void_ratio"] == pytest.approx(first["void_ratio"], abs=2e-5)
    # each axis a column of layers + 1 springs: eps = sigma / M at the top of the path
    modulus = YOUNG * layers / (2.0 * (layers + 1))
    row = np.flatnonzero(history["stage"] == 1)[-1]
    lengths = start * (1.0 - history["sigma_wall"][row] / modulus)
    solid = sim.particles.solid_volume()
    assert top["void_ratio"] == pytest.approx(np.prod(lengths) / solid - 1.0, rel=1e-3)
    assert summary["compression_index"] == pytest.approx(summary["swelling_index"], rel=0.02)


@pytest.fixture(scope="module")
def sheared_sample(small_sample):
    """Shears of the 300-sphere sample: (config, {name: history})."""
    config, sim, _ = small_sample
    histories = {}
    for name, shear in (("constant_p", ShearConfig(max_strain=0.03, constant_p=True)),
                        ("b", ShearConfig(max_strain=0.03, b=0.5))):
        scene = copy.deepcopy(sim)
        run = TriaxialShear(scene, ShearConfig(**{**vars(shear), "inertial_number": 1e-3,
                                                  "records": 60}),
                            config.confining, config.radius, config.density)
        scene.run(run.steps)
        histories[name] = run.recorder.arrays()
    return config, histories


def test_constant_mean_stress_holds_within_one_percent_through_the_shear(sheared_sample):
    config, histories = sheared_sample
    sigma = histories["constant_p"]["sigma_wall"]
    p = mean_stress(sigma)
    assert np.max(np.abs(p / config.confining - 1.0)) < 0.01
    assert summarize(histories["constant_p"])["peak_q"] > 0.3 * config.confining
    assert np.ptp(sigma[:, 2]) > 0.3 * config.confining     # q rose: the condition worked


def test_constant_b_holds_within_one_percent_through_the_shear(sheared_sample):
    """b = (sigma_y - sigma_x) / (sigma_z - sigma_x) within 0.01 (1 % of its range [0, 1]) from
    0.5 % axial strain on (before, the servoed y walls lag the fast rise of sigma_z), within
    1 % of b = 0.5 on average; sigma_3 = sigma_x held as the conventional triaxial's lateral
    stress (its servo's steady error as the sample dilates: under 1 % on average)."""
    config, histories = sheared_sample
    history = histories["b"]
    later = history["axial_strain"] >= 0.005
    b = measured_b(history["sigma_wall"][later], config.confining)
    assert np.isfinite(b).all()
    assert np.max(np.abs(b - 0.5)) < 0.01
    assert np.mean(np.abs(b - 0.5)) < 0.01 * 0.5
    minor = np.abs(history["sigma_wall"][later, 0] / config.confining - 1.0)
    assert minor.mean() < 0.01 and minor.max() < 0.03
