"""The wall servo's law (YADE's TriaxialStressController, pendular.dem.walls.StressServo) against a hand
computation, step by step."""

from types import SimpleNamespace

import numpy as np
import pytest

from pendular.dem.state import Walls
from pendular.dem.walls import StressServo


def _scene(lo, hi, force, stiffness):
    walls = Walls.box(lo, hi)
    walls.force[:] = force
    walls.stiffness[:] = stiffness
    return SimpleNamespace(walls=walls, dt=1e-3)


@pytest.mark.parametrize("scale", [False, True])
def test_servo_moves_each_wall_by_its_clipped_stress_error_with_memory(scale):
    lo, hi = np.zeros(3), np.array([1.0, 2.0, 4.0])
    force = np.array([10.0, 3.0, 9.0, 8.0, 0.0, 2.0])         # N
    stiffness = np.array([1e3, 1e3, 2e3, 1e4, 5e2, 0.0])       # the z+ wall touches nothing
    sim = _scene(lo, hi, force, stiffness)
    servo = StressServo("xyz", 1.5, max_velocity=2.0, gain=0.75, memory=0.8,
                        scale_max_velocity=scale)
    previous = np.zeros(6)
    position = sim.walls.position.copy()
    for _ in range(2):
        lengths = position[1::2] - position[0::2]
        area = np.repeat([lengths[1] * lengths[2], lengths[0] * lengths[2],
                          lengths[0] * lengths[1]], 2)
        cap = 2.0 * 1e-3 * (np.repeat(3.0 * lengths / lengths.sum(), 2) if scale else np.ones(6))
        shift = np.where(stiffness > 0.0,
                         np.clip((force - 1.5 * area) / np.where(stiffness > 0, stiffness, 1.0),
                                 -cap, cap), -cap)
        previous = 0.75 * shift + 0.8 * previous
        position += np.array([-1.0, 1.0] * 3) * previous        # outward shift opens the box
        servo.apply(sim)
        assert sim.walls.position == pytest.approx(position, rel=1e-14, abs=1e-15)
        assert sim.walls.velocity == pytest.approx(previous / 1e-3, rel=1e-14, abs=1e-12)
    assert previous[5] < 0.0 and previous[0] < 0.0     # untouched and underloaded walls close in


def test_servo_keeps_its_stiffness_between_refreshes():
    """stiffness_every = 10 (YADE's interval): after the warm-up the servo uses the stiffness
    of its last refresh, whatever the walls' current value."""
    sim = _scene(np.zeros(3), np.ones(3), np.full(6, 1.0), np.full(6, 1e3))
    servo = StressServo("x", 0.0, max_velocity=1e3, stiffness_every=10)
    servo.calls = StressServo.STIFFNESS_WARMUP + 1          # past the warm-up, not a refresh
    servo.stiffness[:] = 2e3
    servo.apply(sim)
    assert sim.walls.velocity[:2] == pytest.approx(0.75 * 1.0 / 2e3 / 1e-3)
