"""Capillary bridges: exact solver, suction- and volume-controlled families, tables, YADE files, toroidal."""

import json
import math
import os
import subprocess

import numba
import numpy as np
import pytest
from scipy.integrate import quad

from conftest import requires

from pendular import capillary
from pendular.capillary.verification import reference_bridge
from pendular.interop.yade.capillary_files import read_yade, write_table_files

# (radius_ratio, contact_angle, suction_star, filling_angle) spanning the solver's range
CASES = [
    (1.0, 0.0, 0.0, 20.0),
    (1.0, 0.0, 1.0, 45.0),
    (1.0, 40.0, 10.0, 5.0),
    (2.0, 20.0, 100.0, 12.0),
    (3.7, 70.0, 0.5, 15.0),
    (10.0, 0.0, 1e4, 0.8),
    (10.0, 80.0, 3.0, 9.5),
    (6.0, 10.0, 0.01, 80.0),
]


@pytest.mark.parametrize("case", CASES)
def test_solver_matches_independent_integration(case):
    bridge = capillary.solve_bridge(*case)
    reference = reference_bridge(*case)
    assert bridge.distance == pytest.approx(reference["distance"], rel=1e-8, abs=1e-10)
    for name in ("volume", "delta2", "nn11", "nn33"):
        assert getattr(bridge, name) == pytest.approx(reference[name], rel=1e-7), name


@pytest.mark.parametrize("case", CASES)
def test_force_is_the_same_on_both_contact_lines_and_at_the_neck(case):
    radius_ratio, contact_angle, suction, filling_angle = case
    bridge = capillary.solve_bridge(*case)
    theta, delta2 = math.radians(contact_angle), math.radians(bridge.delta2)
    on_sphere2 = math.sin(delta2) * math.sin(delta2 + theta) + 0.5 * suction * math.sin(delta2) ** 2
    assert on_sphere2 == pytest.approx(bridge.force, rel=1e-12)
    reference = reference_bridge(*case)
    assert reference["force_neck"] == pytest.approx(bridge.force, rel=1e-9)
    assert reference["force_2"] == pytest.approx(bridge.force, rel=1e-9)


@pytest.mark.parametrize("contact_angle, filling_angle", [(0.0, 10.0), (0.0, 40.0), (30.0, 25.0), (60.0, 20.0)])
def test_zero_suction_bridge_is_the_catenoid(contact_angle, filling_angle):
    """Equal spheres, u* = 0: y = a cosh(x/a) with a = sin(delta) sin(delta + theta)."""
    bridge = capillary.solve_bridge(1.0, contact_angle, 0.0, filling_angle)
    delta, theta = math.radians(filling_angle), math.radians(contact_angle)
    a = math.sin(delta) * math.sin(delta + theta)
    x_contact = a * math.asinh(1.0 / math.tan(delta + theta))  # tangent angle 90 - theta - delta there
    cap = math.pi / 3.0 * (1.0 - math.cos(delta)) ** 2 * (2.0 + math.cos(delta))
    revolved = math.pi * a * a * (x_contact + 0.5 * a * math.sinh(2.0 * x_contact / a))  # ∫ pi y**2 dx
    assert bridge.distance == pytest.approx(2.0 * (x_contact + math.cos(delta) - 1.0), rel=1e-10, abs=1e-12)
    assert bridge.volume == pytest.approx(revolved - 2.0 * cap, rel=1e-10)
    assert bridge.area == pytest.approx(2.0 * revolved / a, rel=1e-10)  # 2 pi ∫ y dl = 2 pi ∫ y**2/a dx
    assert bridge.force == pytest.approx(a, rel=1e-12)
    assert bridge.delta2 == pytest.approx(filling_angle, rel=1e-12)


@pytest.mark.parametrize("contact_angle", [0.0, 30.0, 60.0])
def test_small_bridge_between_touching_spheres_pulls_with_cos_theta(contact_angle):
    """F -> 2 pi gamma R cos(theta) as the filling angle at contact vanishes (high suction)."""
    bridges = [capillary.bridge_at_distance(1.0, contact_angle, suction, 0.0) for suction in (1e2, 1e4, 1e6)]
    limit = math.cos(math.radians(contact_angle))
    gaps = [abs(b.force - limit) for b in bridges]
    assert gaps[0] > gaps[1] > gaps[2] and gaps[2] < 1e-3
    # the force approaches the limit linearly in the filling angle: extrapolate to delta1 = 0
    (a, force_a), (b, force_b) = ((x.delta1, x.force) for x in bridges[1:])
    assert force_b - b * (force_a - force_b) / (a - b) == pytest.approx(limit, abs=2e-5)


