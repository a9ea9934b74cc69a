"""A periodic cell on the device (pendular.dem.cell.PeriodicCell): its stress reduced in a
fixed order each step, then its controls (stress servo, constant strain rate, constant shear
rate, mixed stress condition, radius growth) in the scene's order, with no host round trip.

The reduction (``cell_partials``): each block of REDUCE_CHUNK particles sums, in particle
order, x_p (x) F_p over its particles, the face terms (image L) (x) f of its particles' pairs
through a face (f with the attraction of bridges at contact, wet, and the forces of bridges
across gaps on their own, the CPU's gather_pair_forces_virial) and, at a step where a servo
refreshes the cell's stiffness (``refreshes``), the pairs' stiffness kn (l_a n_a)^2
(pendular.dem.virial, pendular.dem.cell.contact_stiffness); then one thread
(``cell_controls``) adds the blocks in order, divides by the volume (the CPU's
store_cell_stress: Love–Weber, Eq. 3.41), sets the rates to zero (PeriodicCell.after_forces)
and runs the controls: the rows of pendular.gpu.walls's program whose ``control_walls[c,
:wall_counts[c]]`` hold, in a periodic cell, a servo's axes (StressServo's, the CPU's
servo_cell) or a strain rate's axis (PeriodicCell.stretch); a shear rate's row
(SHEAR_RATE) sets gamma_dot (ConstantShearRate.apply); a mixed condition's row sets its
servos' targets from the diagonal of the cell's stress (MixedStress.apply reads
PeriodicCell.stress(); pendular.gpu.walls.mixed_stress, the walls' law), and a radius
growth's row its rate from their mean (pendular.gpu.walls.growth_rate; the radii grow in
pendular.gpu.growth, in a cell whose faces no control moves). Last, ``period`` (3,) [m] and
``affine_rate`` (3,) [1/s], which the next step's kernels read, take the cell's new lengths
and rates.

Simple shear (Lees–Edwards, x with z; pendular.dem.cell's module docstring): a scene that
shears, or whose cell is sheared, holds ``period`` (4,) (Lx, Ly, Lz, delta) and
``affine_rate`` (4,) (the rates, gamma_dot), which the CPU's kernels compiled for the device
read behind the same tests of the arrays' lengths as on the CPU (the branch vector, the face
terms, the contact law's relative velocity, the leapfrog), and ``shear`` (SHEAR_FIELDS) the
cell's shear state. ``cell_controls`` sets gamma_dot to zero with the rates, runs the
controls, then advances the offset over the step (PeriodicCell.follow, after the controls as
the CPU's integrator calls it: the leapfrog does not read the offset); at a rebuild the
offset is brought into [-Lx/2, Lx/2) (pendular.gpu.neighbors.reduced_offset, the CPU's
_wrap_sheared: each thread of the wrap and the pair search takes it from the offset of
before, and pendular.gpu.neighbors.shear_rebuilt stores it after them). A cell that neither
shears nor is sheared keeps (3,) arrays and a one-entry ``shear``: the code of before.
"""

import numpy as np

from pendular.dem.cell import (ConstantShearRate, PeriodicCell,
    pair_stiffness as cpu_pair_stiffness, servo_cell)
from pendular.dem.virial import add_face_term, add_outer, pair_force_with_attraction
from pendular.dem.walls import StressServo
from pendular.gpu import integrate, neighbors
from pendular.gpu.cuda import cuda, device, device_twin
from pendular.gpu.operations import BoxSide, ControlSide, device_side
from pendular.gpu.walls import (MIXED_STRESS, RADIUS_GROWTH, REDUCE_CHUNK, SHEAR_RATE,
    STRAIN_RATE, STRESS_SERVO, growth_rate, mixed_stress, servo_refreshes)

servo = device_twin(servo_cell)
outer = device_twin(add_outer)
face_term = device_twin(add_face_term)
pull_less = device_twin(pair_force_with_attraction)
pair_stiffness = device_twin(cpu_pair_stiffness)

