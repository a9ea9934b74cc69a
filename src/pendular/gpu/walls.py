"""The six walls on the device: the particles' forces on them reduced in a fixed order, then
the walls' controls (stress servo, constant strain rate, mixed stress condition, the rate of a
radius growth) in the scene's order, with no host round trip (pendular.dem.walls,
pendular.dem.mixed_stress and pendular.dem.growth on the CPU).

The reduction: each block of REDUCE_CHUNK particles sums its contacts with each wall in
particle order (``wall_partials``), then one thread per wall quantity adds the blocks in order
(``wall_sums``): for up to REDUCE_CHUNK particles the CPU's sum (pendular.dem.contact_law.
wall_forces) in the CPU's order.

The controls are a small program: row c of ``kinds`` is STRESS_SERVO, STRAIN_RATE,
MIXED_STRESS, RADIUS_GROWTH or GROWTH_TIMESTEP, its walls in
``control_walls[c, :wall_counts[c]]``, its parameters in ``parameters[c]`` (SERVO_FIELDS,
STRAIN_RATE_FIELDS, MIXED_FIELDS or GROWTH_FIELDS) and a servo's memory in ``previous[c]``,
``stiffness[c]`` and ``calls[c]`` (pendular.dem.walls.StressServo's ``previous``,
``stiffness``, ``calls``). A mixed condition's row holds no walls:
``control_walls[c, axis]`` (axis 0-2) is the row of the servo it sets on that axis (-1: none),
``control_walls[c, 3:3 + wall_counts[c]]`` its free axes in order; it writes the servos'
targets (``parameters[row, 0]``), and a target below zero is written instead into
``failure`` (FAILURE_FIELDS), the first since the host last read it, for the host to raise
(pendular.dem.mixed_stress.MixedStress.failure). ``step[0]`` counts the steps as the
Simulation does (its ``step`` when the run started), for that message.
"""

import math
from collections import namedtuple

import numpy as np

from pendular.dem.growth import GrowthTimeStep, RadiusGrowth
from pendular.dem.mixed_stress import MixedStress
from pendular.dem.walls import (ConstantStrainRate, StressServo, WallForces,
    move_walls as cpu_move_walls, servo_refreshes as cpu_servo_refreshes,
    servo_walls as cpu_servo_walls)
from pendular.gpu.cuda import cuda, device, device_twin
from pendular.dem.state import Walls
from pendular.gpu import integrate, neighbors
from pendular.gpu.forces import wall_push
from pendular.gpu.operations import BoxSide, ControlSide, DeviceSide, device_side

servo_walls = device_twin(cpu_servo_walls)
servo_refreshes = device_twin(cpu_servo_refreshes)
move_walls = device_twin(cpu_move_walls)

#: Particles summed by one thread of wall_partials.
REDUCE_CHUNK = 1024
#: Wall quantities summed: force [N], stiffness [N/m], moment [N m] (pendular.dem.state.Walls).
WALL_SUMS = 3

STRESS_SERVO = 0
STRAIN_RATE = 1
MIXED_STRESS = 2
#: A radius growth's row sets its rate (pendular.gpu.growth grows the radii); a growth time
#: step's row does nothing on the device (the host sets dt at the rebuilds).
RADIUS_GROWTH = 3
GROWTH_TIMESTEP = 4
#: A periodic cell's ConstantShearRate, its rate gamma_dot [1/s] in parameters[c, 0]
#: (pendular.gpu.cell.cell_controls).
SHEAR_RATE = 5
#: A Grip's row: no wall control (wall_controls skips it); the grips' own launches hold their
#: members after every wall control (pendular.gpu.grips).
GRIP = 6
#: parameters[c] of a servo, of a constant strain rate and of a mixed condition (NaN: a mean
#: stress or b not held, an axis given no stress).
SERVO_FIELDS = ("target", "gain", "memory", "max_velocity", "scale_max_velocity",
                "stiffness_every")
