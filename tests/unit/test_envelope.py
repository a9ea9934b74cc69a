"""Mohr–Coulomb fit against envelopes built by hand from Mohr circles."""

import numpy as np
import pytest

from pendular.studies.envelope import envelope_runs, mohr_coulomb_envelope, mohr_coulomb_fit


def peaks_on_envelope(phi_deg, cohesion, lateral):
    """Axial stress at failure for each lateral stress: the Mohr circle tangent to the line."""
    phi = np.radians(phi_deg)
    passive = (1 + np.sin(phi)) / (1 - np.sin(phi))
    axial = lateral * passive + 2 * cohesion * np.sqrt(passive)
    q = axial - lateral
    p = (axial + 2 * lateral) / 3
    return p, q


@pytest.mark.parametrize("phi, cohesion", [(25.0, 0.0), (30.0, 1500.0), (18.0, 300.0)])
def test_fit_recovers_friction_angle_and_cohesion(phi, cohesion):
    p, q = peaks_on_envelope(phi, cohesion, np.array([250.0, 500.0, 750.0, 1000.0]))
    fitted_phi, fitted_cohesion = mohr_coulomb_fit(p, q)
    assert fitted_phi == pytest.approx(phi, abs=1e-9)
    assert fitted_cohesion == pytest.approx(cohesion, abs=1e-6)


def test_fit_through_origin_and_bad_input():
    p, q = peaks_on_envelope(25.0, 0.0, np.array([250.0, 1000.0]))
    assert mohr_coulomb_fit(p, q, through_origin=True)[0] == pytest.approx(25.0)
    with pytest.raises(ValueError, match="at least 2"):
        mohr_coulomb_fit([1.0], [1.0])
    with pytest.raises(ValueError, match="slope"):
        mohr_coulomb_fit([1.0, 2.0], [4.0, 8.0])


# ---------------------------------------------------------------- standard errors

def closed_form_errors(p, q):
    """Textbook errors of the least-squares line q = M p + q0: residual variance s^2 over
    n - 2, var M = s^2 / Sxx, var q0 = s^2 (1/n + mean(p)^2 / Sxx), cov = -mean(p) s^2 / Sxx."""
    n = len(p)
    mean = p.mean()
    sxx = np.sum((p - mean) ** 2)
    slope = np.sum((p - mean) * (q - q.mean())) / sxx
    intercept = q.mean() - slope * mean
    s2 = np.sum((q - intercept - slope * p) ** 2) / (n - 2)
    covariance = s2 * np.array([[1 / sxx, -mean / sxx], [-mean / sxx, 1 / n + mean ** 2 / sxx]])
    return slope, intercept, covariance


def angle_and_cohesion(slope, intercept):
    """phi [deg] and c [Pa] of the p–q line, from the Mohr–Coulomb relations."""
    sin_phi = 3 * slope / (6 + slope)
    phi = np.arcsin(sin_phi)
    return np.degrees(phi), intercept * (3 - sin_phi) / (6 * np.cos(phi))


def noisy_peaks(rng, noise, phi=25.0, cohesion=300.0):
    p, q = peaks_on_envelope(phi, cohesion, np.array([250.0, 500.0, 1000.0, 2000.0]))
    return p, q + rng.normal(0.0, noise, size=q.shape)


def test_standard_errors_are_those_of_the_closed_form_carried_to_phi_and_c():
    rng = np.random.default_rng(3)
    p, q = noisy_peaks(rng, 40.0)
    fit = mohr_coulomb_envelope(p, q)
    slope, intercept, covariance = closed_form_errors(p, q)
    assert fit.slope == pytest.approx(slope, rel=1e-12)
    assert fit.intercept == pytest.approx(intercept, rel=1e-9)
    assert fit.slope_error == pytest.approx(np.sqrt(covariance[0, 0]), rel=1e-9)
    assert fit.intercept_error == pytest.approx(np.sqrt(covariance[1, 1]), rel=1e-9)
    assert fit.points == 4 and fit.degrees_of_freedom == 2
    # first order: the gradients of phi(M) and c(M, q0) by central differences
    h = 1e-6
    dphi = (angle_and_cohesion(slope + h, intercept)[0]
            - angle_and_cohesion(slope - h, intercept)[0]) / (2 * h)
    gradient = np.array([(angle_and_cohesion(slope + h, intercept)[1]
                          - angle_and_cohesion(slope - h, intercept)[1]) / (2 * h),
                         (angle_and_cohesion(slope, intercept + h)[1]
                          - angle_and_cohesion(slope, intercept - h)[1]) / (2 * h)])
    assert fit.phi_error_deg == pytest.approx(abs(dphi) * np.sqrt(covariance[0, 0]), rel=1e-6)
    assert fit.cohesion_error == pytest.approx(np.sqrt(gradient @ covariance @ gradient),
                                               rel=1e-6)


def test_standard_errors_match_the_scatter_of_repeated_fits_with_known_noise():
    """4,000 envelopes of the same four peaks with Gaussian noise of 20 Pa on q: the spread of
    the fitted phi and c is what each fit's standard error says (mean of the squared errors
    against the variance of the fits, within 6 %), and c = 300 Pa lies within 2 standard
    errors as often as a t distribution with 2 degrees of freedom says: 81.6 %."""
    rng = np.random.default_rng(7)
    fits = [mohr_coulomb_envelope(*noisy_peaks(rng, 20.0)) for _ in range(4000)]
    phi = np.array([f.phi_deg for f in fits])
    cohesion = np.array([f.cohesion for f in fits])
    for values, errors in ((phi, [f.phi_error_deg for f in fits]),
                           (cohesion, [f.cohesion_error for f in fits])):
        assert np.mean(np.square(errors)) == pytest.approx(np.var(values), rel=0.06)
    assert phi.mean() == pytest.approx(25.0, abs=0.02)
    inside = np.mean(np.abs(cohesion - 300.0) <= 2 * np.array([f.cohesion_error for f in fits]))
    assert inside == pytest.approx(0.816, abs=0.02)       # 2 P(T_2 < 2) - 1