def test_zero_suction_rupture_distances_match_yade_generator():
    """maxD for theta = 0 quoted in YADE's writesCapFile.m (finite differences, dz = 2e-6)."""
    yade = {1.0: 0.3995, 1.1: 0.3808, 1.25: 0.3567, 1.5: 0.3241, 1.75: 0.2983, 2.0: 0.2772, 3.0: 0.2199, 5.0: 0.1615}
    for radius_ratio, distance in yade.items():
        assert capillary.rupture_distance(radius_ratio, 0.0, 0.0) == pytest.approx(distance, rel=1.5e-3)


def test_bridge_at_distance_returns_the_stable_branch():
    radius_ratio, contact_angle, suction = 2.0, 20.0, 5.0
    rupture = capillary.rupture_distance(radius_ratio, contact_angle, suction)
    distances = np.linspace(0.0, rupture, 6)
    bridges = [capillary.bridge_at_distance(radius_ratio, contact_angle, suction, d) for d in distances]
    for bridge, distance in zip(bridges, distances):
        assert bridge.distance == pytest.approx(distance, abs=1e-12)
    assert np.all(np.diff([b.delta1 for b in bridges]) < 0.0)  # separating: the filling angle shrinks
    assert min(b.volume for b in bridges) == bridges[-1].volume  # YADE's criterion: V >= V at rupture
    # at the same distance the other (unstable) solution has a smaller filling angle
    middle = capillary.bridge_at_distance(radius_ratio, contact_angle, suction, 0.5 * rupture)
    angles = np.linspace(0.5, middle.delta1, 60)
    smaller = [capillary.solve_bridge(radius_ratio, contact_angle, suction, a) for a in angles]
    assert min(b.distance for b in smaller) < 0.5 * rupture < max(b.distance for b in smaller)
    with pytest.raises(ValueError, match="rupture distance"):
        capillary.bridge_at_distance(radius_ratio, contact_angle, suction, 1.01 * rupture)


def test_invalid_input_is_rejected_with_name_value_and_range():
    with pytest.raises(ValueError, match=r"contact_angle = 90.0 deg .*\[0, 90\)"):
        capillary.solve_bridge(1.0, 90.0, 1.0, 10.0)
    with pytest.raises(ValueError, match="contact_angle = -1.0"):
        capillary.solve_bridge(1.0, -1.0, 1.0, 10.0)
    with pytest.raises(ValueError, match=r"suction_star = -0.5 .*\[0, inf\)"):
        capillary.solve_bridge(1.0, 0.0, -0.5, 10.0)
    with pytest.raises(ValueError, match=r"radius_ratio = 0.5 .*\[1, "):
        capillary.solve_bridge(0.5, 0.0, 1.0, 10.0)
    with pytest.raises(ValueError, match=f"radius_ratio = 50.0 .*{capillary.MAX_SOLVER_RADIUS_RATIO}"):
        capillary.rupture_distance(50.0, 0.0, 1.0)
    with pytest.raises(ValueError, match="filling_angle = 70.0 deg .*90 - contact_angle"):
        capillary.solve_bridge(1.0, 30.0, 1.0, 70.0)
    with pytest.raises(ValueError, match="filling_angle = 0.0"):
        capillary.solve_bridge(1.0, 0.0, 1.0, 0.0)
    for position in range(4):
        arguments = [1.0, 0.0, 1.0, 10.0]
        arguments[position] = math.nan
        with pytest.raises(ValueError, match="= nan is not finite; valid range"):
            capillary.solve_bridge(*arguments)
    with pytest.raises(ValueError, match=r"suction_star = inf is not finite; valid range \[0, inf\)"):
        capillary.bridge_at_distance(1.0, 0.0, math.inf, 0.0)


@pytest.fixture(scope="module")
def small_table():
    return capillary.BridgeTable.build(20.0, radius_ratios=(1.0, 1.1), n_suction=120, n_distance=40, suction_max=2000.0)


