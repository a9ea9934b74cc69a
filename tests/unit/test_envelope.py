"""Mohr–Coulomb fit against envelopes built by hand from Mohr circles."""

import numpy as np
import pytest

from pendular.studies.envelope import mohr_coulomb_fit


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
