"""The critical time step (pendular.dem.timestep) against closed forms, the assembled stiffness and leapfrog."""

import json

import h5py
import numpy as np
import pytest
import scipy.linalg

from conftest import RADIUS, YOUNG, two_body_scene
from pendular.dem.contact_law import ContactForces, normal_stiffness
from pendular.dem.integrate import Integrator
from pendular.dem.neighbors import NeighborList
from pendular.procedures.preparation import PrepareConfig, timestep
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.timestep import critical_timestep, pwave_timestep
from pendular.dem.walls import WallForces
from pendular.cli import run_command

SHEAR_RATIO = 0.3


def _skew(n):
    """[n]x: the matrix of v -> n x v."""
    return np.array([[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]])


def exact_critical_step(sim, young=YOUNG, shear_ratio=SHEAR_RATIO):
    """2 / omega_max of the assembled stiffness (6N x 6N, translations and rotations) of the
    touching pairs and wall contacts of ``sim``: the relative displacement at a contact is
    u_j - u_i + r_i [n]x theta_i + r_j [n]x theta_j (the contact law's relative velocity),
    its spring kn n n^T + ks (I - n n^T)."""
    if sim.contacts is None:
        sim.neighbors.apply(sim)
    p, c = sim.particles, sim.contacts
    count = len(p.radius)
    stiffness = np.zeros((6 * count, 6 * count))
    for k in range(len(c.pair_i)):
        i, j = c.pair_i[k], c.pair_j[k]
        branch = p.position[j] - p.position[i] + c.image[k] * sim.walls.period
        distance = np.linalg.norm(branch)
        if distance >= p.radius[i] + p.radius[j]:
            continue
        n = branch / distance
        kn = normal_stiffness(young, p.radius[i], p.radius[j])
        spring = kn * np.outer(n, n) + shear_ratio * kn * (np.eye(3) - np.outer(n, n))
        # the arm's columns of particles i and j (its only nonzero ones): the pair adds its
        # 12 x 12 block arm^T spring arm there
        arm = np.hstack([-np.eye(3), p.radius[i] * _skew(n), np.eye(3), p.radius[j] * _skew(n)])
        block = np.r_[6 * i:6 * i + 6, 6 * j:6 * j + 6]
        stiffness[np.ix_(block, block)] += arm.T @ spring @ arm
    if not sim.walls.periodic:
        faces = sim.walls.position
        for q in range(count):
            for a in range(3):
                touching = (int(p.position[q, a] - faces[2 * a] < p.radius[q])
                            + int(faces[2 * a + 1] - p.position[q, a] < p.radius[q]))
                stiffness[6 * q + a, 6 * q + a] += touching * young * p.radius[q]
    scale = 1.0 / np.sqrt(np.repeat(np.stack([p.mass] * 3 + [p.inertia] * 3, axis=1), 1))
    scale = scale.ravel()
    largest = scipy.linalg.eigvalsh(scale[:, None] * stiffness * scale[None, :],
                                    subset_by_index=[6 * count - 1, 6 * count - 1])[0]
    return 2.0 / np.sqrt(largest)


def _rounded(step):
    """``step`` rounded down to 3 significant digits, as critical_timestep returns it."""
    digits = 10.0 ** (np.floor(np.log10(step)) - 2)
    return np.floor(step / digits) * digits


def test_a_free_pair_has_the_closed_form_critical_step():
    """Two equal spheres touching along x: the fastest modes are the normal one
    (omega^2 = 2 kn / m) and sliding with rolling (omega^2 = ks (2/m + 2 r^2/I) = 7 ks / m,
    I = 0.4 m r^2)."""
    sim = two_body_scene([[0.0, 0.0, 0.0], [1.99 * RADIUS, 0.0, 0.0]], [[0, 0, 0]] * 2)
    mass = sim.particles.mass[0]
    kn = normal_stiffness(YOUNG, RADIUS, RADIUS)
    critical = 2.0 / np.sqrt(max(2.0 * kn, 7.0 * SHEAR_RATIO * kn) / mass)
    assert critical_timestep(sim, YOUNG, SHEAR_RATIO) == pytest.approx(_rounded(critical),
                                                                         rel=1e-12)
    # a scene without a neighbour list is read, not changed: its first step evaluates forces
    assert sim.contacts is None
    assert exact_critical_step(sim) == pytest.approx(critical, rel=1e-9)
    # with stiffer shear springs the rolling mode is the fastest
    stiff = critical_timestep(sim, YOUNG, 1.0)
    assert stiff == pytest.approx(_rounded(2.0 / np.sqrt(7.0 * kn / mass)), rel=1e-12)


def test_a_sphere_between_two_walls_has_the_closed_form_critical_step():
    """One sphere pressed by the two walls of the x axis: omega^2 = 2 kn / m, kn = E r."""
    sim = two_body_scene([[0.0, 0.0, 0.0]], [[0, 0, 0]], box=0.99 * RADIUS)
    sim.walls.position[2:] = [-1.0, 1.0, -1.0, 1.0]
    expected = 2.0 * np.sqrt(sim.particles.mass[0] / (2.0 * YOUNG * RADIUS))
    assert critical_timestep(sim, YOUNG, SHEAR_RATIO) == pytest.approx(_rounded(expected),
                                                                         rel=1e-12)
    assert exact_critical_step(sim) == pytest.approx(expected, rel=1e-12)