def test_table_interpolation_error_is_small(small_table):
    rng = np.random.default_rng(3)
    errors = []
    for _ in range(40):
        radius_ratio = float(rng.choice([1.0, 1.1]))
        suction = 10.0 ** rng.uniform(-2.0, math.log10(2000.0))
        rupture = capillary.rupture_distance(radius_ratio, 20.0, suction)
        distance = rng.uniform(0.0, 0.99 * rupture)
        exists, force, volume, delta1, delta2 = small_table.lookup(radius_ratio, suction, distance)
        exact = capillary.bridge_at_distance(radius_ratio, 20.0, suction, distance)
        assert exists
        errors.append([force / exact.force - 1, volume / exact.volume - 1, delta1 / exact.delta1 - 1,
                       delta2 / exact.delta2 - 1])
    assert np.abs(errors).max() < 5e-3


def test_table_interpolates_between_radius_ratios_and_detects_rupture(small_table):
    exact = capillary.bridge_at_distance(1.05, 20.0, 10.0, 0.02)
    exists, force, volume, _, _ = small_table.lookup(1.05, 10.0, 0.02)
    assert exists and force == pytest.approx(exact.force, rel=1e-2) and volume == pytest.approx(exact.volume, rel=2e-2)
    rupture = capillary.rupture_distance(1.0, 20.0, 10.0)
    assert small_table.lookup(1.0, 10.0, 0.995 * rupture)[0]
    assert not small_table.lookup(1.0, 10.0, 1.005 * rupture)[0]
    # overlaps get the contact values, as in YADE
    assert small_table.lookup(1.0, 10.0, -1e-3) == small_table.lookup(1.0, 10.0, 0.0)


def test_table_lookup_runs_inside_numba_and_rejects_out_of_range(small_table):
    @numba.njit
    def total_force(radius_ratios, suction_axis, distance_low, log_rupture, log_values, suction, distances):
        total = 0.0
        for d in distances:
            exists, force, volume, delta1, delta2 = capillary.lookup_suction(
                radius_ratios, suction_axis, distance_low, log_rupture, log_values, 1.0, suction, d
            )
            if exists:
                total += force
        return total

    distances = np.array([0.0, 0.01, 10.0])
    expected = sum(small_table.lookup(1.0, 5.0, d)[1] for d in distances)
    assert total_force(*small_table.arrays(), 5.0, distances) == pytest.approx(expected, rel=1e-14)
    for radius_ratio, suction in ((1.2, 1.0), (0.9, 1.0), (1.0, -1.0), (1.0, 3000.0), (math.nan, 1.0)):
        with pytest.raises(ValueError):
            small_table.lookup(radius_ratio, suction, 0.0)


def test_table_hdf5_round_trip_and_cache(tmp_path, monkeypatch, small_table):
    path = tmp_path / "table.h5"
    small_table.save(path)
    loaded = capillary.BridgeTable.load(path)
    for mine, theirs in zip(small_table.arrays(), loaded.arrays()):
        np.testing.assert_array_equal(mine, theirs)
    assert loaded.parameters() == small_table.parameters()
    monkeypatch.setenv("PENDULAR_CACHE", str(tmp_path / "cache"))
    first = capillary.BridgeTable.cached(0.0, radius_ratios=(1.0,), n_suction=6, n_distance=5, suction_max=50.0)
    files = list((tmp_path / "cache").glob("bridge_table_*.h5"))
    assert len(files) == 1
    second = capillary.BridgeTable.cached(0.0, radius_ratios=(1.0,), n_suction=6, n_distance=5, suction_max=50.0)
    np.testing.assert_array_equal(first.values, second.values)