STRAIN_RATE_FIELDS = ("rate", "reference_length", "on_current_length")
MIXED_FIELDS = ("mean_stress", "b", "stress_x", "stress_y", "stress_z")
#: parameters[c] of a radius growth: its target [Pa] and max_rate, the rate g it sets this step.
GROWTH_FIELDS = ("target_stress", "max_rate", "rate")
#: The controls' program on the device (module docstring): ``kinds``, ``control_walls``,
#: ``wall_counts``, ``parameters``, a servo's memory ``previous``, ``stiffness``, ``calls``,
#: the ``step`` counted and a mixed condition's ``failure``.
Program = namedtuple("Program", "kinds control_walls wall_counts parameters previous "
                                "stiffness calls step failure")
#: failure[:] of a mixed condition that cannot hold (failed: 0 none, 1 one to report; row:
#: the control's; step, axis, target [Pa] and sigma_z [Pa] of the message).
FAILURE_FIELDS = ("failed", "row", "step", "axis", "target", "sigma_z")


@cuda.jit
def wall_partials(position, radius, wall_position, young, partial):
    """partial[b, w, q]: block b's sum over its particles, in order, of wall w's force,
    stiffness and moment (q: WALL_SUMS) from their contacts."""
    b = cuda.grid(1)
    if b >= partial.shape[0]:
        return
    for w in range(6):
        for q in range(WALL_SUMS):
            partial[b, w, q] = 0.0
    for p in range(b * REDUCE_CHUNK, min((b + 1) * REDUCE_CHUNK, position.shape[0])):
        for axis in range(3):
            for side in range(2):
                push, kn, gap_overlap = wall_push(p, axis, side == 1, position, radius,
                                                  wall_position, young)
                if gap_overlap > 0.0:
                    w = 2 * axis + side
                    partial[b, w, 0] += push
                    partial[b, w, 1] += kn
                    partial[b, w, 2] += (radius[p] - gap_overlap) * push


@device
def servo(c, control_walls, count, parameters, previous, stiffness, calls, wall_position,
          wall_velocity, wall_force, wall_stiffness, dt):
    """One call of StressServo c (StressServo.apply): the CPU's own refresh rule and law on
    its walls (pendular.dem.walls.servo_refreshes and servo_walls, compiled by
    device_twin)."""
    refresh = servo_refreshes(calls[c], int(parameters[c, 5]))
    calls[c] += 1
    servo_walls(wall_position, wall_velocity, wall_force, wall_stiffness, stiffness[c],
                previous[c], control_walls[c, :count], parameters[c, 0], parameters[c, 1],
                parameters[c, 2], parameters[c, 3], parameters[c, 4] != 0.0, refresh, dt)


@device
def strain_rate(c, control_walls, parameters, previous, wall_position, wall_velocity, dt):
    """One call of ConstantStrainRate c (pendular.dem.walls.ConstantStrainRate.apply): both
    walls of its axis move inward at rate * L / 2, L the reference or current length (the
    CPU's move_walls, compiled by device_twin)."""
    rate = parameters[c, 0]
    axis = control_walls[c, 0] // 2
    length = parameters[c, 1]
    if parameters[c, 2] != 0.0:
        length = wall_position[2 * axis + 1] - wall_position[2 * axis]
    shift = -0.5 * rate * length * dt
    previous[c, 0] = shift
    previous[c, 1] = shift
    move_walls(wall_position, wall_velocity, control_walls[c, :2], previous[c], dt)


@device
def wall_stress(axis, wall_force, wall_position):
    """Mean normal stress [Pa] of the two walls of ``axis``, compression positive
    (pendular.dem.state.Walls.stress: each wall's force over the face's area, then their
    mean)."""
    lx = wall_position[1] - wall_position[0]
    ly = wall_position[3] - wall_position[2]
    lz = wall_position[5] - wall_position[4]
    area = ly * lz if axis == 0 else (lx * lz if axis == 1 else lx * ly)
    return 0.5 * (wall_force[2 * axis] / area + wall_force[2 * axis + 1] / area)


@device
def walls_stress(wall_force, wall_position):
    """(sigma_x, sigma_y, sigma_z) [Pa] of the walls now (wall_stress; Walls.stress)."""
    return (wall_stress(0, wall_force, wall_position), wall_stress(1, wall_force, wall_position),
            wall_stress(2, wall_force, wall_position))


