"""Wall operations: sphere–wall forces, stress servo, constant strain rate and constant volume
(docs/physics.md 'Walls, servo and preparation').

A wall displacement ``outward`` > 0 opens the box: the low wall moves to -axis, the high to +axis.
"""

import math

import numba
import numpy as np

from pendular.dem.cell import MAX_STRAIN_RATE, servo_cell
from pendular.dem.contact_law import wall_forces
from pendular.dem.protocols import state_array
from pendular.utils.validate import check_int, check_positive, check_range

AXES = {"x": 0, "y": 1, "z": 2}
#: Servo calls during which the stiffness is refreshed every call (YADE: scene->iter < 100).
STIFFNESS_WARMUP = 100


def _axes(names):
    try:
        return tuple(AXES[name] for name in names)
    except (KeyError, TypeError):
        raise ValueError(f"axes must be letters among 'x', 'y', 'z', got {names!r}") from None


def _axis_names(axes):
    """The letters of the axis indices ``axes`` (e.g. "xy")."""
    return "".join("xyz"[axis] for axis in axes)


@numba.njit(cache=True)
def move_walls(wall_position, wall_velocity, wall_indices, outward, dt):
    """Shift the walls ``wall_indices`` outward by ``outward`` [m] each and record their
    velocity [m/s] over the step ``dt`` [s]."""
    for slot in range(len(wall_indices)):
        w = wall_indices[slot]
        sign = 1.0 if w % 2 else -1.0
        wall_position[w] += sign * outward[slot]
        wall_velocity[w] = outward[slot] / dt


@numba.njit(cache=True)
def servo_refreshes(calls, every):
    """Whether a servo refreshes its stiffness at its call after ``calls`` calls: at each call
    of the warm-up (STIFFNESS_WARMUP), then every ``every`` calls."""
    return calls < STIFFNESS_WARMUP or calls % every == 0


@numba.njit(cache=True)
def servo_walls(wall_position, wall_velocity, wall_force, wall_stiffness, stiffness, previous,
                walls, target, gain, memory, max_velocity, scale_max_velocity, refresh, dt):
    """One step of StressServo's law (its docstring) for the walls ``walls``, in place: their
    shifts from the current forces and face areas, then the moves. ``stiffness`` holds each
    servoed wall's K_wall [N/m], refreshed from ``wall_stiffness`` when ``refresh``."""
    lx = wall_position[1] - wall_position[0]
    ly = wall_position[3] - wall_position[2]
    lz = wall_position[5] - wall_position[4]
    for slot in range(len(walls)):
        w = walls[slot]
        axis = w // 2
        if refresh:
            stiffness[slot] = wall_stiffness[w]
        cap = max_velocity * dt
        if scale_max_velocity:
            length = lx if axis == 0 else (ly if axis == 1 else lz)
            cap = cap * (3.0 * length / (lx + ly + lz))
        if stiffness[slot] > 0.0:
            area = ly * lz if axis == 0 else (lx * lz if axis == 1 else lx * ly)
            shift = (wall_force[w] - target * area) / stiffness[slot]
            shift = min(max(shift, -cap), cap)
        else:
            shift = -cap
        previous[slot] = gain * shift + memory * previous[slot]
    move_walls(wall_position, wall_velocity, walls, previous, dt)


class WallForces:
    """Frictionless sphere–wall springs with kn = E R
    (YADE's Ig2_Box_Sphere_ScGeom, docs/physics.md 'The contact law')."""

    stateless = True

    def __init__(self, young):
        self.young = check_positive("young", young, "Pa")

    def apply(self, sim):
        p = sim.particles
        wall_forces(p.position, p.radius, sim.contacts.near_wall, sim.walls.position,
                    self.young, p.force, sim.walls.force, sim.walls.stiffness, sim.walls.moment)


