"""Operations carry their device side (pendular.gpu.operations): the scene's sides are found
through the operations' classes, a subclass that keeps its parent's step inherits the side
and one with a step of its own is refused by name; the controls' program is built from the
sides' rows; no GPU module tests an operation's type. In this process: nothing here runs a
kernel.
"""

import ast
import os

import numpy as np
import pytest

from conftest import requires

pytestmark = requires("numba_cuda")

GPU = os.path.join(os.path.dirname(__file__), "..", "..", "src", "pendular", "gpu")


@pytest.fixture
def sim():
    from simulated import scene

    return scene()


def test_a_subclass_keeping_the_step_inherits_the_device_side(sim):
    from pendular.dem.walls import StressServo
    from pendular.gpu.simulation import check_scene
    from pendular.gpu.walls import ServoRow

    class NamedServo(StressServo):
        """A servo under another name, its step the parent's."""

    sim.controls[0] = NamedServo("xy", 1e4, 0.01)
    assert isinstance(check_scene(sim).controls[0], ServoRow)


def test_a_subclass_with_its_own_step_is_refused_by_name(sim):
    from pendular.dem.walls import StressServo
    from pendular.gpu.simulation import check_scene

    class OwnServo(StressServo):
        def apply(self, sim):
            super().apply(sim)

    sim.controls[0] = OwnServo("xy", 1e4, 0.01)
    with pytest.raises(ValueError, match=r"does not run the control OwnServo yet \(valid: "
                                         r"StressServo, ConstantStrainRate, MixedStress"):
        check_scene(sim)


def test_the_controls_program_holds_each_sides_row(sim):
    """Rows in the scene's order: the servo's walls and memory, the strain rate's walls, a
    mixed condition's servo rows (-1: an axis it does not set) and free axes."""
    from pendular.dem.mixed_stress import MixedStress
    from pendular.gpu.operations import ControlProgram
    from pendular.gpu.simulation import check_scene
    from pendular.gpu.walls import MIXED_STRESS, STRAIN_RATE, STRESS_SERVO

    servo = sim.controls[0]
    servo.previous[:] = [1.0, 2.0, 3.0, 4.0]
    servo.calls = 7
    sim.controls.insert(0, MixedStress({0: servo, 1: servo}, "xy", mean_stress=2e4))
    scene = check_scene(sim)
    program = ControlProgram.empty(len(scene.controls))
    for row, side in enumerate(scene.controls):
        side.upload(row, program, scene)
    assert list(program.kinds) == [MIXED_STRESS, STRESS_SERVO, STRAIN_RATE]
    assert list(program.control_walls[0]) == [1, 1, -1, 0, 1, 0] and program.wall_counts[0] == 2
    assert list(program.control_walls[1, :4]) == [0, 1, 2, 3] and program.wall_counts[1] == 4
    assert list(program.previous[1, :4]) == [1.0, 2.0, 3.0, 4.0] and program.calls[1] == 7
    assert list(program.control_walls[2, :2]) == [4, 5] and program.wall_counts[2] == 2
    assert scene.controls[0].driven(scene) == [1, 1]
    values = np.zeros(6)
    scene.controls[1].parameters(values)
    assert list(values) == [1e4, servo.gain, servo.memory, 0.01, 0.0, 1.0]


def test_a_periodic_cell_refuses_what_has_walls_by_name():
    from pendular.dem.gravity import Gravity
    from pendular.gpu.simulation import check_scene
    from periodic_checks import scene

    sim = scene()
    sim.forces.append(Gravity(9.81))
    with pytest.raises(ValueError, match="runs a periodic cell without Gravity"):
        check_scene(sim)


def test_walls_with_springs_take_the_walls_role(sim):
    """A wall law with springs is the scene's walls, the gather adding no wall springs then
    (its side's own launches run them)."""
    from pendular.dem.wall_friction import FrictionalWallForces
    from pendular.gpu.simulation import check_scene
    from pendular.gpu.wall_friction import SpringWalls
    from simulated import YOUNG

    sim.forces[1] = FrictionalWallForces(YOUNG, 0.3, 25.0)
    walls = check_scene(sim).force("walls")
    assert isinstance(walls, SpringWalls) and walls.young == 0.0


def test_no_gpu_module_tests_an_operations_type():
    """isinstance or type() only where the device compiles the CPU's functions (cuda.py) and
    where a side is found through the operation's classes (operations.py)."""
    found = []
    for name in sorted(os.listdir(GPU)):
        if not name.endswith(".py") or name in ("cuda.py", "operations.py"):
            continue
        for node in ast.walk(ast.parse(open(os.path.join(GPU, name)).read())):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                    and node.func.id in ("isinstance", "type")):
                found.append(f"{name}:{node.lineno}")
    assert not found, found