#: ``shear`` of a sheared cell: PeriodicCell's shear_offset delta [m], shear_rate gamma_dot
#: [1/s] and shear_strain gamma [-], and delta at the last rebuild (the rebuild test's).
SHEAR_FIELDS = ("offset", "rate", "strain", "reference_offset")

#: Columns of a block's partial sums: x (x) F (9), the face terms (9), the stiffness (3).
CELL_SUMS = 21
#: Fewest servo calls between refreshes of the cell's stiffness after the warm-up.
CELL_STIFFNESS_EVERY = StressServo.CELL_STIFFNESS_EVERY


@device
def refreshes(c, parameters, calls):
    """Whether the servo of row c refreshes the cell's stiffness at its next call
    (StressServo.apply in a periodic cell: every call of the warm-up, then every
    max(stiffness_every, CELL_STIFFNESS_EVERY) calls)."""
    return servo_refreshes(calls[c], max(int(parameters[c, 5]), CELL_STIFFNESS_EVERY))


@cuda.jit
def cell_partials(position, force, radius, pairs, images, wet, attraction, persist,
                  bridge_pair_force, program, partial):
    """partial[b]: block b's sums (module docstring), its particles in order; the face terms
    with the ``attraction`` (K,) [N] along the normals when ``wet`` (bridges at contact),
    with ``persist`` those of the bridges' forces on j from i ``bridge_pair_force`` (K, 3) [N]
    too (bridges across gaps: the CPU's gather_pair_forces_virial); the stiffness when a
    servo among the controls (``program``'s kinds) refreshes it this step. The bundles
    pendular.gpu.forces.Pairs and Images, pendular.gpu.walls.Program."""
    pair_count, pair_j = pairs.count, pairs.second
    pair_force, normal, overlap, normal_force = (pairs.force, pairs.normal, pairs.overlap,
                                                 pairs.normal_force)
    image, period = images.image, images.period
    kinds, parameters, calls = program.kinds, program.parameters, program.calls
    b = cuda.grid(1)
    n = position.shape[0]
    if b >= partial.shape[0]:
        return
    stiffness = False
    for c in range(kinds.shape[0]):
        if kinds[c] == STRESS_SERVO and refreshes(c, parameters, calls):
            stiffness = True
    moments = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    faces = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    k0 = k1 = k2 = 0.0
    for p in range(b * REDUCE_CHUNK, min(n, (b + 1) * REDUCE_CHUNK)):
        moments = outer(moments, position[p, 0], position[p, 1], position[p, 2],
                        force[p, 0], force[p, 1], force[p, 2])
        for s in range(pair_count[p]):
            k = s * n + p
            if image[k, 0] != 0 or image[k, 1] != 0 or image[k, 2] != 0:
                if wet:
                    f0, f1, f2 = pull_less(pair_force, attraction, normal, k)
                else:
                    f0, f1, f2 = pull_less(pair_force, None, normal, k)
                faces = face_term(faces, image, k, period, f0, f1, f2)
                if persist:
                    faces = face_term(faces, image, k, period, bridge_pair_force[k, 0],
                                      bridge_pair_force[k, 1], bridge_pair_force[k, 2])
            if stiffness:
                s0, s1, s2 = pair_stiffness(k, p, radius, pair_j, normal, normal_force,
                                            overlap)
                k0 += s0
                k1 += s1
                k2 += s2
    for c in range(9):
        partial[b, c] = moments[c]
        partial[b, 9 + c] = faces[c]
    partial[b, 18] = k0
    partial[b, 19] = k1
    partial[b, 20] = k2


@device
def stretch(cell_position, rate, axis, shift, dt):
    """The length of ``axis`` changed by ``shift`` [m] over ``dt`` [s], its rate set
    (PeriodicCell.stretch)."""
    length = cell_position[2 * axis + 1]
    cell_position[2 * axis + 1] += shift
    rate[axis] = shift / (length * dt)


