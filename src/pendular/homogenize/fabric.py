"""Fabric tensors of contacts (Eq. 4.1) and bridges (Eq. 3.53), and their anisotropy."""

import numba
import numpy as np


@numba.njit(cache=True)
def _fabric_sum(normal, mask):
    total = np.zeros((3, 3))
    count = 0
    for k in range(normal.shape[0]):
        if not mask[k]:
            continue
        count += 1
        for a in range(3):
            for b in range(3):
                total[a, b] += normal[k, a] * normal[k, b]
    return total, count


def fabric_tensor(normal, mask):
    """F_ij = (1 / 2Nc) sum over both orientations of n_i n_j = (1/Nc) sum n_i n_j (Eq. 4.1).

    normal: (K, 3) unit vectors, mask: (K,) bool selecting the contacts (or bridges, Eq. 3.53).
    Returns zeros when nothing is selected.
    """
    normal = np.asarray(normal)
    mask = np.asarray(mask)
    if normal.ndim != 2 or normal.shape[1] != 3 or mask.shape != (len(normal),):
        raise ValueError(f"normal must have shape (K, 3) and mask shape (K,), got normal "
                         f"{normal.shape} and mask {mask.shape}")
    total, count = _fabric_sum(normal, mask)
    return total / count if count else total


def fabric_anisotropy(fabric):
    """a = 5/2 (F_z - F_x) / tr F from the principal values, largest minus smallest (Eq. 3.51).

    For the axisymmetric triaxial the principal axes follow the box: F_z = F[2, 2] and
    F_x = mean of F[0, 0], F[1, 1].
    """
    trace = np.trace(fabric)
    if trace == 0.0:
        return 0.0
    return 2.5 * (fabric[2, 2] - 0.5 * (fabric[0, 0] + fabric[1, 1])) / trace


def principal_anisotropy(tensor):
    """a = 5/2 (T_z - T_x) / tr T from the principal values of a symmetric 3x3 tensor.

    The form of Eq. 3.51 (fabric), Eq. 3.54 (bridge fabric) and Eq. 4.5 (capillary stress).
    T_z is the principal value whose principal axis is closest to the z axis (the axial
    direction of the packings and of the triaxial box), T_x the mean of the other two, so that
    a < 0 when the largest principal value lies in the x-y plane (the thesis's BCC with l' = 2.1).
    Returns NaN when tr T = 0 (no bridges: the anisotropy is undefined). ValueError when T
    holds a NaN or an infinity (the state it was measured on diverged).
    """
    tensor = np.asarray(tensor, dtype=float)
    if tensor.shape != (3, 3):
        raise ValueError(f"tensor has shape {tensor.shape}; expected (3, 3)")
    if not np.all(np.isfinite(tensor)):
        raise ValueError(f"tensor = {tensor.tolist()} is not finite, so neither is its "
                         "anisotropy: the state it was measured on diverged (lower the time "
                         "step, e.g. --timestep-safety, or check the forces)")
    trace = np.trace(tensor)
    if trace == 0.0:
        return np.nan
    values, vectors = np.linalg.eigh(0.5 * (tensor + tensor.T))
    axial = int(np.argmax(np.abs(vectors[2])))
    lateral = np.delete(values, axial).mean()
    return 2.5 * (values[axial] - lateral) / trace
