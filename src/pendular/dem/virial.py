"""Sums of outer products l (x) f over pair forces in fixed blocks: the Love–Weber virial of a
periodic cell (Eq. 3.41).

The sum over the pairs of l (x) f (l the branch vector i -> j, f the force on j from i) is

    sum_pairs l (x) f = sum_p x_p (x) F_p + sum_pairs (image L) (x) f

(l = x_j - x_i + image L, F_p the resultant of p's pair forces). The first sum is taken once a
step from the particles' total forces (pendular.dem.cell.store_cell_stress). The second has terms only
for the pairs through a face: each force's gather, after a block of particles, adds those whose
first member is in the block (a slice of Contacts.through_face, from Contacts.face_start;
their forces are still in cache). Particles are split into SUM_BLOCKS fixed blocks; each
block's sum is kept apart and the blocks are added in order (``sum_blocks``), so the result
does not depend on the thread count. Walled scenes use the gathers without it. (Measured at
1,000 spheres: x_p (x) F_p in each gather cost 2-4 us a gather, once a step about 2 us;
testing each pair's image inside the pair loop instead cost more than the face slices.)
"""

import numba
import numpy as np

#: Fixed blocks of particles summed apart then together: a sum in the same order for any
#: thread count (results thread-independent).
SUM_BLOCKS = 64

#: Nine zeros: the start of a sum of outer products (add_outer).
ZERO9 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@numba.njit(cache=True, inline="always")
def block_bounds(count, block):
    """First and one-past-last of the ``count`` items in block ``block`` of SUM_BLOCKS."""
    return count * block // SUM_BLOCKS, count * (block + 1) // SUM_BLOCKS


@numba.njit(cache=True, inline="always")
def add_outer(total, a0, a1, a2, b0, b1, b2):
    """``total`` (9 numbers, row by row) plus the outer product a (x) b: a tuple, so that a
    sum over a loop stays in registers."""
    return (total[0] + a0 * b0, total[1] + a0 * b1, total[2] + a0 * b2,
            total[3] + a1 * b0, total[4] + a1 * b1, total[5] + a1 * b2,
            total[6] + a2 * b0, total[7] + a2 * b1, total[8] + a2 * b2)


def face_block_starts(through_face, row_start):
    """(SUM_BLOCKS + 1,) int64: the pairs through a face whose first member lies in block b of
    the particles (block_bounds) are through_face[starts[b]:starts[b + 1]] (``through_face``
    sorted pair indices, CSR ``row_start``). Computed once per neighbour list."""
    count = len(row_start) - 1
    firsts = row_start[[count * block // SUM_BLOCKS for block in range(SUM_BLOCKS + 1)]]
    return np.searchsorted(through_face, firsts).astype(np.int64)


@numba.njit(cache=True, inline="always")
def add_face_term(total, image, k, period, f0, f1, f2):
    """``total`` plus (image_k L) (x) f for pair k through a face, f [N] its force on j from i
    (what its branch vector holds beyond x_j - x_i; a sheared cell's ``period`` (4,) adds its
    offset along x per image in z, pendular.dem.neighbors.branch_vector)."""
    shift0 = image[k, 0] * period[0]
    if len(period) > 3:
        shift0 += image[k, 2] * period[3]
    return add_outer(total, shift0, image[k, 1] * period[1], image[k, 2] * period[2], f0, f1,
                     f2)


@numba.njit(cache=True, inline="always")
def pair_force_with_attraction(pair_force, attraction, normal, k):
    """Pair k's force on j from i [N]: ``pair_force[k]``, less ``attraction[k]`` along the
    normal unless ``attraction`` (K,) [N] is None (a central pull, +a n on i, -a n on j:
    capillary bridges at contact, pendular.dem.contact_law.ContactForces.gather). A None argument is a
    type of its own to Numba: the kernels compiled for it hold no test."""
    a0 = pair_force[k, 0]
    a1 = pair_force[k, 1]
    a2 = pair_force[k, 2]
    if attraction is not None:
        b = attraction[k]
        a0 -= b * normal[k, 0]
        a1 -= b * normal[k, 1]
        a2 -= b * normal[k, 2]
    return a0, a1, a2


@numba.njit(cache=True, inline="always")
def add_face_forces(total, through_face, first, last, image, period, pair_force, attraction,
                    normal):
    """``total`` plus (image_k L) (x) f_k over the pairs k = through_face[first:last], f the
    force on j from i [N] (pair_force_with_attraction: ``pair_force`` (K, 3), less the
    ``attraction`` along ``normal`` unless it is None)."""
    for slot in range(first, last):
        k = through_face[slot]
        f0, f1, f2 = pair_force_with_attraction(pair_force, attraction, normal, k)
        total = add_face_term(total, image, k, period, f0, f1, f2)
    return total


@numba.njit(cache=True, inline="always")
def add_face_block(virial, block, through_face, face_start, image, period, pair_force,
                   attraction, normal):
    """Add to row ``block`` of ``virial`` the face terms (add_face_forces) of the pairs through
    a face whose first member lies in that block of particles (``face_start``:
    face_block_starts)."""
    add_to_block(virial, block, add_face_forces(ZERO9, through_face, face_start[block],
                                                face_start[block + 1], image, period,
                                                pair_force, attraction, normal))


@numba.njit(cache=True, inline="always")
def add_to_block(sums, block, total):
    """Add the 9 numbers of ``total`` to row ``block`` of ``sums`` (SUM_BLOCKS, 9)."""
    for c in range(9):
        sums[block, c] += total[c]


@numba.njit(cache=True)
def sum_blocks(sums):
    """Column sums of the per-block sums, block after block (the same order for any thread
    count)."""
    total = np.zeros(sums.shape[1])
    for block in range(sums.shape[0]):
        for c in range(sums.shape[1]):
            total[c] += sums[block, c]
    return total
