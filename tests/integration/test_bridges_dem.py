"""Capillary bridges in the DEM (pendular.capillary.bridges): pair laws against the exact solver and
the tables, force bookkeeping, saturation, neighbour-list reach, the wet triaxial scenario."""

import copy
import json
import math
import os
import subprocess
import sys

import h5py
import numba
import numpy as np
import pytest

from pendular import capillary
from pendular.capillary import BridgeState, CapillaryBridges
from pendular.capillary.bridge_kernels import (gather_contact_bridges, particle_pairs,
    pendular_overlap_counts)
from conftest import PrescribedGap, ROOT, requires, two_body_scene
from pendular.dem.contact_law import ContactForces, gather_contact_forces
from pendular.dem.neighbors import NeighborList, build_contacts
from pendular.dem.state import Walls
from pendular.dem.walls import WallForces
from pendular.homogenize import capillary_force_stress, contact_stress

GAMMA = capillary.SURFACE_TENSION
YOUNG = 1e6


def add(sim, bridges):
    """Add the bridge operation to the scene's forces; return it."""
    sim.forces.append(bridges)
    return bridges


def pull_apart(bridges, radii, rate, max_steps=20000):
    """Two spheres touching, then separated at ``rate`` [m/step]; rows of (gap, force on
    sphere 1 along x, bridge state, volume) after each step, until the bridge breaks."""
    sim = two_body_scene([[0, 0, 0], [sum(radii) - 2 * rate, 0, 0]], np.zeros((2, 3)),
                         radius=radii)
    sim.integrator = PrescribedGap(-2 * rate, rate)
    sim.forces.append(bridges)
    rows = []
    for _ in range(max_steps):
        sim.advance()
        extra = BridgeState.of(sim.contacts)
        rows.append((-sim.contacts.overlap[0], sim.particles.force[1, 0], extra.state[0],
                     extra.volume[0]))
        if rows[-1][0] > 0 and extra.state[0] == 0:
            break
    return sim, np.array(rows)


def test_pulled_pair_follows_the_exact_force_distance_curve_and_ruptures_where_the_table_ends():
    """Suction control with persist: unequal spheres (r = 1.5) separated slowly."""
    radii = (1e-3, 1.5e-3)
    suction = 2000.0
    u_star = suction * radii[1] / GAMMA
    bridges = CapillaryBridges(suction, GAMMA, persist=True)
    sim, rows = pull_apart(bridges, radii, rate=2e-7)
    apart = rows[:, 0] > 0
    alive = rows[:, 2] > 0
    # the force on sphere 1 is the bridge's, pulling it back toward sphere 0 (-x)
    for gap, force, _, _ in rows[apart & alive][::15]:
        exact = capillary.bridge_at_distance(1.5, 0.0, u_star, gap / radii[1])
        assert -force / (2 * math.pi * GAMMA * radii[1]) == pytest.approx(exact.force, rel=3e-3)
    # while touching: the table's contact value on top of the spring (kn = 2 E R1 R2/(R1+R2))
    touching = rows[~apart][-1]
    kn = 2 * YOUNG * radii[0] * radii[1] / sum(radii)
    contact = capillary.bridge_at_distance(1.5, 0.0, u_star, 0.0)
    assert touching[1] == pytest.approx(
        kn * -touching[0] - contact.force * 2 * math.pi * GAMMA * radii[1], rel=1e-3)
    # rupture between the last gap with a bridge and the first without
    rupture = capillary.rupture_distance(1.5, 0.0, u_star) * radii[1]
    last_alive, first_broken = rows[alive, 0][-1], rows[-1, 0]
    assert last_alive <= rupture * (1 + 2e-3)
    assert first_broken >= rupture * (1 - 2e-3)
    assert rows[-1, 1] == 0.0
    assert bridges.required_range >= rupture


def test_bridge_breaks_with_contact_by_default():
    radii = (1e-3, 1e-3)
    bridges = CapillaryBridges(2000.0, GAMMA)
    sim, rows = pull_apart(bridges, radii, rate=2e-7, max_steps=50)
    assert rows[0, 2] == 1 and rows[0, 0] < 0
    first_gap = np.argmax(rows[:, 0] > 0)
    assert rows[first_gap, 2] == 0 and rows[first_gap, 1] == 0.0
    assert sim.operation(NeighborList).interaction_range == 0.0


