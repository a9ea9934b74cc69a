"""The posterior a calibration reports: every iteration's samples weighed together.

GrainLearning's iterative Bayesian filter draws each iteration's samples from another density
(the first a Halton design over the prior box, each next one a Gaussian mixture trained on the
weighted ensemble before it) and, to keep its effective sample size, tempers the likelihood
with an uncertainty ``sigma`` above the seed noise. Its weights serve the next proposal; the
posterior reported is the likelihood's at the seed noise itself, prior times likelihood,
estimated from all the samples together by multiple importance sampling with the
deterministic-mixture (balance heuristic) weights: each sample's likelihood divided by the
mixture of every iteration's proposal density, each in proportion to its samples (Veach and
Guibas 1995; Owen and Zhou 2000). The uniform first design in that mixture bounds the weight
of a sample in a later proposal's tail (a defensive mixture, Hesterberg 1995), where one
iteration's own importance weights let a few such samples set the standard deviation.

Densities are per unit of each fitted option's own unit (the prior box's volume: 1 / its
product of ranges for the uniform design).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.stats import multivariate_normal

#: Draws of a Gaussian mixture that measure its mass inside the prior box (its truncation).
TRUNCATION_DRAWS = 100_000


@dataclass(frozen=True)
class Proposal:
    """The density one iteration's samples were drawn from, on the prior box [``low``,
    ``high``] (arrays, one entry per fitted option): uniform when ``weights`` is None, else a
    Gaussian mixture (``weights`` (k,), ``means`` (k, d), ``covariances`` (k, d, d)) in the
    coordinates (x - ``offset``) / ``scale``, truncated to the box, ``inside`` its mass there."""

    low: np.ndarray
    high: np.ndarray
    weights: np.ndarray | None = None
    means: np.ndarray | None = None
    covariances: np.ndarray | None = None
    offset: np.ndarray | None = None
    scale: np.ndarray | None = None
    inside: float = 1.0

    @classmethod
    def uniform(cls, low, high):
        return cls(np.asarray(low, dtype=float), np.asarray(high, dtype=float))

    @classmethod
    def of_mixture(cls, weights, means, covariances, offset, scale, low, high):
        """The mixture truncated to the box, its mass there measured by TRUNCATION_DRAWS
        draws of a fixed seed."""
        proposal = cls(np.asarray(low, dtype=float), np.asarray(high, dtype=float),
                       np.asarray(weights, dtype=float), np.atleast_2d(means),
                       np.asarray(covariances, dtype=float), np.asarray(offset, dtype=float),
                       np.asarray(scale, dtype=float))
        rng = np.random.default_rng(0)
        counts = rng.multinomial(TRUNCATION_DRAWS, proposal.weights / proposal.weights.sum())
        points = np.concatenate([rng.multivariate_normal(mean, covariance, count)
                                 for mean, covariance, count
                                 in zip(proposal.means, proposal.covariances, counts)])
        points = points * proposal.scale + proposal.offset
        inside = np.mean(np.all((points > proposal.low) & (points < proposal.high), axis=1))
        return replace(proposal, inside=max(float(inside), 1.0 / TRUNCATION_DRAWS))

    @classmethod
    def of_sampling(cls, sampling, low, high):
        """The proposal of GrainLearning's GaussianMixtureModel ``sampling`` as trained now:
        its scikit-learn mixture draws (``sample``: each component's weight, mean and
        covariance) in coordinates normalised by the trained samples' least and largest
        values, and the draws outside the box are dropped. (The mixture's ``score_samples``
        is a variational estimate, not this density.)"""
        mixture = sampling.gmm
        offset = np.asarray(sampling.min_params, dtype=float)
        scale = np.asarray(sampling.max_params, dtype=float) - offset
        return cls.of_mixture(mixture.weights_, mixture.means_,
                              _component_covariances(mixture), offset, scale, low, high)

    def density(self, samples):
        """The density at each row of ``samples`` (0 outside the box)."""
        samples = np.atleast_2d(np.asarray(samples, dtype=float))
        within = np.all((samples >= self.low) & (samples <= self.high), axis=1)
        if self.weights is None:
            value = np.full(len(samples), 1.0 / np.prod(self.high - self.low))
        else:
            points = (samples - self.offset) / self.scale
            value = sum(weight * multivariate_normal.pdf(points, mean, covariance)
                        for weight, mean, covariance
                        in zip(self.weights / self.weights.sum(), self.means, self.covariances))
            value = np.reshape(value, len(samples)) / (np.prod(self.scale) * self.inside)
        return np.where(within, value, 0.0)


def _component_covariances(mixture):
    """Each component's covariance matrix (k, d, d) of a scikit-learn mixture, whatever its
    ``covariance_type``."""
    count, dimension = np.shape(mixture.means_)
    covariances = np.asarray(mixture.covariances_, dtype=float)
    if mixture.covariance_type == "full":
        return covariances
    if mixture.covariance_type == "tied":
        return np.repeat(covariances[None], count, axis=0)
    if mixture.covariance_type == "diag":
        return np.array([np.diag(variances) for variances in covariances])
    return np.array([variance * np.eye(dimension) for variance in covariances])


def mixture_density(proposals, counts, samples):
    """The density the pooled ``samples`` were drawn from: the mixture of ``proposals``, each
    weighed by its ``counts`` of samples (the deterministic mixture)."""
    counts = np.asarray(counts, dtype=float)
    return sum(count * proposal.density(samples)
               for proposal, count in zip(proposals, counts)) / counts.sum()


def moments(samples, weights):
    """[(mean, standard deviation)] of each column of ``samples`` under ``weights`` (summing
    to 1)."""
    samples = np.asarray(samples, dtype=float)
    mean = weights @ samples
    std = np.sqrt(weights @ (samples - mean) ** 2)
    return list(zip(mean, std))
