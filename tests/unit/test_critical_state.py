"""The critical state of a shear (pendular.procedures.critical_state) on synthetic histories:
reached at a stable q/p and volume, not reached while q/p drifts, while the sample dilates or
before the window; in every triaxial summary with the rule in its note; extension and b."""

import math

import numpy as np
import pytest

from pendular.homogenize.invariants import von_mises_stress
from pendular.procedures.critical_state import CRITICAL_STATE_KEYS, CRITICAL_STATE_WINDOW
from pendular.procedures.triaxial import summarize

STRAIN = np.linspace(0.0, 0.25, 251)
CONFINING = 1000.0


def triaxial_history(q, volumetric, porosity=0.4, strain=STRAIN, extension=False):
    """A drained triaxial history: lateral stress CONFINING, axial CONFINING + q [Pa]."""
    sigma = np.empty((len(strain), 3))
    sigma[:, :2] = CONFINING
    sigma[:, 2] = CONFINING + q
    return {"axial_strain": -strain if extension else strain, "sigma_wall": sigma,
            "volumetric_strain": volumetric, "porosity": np.full(len(strain), porosity)}


def dense(strain, ratio_cs=1.2):
    """q of a dense sample: a peak near 3 % then softening to M = ratio_cs (q/p), with p
    following q on the conventional path (p = CONFINING + q / 3)."""
    ratio = ratio_cs + 0.4 * np.exp(-((strain - 0.03) / 0.02) ** 2) - ratio_cs * np.exp(
        -strain / 0.005)
    return CONFINING * ratio / (1.0 - ratio / 3.0)


def dilation(strain, total=-0.04, scale=0.03):
    """eps_v of a dense sample: contraction, then dilation at a rate falling to 0."""
    return 0.002 * (1.0 - np.exp(-strain / 0.002)) + total * (1.0 - np.exp(-strain / scale))


def test_a_dense_sample_at_constant_stress_ratio_and_volume_reaches_it():
    history = triaxial_history(dense(STRAIN), dilation(STRAIN), porosity=0.42)
    found = summarize(history)
    assert found["M_cs"] == pytest.approx(1.2, rel=1e-3)
    # sin phi = 3 M / (6 + M) in axisymmetric compression
    assert found["phi_cs_deg"] == pytest.approx(math.degrees(math.asin(3.6 / 7.2)), rel=1e-3)
    assert found["void_ratio_cs"] == pytest.approx(0.42 / 0.58)
    assert found["critical_state_note"].startswith("reached: over the last 5 % of axial")


def test_not_reached_while_the_sample_still_dilates_or_q_p_drifts():
    still_dilating = summarize(triaxial_history(dense(STRAIN), -0.2 * STRAIN))
    assert all(still_dilating[key] is None for key in CRITICAL_STATE_KEYS)
    assert "|dεv/dεa| 0.2 (at most 0.05)" in still_dilating["critical_state_note"]
    hardening = summarize(triaxial_history(1000.0 + 8000.0 * STRAIN, dilation(STRAIN)))
    assert hardening["M_cs"] is None
    assert hardening["critical_state_note"].startswith("not reached: over the last 5 %")


def test_not_reached_before_the_window_nor_measured_on_too_few_records():
    short = np.linspace(0.0, 0.9 * CRITICAL_STATE_WINDOW, 50)
    found = summarize(triaxial_history(dense(short), dilation(short), strain=short))
    assert found["phi_cs_deg"] is None and "ended at an axial strain of 4.5 %" in \
        found["critical_state_note"]
    sparse = np.linspace(0.0, 0.25, 11)           # 3 records in the last 5 %
    found = summarize(triaxial_history(dense(sparse), dilation(sparse), strain=sparse))
    assert found["void_ratio_cs"] is None and "3 records" in found["critical_state_note"]


def test_the_scatter_of_a_small_sample_does_not_hide_a_critical_state():
    noise = np.random.default_rng(1).uniform(-80.0, 80.0, len(STRAIN))
    found = summarize(triaxial_history(dense(STRAIN) + noise, dilation(STRAIN)))
    assert found["M_cs"] == pytest.approx(1.2, rel=0.02)


def test_extension_gives_a_positive_M_and_its_own_friction_angle():
    """In extension q < 0 and sin phi = 3 M / (6 - M)."""
    ratio = 0.8
    q = -CONFINING * ratio / (1.0 + ratio / 3.0) * (1.0 - np.exp(-STRAIN / 0.005))
    found = summarize(triaxial_history(q, dilation(STRAIN), extension=True),
                      direction="extension")
    assert found["peak_q"] < 0.0 and found["axial_strain_at_peak"] <= 0.0
    assert found["M_cs"] == pytest.approx(ratio, rel=1e-3)
    assert found["phi_cs_deg"] == pytest.approx(
        math.degrees(math.asin(3 * ratio / (6 - ratio))), rel=1e-3)


def test_at_b_q_is_von_mises_and_sigma_1_minus_sigma_3_is_given_beside_it():
    """At b = 0.5 the summary's q is the von Mises stress, not sigma_z - (sigma_x + sigma_y)/2,
    and sigma_1 - sigma_3 is given under its own name."""
    history = triaxial_history(dense(STRAIN), dilation(STRAIN))
    sigma = history["sigma_wall"]
    sigma[:, 1] = sigma[:, 0] + 0.5 * (sigma[:, 2] - sigma[:, 0])
    found = summarize(history, b=0.5)
    peak = found["peak_index"]
    assert found["peak_q"] == pytest.approx(von_mises_stress(sigma[peak]))
    assert found["peak_q"] == pytest.approx(math.sqrt(0.75) * (sigma[peak, 2] - sigma[peak, 0]))
    assert found["principal_difference_at_peak"] == pytest.approx(sigma[peak, 2]
                                                                  - sigma[peak, 0])
    assert found["M_cs"] is not None


def test_von_mises_is_q_when_the_lateral_stresses_are_equal():
    sigma = np.array([[100.0, 100.0, 350.0], [500.0, 500.0, 200.0]])
    assert von_mises_stress(sigma) == pytest.approx([250.0, 300.0])
