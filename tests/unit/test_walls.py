"""The wall servo's law (YADE's TriaxialStressController, pendular.dem.walls.StressServo) against a hand
computation, step by step; the mixed stress conditions that set its targets
(pendular.dem.mixed_stress.MixedStress) from the walls' stresses."""

from types import SimpleNamespace

import numpy as np
import pytest

from pendular.dem import mixed_stress
from pendular.dem.mixed_stress import MixedStress, StageFailed
from pendular.dem.state import Walls
from pendular.dem.walls import StressServo
from pendular.procedures import loading


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


def _walls_with_stress(sigma):
    """A scene whose walls (edges 1, 2, 4 m) carry the normal stresses ``sigma`` (3,) [Pa]."""
    sim = _scene(np.zeros(3), np.array([1.0, 2.0, 4.0]), 0.0, 0.0)
    sim.walls.force[:] = np.repeat(sigma, 2) * sim.walls.areas()
    sim.step = 7
    return sim


def test_a_mixed_condition_sets_its_servos_targets_from_the_walls_stresses():
    """Constant p on x and y (one servo): (3 p - sigma_z) / 2 each; b with p: sigma_3 =
    (3 p - (1 + b) sigma_z) / (2 - b) on x and sigma_3 + b (sigma_z - sigma_3) on y."""
    sim = _walls_with_stress([600.0, 800.0, 1400.0])
    lateral = StressServo("xy", 1.0, 1.0)
    MixedStress({0: lateral, 1: lateral}, "xy", mean_stress=1000.0).apply(sim)
    assert lateral.target == pytest.approx((3000.0 - 1400.0) / 2, rel=1e-15)
    x, y = StressServo("x", 1.0, 1.0), StressServo("y", 1.0, 1.0)
    MixedStress({0: x, 1: y}, "xy", mean_stress=1000.0, b=0.25).apply(sim)
    minor = (3000.0 - 1.25 * 1400.0) / 1.75
    assert x.target == pytest.approx(minor, rel=1e-15)
    assert y.target == pytest.approx(minor + 0.25 * (1400.0 - minor), rel=1e-15)
    assert (x.target + y.target + 1400.0) / 3 == pytest.approx(1000.0, rel=1e-14)


def test_a_mixed_condition_that_needs_walls_to_pull_names_the_step_axis_and_stresses():
    sim = _walls_with_stress([600.0, 800.0, 3500.0])
    lateral = StressServo("xy", 750.0, 1.0)
    with pytest.raises(StageFailed, match=r"the mean stress condition cannot be held at step 7: "
                                          r"it needs -250 Pa on x with sigma_z = 3500 Pa"):
        MixedStress({0: lateral, 1: lateral}, "xy", mean_stress=1000.0).apply(sim)
    assert lateral.target == 750.0          # nothing set


@pytest.mark.parametrize("arguments, words", [
    ({"free": "xy"}, "mean_stress and b are both None"),
    ({"free": "xy", "mean_stress": -1.0}, "mean_stress = -1.0"),
    ({"free": "xz", "mean_stress": 1.0}, "free = 'xz': valid: axes of this scene's servos (xy)"),
    ({"free": "w", "mean_stress": 1.0}, "free axis = 'w'"),
    ({"free": "xy", "b": 0.5}, "free = 'xy' with b = 0.5: valid: y"),
    ({"free": "y", "b": 0.5, "mean_stress": 1.0}, "free = 'y' with b = 0.5: valid: xy"),
    ({"free": "y", "b": 0.5, "stress": {"x": -3.0}}, "stress/x = -3.0"),
])
def test_a_mixed_condition_refuses_what_it_cannot_hold_naming_it(arguments, words):
    servos = {0: StressServo("x", 1.0, 1.0), 1: StressServo("y", 1.0, 1.0)}
    free = arguments.pop("free")
    with pytest.raises(ValueError, match=words.replace("(", r"\(").replace(")", r"\)")):
        MixedStress(servos, free, **arguments)


def test_the_loading_paths_mixed_condition_is_the_engines():
    """pendular.procedures.loading keeps its names: MixedStress built from a Stage (its
    checkpoints keep their type) and StageFailed, the engine's exception."""
    assert loading.StageFailed is mixed_stress.StageFailed
    assert issubclass(loading.MixedStress, MixedStress)
    stage = loading.Stage(stress={"x": 750.0}, strain_rate={"z": 1.0}, b=0.4,
                          until=loading.Strain(0.1))
    servos = {0: StressServo("x", 1.0, 1.0), 1: StressServo("y", 1.0, 1.0)}
    built = loading.MixedStress(stage, servos)
    assert built.state_dict() == {"mean_stress": None, "b": 0.4, "stress": {"x": 750.0},
                                  "free": "y"}
