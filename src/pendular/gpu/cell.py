"""A periodic cell on the device (pendular.dem.cell.PeriodicCell, not sheared): its stress
reduced in a fixed order each step, then its controls (stress servo, constant strain rate) in
the scene's order, with no host round trip.

The reduction (``cell_partials``): each block of REDUCE_CHUNK particles sums, in particle
order, x_p (x) F_p over its particles, the face terms (image L) (x) f of its particles' pairs
through a face (f with the bridges' attraction, wet) and, at a step where a servo refreshes
the cell's stiffness (``refreshes``), the pairs' stiffness kn (l_a n_a)^2 (pendular.dem.virial,
pendular.dem.cell.contact_stiffness); then one thread
(``cell_controls``) adds the blocks in order, divides by the volume (the CPU's
store_cell_stress: Love–Weber, Eq. 3.41), sets the rates to zero (PeriodicCell.after_forces)
and runs the controls: the rows of pendular.gpu.walls's program whose ``control_walls[c,
:wall_counts[c]]`` hold, in a periodic cell, a servo's axes (StressServo's, the CPU's
servo_cell) or a strain rate's axis (PeriodicCell.stretch). Last, ``period`` (3,) [m] and
``affine_rate`` (3,) [1/s], which the next step's kernels read, take the cell's new lengths
and rates.
"""

from pendular.dem.cell import pair_stiffness as cpu_pair_stiffness, servo_cell
from pendular.dem.virial import add_face_term, add_outer, pair_force_with_attraction
from pendular.dem.walls import StressServo
from pendular.gpu.cuda import cuda, device, device_twin
from pendular.gpu.walls import REDUCE_CHUNK, STIFFNESS_WARMUP, STRAIN_RATE, STRESS_SERVO

servo = device_twin(servo_cell)
outer = device_twin(add_outer)
face_term = device_twin(add_face_term)
pull_less = device_twin(pair_force_with_attraction)
pair_stiffness = device_twin(cpu_pair_stiffness)

#: Columns of a block's partial sums: x (x) F (9), the face terms (9), the stiffness (3).
CELL_SUMS = 21
#: Fewest servo calls between refreshes of the cell's stiffness after the warm-up.
CELL_STIFFNESS_EVERY = StressServo.CELL_STIFFNESS_EVERY


@device
def refreshes(c, parameters, calls):
    """Whether the servo of row c refreshes the cell's stiffness at its next call
    (StressServo.apply in a periodic cell: every call of the warm-up, then every
    max(stiffness_every, CELL_STIFFNESS_EVERY) calls)."""
    every = max(int(parameters[c, 5]), CELL_STIFFNESS_EVERY)
    return calls[c] < STIFFNESS_WARMUP or calls[c] % every == 0


@cuda.jit
def cell_partials(position, force, radius, pair_count, pair_j, image, period, pair_force,
                  normal, overlap, normal_force, wet, attraction, kinds, parameters, calls,
                  partial):
    """partial[b]: block b's sums (module docstring), its particles in order; the face terms
    with the ``attraction`` (K,) [N] along the normals when ``wet``; the stiffness when a
    servo among the controls (``kinds``) refreshes it this step."""
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


@cuda.jit
def cell_controls(partial, cell_position, rate, stress_tensor, cell_stiffness, period,
                  affine_rate, kinds, control_walls, wall_counts, parameters, previous,
                  stiffness, calls, dt):
    """The cell's stress from the blocks' sums, its rates to zero, its controls, then
    ``period`` and ``affine_rate`` (module docstring). One thread."""
    if cuda.grid(1) != 0:
        return
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
    for axis in range(3):
        period[axis] = cell_position[2 * axis + 1]
        affine_rate[axis] = rate[axis]
