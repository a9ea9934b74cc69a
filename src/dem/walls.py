"""Wall operations: sphere–wall forces, stress servo and constant strain rate (SPEC §3).

A wall displacement ``outward`` > 0 opens the box: the low wall moves to -axis, the high to +axis.
"""

import numpy as np

from .contact_law import wall_forces
from .validate import check_positive, check_range

AXES = {"x": 0, "y": 1, "z": 2}


def _axes(names):
    try:
        return tuple(AXES[name] for name in names)
    except KeyError:
        raise ValueError(f"axes must be letters among 'x', 'y', 'z', got {names!r}") from None


def move_walls(walls, wall_indices, outward, dt):
    """Shift the given walls outward by ``outward`` [m] each and record their velocity."""
    for w, shift in zip(wall_indices, outward):
        sign = 1.0 if w % 2 else -1.0
        walls.position[w] += sign * shift
        walls.velocity[w] = shift / dt


class WallForces:
    """Frictionless sphere–wall springs with kn = E R (YADE's Ig2_Box_Sphere_ScGeom, SPEC §2)."""

    def __init__(self, young):
        self.young = check_positive("young", young, "Pa")

    def apply(self, sim):
        p = sim.particles
        wall_forces(p.position, p.radius, sim.walls.position, self.young, p.force,
                    sim.walls.force, sim.walls.stiffness, sim.walls.moment)


class StressServo:
    """Hold the normal stress of the walls of ``axes`` at ``target`` [Pa, compression positive].

    Each step every wall moves outward by
        shift_n = gain * clip((F_wall - target A) / K_wall, +-max_velocity dt) + memory * shift_n-1,
    K_wall being the sum of its contacts' normal stiffness; a wall without contacts moves inward
    at max_velocity. This is YADE's TriaxialStressController law, where gain = 1 - stressDamping
    (0.75) and memory = 0.8; the memory term lets a wall follow a dilating sample with a steady
    stress error (1 - memory) / gain times that of a memoryless servo.
    """

    def __init__(self, axes, target, max_velocity, gain=0.75, memory=0.8):
        self.walls = tuple(w for axis in _axes(axes) for w in (2 * axis, 2 * axis + 1))
        self.target = check_range("target stress", target, 0.0, unit="Pa")
        self.max_velocity = check_positive("max_velocity", max_velocity, "m/s")
        self.gain = check_range("servo gain", gain, 0.0, 1.0, low_inclusive=False)
        self.memory = check_range("servo memory", memory, 0.0, 1.0, high_inclusive=False)
        self.previous = np.zeros(len(self.walls))

    def apply(self, sim):
        walls = sim.walls
        areas = walls.areas()
        step_cap = self.max_velocity * sim.dt
        for slot, w in enumerate(self.walls):
            stiffness = walls.stiffness[w]
            if stiffness > 0.0:
                shift = (walls.force[w] - self.target * areas[w]) / stiffness
                shift = min(max(shift, -step_cap), step_cap)
            else:
                shift = -step_cap
            self.previous[slot] = self.gain * shift + self.memory * self.previous[slot]
        move_walls(walls, self.walls, self.previous, sim.dt)


class ConstantStrainRate:
    """Drive the two walls of ``axis`` at a constant engineering strain rate [1/s].

    rate > 0 compresses: each wall moves inward at rate * L0 / 2, L0 being the box length on
    that axis when the operation is attached (the reference of ``axial_strain``).
    """

    def __init__(self, axis, rate, reference_length):
        (self.axis,) = _axes(axis)
        self.rate = check_range("strain_rate", rate, -1e6, 1e6, unit="1/s")
        self.reference_length = check_positive("reference_length", reference_length, "m")

    def strain(self, walls):
        """Engineering strain of the axis, compression positive."""
        return 1.0 - walls.lengths()[self.axis] / self.reference_length

    def apply(self, sim):
        shift = -0.5 * self.rate * self.reference_length * sim.dt
        move_walls(sim.walls, (2 * self.axis, 2 * self.axis + 1), (shift, shift), sim.dt)