@device
def given_stress(c, axis, parameters, sigma):
    """The stress of ``axis`` [Pa] a mixed condition counts: the one given its servo, else
    the box's now, ``sigma`` (3 numbers) [Pa] (MixedStress.targets's ``given``)."""
    given = parameters[c, 2 + axis]
    if math.isnan(given):
        return sigma[axis]
    return given


@device
def set_target(c, axis, target, control_walls, parameters, step, axial, failure):
    """Give the servo of ``axis`` the ``target`` [Pa] of mixed condition c; False (and the
    failure recorded, unless one is waiting for the host) when the target is below zero or
    not a number (MixedStress.apply)."""
    if not target >= 0.0:
        if failure[0] == 0.0:
            failure[1] = c
            failure[2] = step
            failure[3] = axis
            failure[4] = target
            failure[5] = axial
            failure[0] = 1.0
        return False
    parameters[control_walls[c, axis], 0] = target
    return True


@device
def mixed_stress(c, control_walls, count, parameters, sigma, step, failure):
    """One call of MixedStress c (pendular.dem.mixed_stress.MixedStress.targets and apply:
    the same operations in the same order) for the box's stresses now ``sigma`` (3 numbers)
    [Pa] (the walls', or a periodic cell's: pendular.gpu.cell), setting its servos' targets
    in its order; stops at a target below zero."""
    mean = parameters[c, 0]
    b = parameters[c, 1]
    axial = sigma[2]
    if math.isnan(b):
        others = 0.0
        for axis in range(3):
            free = False
            for slot in range(count):
                free = free or control_walls[c, 3 + slot] == axis
            if not free:
                others += given_stress(c, axis, parameters, sigma)
        share = (3.0 * mean - others) / count
        for slot in range(count):
            if not set_target(c, control_walls[c, 3 + slot], share, control_walls, parameters,
                              step, axial, failure):
                return
        return
    if math.isnan(mean):
        minor = given_stress(c, 0, parameters, sigma)
        set_target(c, 1, minor + b * (axial - minor), control_walls, parameters, step, axial,
                   failure)
        return
    minor = (3.0 * mean - (1.0 + b) * axial) / (2.0 - b)
    if set_target(c, 0, minor, control_walls, parameters, step, axial, failure):
        set_target(c, 1, minor + b * (axial - minor), control_walls, parameters, step, axial,
                   failure)


@device
def growth_rate(c, parameters, sigma):
    """The rate g of RadiusGrowth c this step into ``parameters[c, 2]``: max_rate clip(1 -
    sigma_mean / target, -1, 1), sigma_mean the mean of the box's three stresses now
    ``sigma`` [Pa] (the walls', or a periodic cell's: pendular.gpu.cell)
    (pendular.dem.growth.RadiusGrowth.apply, the CPU's mean summed in the same order)."""
    mean = (sigma[0] + sigma[1] + sigma[2]) / 3.0
    parameters[c, 2] = parameters[c, 1] * min(max(1.0 - mean / parameters[c, 0], -1.0), 1.0)


@cuda.jit
def wall_sums(partial, wall_force, wall_stiffness, wall_moment):
    """One thread per wall and quantity: the blocks' partial sums added in order into the
    walls' force, stiffness and moment."""
    t = cuda.grid(1)
    if t >= 6 * WALL_SUMS:
        return
    w = t // WALL_SUMS
    q = t % WALL_SUMS
    total = 0.0
    for b in range(partial.shape[0]):
        total += partial[b, w, q]
    if q == 0:
        wall_force[w] = total
    elif q == 1:
        wall_stiffness[w] = total
    else:
        wall_moment[w] = total


