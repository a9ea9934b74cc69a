"""Per-bridge tensors A_ij, B'_ij (Eqs. 3.48-3.49), their rotation and sums (Eqs. 3.43-3.46),
and the harmonic forms (Eqs. 3.50, 3.55-3.57), against independent integrals and closed forms."""

import math
import time

import numpy as np
import pytest
from scipy.integrate import dblquad, quad

from pendular import homogenize
from pendular.homogenize import (capillary_stress, contact_line_integral, effective_stress,
    effective_stress_parameter, fabric_density, harmonic_effective_stress_parameter,
    harmonic_surface_tension_stress, principal_anisotropy, rotate_to_normal, rotation_onto,
    surface_tension_stress, thesis_rotation, wetted_cap_integral)

CAPS = [(1.0, 5.0), (2e-4, 30.0), (0.7, 60.0), (1.3, 120.0)]  # radius, filling angle [deg]
LINES = [(1.0, 10.0, 0.0), (2e-4, 30.0, 20.0), (0.5, 45.0, 40.0), (1.0, 3.0, 70.0)]  # radius, alpha, theta


def sphere_normal(polar, azimuth):
    return np.array([math.sin(polar) * math.cos(azimuth), math.sin(polar) * math.sin(azimuth), math.cos(polar)])


@pytest.mark.parametrize("radius, filling_angle", CAPS)
def test_wetted_cap_integral_is_the_surface_integral_over_the_cap(radius, filling_angle):
    """A_ij = ∫_cap R n_i n_j dΓ, dΓ = R^2 sin(beta) dbeta dphi, beta in [0, alpha] around z."""
    alpha = math.radians(filling_angle)
    tensor = wetted_cap_integral(radius, filling_angle)
    for i in range(3):
        for j in range(3):
            value, _ = dblquad(lambda beta, phi: radius**3 * math.sin(beta)
                               * sphere_normal(beta, phi)[i] * sphere_normal(beta, phi)[j],
                               0.0, 2.0 * math.pi, 0.0, alpha, epsabs=1e-13 * radius**3, epsrel=1e-11)
            assert tensor[i, j] == pytest.approx(value, rel=1e-9, abs=1e-12 * radius**3)


def test_wetted_cap_integral_limits():
    """Whole sphere: A = V_p I (thesis, after Eq. 3.49); tr A = R x cap area; small caps keep precision."""
    radius = 3.0
    assert wetted_cap_integral(radius, 180.0) == pytest.approx(4.0 / 3.0 * math.pi * radius**3 * np.eye(3))
    for alpha in (1e-4, 0.3, 17.0):
        cap_area = 2.0 * math.pi * radius**2 * (1.0 - math.cos(math.radians(alpha)))
        assert np.trace(wetted_cap_integral(radius, alpha)) == pytest.approx(radius * cap_area, rel=1e-9)


@pytest.mark.parametrize("radius, filling_angle, contact_angle", LINES)
def test_contact_line_integral_is_the_line_integral_of_the_surface_tension(radius, filling_angle, contact_angle):
    """B'_ij = ∫ R gamma n_i e_j dl over the contact line beta = alpha, dl = R sin(alpha) dphi, with e
    built from the geometry: e = cos(theta) t + sin(theta) n, t the unit tangent of the sphere pointing
    to the pole (into the wetted cap), i.e. the liquid-gas interface leaving the solid at angle theta."""
    gamma = 0.073
    alpha, theta = math.radians(filling_angle), math.radians(contact_angle)
    tensor = contact_line_integral(radius, filling_angle, contact_angle, gamma)
    z_axis = np.array([0.0, 0.0, 1.0])

    def direction(phi):
        n = sphere_normal(alpha, phi)
        t = z_axis - (z_axis @ n) * n
        return math.cos(theta) * t / np.linalg.norm(t) + math.sin(theta) * n

    scale = radius**2 * gamma
    for i in range(3):
        for j in range(3):
            value, _ = quad(lambda phi: radius * gamma * sphere_normal(alpha, phi)[i] * direction(phi)[j]
                            * radius * math.sin(alpha), 0.0, 2.0 * math.pi, epsabs=1e-13 * scale, limit=200)
            assert tensor[i, j] == pytest.approx(value, rel=1e-9, abs=1e-12 * scale)
    # the same e gives the surface-tension part of the bridge force of docs/physics.md 'The bridge model'
    axial_force, _ = quad(lambda phi: gamma * direction(phi)[2] * radius * math.sin(alpha), 0.0, 2.0 * math.pi)
    assert axial_force == pytest.approx(2.0 * math.pi * gamma * radius * math.sin(alpha) * math.sin(alpha + theta))