def test_volume_controlled_pair_keeps_its_volume_and_ruptures_near_lian():
    """Constant water content: the volume formed at contact (at 2 kPa) is kept; rupture at the
    exact volume-controlled distance, close to Lian et al.'s (1 + theta/2) V^(1/3)."""
    radius = 1e-3
    bridges = CapillaryBridges(2000.0, GAMMA, control="volume")
    sim, rows = pull_apart(bridges, (radius, radius), rate=2e-7)
    alive = rows[:, 2] > 0
    volume = rows[0, 3]
    contact = capillary.bridge_at_distance(1.0, 0.0, 2000.0 * radius / GAMMA, 0.0)
    assert volume == pytest.approx(contact.volume * radius ** 3, rel=2e-3)
    assert np.all(rows[alive, 3] == volume)
    rupture_gap = rows[alive, 0][-1]
    exact = capillary.rupture_distance_for_volume(1.0, 0.0, volume / radius ** 3) * radius
    assert rupture_gap == pytest.approx(exact, abs=2e-7, rel=5e-3)
    assert rupture_gap == pytest.approx(volume ** (1 / 3), rel=0.03)     # Lian, theta = 0


def test_touching_pair_at_rest_has_the_capillary_equilibrium_overlap():
    """The capillary force acts on top of the contact spring: overlap = F_cap / kn."""
    radius = 1e-3
    sim = two_body_scene([[0, 0, 0], [2 * radius - 1e-7, 0, 0]], np.zeros((2, 3)), damping=0.5)
    bridges = add(sim, CapillaryBridges(1000.0, GAMMA))
    sim.run(15000)
    force = BridgeState.of(sim.contacts).force[0]
    table = bridges.suction_table.lookup(1.0, 1000.0 * radius / GAMMA, 0.0)
    assert force == pytest.approx(table[1] * 2 * math.pi * GAMMA * radius, rel=1e-12)
    assert sim.contacts.overlap[0] == pytest.approx(force / (YOUNG * radius), rel=1e-4)
    assert np.abs(sim.particles.force).max() < 1e-4 * force
    # the mechanical contact force alone is stored in contacts.force (Eq. 3.41 uses it)
    assert sim.contacts.normal_force[0] == pytest.approx(force, rel=1e-4)


def test_toroidal_bridges_use_appendix_a_and_need_equal_spheres():
    radius = 1e-3
    sim = two_body_scene([[0, 0, 0], [2 * radius - 1e-7, 0, 0]], np.zeros((2, 3)))
    add(sim, CapillaryBridges(1000.0, GAMMA, contact_angle=20.0, model="toroidal"))
    sim.advance()
    extra = BridgeState.of(sim.contacts)
    alpha = extra.filling_i[0]
    exact = capillary.toroidal_bridge(alpha, 20.0, 0.0)
    assert exact.suction_star == pytest.approx(1000.0 * radius / GAMMA, rel=1e-3)
    assert extra.force[0] == pytest.approx(exact.force * 2 * math.pi * GAMMA * radius, rel=1e-3)
    assert extra.volume[0] == pytest.approx(exact.volume * radius ** 3, rel=1e-3)
    unequal = two_body_scene([[0, 0, 0], [2.1e-3, 0, 0]], np.zeros((2, 3)),
                             radius=[1e-3, 1.1e-3], extra=[CapillaryBridges(1000.0, model="toroidal")])
    with pytest.raises(ValueError, match="equal spheres"):
        unequal.advance()


@pytest.fixture(scope="module")
def wet_sample(small_sample):
    """The 300-sphere sample wetted at 30 kPa and run 300 steps (bridges formed, rebuilds)."""
    _, sim, _ = small_sample
    sim = copy.deepcopy(sim)
    bridges = add(sim, CapillaryBridges(30000.0, GAMMA))
    sim.run(300)
    return sim, bridges