@cuda.jit
def wall_controls(wall_force, wall_stiffness, program, wall_position, wall_velocity,
                  reference_walls, limit, dt, flags):
    """One thread: the controls of ``program`` (Program) in order, the step counted, then a
    neighbour-list rebuild asked when a wall has moved more than ``limit`` [m] since the last
    one."""
    (kinds, control_walls, wall_counts, parameters, previous, stiffness, calls, step,
     failure) = program
    if cuda.grid(1) != 0:
        return
    for c in range(kinds.shape[0]):
        if kinds[c] == STRESS_SERVO:
            servo(c, control_walls, wall_counts[c], parameters, previous, stiffness, calls,
                  wall_position, wall_velocity, wall_force, wall_stiffness, dt)
        elif kinds[c] == STRAIN_RATE:
            strain_rate(c, control_walls, parameters, previous, wall_position,
                        wall_velocity, dt)
        elif kinds[c] == MIXED_STRESS:
            mixed_stress(c, control_walls, wall_counts[c], parameters,
                         walls_stress(wall_force, wall_position), step[0], failure)
        elif kinds[c] == RADIUS_GROWTH:
            growth_rate(c, parameters, walls_stress(wall_force, wall_position))
    step[0] += 1
    for w in range(6):
        if abs(wall_position[w] - reference_walls[w]) > limit:
            flags[0] = 1


@device_side(StressServo)
class ServoRow(ControlSide):
    """A StressServo's row: its walls (a periodic cell's axes: pendular.gpu.cell), its
    parameters (SERVO_FIELDS) and its memory, which comes back into the servo."""

    role = STRESS_SERVO

    def upload(self, row, program, scene):
        op = self.op
        super().upload(row, program, scene)
        walls = op.axes if scene.periodic else op.walls
        program.control_walls[row, :len(walls)] = walls
        program.wall_counts[row] = len(walls)
        program.previous[row, :len(op.walls)] = op.previous
        program.stiffness[row, :len(op.walls)] = op.stiffness
        program.calls[row] = op.calls

    def parameters(self, values):
        op = self.op
        values[:] = (op.target, op.gain, op.memory, op.max_velocity,
                     float(op.scale_max_velocity), float(op.stiffness_every))

    def to_host(self, row, program):
        op = self.op
        op.previous[:] = program.previous[row, :len(op.walls)]
        op.stiffness[:] = program.stiffness[row, :len(op.walls)]
        op.calls = int(program.calls[row])


@device_side(ConstantStrainRate)
class StrainRateRow(ControlSide):
    """A ConstantStrainRate's row: its axis's two walls (a periodic cell's axis), its
    parameters (STRAIN_RATE_FIELDS)."""

    role = STRAIN_RATE

    def upload(self, row, program, scene):
        axis = self.op.axis
        super().upload(row, program, scene)
        walls = (axis,) if scene.periodic else (2 * axis, 2 * axis + 1)
        program.control_walls[row, :len(walls)] = walls
        program.wall_counts[row] = len(walls)

    def parameters(self, values):
        op = self.op
        values[:3] = (op.rate, op.reference_length, float(op.on_current_length))


@device_side(MixedStress)
class MixedStressRow(ControlSide):
    """A MixedStress's row (module docstring): the rows of its servos, its free axes, its
    parameters (MIXED_FIELDS); the targets it sets on the device come back into its servos
    (``driven``)."""

    role = MIXED_STRESS

    def check(self, scene):
        """Its servos must be among the scene's controls (their rows hold the targets)."""
        controls = [side.op for side in scene.controls]
        if not all(any(self.op.servos[axis] is other for other in controls)
                   for axis in self.op.free):
            raise ValueError("device='gpu' runs a MixedStress whose servos are among the "
                             "scene's controls only")

    def driven(self, scene):
        """The rows of the servos whose targets it sets (``scene``: pendular.gpu.operations.
        Scene)."""
        return [scene.row(self.op.servos[axis]) for axis in self.op.free]

    def upload(self, row, program, scene):
        op = self.op
        super().upload(row, program, scene)
        program.control_walls[row, :3] = [scene.row(op.servos[axis]) if axis in op.free
                                          else -1 for axis in range(3)]
        program.control_walls[row, 3:3 + len(op.free)] = op.free
        program.wall_counts[row] = len(op.free)

    def parameters(self, values):
        op = self.op
        values[:5] = (np.nan if op.mean_stress is None else op.mean_stress,
                      np.nan if op.b is None else op.b,
                      *(op.stress.get(axis, np.nan) for axis in range(3)))