def test_a_line_through_two_points_or_the_origin_has_no_cohesion_error():
    p, q = peaks_on_envelope(30.0, 100.0, np.array([500.0, 1000.0]))
    fit = mohr_coulomb_envelope(p, q)
    assert fit.phi_deg == pytest.approx(30.0) and fit.cohesion == pytest.approx(100.0)
    assert fit.phi_error_deg is None and fit.cohesion_error is None and fit.degrees_of_freedom == 0
    rng = np.random.default_rng(1)
    p, q = noisy_peaks(rng, 20.0, cohesion=0.0)
    origin = mohr_coulomb_envelope(p, q, through_origin=True)
    assert origin.cohesion == 0.0 and origin.cohesion_error == 0.0
    assert origin.degrees_of_freedom == 3
    # var M = s^2 / sum(p^2), s^2 over n - 1
    slope = p @ q / (p @ p)
    s2 = np.sum((q - slope * p) ** 2) / 3
    assert origin.slope_error == pytest.approx(np.sqrt(s2 / (p @ p)), rel=1e-9)


# ---------------------------------------------------------------- the study's runs

def test_an_envelope_is_one_triaxial_per_confining_stress():
    runs = envelope_runs({"confining": "250,500,1000", "particles": 300, "suction": 30000,
                          "max_strain": 0.05})
    assert [run.name for run in runs] == ["confining250", "confining500", "confining1000"]
    assert [run.config.confining for run in runs] == [250.0, 500.0, 1000.0]
    assert all(run.config.sample.particles == 300 and run.config.suction == 30000.0
               and run.config.shear.max_strain == 0.05 for run in runs)
    assert envelope_runs({"confining": [250.5, 500]})[0].name == "confining250.5"


@pytest.mark.parametrize("options, message", [
    ({}, "confining is missing"),
    ({"confining": "500"}, "confining = '500': at least 2 confining stresses"),
    ({"confining": [500]}, "confining = [500]: at least 2"),
    ({"confining": "500,1000,500"}, "confining = '500,1000,500' repeats 500"),
    ({"confining": "0,500"}, "confining = 0.0 Pa is outside the valid range (0, 1e+07]"),
    ({"confining": "-250,500"}, "confining = -250.0 Pa is outside the valid range"),
    ({"confining": "250,x"}, "confining = '250,x' is not a comma-separated list"),
    ({"confining": "250,500", "direction": "extension"}, "direction: not an option of an "
                                                         "envelope"),
    ({"confining": "250,500", "particles": 3}, "particles = 3 is outside the valid range"),
])
def test_bad_envelopes_are_refused_naming_the_option(options, message):
    with pytest.raises(ValueError) as error:
        envelope_runs(options)
    assert message in str(error.value)


def test_a_summary_of_peaks_on_known_envelopes_gives_them_back_and_draws_them(tmp_path):
    """Peaks on c = 1.2 kPa, phi = 33 deg in net stresses and on c' = 0, phi' = 25 deg in
    effective ones (a wet test at a water content): the summary's fits, its tests' principal
    stresses and both figures."""
    from conftest import assert_drawn

    from pendular.io.schema import undeclared_keys
    from pendular.studies.envelope import envelope_summary, peak_row
    from pendular.studies.envelope_figures import plot_mohr_circles, plot_peaks

    lateral = np.array([250.0, 500.0, 1000.0, 2000.0])
    p, q = peaks_on_envelope(33.0, 1200.0, lateral)
    p_eff, q_eff = peaks_on_envelope(25.0, 0.0, lateral + 4000.0)
    rows = []
    for k, confining in enumerate(lateral):
        summary = {"peak_q": q[k], "p_at_peak": p[k], "peak_q_effective": q_eff[k],
                   "p_effective_at_peak": p_eff[k], "phi_peak_deg": 40.0,
                   "phi_peak_effective_deg": 25.0, "peak_reached": k != 3}
        folder = str(tmp_path / "runs" / f"confining{confining:g}")
        rows.append({"confining": confining, **peak_row(summary, folder, str(tmp_path), False)})
    config = envelope_runs({"confining": "250,500", "water_content": 1.0})[0].config
    summary = envelope_summary(rows[::-1], config)
    assert summary["phi_deg"] == pytest.approx(33.0) and summary["cohesion"] == pytest.approx(1200)
    assert summary["phi_effective_deg"] == pytest.approx(25.0)
    assert summary["cohesion_effective"] == pytest.approx(0.0, abs=1e-6)
    assert summary["cohesion_error"] == pytest.approx(0.0, abs=1e-6)     # exact points
    assert summary["suction"] is None and summary["water_content_percent"] == 1.0
    assert summary["confining"] == lateral.tolist() and summary["peak_not_reached"] == [2000.0]
    test = summary["tests"][0]
    assert test["run"] == "runs/confining250"
    assert test["sigma_3_at_peak"] == pytest.approx(250.0)
    assert test["sigma_3_effective_at_peak"] == pytest.approx(4250.0)
    assert test["sigma_1_at_peak"] - test["sigma_3_at_peak"] == pytest.approx(test["peak_q"])
    assert summary["units"]["tests"]["sigma_1_at_peak"] == "Pa"
    assert summary["units"]["phi_effective_error_deg"] == "deg"
    assert not undeclared_keys(summary, "envelope")
    for draw, name in ((plot_mohr_circles, "mohr.png"), (plot_peaks, "pq.png")):
        assert_drawn(draw(str(tmp_path / name), summary))