def test_saturation_bridges_and_pendular_overlaps_against_hand_sums(wet_sample):
    sim, bridges = wet_sample
    c = sim.contacts
    p = sim.particles
    touching = np.nonzero(c.overlap > 0)[0]
    assert bridges.count(sim) == len(touching) > 0
    water = 0.0
    for k in touching:
        larger = max(p.radius[c.pair_i[k]], p.radius[c.pair_j[k]])
        ratio = larger / min(p.radius[c.pair_i[k]], p.radius[c.pair_j[k]])
        _, _, volume_star, _, _ = bridges.suction_table.lookup(ratio, 30000.0 * larger / GAMMA, 0.0)
        water += volume_star * larger ** 3
    voids = np.prod(sim.walls.lengths()) - np.sum(4 / 3 * np.pi * p.radius ** 3)
    assert bridges.saturation(sim) == pytest.approx(water / voids, rel=1e-12)
    # pendular limit: brute force over the caps of every particle
    caps = {n: [] for n in range(len(p.radius))}
    for k in touching:
        i, j = c.pair_i[k], c.pair_j[k]
        branch = p.position[j] - p.position[i]
        branch /= np.linalg.norm(branch)
        caps[i].append((branch, BridgeState.of(c).filling_i[k]))
        caps[j].append((-branch, BridgeState.of(c).filling_j[k]))
    expected = 0
    for items in caps.values():
        for a in range(len(items)):
            for b in range(a + 1, len(items)):
                separation = math.degrees(math.acos(np.clip(items[a][0] @ items[b][0], -1, 1)))
                expected += separation < items[a][1] + items[b][1]
    assert bridges.pendular_overlaps(sim) == expected
    # a case that does overlap: three spheres in a tight triangle with large menisci
    position = np.array([[0.0, 0, 0], [2.0, 0, 0], [1.0, math.sqrt(3), 0]])
    contacts = build_contacts(position, np.full(3, 1.0), 0.1)
    state = np.ones(len(contacts), np.int8)
    wide = np.full(len(contacts), 31.0)    # caps 60 deg apart: 31 + 31 > 60
    zero = np.zeros(len(contacts))
    pairs = (position, np.full(3, 1.0), contacts.pair_i, contacts.pair_j, contacts.image,
             Walls.box([-3.0] * 3, [3.0] * 3).period, contacts.overlap, contacts.normal)
    assert pendular_overlap_counts(pairs, particle_pairs(contacts),
                                   BridgeState(state, zero, zero, wide, wide, zero)).sum() == 3


def test_wet_static_sample_balances_wall_contact_and_capillary_stresses(wet_sample):
    """Static equilibrium: sigma_wall = sigma_contact (Eq. 3.41) + sigma_capillary."""
    sim, bridges = wet_sample
    sim = copy.deepcopy(sim)
    bridges = sim.operation(CapillaryBridges)
    from pendular.dem.measure import unbalanced_force
    sim.run(30000, until=lambda s: unbalanced_force(s.particles, s.contacts) < 2e-4,
            check_every=500)
    capillary_stress = capillary_force_stress(sim, bridges)
    total = contact_stress(sim.particles, sim.contacts, sim.walls) + capillary_stress
    walls = sim.walls.stress()
    assert np.all(np.diag(capillary_stress) < -2 * walls.mean())   # tensile, large at 30 kPa
    assert np.allclose(np.diag(total), walls, rtol=2e-2)


@requires("threads")
def test_bridges_survive_rebuilds_and_thread_count_does_not_change_results(wet_sample):
    sim, _ = wet_sample
    neighbor_list = sim.operation(NeighborList)
    assert neighbor_list.rebuilds >= 1     # the bridges went through rebuilds
    runs = []
    for threads in (1, numba.config.NUMBA_NUM_THREADS):
        copied = copy.deepcopy(sim)
        copied.threads = threads
        copied.run(200)
        runs.append(copied)
    assert np.array_equal(runs[0].particles.position, runs[1].particles.position)
    assert np.array_equal(BridgeState.of(runs[0].contacts).force,
                          BridgeState.of(runs[1].contacts).force)


def test_bridges_at_contact_are_gathered_with_the_contact_forces(wet_sample):
    """Bridges at contact join the contact law's gather (one pass over the pairs): the forces
    are those of the two gathers apart, the torques bit for bit the contact law's alone; a
    scene without the bridges, or with bridges across gaps, gathers the contacts alone."""
    sim, _ = wet_sample
    dried = copy.deepcopy(sim)
    sim = copy.deepcopy(sim)
    contact_law, bridges = sim.operation(ContactForces), sim.operation(CapillaryBridges)
    assert contact_law.joined_by(sim) is bridges
    sim.evaluate_forces()
    c, p = sim.contacts, sim.particles
    assert np.count_nonzero(BridgeState.of(c).force) > 100
    force, torque = np.zeros_like(p.force), np.zeros_like(p.torque)
    gather_contact_forces(c.force, None, c.normal, c.overlap, p.radius, c.row_start,
                          c.second_start, c.second_pair, force, torque)
    walls_only = copy.deepcopy(sim)
    walls_only.particles.force[:] = 0.0
    walls_only.operation(WallForces).apply(walls_only)
    force += walls_only.particles.force
    dry_force = force.copy()
    gather_contact_bridges(BridgeState.of(c).force, c.normal, c.row_start, c.second_start,
                           c.second_pair, force)
    # the sums differ in order (each pair's contact force and pull added at once): round-off
    # of the pair forces summed, which can be far larger than the particles' net forces
    pair_scale = max(np.abs(c.force).max(), np.abs(BridgeState.of(c).force).max())
    np.testing.assert_allclose(p.force, force, rtol=0, atol=1e-13 * pair_scale)
    np.testing.assert_array_equal(p.torque, torque)
    dried.forces.remove(dried.operation(CapillaryBridges))  # the contact law gathers alone
    assert dried.operation(ContactForces).joined_by(dried) is None
    dried.evaluate_forces()
    np.testing.assert_allclose(dried.particles.force, dry_force, rtol=0,
                               atol=1e-12 * np.abs(dry_force).max())
    np.testing.assert_array_equal(dried.particles.torque, torque)
    assert not CapillaryBridges(30000.0, GAMMA, persist=True).joins_contact_gather
    with pytest.raises(ValueError, match=r"attraction has shape \(3,\)"):
        contact_law.gather(sim, np.zeros(3))