def test_yade_files_round_trip(tmp_path):
    table = capillary.BridgeTable.build(0.0, radius_ratios=(1.0, 2.0), n_suction=12, n_distance=4, suction_max=100.0)
    paths = write_table_files(table, tmp_path, n_distance=7)
    assert sorted(p.name for p in paths) == ["M(r=1)", "M(r=2)"]
    lines = (tmp_path / "M(r=2)").read_text().splitlines()
    assert lines[0] == "2" and lines[1] == "7"
    assert lines[2].split()[1:] == ["0"] * 7  # block header: row count then seven zeros
    files = read_yade(tmp_path)
    assert sorted(files) == [1.0, 2.0]
    for radius_ratio, capillary_file in files.items():
        distances = capillary_file.distances
        assert len(capillary_file.blocks) == 7 and distances[0] == 0.0
        assert np.all(np.diff(distances) > 0.0)
        assert distances[-1] == pytest.approx(capillary.rupture_distance(radius_ratio, 0.0, 0.0), rel=1e-10)
        for block in capillary_file.blocks:
            assert block.shape[1] == 8 and np.all(block[:, 0] == block[-1, 0])
            assert np.all(np.diff(block[:, 1]) > 0.0)
        row = capillary_file.blocks[2][3]
        exact = capillary.bridge_at_distance(radius_ratio, 0.0, row[1], row[0])
        expected = [exact.distance, exact.suction, exact.volume, exact.force, exact.delta1, exact.delta2, exact.nn11,
                    exact.nn33]
        np.testing.assert_allclose(row, expected, rtol=1e-9, atol=1e-12)


def test_toroidal_volume_is_the_integral_of_eq_a6():
    alpha, theta, separation = 25.0, 15.0, 0.1
    bridge = capillary.toroidal_bridge(alpha, theta, separation)
    r1, r2 = bridge.meridian_radius, bridge.neck_radius
    n = separation / 2 + 1 - math.cos(math.radians(alpha))
    lens = quad(lambda x: (r1 + r2 - math.sqrt(r1 * r1 - x * x)) ** 2, 0.0, n, epsabs=1e-14)[0]
    cap = quad(lambda x: 1.0 - (x - separation / 2 - 1.0) ** 2, separation / 2, n, epsabs=1e-14)[0]
    assert bridge.volume == pytest.approx(2 * math.pi * (lens - cap), rel=1e-10)
    assert bridge.suction_star == pytest.approx(1 / r1 - 1 / r2, rel=1e-14)


def test_toroidal_approximation_is_close_for_small_touching_bridges_and_rejects_its_limits():
    alpha = 5.0
    toroidal = capillary.toroidal_bridge(alpha, 0.0, 0.0)
    suction = 200.0
    for _ in range(30):  # exact suction of the touching bridge with this filling angle (fixed point)
        exact = capillary.bridge_at_distance(1.0, 0.0, suction, 0.0)
        suction *= (exact.delta1 / alpha) ** 2
    assert exact.delta1 == pytest.approx(alpha, rel=1e-6)
    assert toroidal.suction_star == pytest.approx(exact.suction, rel=0.02)
    assert toroidal.suction_star < exact.suction  # the toroidal approximation under-predicts suction
    assert toroidal.volume == pytest.approx(exact.volume, rel=0.01)
    with pytest.raises(ValueError, match="alpha \\+ contact_angle < 90"):
        capillary.toroidal_bridge(50.0, 40.0, 0.0)
    with pytest.raises(ValueError, match="neck radius"):
        capillary.toroidal_bridge(2.0, 0.0, 0.5)
    with pytest.raises(ValueError, match="separation"):
        capillary.toroidal_bridge(10.0, 0.0, -0.1)


def test_volume_controlled_bridge_keeps_its_volume_and_ruptures_near_lian_estimate():
    volume = 1e-3
    bridge = capillary.bridge_with_volume(1.0, 0.0, volume, 0.05)
    assert bridge.volume == pytest.approx(volume, rel=1e-10) and bridge.distance == pytest.approx(0.05, abs=1e-12)
    same = capillary.solve_bridge(1.0, 0.0, bridge.suction, bridge.delta1)  # it is a Young-Laplace bridge
    assert same.distance == pytest.approx(0.05, abs=1e-12) and same.volume == pytest.approx(volume, rel=1e-10)
    # past the suction-controlled rupture filling angle: stable only under volume control
    assert bridge.delta1 < capillary.bridge_at_distance(1.0, 0.0, bridge.suction, 0.05).delta1
    rupture = capillary.rupture_distance_for_volume(1.0, 0.0, volume)
    assert rupture == pytest.approx(volume ** (1 / 3), rel=0.02)  # Lian et al. (1993), theta = 0
    assert rupture > capillary.rupture_distance(1.0, 0.0, bridge.suction)  # beyond suction-controlled rupture
    near = capillary.bridge_with_volume(1.0, 0.0, volume, 0.999 * rupture)
    assert near.volume == pytest.approx(volume, rel=1e-9)
    with pytest.raises(ValueError, match="beyond the rupture distance"):
        capillary.bridge_with_volume(1.0, 0.0, volume, 1.001 * rupture)
    with pytest.raises(ValueError, match="volume_star = 10.0 is outside the valid range"):
        capillary.bridge_with_volume(1.0, 0.0, 10.0, 0.0)


