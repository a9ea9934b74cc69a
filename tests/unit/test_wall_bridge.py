"""The sphere–plane bridge (pendular.capillary.wall_bridge) against the sphere–sphere solver
at large radius ratios (the plane is their limit: the difference falls as 1/r), against the
closed form of a small bridge at contact (F = 4 pi gamma R cos theta), and its table against the
exact solver."""

import math

import numpy as np
import pytest

from pendular.capillary.meniscus import bridge_kernel
from pendular.capillary.wall_bridge import (WallBridgeTable, solve_wall_bridge,
    wall_bridge_at_distance, wall_bridge_kernel, wall_rupture_distance)


def sphere_sphere_in_sphere_units(ratio, theta, suction, delta1):
    """(D/R1, V/R1^3, F/(2 pi gamma R1)) of the sphere–sphere bridge of radius ratio ``ratio``
    at the suction u = s R1 / gamma (u* = u r)."""
    distance, volume, force, *_ = bridge_kernel(ratio, theta, suction * ratio, delta1)
    return np.array([distance * ratio, volume * ratio ** 3, force * ratio])


@pytest.mark.parametrize("contact_angle", [0.0, 30.0])
@pytest.mark.parametrize("suction", [0.1, 10.0, 1000.0])
@pytest.mark.parametrize("filling_angle", [5.0, 20.0, 40.0])
def test_the_plane_is_the_limit_of_a_large_sphere(contact_angle, suction, filling_angle):
    """At r = 1000 the sphere–sphere bridge of the same filling angle and suction is the
    sphere–plane one within a few 1e-2 (gap, volume), the force identical (the same invariant);
    the difference falls as 1/r (r = 1000 against r = 10000: ten times smaller)."""
    theta, delta1 = math.radians(contact_angle), math.radians(filling_angle)
    plane = np.array(wall_bridge_kernel(theta, suction, delta1)[:3])
    errors = []
    for ratio in (1000.0, 10000.0):
        sphere = sphere_sphere_in_sphere_units(ratio, theta, suction, delta1)
        errors.append(np.abs(sphere - plane) / np.abs(plane))
    assert np.all(errors[0][:2] < 0.05)
    assert errors[0][2] < 1e-15
    np.testing.assert_allclose(errors[0][:2] / errors[1][:2], 10.0, rtol=0.05)


@pytest.mark.parametrize("contact_angle", [0.0, 20.0])
def test_a_small_bridge_at_contact_pulls_with_four_pi_gamma_r_cos_theta(contact_angle):
    """At contact (D = 0) the stable bridge shrinks as the suction rises, and its force tends
    to 4 pi gamma R cos theta (F* = 2 cos theta), the error falling with the filling angle as
    sqrt(1/u)."""
    closed = 2.0 * math.cos(math.radians(contact_angle))
    errors = [abs(wall_bridge_at_distance(contact_angle, u, 0.0).force / closed - 1.0)
              for u in (1e3, 1e4)]
    assert errors[1] < 5e-3
    assert errors[0] / errors[1] == pytest.approx(math.sqrt(10.0), rel=0.05)


def test_the_stable_bridge_sits_between_contact_and_rupture():
    rupture = wall_rupture_distance(0.0, 10.0)
    near, far = (wall_bridge_at_distance(0.0, 10.0, d) for d in (0.0, 0.9 * rupture))
    assert 0.0 < rupture < 0.5
    assert near.volume > far.volume > 0.0 and near.force > far.force > 0.0
    with pytest.raises(ValueError, match="outside the valid range"):
        wall_bridge_at_distance(0.0, 10.0, 1.01 * rupture)
    # the meniscus meets the plane tangentially (theta = 0) at sqrt(2 F* / u)
    assert near.wetted_radius == pytest.approx(math.sqrt(2.0 * near.force / 10.0), rel=1e-12)


def test_bad_input_is_refused_naming_it():
    with pytest.raises(ValueError, match="suction"):
        solve_wall_bridge(0.0, 0.0, 10.0)
    with pytest.raises(ValueError, match="filling_angle"):
        solve_wall_bridge(30.0, 1.0, 70.0)
    with pytest.raises(ValueError, match="contact_angle"):
        solve_wall_bridge(90.0, 1.0, 10.0)


def test_the_table_interpolates_the_exact_solver_and_is_cached(tmp_path):
    """Lookups between the nodes within 1 % of the exact bridge; a cached table comes back
    from its file equal; beyond rupture no bridge."""
    table = WallBridgeTable.cached(10.0, 40, 30, 0.01, 1500.0, directory=tmp_path)
    again = WallBridgeTable.cached(10.0, 40, 30, 0.01, 1500.0, directory=tmp_path)
    assert np.array_equal(table.values, again.values)
    for suction in (0.05, 3.0, 200.0):
        rupture = wall_rupture_distance(10.0, suction)
        # the family ends at delta1 = 90 - theta, above contact at low suction
        lowest = max(0.0, wall_bridge_kernel(math.radians(10.0), suction, math.radians(80.0))[0])
        for fraction in (0.1, 0.5, 0.9):
            distance = lowest + fraction * (rupture - lowest)
            exact = wall_bridge_at_distance(10.0, suction, distance)
            exists, force, volume, delta1, wetted = table.lookup(suction, distance)
            assert exists
            assert force == pytest.approx(exact.force, rel=1e-2)
            assert volume == pytest.approx(exact.volume, rel=2e-2)
            assert delta1 == pytest.approx(exact.delta1, rel=1e-2)
        assert not table.lookup(suction, 1.01 * rupture)[0]
