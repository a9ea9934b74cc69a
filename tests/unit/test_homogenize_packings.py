"""Regular packings (Table 4.1, Eqs. 4.2-4.3) and their pendular states (Tables 4.2-4.4, Eq. 4.5)."""

import math

import numpy as np
import pytest

from pendular.homogenize import packing_state, regular_packing
from pendular.procedures.reference import CHAPTER4_SURFACE_TENSION as GAMMA

RADIUS = 1e-4
TABLE_4_1_PRINTED = {  # l': (n, Fx, Fz, a) as printed in the thesis
    2.1: (0.312, 0.362, 0.276, -0.22), 2.2: (0.318, 0.335, 0.330, -0.012), 2.3094: (0.320, 0.333, 0.333, 0.0),
    2.4: (0.318, 0.320, 0.360, 0.10), 2.5: (0.313, 0.305, 0.390, 0.21), 2.6: (0.303, 0.289, 0.422, 0.33),
    2.7: (0.288, 0.272, 0.456, 0.46),
}


def state(packing, contact_angle=0.0, method="exact", **state_input):
    return packing_state(packing, radius=RADIUS, contact_angle=contact_angle, surface_tension=GAMMA, method=method,
                         **state_input)


@pytest.mark.parametrize("kind, porosity, coordination, max_angle", [
    ("scp", 1.0 - math.pi / 6.0, 6, 45.0), ("fcp", 1.0 - math.pi / (3.0 * math.sqrt(2.0)), 12, 30.0),
    ("bcc", 1.0 - 2.0 * (4.0 * math.pi / 3.0) / (4.0 / math.sqrt(3.0)) ** 3, 8, 0.5 * math.degrees(math.acos(1 / 3)))])
def test_isotropic_packings(kind, porosity, coordination, max_angle):
    packing = regular_packing(kind)
    assert packing.porosity == pytest.approx(porosity, rel=1e-12)
    assert packing.coordination == coordination
    assert packing.fabric == pytest.approx(np.eye(3) / 3.0, abs=1e-15)
    assert packing.anisotropy == pytest.approx(0.0, abs=1e-14)
    assert packing.max_filling_angle == pytest.approx(max_angle, rel=1e-12)
    assert packing.bridges_per_cell == packing.particles_per_cell * coordination // 2
    assert np.linalg.norm(packing.normals, axis=1) == pytest.approx(np.ones(coordination))
    bridge_fabric = packing.bridge_normals.T @ packing.bridge_normals / packing.bridges_per_cell
    assert bridge_fabric == pytest.approx(packing.fabric, abs=1e-15)


def test_thesis_porosities():
    assert round(regular_packing("scp").porosity, 3) == 0.476
    assert round(regular_packing("fcp").porosity, 2) == 0.26
    assert regular_packing("bcc", 2.0 * math.sqrt(2.0)).porosity == pytest.approx(regular_packing("fcp").porosity)


@pytest.mark.parametrize("separation", [0.0, 0.1])
def test_bcc_contact_counts_at_the_geometric_limits(separation):
    scale = 1.0 + separation / 2
    assert regular_packing("bcc", 2.0 * scale, separation).coordination == 10
    assert regular_packing("bcc", 2.3 * scale, separation).coordination == 8
    assert regular_packing("bcc", 2.0 * math.sqrt(2.0) * scale, separation).coordination == 12
    isotropic = regular_packing("bcc", separation=separation)
    assert isotropic.l_prime == pytest.approx(4.0 / math.sqrt(3.0) * scale)
    assert isotropic.fabric == pytest.approx(np.eye(3) / 3.0, abs=1e-15)


@pytest.mark.parametrize("l_prime", sorted(TABLE_4_1_PRINTED))
def test_table_4_1(l_prime):
    """Eq. 4.2 in closed form: l^2 = (16 - l'^2)/2, porosity 1 - 2 (4 pi/3) / (l^2 l'); the 8 normals
    (+-l/2, +-l/2, +-l'/2)/2 give F_z = (l'/4)^2. The printed row l' = 2.2 has Fx, Fz and a wrong
    (0.335, 0.330, -0.012 for 0.349, 0.3025, -0.116: a misprint); the other rows agree to their last
    digit (l' = 2.5 prints Fz = 0.3906 as 0.390)."""
    packing = regular_packing("bcc", l_prime)
    lateral_squared = (16.0 - l_prime**2) / 2.0
    fz = (l_prime / 4.0) ** 2
    fx = (1.0 - fz) / 2.0
    assert packing.porosity == pytest.approx(1.0 - 8.0 * math.pi / 3.0 / (lateral_squared * l_prime), rel=1e-12)
    assert np.diag(packing.fabric) == pytest.approx([fx, fx, fz], rel=1e-12)
    assert packing.anisotropy == pytest.approx(2.5 * (fz - fx), abs=1e-12)
    porosity, printed_fx, printed_fz, printed_a = TABLE_4_1_PRINTED[l_prime]
    assert packing.porosity == pytest.approx(porosity, abs=1e-3)
    close = [abs(fx - printed_fx) < 1e-3, abs(fz - printed_fz) < 1e-3, abs(packing.anisotropy - printed_a) < 6e-3]
    assert close == ([False] * 3 if l_prime == 2.2 else [True] * 3)