def test_volume_table_lookup_matches_exact_solution():
    table = capillary.VolumeBridgeTable.build(0.0, radius_ratios=(1.0,), n_volume=40, n_distance=30, workers=1)
    for volume, fraction in ((1e-4, 0.3), (3e-3, 0.8), (0.03, 0.5)):
        rupture = capillary.rupture_distance_for_volume(1.0, 0.0, volume)
        exists, force, suction, delta1, _ = table.lookup(1.0, volume, fraction * rupture)
        exact = capillary.bridge_with_volume(1.0, 0.0, volume, fraction * rupture)
        assert exists
        assert force == pytest.approx(exact.force, rel=1e-2)
        assert suction == pytest.approx(exact.suction, rel=2e-2, abs=2e-2)
        assert delta1 == pytest.approx(exact.delta1, rel=1e-2)
        assert not table.lookup(1.0, volume, 1.01 * rupture)[0]
    with pytest.raises(ValueError):
        table.lookup(1.0, 10.0, 0.0)


YADE_TWO_SPHERES = """
import json
r1, r2, gamma, suction_star = 1e-4, 2e-4, 0.073, 10.0
O.bodies.append(sphere(center=Vector3(0, 0, 0), radius=r1, dynamic=0))
O.bodies.append(sphere(center=Vector3(0, 0, 0.999 * (r1 + r2)), radius=r2, dynamic=0))
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(aabbEnlargeFactor=1.5)], verletDist=0),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(interactionDetectionFactor=1.5)], [Ip2_FrictMat_FrictMat_CapillaryPhys()],
                    [Law2_ScGeom_FrictPhys_CundallStrack(neverErase=1)]),
    Law2_ScGeom_CapillaryPhys_Capillarity(capillaryPressure=suction_star * gamma / r2, surfaceTension=gamma),
    NewtonIntegrator(),
]
O.dt = 1e-9
O.step()
out = []
for distance_star in (0.0, 0.013, 0.05):
    O.bodies[1].state.pos = Vector3(0, 0, r1 + r2 + distance_star * r2)
    O.step()
    phys = O.interactions[0, 1].phys
    out.append([distance_star, phys.fCap.norm() / (2 * 3.141592653589793 * gamma * r2), phys.vMeniscus / r2**3])
print("RESULT" + json.dumps(out))
"""


@requires("yade")
def test_yade_reads_the_files_and_reproduces_the_exact_bridges(tmp_path):
    """YADE's Law2_ScGeom_CapillaryPhys_Capillarity, fed our M(r=...) files, gives back our bridges."""
    table = capillary.BridgeTable.build(0.0, n_suction=60, n_distance=4, suction_max=200.0)
    write_table_files(table, tmp_path, n_distance=60)
    (tmp_path / "two_spheres.py").write_text(YADE_TWO_SPHERES)
    environment = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH")}
    run = subprocess.run(["yade", "-n", "-x", "two_spheres.py"], cwd=tmp_path, capture_output=True, text=True,
                         timeout=120, env=environment)
    result = next(line for line in run.stdout.splitlines() if line.startswith("RESULT"))
    for distance, force, volume in json.loads(result[len("RESULT"):]):
        exact = capillary.bridge_at_distance(2.0, 0.0, 10.0, distance)
        assert force == pytest.approx(exact.force, rel=2e-3)  # YADE interpolates linearly in u* and d*
        assert volume == pytest.approx(exact.volume, rel=1e-2)


def test_the_samples_radius_ratio_range_is_the_tables_and_within_the_solvers():
    """One range, declared by the engine (pendular.dem.grading) and met by the tables' last
    radius-ratio node (YADE's M(r=10)) and the exact solver's verified range."""
    from pendular.capillary import MAX_SOLVER_RADIUS_RATIO, YADE_RADIUS_RATIOS
    from pendular.dem.grading import MAX_RADIUS_RATIO

    assert YADE_RADIUS_RATIOS[-1] == MAX_RADIUS_RATIO <= MAX_SOLVER_RADIUS_RATIO