def random_normals(count, seed=0):
    normals = np.random.default_rng(seed).normal(size=(count, 3))
    return normals / np.linalg.norm(normals, axis=1)[:, None]


def test_rotation_onto_is_a_proper_rotation_onto_the_normal():
    normals = np.vstack([random_normals(200), [[0, 0, 1.0], [0, 0, -1.0], [1e-9, 0, -1.0], [1.0, 0, 0]]])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    rotation = rotation_onto(normals)
    assert np.einsum("kia,kja->kij", rotation, rotation) == pytest.approx(np.broadcast_to(np.eye(3), rotation.shape),
                                                                        abs=1e-12)
    assert np.linalg.det(rotation) == pytest.approx(np.ones(len(normals)), abs=1e-12)
    assert rotation[:, :, 2] == pytest.approx(normals, abs=1e-12)


def test_rotating_an_axisymmetric_tensor_depends_only_on_the_normal():
    """Rot(diag(a, a, c)) = a I + (c - a) n n^T, the same for n and -n; a general tensor about e_z is unchanged."""
    normals = random_normals(50, seed=1)
    local = np.broadcast_to(np.diag([2.0, 2.0, -5.0]), (50, 3, 3))
    expected = 2.0 * np.eye(3) + (-7.0) * np.einsum("ki,kj->kij", normals, normals)
    assert rotate_to_normal(local, normals) == pytest.approx(expected, abs=1e-12)
    assert rotate_to_normal(local, -normals) == pytest.approx(expected, abs=1e-12)
    general = np.arange(9.0).reshape(1, 3, 3)
    assert rotate_to_normal(general, np.array([[0.0, 0.0, 1.0]])) == pytest.approx(general)


def test_thesis_rotation_sends_z_to_the_opposite_azimuth():
    """Eq. 3.26 as printed is a rotation with M e_z at azimuth phi + pi (docs/physics.md 'Errata')."""
    for beta, phi in ((30.0, 0.0), (70.0, 125.0), (140.0, 290.0)):
        rotation = thesis_rotation(beta, phi)
        assert rotation @ rotation.T == pytest.approx(np.eye(3), abs=1e-14)
        assert np.linalg.det(rotation) == pytest.approx(1.0)
        assert rotation[:, 2] == pytest.approx(sphere_normal(math.radians(beta), math.radians(phi + 180.0)), abs=1e-14)


def test_discrete_sums_of_one_bridge():
    """One bridge along x between R1 and R2: chi and B from the caps of both particles (Eqs. 3.44-3.45)."""
    r1, r2, d1, d2, theta, gamma, volume, water = 1e-4, 2e-4, 20.0, 9.0, 15.0, 0.07, 1e-10, 3e-14
    normal = np.array([[1.0, 0.0, 0.0]])
    chi = effective_stress_parameter(normal, r1, r2, d1, d2, water, volume)
    b = surface_tension_stress(normal, r1, r2, d1, d2, theta, gamma, volume)
    caps = wetted_cap_integral(r1, d1) + wetted_cap_integral(r2, d2)
    lines = contact_line_integral(r1, d1, theta, gamma) + contact_line_integral(r2, d2, theta, gamma)
    assert chi == pytest.approx(np.diag([water + caps[2, 2], water + caps[0, 0], water + caps[1, 1]]) / volume)
    assert b == pytest.approx(np.diag([lines[2, 2], lines[0, 0], lines[1, 1]]) / volume)
    suction, total, air = 2e4, np.diag([1e3, 2e3, 3e3]), 50.0
    psi = capillary_stress(chi, b, suction)
    assert psi == pytest.approx(chi * suction + b)
    assert effective_stress(total, chi, b, suction, air) == pytest.approx(total - air * np.eye(3) + psi)