def test_separation_scales_the_cells():
    assert regular_packing("scp", separation=0.2).porosity == pytest.approx(1.0 - 4.0 * math.pi / 3.0 / 2.2**3)
    assert regular_packing("fcp", separation=0.09).cell_volume == pytest.approx(8 * math.sqrt(2) * 1.045**3)


@pytest.mark.parametrize("kind, l_prime, separation, message", [
    ("sc", None, 0.0, "kind = 'sc'"), ("bcc", 1.9, 0.0, "l_prime = 1.9"), ("bcc", 2.9, 0.0, "l_prime = 2.9"),
    ("bcc", 2.05, 0.1, "l_prime = 2.05"), ("scp", 2.3, 0.0, "l_prime = 2.3"), ("fcp", None, -0.1, "separation"),
    ("bcc", float("nan"), 0.0, "l_prime"), ("scp", None, float("nan"), "separation")])
def test_packing_errors(kind, l_prime, separation, message):
    with pytest.raises(ValueError, match=message):
        regular_packing(kind, l_prime, separation)


# ---------------------------------------------------------------- pendular states

@pytest.mark.parametrize("method", ["exact", "toroidal"])
@pytest.mark.parametrize("kind", ["scp", "fcp", "bcc"])
def test_b_vanishes_for_isotropic_packings_at_zero_contact_angle(kind, method):
    """At theta = 0, B' is traceless (diag(-1, -1, 2) pi R^2 gamma sin^2 a cos a) and the bridge fabric is
    exactly I/3, so the discrete sum B = N k (3F - I)/V vanishes to rounding; at theta > 0 it is isotropic
    with tr B' = 2 pi R^2 gamma sin(a) sin(theta) per cap."""
    packing = regular_packing(kind)
    dry_angle = state(packing, method=method, saturation=0.05)
    scale = math.pi * RADIUS**2 * GAMMA * packing.bridges_per_cell / (packing.cell_volume * RADIUS**3)
    assert np.abs(dry_angle.B).max() < 1e-13 * scale
    wet_angle = state(packing, contact_angle=25.0, method=method, saturation=0.05)
    alpha = math.radians(wet_angle.filling_angle)
    per_cap = 2.0 * math.pi * RADIUS**2 * GAMMA * math.sin(alpha) * math.sin(math.radians(25.0)) / 3.0
    expected = 2 * packing.bridges_per_cell * per_cap / (packing.cell_volume * RADIUS**3)
    assert wet_angle.B == pytest.approx(expected * np.eye(3), rel=1e-12, abs=1e-13 * scale)


def test_b_is_deviatoric_for_anisotropic_packings_at_zero_contact_angle():
    s = state(regular_packing("bcc", 2.7), saturation=0.05)
    assert np.trace(s.B) == pytest.approx(0.0, abs=1e-12 * np.abs(s.B).max())
    assert s.B[2, 2] > 0.0 > s.B[0, 0]


@pytest.mark.parametrize("kind", ["scp", "fcp"])
def test_chi_of_isotropic_packings_from_the_wetted_area(kind):
    """Isotropic packing: chi = n Sr + (2 N_LB / V) R (cap area) / 3, cap area 2 pi R^2 (1 - cos a)."""
    packing = regular_packing(kind)
    s = state(packing, saturation=0.1)
    cap_area = 2.0 * math.pi * RADIUS**2 * (1.0 - math.cos(math.radians(s.filling_angle)))
    expected = packing.porosity * s.saturation + 2 * packing.bridges_per_cell * RADIUS * cap_area / 3.0 / (
        packing.cell_volume * RADIUS**3)
    assert s.chi == pytest.approx(expected * np.eye(3), rel=1e-12, abs=1e-15)
    assert s.saturation == pytest.approx(packing.bridges_per_cell * s.bridge_volume
                                         / (packing.porosity * packing.cell_volume * RADIUS**3), rel=1e-12)


@pytest.mark.parametrize("method", ["exact", "toroidal"])
@pytest.mark.parametrize("l_prime", [2.1, 2.7])
def test_a_psi_tends_to_the_fabric_anisotropy_as_the_packing_dries(l_prime, method):
    packing = regular_packing("bcc", l_prime)
    gaps = [abs(state(packing, method=method, saturation=sr).a_psi - packing.anisotropy) for sr in (1e-2, 1e-4, 1e-6)]
    assert gaps[0] > gaps[1] > gaps[2]
    assert gaps[2] < 2e-3 * abs(packing.anisotropy)


