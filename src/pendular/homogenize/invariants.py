"""Stress invariants of triaxial tests: q and p, defined once (docs/units.md).

Compression positive [Pa]; the lateral stress is the mean of the x and y stresses:
q = sigma_z - (sigma_x + sigma_y) / 2 (axisymmetric tests, negative in extension),
p = (sigma_x + sigma_y + sigma_z) / 3; at an intermediate principal stress (b != 0) q is the
von Mises deviatoric stress (``von_mises_stress``).
"""

import numpy as np


def lateral_stress(sigma):
    """(sigma_x + sigma_y) / 2 of principal stresses ``sigma`` (..., 3) [Pa]."""
    sigma = np.asarray(sigma, dtype=np.float64)
    return 0.5 * (sigma[..., 0] + sigma[..., 1])


def deviator_stress(sigma):
    """q = sigma_z - (sigma_x + sigma_y) / 2 [Pa] of principal stresses (..., 3)."""
    sigma = np.asarray(sigma, dtype=np.float64)
    return sigma[..., 2] - lateral_stress(sigma)


def von_mises_stress(sigma):
    """q = sqrt(((sigma_x - sigma_y)^2 + (sigma_y - sigma_z)^2 + (sigma_z - sigma_x)^2) / 2)
    [Pa] of principal stresses (..., 3): the von Mises deviatoric stress, equal to |sigma_z -
    sigma_x| when sigma_x = sigma_y (Wood 1990, Ch. 1)."""
    sigma = np.asarray(sigma, dtype=np.float64)
    x, y, z = sigma[..., 0], sigma[..., 1], sigma[..., 2]
    return np.sqrt(0.5 * ((x - y) ** 2 + (y - z) ** 2 + (z - x) ** 2))


def shear_deviator(sigma, b=None):
    """The q [Pa] of a test of principal stresses (..., 3) held at ``b`` = (sigma_2 - sigma_3)
    / (sigma_1 - sigma_3): von_mises_stress where b is given and not 0, else
    deviator_stress (sigma_z - sigma_lateral, signed)."""
    return von_mises_stress(sigma) if b else deviator_stress(sigma)


def principal_difference(sigma):
    """sigma_1 - sigma_3 [Pa]: the largest less the least principal stress (..., 3)."""
    sigma = np.asarray(sigma, dtype=np.float64)
    return sigma.max(axis=-1) - sigma.min(axis=-1)


def mean_stress(sigma):
    """p = (sigma_x + sigma_y + sigma_z) / 3 [Pa] of principal stresses (..., 3)."""
    sigma = np.asarray(sigma, dtype=np.float64)
    return (sigma[..., 2] + 2.0 * lateral_stress(sigma)) / 3.0


def stress_ratio(sigma):
    """q / p (NaN where p <= 0) of principal stresses (..., 3)."""
    p = mean_stress(sigma)
    return deviator_stress(sigma) / np.where(p > 0.0, p, np.nan)