def test_nothing_touching_has_no_critical_step():
    sim = two_body_scene([[0.0, 0.0, 0.0], [3.0 * RADIUS, 0.0, 0.0]], [[0, 0, 0]] * 2)
    assert critical_timestep(sim, YOUNG, SHEAR_RATIO) == np.inf


def test_the_critical_step_of_a_prepared_packing_is_the_assembled_one(small_sample):
    """A 300-sphere sample at 750 Pa (walls, friction 18 deg): the Lanczos step equals the
    eigenvalue of the assembled stiffness (1e-3, 3 digits kept) and lies well above the P-wave
    estimate."""
    config, sim, _ = small_sample
    found = critical_timestep(sim, config.young, config.shear_ratio)
    exact = exact_critical_step(sim, config.young, config.shear_ratio)
    assert found <= exact < found * 1.01
    pwave = pwave_timestep(sim.particles.radius, config.young, config.density)
    assert 1.2 * pwave < exact < 2.0 * pwave


def test_leapfrog_is_stable_below_the_critical_step_and_not_above(small_sample):
    """The packing at 750 Pa released undamped between fixed walls (friction high enough that
    nothing slides): over 200 steps at 0.95 of the critical step its kinetic energy stays
    below 5 % of the elastic energy it started with; at 1.1 the fastest mode grows until
    contacts open, and the kinetic energy passes the elastic energy."""
    config, prepared, _ = small_sample
    critical = critical_timestep(prepared, config.young, config.shear_ratio)
    c = prepared.contacts
    touching = c.overlap > 0.0
    elastic = 0.5 * np.sum(c.normal_force[touching] * c.overlap[touching])
    kinetic = {}
    for factor in (0.95, 1.1):
        p = prepared.particles
        particles = Particles(p.position.copy(), p.radius.copy(), p.density)
        sim = Simulation(particles, Walls(position=prepared.walls.position.copy()),
                         factor * critical, neighbors=NeighborList(0.3 * config.radius),
                         forces=[ContactForces(config.young, config.shear_ratio, 89.0),
                                 WallForces(config.young)],
                         integrator=Integrator(0.0))
        largest = 0.0
        for _ in range(200):
            sim.advance()
            largest = max(largest, 0.5 * np.sum(particles.mass[:, None]
                                                * particles.velocity ** 2))
        kinetic[factor] = largest / elastic
    assert kinetic[0.95] < 0.05
    assert kinetic[1.1] > 1.0


def test_the_stiffness_rule_sets_the_step_from_the_contacts(small_sample):
    """timestep() with the stiffness rule: safety times the critical step; without contacts,
    the P-wave estimate of the current radii (a cloud before it touches)."""
    config, sim, _ = small_sample
    rule = PrepareConfig(particles=300, confining=750.0, seed=1, timestep_rule="stiffness")
    critical = critical_timestep(sim, config.young, config.shear_ratio)
    assert timestep(sim, rule) == pytest.approx(rule.timestep_safety * critical, rel=1e-12)
    apart = two_body_scene([[0.0, 0.0, 0.0], [3.0 * RADIUS, 0.0, 0.0]], [[0, 0, 0]] * 2)
    assert timestep(apart, rule) == pytest.approx(
        rule.timestep_safety * pwave_timestep(apart.particles.radius, rule.young,
                                              rule.density), rel=1e-12)
    with pytest.raises(ValueError, match="timestep_rule"):
        PrepareConfig(timestep_rule="courant")


def test_the_triaxial_command_runs_with_the_stiffness_rule(tmp_path, capsys):
    """``--timestep-rule stiffness``: the shear's step is 0.7 of the critical step of the
    prepared packing, larger than the P-wave rule's, and said so in the summary's
    configuration; an unknown rule ends in argparse's error line naming the option."""
    out = tmp_path / "stiff"
    assert run_command("triaxial", ["--particles", "120", "--max-strain", "0.004",
                                    "--inertial-number", "2e-3", "--timestep-rule", "stiffness",
                                    "--vtk-every", "0", "--quiet", "--out", str(out)],
                       prog="triaxial.py") == 0
    summary = json.loads((out / "summary.json").read_text())
    table = PrepareConfig()         # the command's material: thesis Table 5.2
    pwave = 0.7 * pwave_timestep(summary["grading"]["radius_min"], table.young, table.density)
    assert summary["dt"] > 1.2 * pwave
    with h5py.File(out / "history.h5") as history:
        assert history.attrs["timestep_rule"] == "stiffness"
        assert "critical time step" in history.attrs["timestep"]
    capsys.readouterr()
    with pytest.raises(SystemExit) as stop:
        run_command("triaxial", ["--timestep-rule", "courant", "--out", str(tmp_path / "x")],
                    prog="triaxial.py")
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert stop.value.code == 2 and "error: argument --timestep-rule" in err[-1]
    assert not any("Traceback" in line for line in err)