@device
def follow(cell_position, rate, shear, dt):
    """The offset and the shear strain in ``shear`` (SHEAR_FIELDS) advanced over the step
    ``dt`` [s] with the step's lengths ``cell_position`` and rates ``rate`` [1/s]: delta +=
    (rate_x delta + gamma_dot Lz0) dt, Lz0 the height at the step's start; gamma +=
    gamma_dot dt (PeriodicCell.follow, a method: restated)."""
    if shear[0] != 0.0 or shear[1] != 0.0:          # PeriodicCell.sheared
        height = cell_position[5] / (1.0 + rate[2] * dt)
        shear[0] += (rate[0] * shear[0] + shear[1] * height) * dt
        shear[2] += shear[1] * dt


@cuda.jit
def cell_controls(partial, cell_position, rate, stress_tensor, cell_stiffness, period,
                  affine_rate, shear, program, dt):
    """The cell's stress from the blocks' sums, its rates (and shear rate) to zero, its
    controls, the step counted (``step``, for a mixed condition's ``failure``:
    pendular.gpu.walls), the offset followed over the step (a sheared layout: ``period``
    (4,)), then ``period`` and ``affine_rate`` (module docstring). One thread; ``program``
    the controls' (pendular.gpu.walls.Program)."""
    (kinds, control_walls, wall_counts, parameters, previous, stiffness, calls, step,
     failure) = program
    if cuda.grid(1) != 0:
        return
    sheared = period.shape[0] > 3
    volume = cell_position[1] * cell_position[3] * cell_position[5]
    for c in range(9):
        moments = 0.0
        faces = 0.0
        for b in range(partial.shape[0]):
            moments += partial[b, c]
            faces += partial[b, 9 + c]
        stress_tensor[c // 3, c % 3] = (moments + faces) / volume
    for axis in range(3):
        rate[axis] = 0.0
    if sheared:
        shear[1] = 0.0
    for c in range(kinds.shape[0]):
        if kinds[c] == STRESS_SERVO:
            refresh = refreshes(c, parameters, calls)
            calls[c] += 1
            if refresh:         # PeriodicCell.update_stiffness, in the cell of now
                now = cell_position[1] * cell_position[3] * cell_position[5]
                for axis in range(3):
                    total = 0.0
                    for b in range(partial.shape[0]):
                        total += partial[b, 18 + axis]
                    cell_stiffness[axis] = total / now
            servo(cell_position, rate, stress_tensor, cell_stiffness, stiffness[c],
                  previous[c], control_walls[c, :wall_counts[c]], parameters[c, 0],
                  parameters[c, 1], parameters[c, 2], parameters[c, 3],
                  parameters[c, 4] != 0.0, refresh, dt)
        elif kinds[c] == STRAIN_RATE:
            axis = control_walls[c, 0]
            length = (cell_position[2 * axis + 1] - cell_position[2 * axis]
                      if parameters[c, 2] != 0.0 else parameters[c, 1])
            stretch(cell_position, rate, axis, -parameters[c, 0] * length * dt, dt)
        elif kinds[c] == SHEAR_RATE:
            shear[1] = parameters[c, 0]
        elif kinds[c] == MIXED_STRESS:     # from the cell's normal stresses now
            mixed_stress(c, control_walls, wall_counts[c], parameters,
                         (stress_tensor[0, 0], stress_tensor[1, 1], stress_tensor[2, 2]),
                         step[0], failure)
        elif kinds[c] == RADIUS_GROWTH:
            growth_rate(c, parameters,
                        (stress_tensor[0, 0], stress_tensor[1, 1], stress_tensor[2, 2]))
    step[0] += 1
    for axis in range(3):
        period[axis] = cell_position[2 * axis + 1]
        affine_rate[axis] = rate[axis]
    if sheared:
        follow(cell_position, rate, shear, dt)
        period[3] = shear[0]
        affine_rate[3] = shear[1]


@device_side(ConstantShearRate)
class ShearRateRow(ControlSide):
    """A ConstantShearRate's row (SHEAR_RATE): its rate gamma_dot [1/s] in the row's first
    parameter; a periodic cell's only."""

    role = SHEAR_RATE
    in_walls = False

    def parameters(self, values):
        values[0] = self.op.rate


def upload_shear(state, cell, sheared):
    """A periodic cell's shear on the device (``state``: pendular.gpu.state.DeviceState, its
    ``period``, ``affine_rate`` and ``shear``): the sheared layout from the host's ``cell``
    when ``sheared`` (the cell is sheared or a control shears it), else a one-entry ``shear``
    that nothing reads."""
    if not sheared:
        state.shear = cuda.to_device(np.zeros(1))
        return
    offset, rate = cell.shear_offset, cell.shear_rate
    state.period = cuda.to_device(np.array([*cell.position[1::2], offset]))
    state.affine_rate = cuda.to_device(np.array([*cell.rate, rate]))
    state.shear = cuda.to_device(np.array([offset, rate, cell.shear_strain, offset]))


def shear_to_host(state, cell):
    """The device's offset, shear rate and shear strain into the host's ``cell`` (nothing in
    a cell that does not shear)."""
    if state.period.shape[0] > 3:
        offset, rate, strain, _ = state.shear.copy_to_host()
        cell.shear_offset, cell.shear_rate, cell.shear_strain = (float(offset), float(rate),
                                                                 float(strain))


@device_side(PeriodicCell)
class CellBox(BoxSide):
    """A periodic cell (module docstring): its shear's layout and state, a step's launches."""

    def upload(self, state, scene):
        upload_shear(state, self.op, self.op.sheared or bool(scene.controls_of(SHEAR_RATE)))

    def to_host(self, state, box):
        shear_to_host(state, box)

    def steps(self, gpu):
        """(kernel, items, arguments) of a step in a periodic cell: the rebuild (wrap and
        bin, pairs through the faces, finish; in a sheared cell the offset it took stored),
        the forces (no walls), the cell's stress and controls, the leapfrog carried by the
        cell's stretching and shear."""
        sim = gpu.sim
        s = gpu.state
        n = s.count
        # bridges at contact join the contact law's gather (their attraction in the face
        # terms); persisting ones add their own forces' face terms (the CPU's
        # gather_pair_forces_virial)
        joined = s.wet and not s.persist
        bridges = s.bridges
        sheared = s.period.shape[0] > 3
        return [
            (neighbors.bin_periodic, n, (s.position, s.wall_position, s.period, s.wraps,
                                         s.grid(), s.flags)),
            (neighbors.find_periodic_pairs, n,
             (s.position, s.radius, s.skin + s.reach, s.wall_position, s.period, s.grid(),
              s.rows(), s.image, s.carried(), s.new_carried(), s.flags)),
            gpu.finish_step(),
            *([(neighbors.shear_rebuilt, 1, (s.period, s.shear, s.flags))] if sheared else []),
            *gpu.force_steps(False, 0.0),
            (cell_partials, s.cell_partial.shape[0],
             (s.position, s.force, s.radius, s.pairs(), s.images(), joined, bridges[:, 2],
              s.persist, s.bridge_pair_force, s.program(), s.cell_partial)),
            (cell_controls, 1,
             (s.cell_partial, s.wall_position, s.cell_rate, s.stress_tensor, s.cell_stiffness,
              s.period, s.affine_rate, s.shear, s.program(), sim.dt)),
            (integrate.cell_leapfrog, n,
             (s.motion(), gpu.scene.integrator.damping, s.affine_rate, sim.dt,
              s.reference_position, s.wall_position, s.reference_walls, s.period, s.shear,
              0.5 * s.skin,
              2.0 * float(sim.peek("particles").radius.max()) + s.skin + s.reach,
              s.flags)),
        ]
