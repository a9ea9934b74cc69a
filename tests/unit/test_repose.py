"""The poured pile's parts (pendular.studies.repose): the angle read from a heap's surface,
the floor and the column, the held floor spheres, and the refusals."""

import math

import numpy as np
import pytest

from pendular.procedures.preparation import PrepareConfig
from pendular.studies.repose import (HeldParticles, PileConfig, column_cloud, flank_angle,
    floor_lattice, pile_scene, repose_angle)

RADIUS = 1e-3


@pytest.mark.parametrize("angle", [15.0, 30.0, 40.0])
def test_the_angle_of_a_cone_of_spheres_is_the_cones(angle):
    """Spheres whose tops lie on a cone of slope tan(angle) (a surface layer on a grid of
    half a radius, about an axis off the origin), on a floor at 2R: the angle read back."""
    slope = math.tan(math.radians(angle))
    height = 12.0 * RADIUS
    base = height / slope
    axis = (0.05, 0.04)
    grid = np.arange(-base, base, 0.5 * RADIUS)
    x, y = np.meshgrid(grid, grid)
    r = np.hypot(x, y).ravel()
    inside = r < base
    top = 2.0 * RADIUS + height - slope * r[inside]
    position = np.column_stack([x.ravel()[inside] + axis[0], y.ravel()[inside] + axis[1],
                                top - RADIUS])
    measured, centre, profile, edge = repose_angle(position, np.full(len(position), RADIUS),
                                                   axis, 2.0 * RADIUS)
    assert measured == pytest.approx(angle, abs=0.5)
    # the heap ends where the surface falls below a diameter
    assert edge == pytest.approx(base - 2.0 * RADIUS / slope, abs=2.0 * RADIUS)
    assert profile[0] == pytest.approx(height, rel=0.05)


def test_a_monolayer_on_the_floor_is_not_part_of_the_flank():
    """A cone of 30 deg and, around it to twice its radius, grains lying in the floor's
    hollows (tops 0.7 diameter high): the same angle as the cone alone."""
    slope = math.tan(math.radians(30.0))
    centre = (np.arange(40) + 0.5) * 2.0 * RADIUS
    height = np.maximum(12.0 * RADIUS - slope * centre, 1.4 * RADIUS)
    angle, edge = flank_angle(centre, height)
    assert angle == pytest.approx(30.0, abs=0.5)
    assert edge < 12.0 * RADIUS / slope


def test_the_floor_and_the_column_hold_no_overlap():
    rng = np.random.default_rng(3)
    floor = floor_lattice(20 * RADIUS, RADIUS, 1.05, rng)
    cloud = column_cloud(200, RADIUS, 6 * RADIUS, 0.25, (0.01, 0.01), 2 * RADIUS, rng)
    for points in (floor, cloud):
        gaps = np.linalg.norm(points[:, None] - points[None], axis=2)
        np.fill_diagonal(gaps, np.inf)
        assert gaps.min() >= 2.0 * RADIUS
    assert np.all(floor[:, 2] == RADIUS)
    assert np.all(np.hypot(cloud[:, 0] - 0.01, cloud[:, 1] - 0.01) <= 5 * RADIUS + 1e-12)
    assert cloud[:, 2].min() >= 3 * RADIUS


def test_the_floor_stays_put_and_the_grains_fall_onto_it():
    material = PrepareConfig(radius=RADIUS, density=2650.0, young=1e7, friction_deg=30.0,
                             restitution=0.5, gravity=9.81)
    sim, free, floor_top, _ = pile_scene(PileConfig(material, grains=20, column_radius=3.0,
                                                    floor_side=12.0))
    held = np.setdiff1d(np.arange(len(sim.particles)), free)
    start = sim.particles.position.copy()
    sim.run(3000)
    assert isinstance(sim.forces[-1], HeldParticles)
    np.testing.assert_array_equal(sim.particles.position[held], start[held])
    fallen = start[free, 2] - sim.particles.position[free, 2]
    assert fallen.min() > 0.0
    assert sim.particles.position[free, 2].min() > floor_top      # on the floor, not through


@pytest.mark.parametrize("given, words", [
    ({"grains": 5}, "grains"),
    ({"column_fraction": 0.5}, "column_fraction"),
    ({"column_radius": 8.0, "floor_side": 10.0}, "floor_side"),
])
def test_a_pile_refuses_a_bad_setting(given, words):
    material = PrepareConfig(radius=RADIUS, gravity=9.81)
    with pytest.raises(ValueError, match=words):
        PileConfig(material, **given)


def test_a_pile_needs_gravity():
    with pytest.raises(ValueError, match="gravity = 0"):
        PileConfig(PrepareConfig(radius=RADIUS))