@pytest.mark.parametrize("contact_angle", [0.0, 30.0])
@pytest.mark.parametrize("kind, l_prime", [("scp", None), ("fcp", None), ("bcc", 2.6)])
def test_psi_at_high_suction_is_the_love_weber_stress_of_the_pendular_forces(kind, l_prime, contact_angle):
    """alpha -> 0: psi -> (1/V) sum_bridges l F n n with l = 2R and F = 2 pi gamma R cos(theta) (docs/physics.md 'The bridge model')."""
    packing = regular_packing(kind, l_prime)
    s = state(packing, contact_angle=contact_angle, suction=1e4 * GAMMA / RADIUS)
    force = 2.0 * math.pi * GAMMA * RADIUS * math.cos(math.radians(contact_angle))
    expected = 2.0 * RADIUS * force * packing.bridges_per_cell * packing.fabric / (packing.cell_volume * RADIUS**3)
    assert s.psi == pytest.approx(expected, rel=2e-2, abs=1e-12 * np.abs(expected).max())
    assert s.bridge_force == pytest.approx(force, rel=2e-2)


@pytest.mark.parametrize("method", ["exact", "toroidal"])
@pytest.mark.parametrize("kind, separation, saturation", [("scp", 0.0, 0.1), ("fcp", 0.0, 0.02),
                                                          ("scp", 0.05, 0.12), ("fcp", 0.1, 0.15)])
def test_state_round_trips(kind, separation, saturation, method):
    packing = regular_packing(kind, separation=separation)
    first = state(packing, method=method, saturation=saturation)
    assert first.saturation == pytest.approx(saturation, rel=1e-10)
    by_suction = state(packing, method=method, suction=first.suction)
    assert by_suction.saturation == pytest.approx(saturation, rel=1e-7)
    by_angle = state(packing, method=method, filling_angle=first.filling_angle)
    assert by_angle.suction == pytest.approx(first.suction, rel=1e-7)
    by_water = state(packing, method=method, water_content=first.water_content)
    assert by_water.saturation == pytest.approx(saturation, rel=1e-10)
    assert first.water_content == pytest.approx(saturation * packing.void_ratio / 2.65, rel=1e-12)
    assert by_water.psi == pytest.approx(first.psi, rel=1e-7)


def test_exact_and_toroidal_states_agree_for_small_bridges():
    packing = regular_packing("fcp")
    exact, toroidal = (state(packing, method=m, filling_angle=5.0) for m in ("exact", "toroidal"))
    assert toroidal.suction == pytest.approx(exact.suction, rel=0.02)
    assert toroidal.psi == pytest.approx(exact.psi, rel=0.02)


@pytest.mark.parametrize("state_input, message", [
    (dict(filling_angle=46.0), "pendular limit"),
    (dict(saturation=0.3), "pendular limit"),
    (dict(suction=200.0), "pendular limit"),
    (dict(saturation=0.1, suction=1e3), "exactly one of saturation, suction, water_content, filling_angle"),
    (dict(), "exactly one of"),
    (dict(saturation=1.5), "saturation = 1.5"),
    (dict(saturation=float("nan")), "saturation"),
    (dict(suction=-10.0), "suction = -10.0"),
    (dict(water_content=0.0), "water_content"),
])
@pytest.mark.parametrize("method", ["exact", "toroidal"])
def test_state_input_errors(state_input, message, method):
    with pytest.raises(ValueError, match=message):
        state(regular_packing("scp"), method=method, **state_input)


def test_fcp_beyond_its_pendular_limit():
    """FCP: alpha <= 30 deg; below about 3.4 kPa (R = 0.1 mm, theta = 0) the menisci would merge."""
    with pytest.raises(ValueError, match="pendular limit"):
        state(regular_packing("fcp"), suction=1000.0)
    with pytest.raises(ValueError, match="pendular limit"):
        state(regular_packing("fcp"), filling_angle=31.0, method="toroidal")


@pytest.mark.parametrize("parameters, message", [
    (dict(radius=-1e-4), "radius = -0.0001"), (dict(radius=float("nan")), "radius"),
    (dict(surface_tension=0.0), "surface_tension"), (dict(contact_angle=95.0), "contact_angle"),
    (dict(method="yade"), "method = 'yade'"), (dict(specific_gravity=-2.0), "specific_gravity")])
def test_state_parameter_errors(parameters, message):
    arguments = dict(radius=RADIUS, contact_angle=0.0, surface_tension=GAMMA, saturation=0.05)
    arguments.update(parameters)
    with pytest.raises(ValueError, match=message):
        packing_state(regular_packing("scp"), **arguments)
    with pytest.raises(ValueError, match="RegularPacking"):
        packing_state("scp", radius=RADIUS, contact_angle=0.0, surface_tension=GAMMA, saturation=0.05)


def test_no_bridge_spans_a_wide_gap_at_small_saturation():
    with pytest.raises(ValueError, match="rupture"):
        state(regular_packing("scp", separation=0.1), saturation=1e-5)