class StressServo:
    """Hold the normal stress of the walls of ``axes`` at ``target`` [Pa, compression positive]
    (in a periodic cell: the cell's stress, its lengths moving by pendular.dem.cell.servo_cell, the
    same law with the cell's stiffness).

    Each step every wall moves outward by::

        shift_n = gain * clip((F_wall - target A) / K_wall, +-cap) + memory * shift_n-1,

    K_wall being the sum of its contacts' normal stiffness and cap = max_velocity dt [m]; a
    wall without contacts moves inward by the cap. This is YADE's TriaxialStressController law,
    where gain = 1 - stressDamping (0.75) and memory = 0.8; the memory term lets a wall follow a
    dilating sample with a steady stress error (1 - memory) / gain times that of a memoryless
    servo. Two of YADE's choices are options (defaults: pendular's):

    - scale_max_velocity: the cap of axis a is max_velocity * 3 L_a / (L_x + L_y + L_z)
      (YADE's max_vel1/2/3) instead of max_velocity;
    - stiffness_every: K_wall is refreshed every ``stiffness_every`` calls of the servo and at
      each of its first 100 calls (YADE's stiffnessUpdateInterval, 10) instead of every step;
      a periodic cell's stiffness every max(stiffness_every, CELL_STIFFNESS_EVERY) calls.
    """

    #: Calls during which the stiffness is refreshed every step.
    STIFFNESS_WARMUP = STIFFNESS_WARMUP
    #: Fewest calls between refreshes of a periodic cell's stiffness after the warm-up: a sum
    #: over every contact, as costly as the force gather (YADE's stiffnessUpdateInterval is 10;
    #: the stiffness of a sample under shear changes little in 50 steps, and the servo's tests
    #: hold).
    CELL_STIFFNESS_EVERY = 50
    #: Default gain and memory (YADE's 1 - stressDamping and its 0.8).
    GAIN = 0.75
    MEMORY = 0.8

    def __init__(self, axes, target, max_velocity, gain=GAIN, memory=MEMORY,
                 scale_max_velocity=False, stiffness_every=1):
        self._set_axes(_axes(axes))
        self.target = check_range("target stress", target, 0.0, unit="Pa")
        self.max_velocity = check_positive("max_velocity", max_velocity, "m/s")
        self.gain = check_range("servo gain", gain, 0.0, 1.0, low_inclusive=False)
        self.memory = check_range("servo memory", memory, 0.0, 1.0, high_inclusive=False)
        self.scale_max_velocity = bool(scale_max_velocity)
        self.stiffness_every = check_int("servo stiffness_every", stiffness_every, low=1)
        self.previous = np.zeros(len(self.walls))
        self.stiffness = np.zeros(len(self.walls))
        self.calls = 0

    def _set_axes(self, axes):
        """The servoed axes (indices) and their walls."""
        self.axes = axes
        self.walls = tuple(w for axis in axes for w in (2 * axis, 2 * axis + 1))
        self._wall_index = np.array(self.walls, dtype=np.int64)
        self._axis_index = np.array(axes, dtype=np.int64)

    def state_dict(self):
        """The servo as its path left it: ``axes`` (letters), ``target`` [Pa] and
        ``max_velocity`` [m/s] (a path's stages change them), and its memory: ``previous``
        (shifts of the last step [m], one per wall), ``stiffness`` (K_wall [N/m], or a
        cell's S [Pa], per wall) and ``calls``."""
        return {"axes": _axis_names(self.axes), "target": self.target,
                "max_velocity": self.max_velocity, "previous": self.previous.copy(),
                "stiffness": self.stiffness.copy(), "calls": self.calls}

    def load_state(self, state):
        axes = _axes(state["axes"])
        walls = (2 * len(axes),)
        loaded = {"target": check_range("target", state["target"], 0.0, unit="Pa"),
                  "max_velocity": check_positive("max_velocity", state["max_velocity"], "m/s"),
                  "previous": state_array(state, "previous", np.float64, walls),
                  "stiffness": state_array(state, "stiffness", np.float64, walls),
                  "calls": check_int("calls", state["calls"])}
        self._set_axes(axes)
        for name, value in loaded.items():
            setattr(self, name, value)

    @classmethod
    def max_velocity_for(cls, strain_rate, length):
        """The ``max_velocity`` [m/s] with which the default servo's walls of a box of edge
        ``length`` [m] move at most at ``strain_rate`` [1/s]: the memory lets a wall travel
        gain / (1 - memory) times its cap per step when it keeps moving one way."""
        return strain_rate * 0.5 * length * (1.0 - cls.MEMORY) / cls.GAIN

    def apply(self, sim):
        walls = sim.walls
        every = self.stiffness_every
        if walls.periodic:
            every = max(every, self.CELL_STIFFNESS_EVERY)
        refresh = servo_refreshes(self.calls, every)
        self.calls += 1
        if walls.periodic:          # slots 0 .. len(axes) - 1 of stiffness and previous
            if refresh:
                walls.update_stiffness(sim)
            servo_cell(walls.position, walls.rate, walls.stress_tensor,
                       walls.stiffness, self.stiffness, self.previous, self._axis_index,
                       self.target, self.gain, self.memory, self.max_velocity,
                       self.scale_max_velocity, refresh, sim.dt)
            return
        servo_walls(walls.position, walls.velocity, walls.force, walls.stiffness, self.stiffness,
                    self.previous, self._wall_index, self.target, self.gain, self.memory,
                    self.max_velocity, self.scale_max_velocity, refresh, sim.dt)


