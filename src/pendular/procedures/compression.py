"""Compression indices of a void ratio against log stress, shared by the oedometer's and the
isotropic test's summaries (pendular.procedures.oedometer, pendular.procedures.isotropic).
"""

from __future__ import annotations

import math

import numpy as np


def stage_ends(history, count):
    """Row of each stage's end (the last row of each stage index), for ``count`` stages."""
    stage = history.get("stage")
    if stage is None:
        return [len(history["step"]) - 1]
    return [int(np.flatnonzero(stage == k)[-1]) for k in range(count)
            if np.any(stage == k)]


def index_of_slope(e_high, e_low, stress_high, stress_low):
    """Delta e per log10 of the stress over a stress change [-], None without one."""
    span = math.log10(stress_high / stress_low) if stress_high > 0 and stress_low > 0 else 0.0
    return (e_high - e_low) / span if span > 0.0 else None


def compression_indices(void, stress):
    """(compression index, swelling index) [-] of successive states (void ratio, stress [Pa]):
    the total decrease of e over the total rise of log10 sigma over the steps that load, and
    the total rise of e over the total fall of log10 sigma over those that unload (None
    without such a step)."""
    loading = [0.0, 0.0]
    unloading = [0.0, 0.0]
    for k in range(1, len(stress)):
        if stress[k] <= 0.0 or stress[k - 1] <= 0.0:
            continue
        rise = math.log10(stress[k] / stress[k - 1])
        change = void[k] - void[k - 1]
        side = loading if rise > 0.0 else unloading
        side[0] += -change if rise > 0.0 else change
        side[1] += abs(rise)
    return tuple(total / span if span > 0.0 else None for total, span in (loading, unloading))


def effective_diagonal(history):
    """Diagonal (n, 3) of the effective stress (Eq. 3.43) of a wet history, or None."""
    if "sigma_effective" not in history:
        return None
    return np.diagonal(history["sigma_effective"], axis1=1, axis2=2)


def tangent_modulus(strain, stress, fraction=0.2):
    """Slope d sigma / d eps [Pa] (least squares) over the rows whose stress lies in the top
    ``fraction`` of the range of ``stress``; None with fewer than 3 such rows."""
    top = stress >= stress.max() - fraction * (stress.max() - stress[0])
    if np.count_nonzero(top) < 3 or np.ptp(strain[top]) == 0.0:
        return None
    return float(np.polyfit(strain[top], stress[top], 1)[0])
