"""The critical state of a shear: the end of a test where the sample deforms at constant stress
ratio and constant volume (Schofield & Wroth 1968; Wood 1990, Ch. 6).

The rule (``critical_state``): over the last CRITICAL_STATE_WINDOW of axial strain (at least
MIN_RECORDS records),

- the stress ratio q/p drifts by at most STRESS_RATIO_TOLERANCE of its mean: the least-squares
  slope of q/p against the axial strain, times the window, over the mean q/p;
- the volume no longer changes: the least-squares slope |d eps_v / d eps_a| is at most
  DILATANCY_TOLERANCE.

Then, means over that window: ``M_cs`` = mean |q| / mean p, ``phi_cs_deg`` the mobilised
friction angle asin((sigma_1 - sigma_3) / (sigma_1 + sigma_3)) of the mean principal stresses
(in axisymmetric compression sin phi = 3 M / (6 + M), in extension 3 M / (6 - M)) and
``void_ratio_cs`` the mean void ratio. Otherwise each is None and ``critical_state_note`` says
which condition failed, by how much. Stresses [Pa], compression positive; strains [-].
"""

from __future__ import annotations

import numpy as np

from pendular.homogenize.invariants import mean_stress
from pendular.procedures.columns import friction_angle

#: Axial strain over which the critical state is judged and measured: the last 5 % [-].
CRITICAL_STATE_WINDOW = 0.05
#: Largest drift of q/p over the window, as a fraction of its mean [-].
STRESS_RATIO_TOLERANCE = 0.05
#: Largest |d eps_v / d eps_a| over the window [-] (a dense sample's dilatancy at its peak is
#: 0.3-0.5).
DILATANCY_TOLERANCE = 0.05
#: Fewest records in the window: a slope through fewer is noise.
MIN_RECORDS = 5

#: The keys of a critical state, None when it was not reached.
CRITICAL_STATE_KEYS = ("phi_cs_deg", "M_cs", "void_ratio_cs")


def _slope(x, y):
    """Least-squares slope of y against x."""
    dx = x - x.mean()
    return float(np.sum(dx * (y - y.mean())) / np.sum(dx * dx))


def critical_state(axial_strain, volumetric_strain, sigma, q, porosity):
    """The critical state of a shear's records (module docstring): ``axial_strain`` and
    ``volumetric_strain`` [-] (n,), principal stresses ``sigma`` (n, 3) [Pa], the deviator
    stress ``q`` (n,) [Pa] of the test (negative in extension), ``porosity`` (n,) [-].
    Returns ``phi_cs_deg`` [deg], ``M_cs`` [-], ``void_ratio_cs`` [-] and
    ``critical_state_note`` (text: how it was judged, or why it was not reached)."""
    strain = np.abs(np.asarray(axial_strain, dtype=float))
    volumetric = np.asarray(volumetric_strain, dtype=float)
    sigma = np.asarray(sigma, dtype=float)
    q = np.abs(np.asarray(q, dtype=float))
    p = mean_stress(sigma)
    not_reached = dict.fromkeys(CRITICAL_STATE_KEYS)
    window = strain >= strain[-1] - CRITICAL_STATE_WINDOW
    rule = (f"over the last {100 * CRITICAL_STATE_WINDOW:g} % of axial strain: q/p drift "
            f"{{drift:.3g}} of its mean (at most {STRESS_RATIO_TOLERANCE:g}), |dεv/dεa| "
            f"{{rate:.3g}} (at most {DILATANCY_TOLERANCE:g})")
    if strain[-1] - strain[0] < CRITICAL_STATE_WINDOW:
        return {**not_reached, "critical_state_note": (
            f"not reached: the test ended at an axial strain of {100 * strain[-1]:.3g} %, "
            f"within the {100 * CRITICAL_STATE_WINDOW:g} % of strain over which it is judged")}
    if np.count_nonzero(window) < MIN_RECORDS:
        return {**not_reached, "critical_state_note": (
            f"not measured: {np.count_nonzero(window)} records in the last "
            f"{100 * CRITICAL_STATE_WINDOW:g} % of axial strain, fewer than {MIN_RECORDS}")}
    if not np.all(p[window] > 0.0):
        return {**not_reached, "critical_state_note": (
            "not measured: the mean stress fell to 0 in the last "
            f"{100 * CRITICAL_STATE_WINDOW:g} % of axial strain")}
    x = strain[window]
    ratio = q[window] / p[window]
    drift = abs(_slope(x, ratio)) * CRITICAL_STATE_WINDOW / float(np.mean(ratio))
    rate = abs(_slope(x, volumetric[window]))
    judged = rule.format(drift=drift, rate=rate)
    if drift > STRESS_RATIO_TOLERANCE or rate > DILATANCY_TOLERANCE:
        return {**not_reached, "critical_state_note": f"not reached: {judged}"}
    mean_sigma = sigma[window].mean(axis=0)
    n = np.asarray(porosity, dtype=float)[window]
    return {"phi_cs_deg": float(friction_angle(mean_sigma)),
            "M_cs": float(np.mean(q[window]) / np.mean(p[window])),
            "void_ratio_cs": float(np.mean(n / (1.0 - n))),
            "critical_state_note": f"reached: {judged}; means over that window"}
