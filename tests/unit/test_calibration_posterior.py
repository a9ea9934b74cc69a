"""The posterior a calibration reports (pendular.studies.calibration_posterior and
Calibration.posterior): the proposal densities, and every iteration's samples weighed together
against a posterior known in closed form."""

import numpy as np
import pytest

from conftest import requires

from pendular.studies.calibration import Calibration, parse_fit, read_curve
from pendular.studies.calibration_posterior import Proposal, mixture_density, moments

TRIAXIAL = "axial_strain,q,volumetric_strain\n0.01,300,0.001\n0.02,450,-0.001\n0.04,500,-0.004\n"


def gaussian(mean, std, low, high, offset=0.0, scale=1.0):
    """N(``mean``, ``std``) in the coordinates (x - ``offset``) / ``scale``, truncated to
    [``low``, ``high``]."""
    return Proposal.of_mixture([1.0], [[mean]], [[[std ** 2]]], [offset], [scale], [low],
                               [high])


def test_a_uniform_design_has_the_prior_boxs_density():
    proposal = Proposal.uniform([5.0, 0.0], [40.0, 2.0])
    density = proposal.density([[10.0, 1.0], [40.0, 2.0], [41.0, 1.0]])
    assert density == pytest.approx([1.0 / 70.0, 1.0 / 70.0, 0.0])


def test_a_truncated_gaussian_proposal_integrates_to_one_over_the_box():
    # N(30, 6) in its coordinates (x - 10) / 20, truncated to [5, 40]: its mass inside is
    # that of the standard normal between -25/6 and 10/6
    from math import erf, sqrt
    proposal = gaussian(1.0, 0.3, 5.0, 40.0, offset=10.0, scale=20.0)
    inside = 0.5 * (erf(10.0 / 6.0 / sqrt(2.0)) - erf(-25.0 / 6.0 / sqrt(2.0)))
    assert proposal.inside == pytest.approx(inside, abs=0.005)
    x = np.linspace(5.0, 40.0, 7001)
    assert np.trapezoid(proposal.density(x[:, None]), x) == pytest.approx(1.0, abs=0.005)
    assert proposal.density([[4.9]]) == pytest.approx([0.0])


@requires("grainlearning")
def test_grainlearnings_trained_mixture_is_measured_with_its_truncation():
    from grainlearning import DynamicSystem, GaussianMixtureModel

    system = DynamicSystem(obs_data=np.zeros((1, 3)), ctrl_data=np.arange(3.0), num_samples=12,
                           param_min=[5.0], param_max=[40.0], param_names=["friction"],
                           obs_names=["q"])
    system.param_data = np.linspace(5.0, 40.0, 12)[:, None]
    weights = np.exp(-0.5 * ((system.param_data[:, 0] - 8.0) / 4.0) ** 2)
    sampling = GaussianMixtureModel(max_num_components=2, random_state=0)
    sampling.train(weights / weights.sum(), system)
    proposal = Proposal.of_sampling(sampling, [5.0], [40.0])
    assert proposal.inside < 0.95                       # its mass below 5 is cut off
    x = np.linspace(5.0, 40.0, 7001)
    assert np.trapezoid(proposal.density(x[:, None]), x) == pytest.approx(1.0, abs=0.01)


def test_the_mixture_weighs_each_proposal_by_its_samples():
    uniform = Proposal.uniform([0.0], [10.0])
    narrow = gaussian(0.5, 0.1, 0.0, 10.0, scale=10.0)
    at = np.array([[5.0], [9.0]])
    expected = (12 * uniform.density(at) + 24 * narrow.density(at)) / 36
    assert mixture_density([uniform, narrow], [12, 24], at) == pytest.approx(expected)


def test_weighted_moments():
    samples = np.array([[1.0, 10.0], [3.0, 10.0]])
    (mean_a, std_a), (mean_b, std_b) = moments(samples, np.array([0.5, 0.5]))
    assert (mean_a, std_a, mean_b, std_b) == pytest.approx((2.0, 1.0, 10.0, 0.0))


@requires("grainlearning")
def test_every_iterations_samples_together_give_the_likelihoods_posterior(tmp_path):
    """A curve linear in the friction, so that the likelihood at the seed noise (q's ten
    times the volumetric strain's) is a Gaussian of the friction: N(20, 3) well inside the
    prior [5, 40]. A uniform design of 12 samples,
    then 24 from a proposal narrower than the posterior and off its centre, N(23, 1.5) (whose
    own importance weights let its few tail samples set the spread): together, weighed by the
    mixture of both densities, they give the posterior's mean and standard deviation."""
    path = tmp_path / "curve.csv"
    path.write_text(TRIAXIAL)
    calibration = Calibration("triaxial", {"particles": 60, "max_strain": 0.05},
                              [parse_fit("friction=5:40", "triaxial")],
                              read_curve(path, "triaxial"))
    observed = calibration.observed()                   # 2 columns, 3 points
    noise, std, truth = np.array([0.1, 1.0]), 3.0, 20.0
    # each column's log-likelihood -3 slope^2 (f - 20)^2 / (2 noise): together std 3
    slope = 1.0 / (std * np.sqrt(3.0 * np.sum(1.0 / noise)))
    design = np.linspace(5.0, 40.0, 12)
    rng = np.random.default_rng(1)
    narrow = 23.0 + 1.5 * rng.standard_normal(24)
    samples = np.concatenate([design, narrow])[:, None]
    simulated = observed[None] + slope * (samples[:, :, None] - truth)
    proposals = [Proposal.uniform([5.0], [40.0]), gaussian(23.0, 1.5, 5.0, 40.0)]
    weights = calibration.posterior(samples, simulated, noise, proposals, [12, 24])
    assert weights.sum() == pytest.approx(1.0)
    [(mean, spread)] = moments(samples, weights)
    assert mean == pytest.approx(truth, abs=0.5)
    assert spread == pytest.approx(std, rel=0.1)