def test_discrete_sums_of_many_bridges_are_the_sums_of_the_rotated_tensors():
    """chi and B summed as (sum a) I + sum (c - a) n n^T (axisymmetric_sum) equal the sums of the
    per-bridge tensors turned onto their normals one by one (rotate_to_normal)."""
    count = 500
    rng = np.random.default_rng(5)
    normal = random_normals(count, 9)
    r1, r2 = rng.uniform(1e-5, 3e-5, count), rng.uniform(1e-5, 3e-5, count)
    d1, d2 = rng.uniform(1, 40, count), rng.uniform(1, 40, count)
    theta, gamma, volume, water = 12.0, 0.073, 1e-9, 1e-13
    caps = wetted_cap_integral(r1, d1) + wetted_cap_integral(r2, d2)
    lines = contact_line_integral(r1, d1, theta, gamma) + contact_line_integral(r2, d2, theta, gamma)
    chi = effective_stress_parameter(normal, r1, r2, d1, d2, water, volume)
    b = surface_tension_stress(normal, r1, r2, d1, d2, theta, gamma, volume)
    expected_chi = (water * np.eye(3) + rotate_to_normal(caps, normal).sum(axis=0)) / volume
    expected_b = rotate_to_normal(lines, normal).sum(axis=0) / volume
    np.testing.assert_allclose(chi, expected_chi, rtol=1e-12, atol=1e-14 * np.abs(expected_chi).max())
    np.testing.assert_allclose(b, expected_b, rtol=1e-12, atol=1e-14 * np.abs(expected_b).max())
    assert np.abs(chi - np.diag(np.diag(chi))).max() > 1e-3 * np.abs(chi).max()    # not diagonal


def test_discrete_sums_of_many_bridges_are_fast_and_checked():
    count = 30000
    rng = np.random.default_rng(2)
    args = (random_normals(count, 3), rng.uniform(1e-5, 3e-5, count), rng.uniform(1e-5, 3e-5, count),
            rng.uniform(1, 30, count), rng.uniform(1, 30, count))
    start = time.perf_counter()
    chi = effective_stress_parameter(*args, 1e-12, 1e-9)
    b = surface_tension_stress(*args, 10.0, 0.073, 1e-9)
    assert time.perf_counter() - start < 2.0
    assert chi == pytest.approx(chi.T) and b == pytest.approx(b.T)
    with pytest.raises(ValueError, match="radius_1"):
        effective_stress_parameter(args[0], args[1][:-1], *args[2:], 1e-12, 1e-9)
    with pytest.raises(ValueError, match="volume"):
        surface_tension_stress(*args, 10.0, 0.073, -1.0)
    with pytest.raises(ValueError, match="normal"):
        effective_stress_parameter(args[0][:, :2], *args[1:], 1e-12, 1e-9)


def test_principal_anisotropy_uses_the_axis_closest_to_z():
    assert principal_anisotropy(np.diag([1.0, 1.0, 2.0])) == pytest.approx(2.5 * 1.0 / 4.0)
    assert principal_anisotropy(np.diag([2.0, 2.0, 1.0])) == pytest.approx(2.5 * -1.0 / 5.0)
    turn = np.array([[0.6, -0.8, 0], [0.8, 0.6, 0], [0, 0, 1.0]])  # a rotation about z
    rotated = turn @ np.diag([1.0, 1.0, 2.0]) @ turn.T
    assert principal_anisotropy(rotated) == pytest.approx(0.625)
    assert math.isnan(principal_anisotropy(np.zeros((3, 3))))


@pytest.mark.parametrize("anisotropy", [-0.5, -0.2, 0.0, 0.46, 1.0])
def test_fabric_density_is_normalised_and_has_anisotropy_a(anisotropy):
    """Eq. 3.50: ∫ p dΩ = 1 and the fabric ∫ n n p dΩ has a = 5/2 (F_z - F_x) / tr F (Eq. 3.51)."""
    def moment(i, j):
        return dblquad(lambda beta, phi: fabric_density(anisotropy, math.degrees(beta)) * math.sin(beta)
                       * (sphere_normal(beta, phi)[i] * sphere_normal(beta, phi)[j] if i >= 0 else 1.0),
                       0.0, 2.0 * math.pi, 0.0, math.pi, epsabs=1e-13)[0]
    assert moment(-1, -1) == pytest.approx(1.0, abs=1e-12)
    fabric = np.array([[moment(i, j) for j in range(3)] for i in range(3)])
    assert np.diag(fabric) == pytest.approx([1 / 3 - 2 * anisotropy / 15] * 2 + [1 / 3 + 4 * anisotropy / 15])
    assert principal_anisotropy(fabric) == pytest.approx(anisotropy, abs=1e-12)