def test_extra_pair_arrays_are_carried_to_the_same_pair():
    rng = np.random.default_rng(5)
    position = rng.random((300, 3))
    radius = np.full(300, 0.04)
    old = build_contacts(position, radius, 0.01)
    old.extra["flag"] = rng.integers(0, 3, len(old)).astype(np.int8)
    old.extra["vector"] = rng.random((len(old), 3))
    moved = position + rng.normal(scale=0.005, size=position.shape)
    new = build_contacts(moved, radius, 0.01, previous=old)
    old_rows = {(i, j): k for k, (i, j) in enumerate(zip(old.pair_i, old.pair_j))}
    assert new.extra["flag"].dtype == np.int8 and new.extra["vector"].shape == (len(new), 3)
    for k, (i, j) in enumerate(zip(new.pair_i, new.pair_j)):
        if (i, j) in old_rows:
            assert new.extra["flag"][k] == old.extra["flag"][old_rows[i, j]]
            assert np.array_equal(new.extra["vector"][k], old.extra["vector"][old_rows[i, j]])
        else:
            assert new.extra["flag"][k] == 0 and not new.extra["vector"][k].any()


def test_the_neighbour_list_reaches_as_far_as_persisting_bridges_declare():
    radii = (1e-3, 1e-3)
    sim = two_body_scene([[0, 0, 0], [2e-3 - 1e-7, 0, 0]], np.zeros((2, 3)), radius=radii)
    sim.advance()
    assert sim.neighbors.interaction_range == 0.0
    rebuilds = sim.neighbors.rebuilds
    bridges = add(sim, CapillaryBridges(2000.0, GAMMA, persist=True))
    sim.advance()
    assert sim.neighbors.interaction_range == bridges.required_range > 0
    assert sim.neighbors.rebuilds == rebuilds + 1           # a new reach rebuilds the list
    sim.forces.remove(bridges)
    sim.advance()
    assert sim.neighbors.interaction_range == 0.0


class NegativeReach:
    def reach(self, sim):
        return -1.0

    def apply(self, sim):
        pass


def test_a_force_declaring_a_negative_reach_is_refused():
    sim = two_body_scene([[0, 0, 0], [2e-3 - 1e-7, 0, 0]], np.zeros((2, 3)),
                         extra=[NegativeReach()])
    with pytest.raises(ValueError, match="NegativeReach.reach"):
        sim.advance()


@pytest.mark.parametrize("arguments, message", [
    ({"suction": -5.0}, "suction"),
    ({"suction": 1000.0, "contact_angle": 90.0}, "contact_angle"),
    ({"suction": 1000.0, "contact_angle": 120.0}, "contact_angle"),
    ({"suction": 1000.0, "surface_tension": 0.0}, "surface_tension"),
    ({"suction": 1000.0, "model": "cylinder"}, "model"),
    ({"suction": 1000.0, "control": "flux"}, "control"),
])
def test_bad_bridge_parameters_are_refused(arguments, message):
    with pytest.raises(ValueError, match=message):
        CapillaryBridges(**arguments)


def test_suction_beyond_the_table_is_refused():
    bridges = CapillaryBridges(1e9, GAMMA)
    with pytest.raises(ValueError, match="suction = 1e\\+09 Pa is outside the valid range"):
        bridges.load_tables(2.4e-5, 2.4e-5)