class ConstantStrainRate:
    """Drive the two walls of ``axis`` at a constant strain rate [1/s] (in a periodic cell:
    its length on ``axis``, the particles following affinely).

    rate > 0 compresses: each wall moves inward at rate * L0 / 2, L0 being the box length on
    that axis when the operation is attached (the reference of ``axial_strain``), so that the
    engineering strain grows at ``rate``. With ``on_current_length`` the speed is rate * L / 2,
    L the current length (YADE's TriaxialStressController: the true strain rate is ``rate``).
    """

    #: Largest strain rate [1/s].
    MAX_RATE = MAX_STRAIN_RATE

    def __init__(self, axis, rate, reference_length, on_current_length=False):
        (self.axis,) = _axes(axis)
        self.rate = check_range("strain_rate", rate, -self.MAX_RATE, self.MAX_RATE, unit="1/s")
        self.reference_length = check_positive("reference_length", reference_length, "m")
        self.on_current_length = bool(on_current_length)
        self._walls = np.array([2 * self.axis, 2 * self.axis + 1], dtype=np.int64)
        self._shift = np.zeros(2)

    def state_dict(self):
        """The drive its stage set: ``axis`` (a letter), ``rate`` [1/s] and
        ``reference_length`` [m]."""
        return {"axis": _axis_names((self.axis,)), "rate": self.rate,
                "reference_length": self.reference_length}

    def load_state(self, state):
        axes = _axes(state["axis"])
        if len(axes) != 1:
            raise ValueError(f"axis = {state['axis']!r}; valid: one of 'x', 'y', 'z'")
        rate = check_range("rate", state["rate"], -self.MAX_RATE, self.MAX_RATE, unit="1/s")
        length = check_positive("reference_length", state["reference_length"], "m")
        (self.axis,), self.rate, self.reference_length = axes, rate, length
        self._walls = np.array([2 * self.axis, 2 * self.axis + 1], dtype=np.int64)

    def strain(self, walls):
        """Engineering strain of the axis, compression positive."""
        return 1.0 - walls.lengths()[self.axis] / self.reference_length

    def steps_to(self, strain, dt, start=0.0):
        """Steps [-] of ``dt`` [s] to reach the engineering ``strain`` from the engineering
        strain ``start`` (both from the reference length; the rate must have the sign of
        strain - start; on the current length the length changes by a factor 1 - rate dt per
        step)."""
        change = strain - start
        if self.rate == 0.0 or change / self.rate <= 0.0:
            raise ValueError(f"strain = {strain!r} cannot be reached from {start!r} at "
                             f"strain_rate = {self.rate!r} 1/s: the rate must be non-zero and "
                             "of the sign of the change")
        if not self.on_current_length:
            return int(np.ceil(change / (self.rate * dt)))
        factor = 1.0 - self.rate * dt
        if not 0.0 < factor < 2.0 or factor == 1.0 or strain >= 1.0 or start >= 1.0:
            raise ValueError(f"strain_rate * dt = {self.rate * dt!r} must lie in (-1, 1) and "
                             f"strain = {strain!r} below 1 on the current length")
        return int(np.ceil((np.log1p(-strain) - np.log1p(-start)) / np.log(factor)))

    def apply(self, sim):
        walls = sim.walls
        length = (walls.position[2 * self.axis + 1] - walls.position[2 * self.axis]
                  if self.on_current_length else self.reference_length)
        if walls.periodic:
            walls.stretch(self.axis, -self.rate * length * sim.dt, sim.dt)
            return
        self._shift[:] = -0.5 * self.rate * length * sim.dt
        move_walls(walls.position, walls.velocity, self._walls, self._shift, sim.dt)


class ConstantVolume:
    """Hold the volume of the box at ``volume`` [m^3] by moving the two lateral axes x and y
    (the walls of each, or a periodic cell's lengths): each call scales both lengths by
    sqrt(volume / (L_x L_y L_z)), their ratio kept, so that after it L_x L_y L_z = volume to
    round-off, whatever the axial (z) control did before it in the step. Listed after the
    control that drives z: an undrained (constant-volume) shear of a saturated sample, whose
    pore water keeps the volume while the axial strain is imposed."""

    #: The axes it moves.
    AXES = (0, 1)

    def __init__(self, volume):
        self.volume = check_positive("volume", volume, "m^3")
        self._walls = np.array([0, 1, 2, 3], dtype=np.int64)
        self._shift = np.zeros(4)

    def state_dict(self):
        """The ``volume`` [m^3] its stage holds."""
        return {"volume": self.volume}

    def load_state(self, state):
        self.volume = check_positive("volume", state["volume"], "m^3")

    def apply(self, sim):
        walls = sim.walls
        lengths = walls.lengths()
        factor = math.sqrt(self.volume / (lengths[0] * lengths[1] * lengths[2]))
        change = (factor - 1.0) * lengths[:2]
        if walls.periodic:
            for axis in self.AXES:
                walls.stretch(axis, change[axis], sim.dt)
            return
        self._shift[:] = np.repeat(0.5 * change, 2)
        move_walls(walls.position, walls.velocity, self._walls, self._shift, sim.dt)