@device_side(RadiusGrowth)
class RadiusGrowthRow(ControlSide):
    """A RadiusGrowth's row: it sets the growth's rate (GROWTH_FIELDS); the radii grow in
    pendular.gpu.growth."""

    role = RADIUS_GROWTH
    single = True
    grows_radii = True

    def check(self, scene):
        """In a periodic cell, a growth runs where no control moves the faces and the cell is
        not sheared (its rebuild test: pendular.gpu.growth)."""
        if not scene.periodic:
            return
        moving = [side.name for side in scene.controls
                  if side.role not in (RADIUS_GROWTH, GROWTH_TIMESTEP)]
        if moving or scene.box.op.sheared:
            raise ValueError("device='gpu' runs a RadiusGrowth in a periodic cell whose faces "
                             "no control moves only (its rebuild test: pendular.gpu.growth); "
                             f"found {', '.join(moving) or 'a sheared cell'}")

    def parameters(self, values):
        values[:2] = (self.op.target_stress, self.op.max_rate)


@device_side(GrowthTimeStep)
class GrowthTimeStepRow(ControlSide):
    """A GrowthTimeStep's row: nothing on the device (the host sets dt at the rebuilds,
    pendular.gpu.growth)."""

    role = GROWTH_TIMESTEP
    single = True


@device_side(WallForces)
class WallSprings(DeviceSide):
    """The frictionless walls' springs (WallForces, kn = E R): added in the gather, before
    or after the pair forces as the scene lists them, and reduced on each wall
    (``wall_partials``). A walls side gives ``young``, the stiffness of the springs the
    gather adds, and ``partials(state)``, the launches that fill ``state.partial`` for
    ``wall_sums``."""

    family = "force"
    role = "walls"
    in_cell = False

    @property
    def young(self):
        """E [Pa] of the springs now."""
        return self.op.young

    def partials(self, state):
        """(kernel, items, arguments) of each block's sums on the walls (``wall_partials``)."""
        s = state
        return [(wall_partials, s.partial.shape[0],
                 (s.position, s.radius, s.wall_position, self.young, s.partial))]


@device_side(Walls)
class WallBox(BoxSide):
    """Six walls (Walls, with one walls operation among the forces: WallForces, or a wall law
    with springs, pendular.gpu.wall_friction): a step's launches (module
    docstring of pendular.gpu.simulation), the walls' reduction and controls here."""

    def check(self, scene):
        scene.force("walls", required=True)

    def steps(self, gpu):
        """(kernel, items, arguments) of a step inside walls: the rebuild, the forces (the
        walls' springs before or after the pairs' gather as the forces are listed), the
        walls' sums (the forces' own shares after them: ``wall_launches``) and controls, the
        grips, the leapfrog."""
        sim = gpu.sim
        scene = gpu.scene
        s = gpu.state
        n = s.count
        springs = scene.force("walls")
        gatherer = (scene.force("bridges") if s.wet and not s.persist
                    else scene.force("contact law"))
        walls_first = scene.index(springs) < scene.index(gatherer)
        limit = 0.5 * s.skin
        return [
            (neighbors.bin_particles, n, (s.position, s.wall_position, s.grid(), s.flags)),
            (neighbors.find_pairs, n, (s.position, s.radius, s.skin + s.reach,
                                       s.wall_position, s.grid(), s.rows(), s.carried(),
                                       s.new_carried(), s.flags)),
            gpu.finish_step(),
            *gpu.force_steps(walls_first, springs.young),
            *springs.partials(s),
            (wall_sums, 6 * WALL_SUMS,
             (s.partial, s.wall_force, s.wall_stiffness, s.wall_moment)),
            *(launch for side in scene.forces for launch in side.wall_launches(s)),
            (wall_controls, 1,
             (s.wall_force, s.wall_stiffness, s.program(), s.wall_position, s.wall_velocity,
              s.reference_walls, limit, sim.dt, s.flags)),
            *(gpu.grips.launches(s) if gpu.grips is not None else ()),
            (integrate.leapfrog, n, (s.motion(), scene.integrator.damping, s.no_period,
                                     sim.dt, s.reference_position, limit, s.flags)),
        ]