def test_dry_triaxial_runs_no_capillary_physics(tmp_path):
    """A dry scene pays only for what it uses: no bridge operation, no bridge kernel run."""
    code = ("import sys; from pendular.cli import main; "
            "main(['triaxial', '--particles', '60', '--max-strain', '0.002', "
            f"'--inertial-number', '2e-3', '--quiet', '--out', {str(tmp_path)!r}], 'x'); "
            "import pendular.capillary.bridge_kernels as k; "
            "ran = [n for n in ('contact_bridges', 'suction_bridges', 'volume_bridges', "
            "'gather_contact_bridges') if getattr(k, n).signatures]; "
            "print('RAN', ran)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "RAN []" in done.stdout, done.stdout


def test_wet_triaxial_scenario_writes_the_capillary_history(wet_triaxial_run):
    out = wet_triaxial_run
    summary = json.loads((out / "summary.json").read_text())
    assert 0.0 < summary["saturation_at_peak"] < 0.1
    assert summary["initial_bridges"] > 0
    with h5py.File(out / "history.h5") as handle:
        history = handle["history"]
        rows = len(history["step"])
        for name, shape in {"saturation": (rows,), "suction": (rows,), "bridges": (rows,),
                            "pendular_overlaps": (rows,), "sigma_capillary": (rows, 3, 3)}.items():
            assert history[name].shape == shape, name
        assert np.all(history["suction"][:] == 30000.0)
        assert np.all(history["bridges"][:] > 0)
        first = np.diag(history["sigma_contact"][0] + history["sigma_capillary"][0])
        assert np.allclose(first, history["sigma_wall"][0], rtol=0.05)   # wetted, static
        assert handle.attrs["suction"] == 30000.0 and handle.attrs["bridges"] == "exact"


@pytest.mark.parametrize("arguments, message", [
    (["--suction", "-5"], "--suction"),
    (["--suction", "30000", "--contact-angle", "95"], "--contact-angle = 95.0 deg"),
    (["--suction", "1e9"], "suction = 1e+09 Pa is outside the valid range"),
    (["--contact-angle", "10"], "--suction > 0"),
    (["--suction", "30000", "--bridges", "cylinder"], "invalid choice"),
])
def test_wet_scenario_refuses_bad_input(arguments, message, capsys):
    """What scenarios/triaxial.py runs (pendular.cli.main with its prog), in this process; the
    script itself, in its own process, in the test below."""
    from pendular.cli import main

    try:
        status = main(["triaxial", *arguments, "--out", os.devnull], prog="triaxial.py")
    except SystemExit as stop:
        status = stop.code
    assert status != 0
    assert message in capsys.readouterr().err


def test_the_wet_scenario_script_exits_with_the_error_line():
    command = [sys.executable, os.path.join(ROOT, "scenarios", "triaxial.py"),
               "--suction", "30000", "--contact-angle", "95", "--out", os.devnull]
    result = subprocess.run(command, capture_output=True, text=True)
    assert result.returncode != 0
    assert "--contact-angle = 95.0 deg" in result.stderr


def test_rough_contact_bridge_is_the_exact_bridge_at_the_roughness_separation():
    """Volume control with roughness h: the bridge of two touching spheres is the Young–Laplace
    bridge whose surfaces are h R apart: solved independently from its filling angle and
    suction, it has the DEM bridge's separation, volume and force."""
    radius, roughness, surface_tension = 1e-4, 0.09, 0.073
    sim = two_body_scene([[0.0, 0.0, 0.0], [2 * radius * (1 - 1e-6), 0.0, 0.0]],
                         [[0.0] * 3] * 2, radius=radius)
    bridges = add(sim, CapillaryBridges(5000.0, surface_tension, control="volume",
                               roughness=roughness))
    sim.run(1)
    extra = BridgeState.of(sim.contacts)
    assert bridges.count(sim) == 1
    suction_star = extra.suction[0] * radius / surface_tension
    exact = capillary.solve_bridge(1.0, 0.0, suction_star, extra.filling_i[0])
    assert exact.distance == pytest.approx(roughness, abs=2e-3)
    assert extra.volume[0] / radius**3 == pytest.approx(exact.volume, rel=2e-3)
    force_star = extra.force[0] / (2 * math.pi * surface_tension * radius)
    assert force_star == pytest.approx(exact.force, rel=2e-3)
    smooth = two_body_scene([[0.0, 0.0, 0.0], [2 * radius * (1 - 1e-6), 0.0, 0.0]],
                            [[0.0] * 3] * 2, radius=radius)
    add(smooth, CapillaryBridges(5000.0, surface_tension, control="volume"))
    smooth.run(1)
    assert extra.force[0] < 0.95 * BridgeState.of(smooth.contacts).force[0]


def test_roughness_needs_volume_control():
    with pytest.raises(ValueError, match="roughness"):
        CapillaryBridges(5000.0, roughness=0.05)
    with pytest.raises(ValueError, match="roughness"):
        CapillaryBridges(5000.0, control="volume", roughness=-0.1)