@pytest.mark.parametrize("kind, l_prime", [("scp", None), ("fcp", None), ("bcc", None), ("bcc", 2.1),
                                           ("bcc", 2.5), ("bcc", 2.7), ("bcc", 2.0)])
@pytest.mark.parametrize("contact_angle", [0.0, 25.0])
def test_harmonic_forms_equal_the_discrete_sums_for_the_axisymmetric_packings(kind, l_prime, contact_angle):
    """Eqs. 3.55-3.56 with a = the packing's anisotropy and N_LB = its bridges equal the discrete sums:
    both depend on the normals only through their fabric, and p(n) has the packing's (axisymmetric) fabric."""
    packing = homogenize.regular_packing(kind, l_prime)
    radius, alpha, gamma = 1e-4, 23.0, 0.074
    volume = packing.cell_volume * radius**3
    count = packing.bridges_per_cell
    water = 0.01 * volume
    discrete_chi = effective_stress_parameter(packing.bridge_normals, radius, radius, alpha, alpha, water, volume)
    discrete_b = surface_tension_stress(packing.bridge_normals, radius, radius, alpha, alpha, contact_angle, gamma,
                                        volume)
    chi = harmonic_effective_stress_parameter(packing.anisotropy, count, volume, radius, alpha, water)
    b = harmonic_surface_tension_stress(packing.anisotropy, count, volume, radius, alpha, contact_angle, gamma)
    assert chi == pytest.approx(discrete_chi, rel=1e-12, abs=1e-13)
    scale = np.abs(contact_line_integral(radius, alpha, contact_angle, gamma)).max() * count / volume
    assert b == pytest.approx(discrete_b, abs=1e-12 * scale)


def test_harmonic_forms_miss_the_non_axisymmetric_part_of_a_fabric():
    """Orthotropic normals (F diagonal, F_x != F_y): the harmonic forms differ from the discrete sums by
    (2 N / V)(c - a)(F - F_harmonic) for a cap tensor diag(a, a, c), F_harmonic of Eq. 3.50."""
    base = random_normals(100, seed=4) * np.array([1.6, 0.8, 1.2])
    signs = np.array([[sx, sy, sz] for sx in (1, -1) for sy in (1, -1) for sz in (1, -1)])
    normals = (base[:, None, :] * signs[None, :, :]).reshape(-1, 3)
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    fabric = normals.T @ normals / len(normals)
    assert fabric == pytest.approx(np.diag(np.diag(fabric)), abs=1e-15)
    anisotropy = principal_anisotropy(fabric)
    harmonic_fabric = np.diag([1 / 3 - 2 * anisotropy / 15] * 2 + [1 / 3 + 4 * anisotropy / 15])
    radius, alpha, theta, gamma, volume = 1.0, 30.0, 10.0, 0.07, 500.0
    weight = 2 * len(normals) / volume
    discrete = effective_stress_parameter(normals, radius, radius, alpha, alpha, 0.0, volume)
    harmonic = harmonic_effective_stress_parameter(anisotropy, len(normals), volume, radius, alpha, 0.0)
    cap = wetted_cap_integral(radius, alpha)
    expected = weight * (cap[2, 2] - cap[0, 0]) * (fabric - harmonic_fabric)
    assert np.abs(expected).max() > 1e-3 * np.abs(discrete).max()
    assert discrete - harmonic == pytest.approx(expected, abs=1e-12)
    discrete_b = surface_tension_stress(normals, radius, radius, alpha, alpha, theta, gamma, volume)
    harmonic_b = harmonic_surface_tension_stress(anisotropy, len(normals), volume, radius, alpha, theta, gamma)
    line = contact_line_integral(radius, alpha, theta, gamma)
    expected_b = weight * (line[2, 2] - line[0, 0]) * (fabric - harmonic_fabric)
    assert discrete_b - harmonic_b == pytest.approx(expected_b, abs=1e-14)


def test_harmonic_forms_check_their_inputs():
    with pytest.raises(ValueError, match="anisotropy = 1.5"):
        harmonic_effective_stress_parameter(1.5, 10, 1.0, 1.0, 20.0, 0.0)
    with pytest.raises(ValueError, match="volume"):
        harmonic_surface_tension_stress(0.0, 10, 0.0, 1.0, 20.0, 0.0, 0.07)
    with pytest.raises(ValueError, match="bridge_count"):
        harmonic_surface_tension_stress(0.0, float("nan"), 1.0, 1.0, 20.0, 0.0, 0.07)
