"""Stress invariants of axisymmetric (triaxial) tests: q and p, defined once (docs/units.md).

Compression positive [Pa]; the lateral stress is the mean of the x and y stresses:
q = sigma_z - (sigma_x + sigma_y) / 2, p = (sigma_x + sigma_y + sigma_z) / 3.
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


def mean_stress(sigma):
    """p = (sigma_x + sigma_y + sigma_z) / 3 [Pa] of principal stresses (..., 3)."""
    sigma = np.asarray(sigma, dtype=np.float64)
    return (sigma[..., 2] + 2.0 * lateral_stress(sigma)) / 3.0


def stress_ratio(sigma):
    """q / p (NaN where p <= 0) of principal stresses (..., 3)."""
    p = mean_stress(sigma)
    return deviator_stress(sigma) / np.where(p > 0.0, p, np.nan)
