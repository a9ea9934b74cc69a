"""Particle-size distributions of samples: radii from a grading, and the grading of radii.

A grading is either a relative spread S (radii uniform in R(1 ± S)) or a grading curve as from
a sieve analysis: ((diameter [m], percent passing by mass), ...), diameters increasing, from
0 % passing at the smallest size present to 100 % at the largest. Between two sieves the curve
is taken linear in log(diameter) (mass spread evenly over log d), so the number of grains per
log d falls as d^-3 there.

Radii are drawn by stratified sampling: the quantiles (i + 1/2) / N of the number distribution,
shuffled with the seed. A sample of N spheres then follows its distribution as closely as N
spheres can (no sampling noise in the grading), and its mass-based curve matches the input
within what its few largest grains resolve.

The radius ratio of a sample, largest / smallest, is at most MAX_RADIUS_RATIO: the bridge
tables cover pairs up to that ratio (capillary, YADE's capillary files).
"""

import csv
import os

import numpy as np

from pendular.utils.validate import check_range

#: Largest radius ratio of a sample (the capillary tables' range, YADE's M(r=10)).
MAX_RADIUS_RATIO = 10.0
#: Largest relative spread S: (1 + S) / (1 - S) = MAX_RADIUS_RATIO.
MAX_RADIUS_SPREAD = (MAX_RADIUS_RATIO - 1.0) / (MAX_RADIUS_RATIO + 1.0)


def check_grading_curve(curve, name="psd"):
    """The grading curve ``curve`` as a tuple of (diameter [m], percent passing) float pairs,
    after checking it (ValueError naming ``name``): at least two points, diameters positive and
    increasing, passing non-decreasing from 0 % to 100 %, largest / smallest diameter at most
    MAX_RADIUS_RATIO."""
    try:
        points = tuple((float(d), float(p)) for d, p in curve)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {curve!r} is not a list of (diameter [m], percent passing) "
                         "pairs") from None
    if len(points) < 2:
        raise ValueError(f"{name} has {len(points)} points, outside the valid range [2, inf): "
                         "a grading curve needs at least the smallest and the largest size")
    diameter = np.array([d for d, _ in points])
    passing = np.array([p for _, p in points])
    if not (np.all(np.isfinite(diameter)) and np.all(np.isfinite(passing))):
        raise ValueError(f"{name} holds values that are not finite: {points}")
    if diameter[0] <= 0.0 or np.any(np.diff(diameter) <= 0.0):
        raise ValueError(f"{name} diameters {diameter.tolist()} m must be positive and "
                         "strictly increasing")
    if np.any(np.diff(passing) < 0.0):
        raise ValueError(f"{name} percent passing {passing.tolist()} must not decrease with "
                         "the diameter")
    if passing[0] != 0.0 or passing[-1] != 100.0:
        raise ValueError(f"{name} percent passing runs from {passing[0]:g} to {passing[-1]:g}; "
                         "valid: from 0 (the smallest size present) to 100 (the largest)")
    ratio = diameter[-1] / diameter[0]
    if ratio > MAX_RADIUS_RATIO:
        raise ValueError(f"{name} spans diameters {diameter[0]:g} to {diameter[-1]:g} m, a "
                         f"ratio of {ratio:.3g}, outside the valid range [1, "
                         f"{MAX_RADIUS_RATIO:g}] (the bridge tables' radius ratios)")
    return points


def read_grading_curve(path):
    """The grading curve in the CSV file ``path``: rows of two values, diameter [m] and
    percent passing by mass (a header row first, blank and '#' lines and empty trailing cells
    are skipped). ValueError naming the path and the row (its line in the file) of a value
    that is not a number, or of a third value (which the curve would otherwise drop)."""
    path = os.fspath(path)
    try:
        with open(path, newline="") as handle:
            reader = csv.reader(handle)
            rows = [(reader.line_num, row) for row in reader
                    if row and row[0].strip() and not row[0].lstrip().startswith("#")]
    except (OSError, UnicodeDecodeError, csv.Error) as error:
        raise ValueError(f"psd file {path!r} cannot be read: "
                         f"{getattr(error, 'strerror', None) or error}") from None
    points = []
    for number, (line, row) in enumerate(rows):
        while len(row) > 2 and not row[-1].strip():
            row = row[:-1]
        try:
            point = (float(row[0]), float(row[1]))
        except (ValueError, IndexError):
            if number == 0:
                continue                     # a header
            raise ValueError(f"psd file {path!r}: row {line} {row!r} is not "
                             "'diameter [m], percent passing'") from None
        if len(row) > 2:
            raise ValueError(f"psd file {path!r}: row {line} {row!r} has {len(row)} values; "
                             "valid: 2, 'diameter [m], percent passing'")
        points.append(point)
    return check_grading_curve(points, name=f"psd file {path!r}")


def _number_quantiles(curve, quantiles):
    """Diameters [m] at the number-based ``quantiles`` of the grading curve (module docstring:
    per interval, mass even in log d, grain count per log d as d^-3)."""
    diameter = np.array([d for d, _ in curve])
    mass = np.diff([p for _, p in curve]) / 100.0
    inverse_cube = diameter ** -3.0
    # grains per interval: mass / (mean grain volume), the d^-3 law integrated over log d
    count = mass * (inverse_cube[:-1] - inverse_cube[1:]) / (3.0 * np.log(diameter[1:]
                                                                         / diameter[:-1]))
    cumulative = np.concatenate(([0.0], np.cumsum(count / count.sum())))
    interval = np.clip(np.searchsorted(cumulative, quantiles, side="right") - 1, 0,
                       len(mass) - 1)
    within = (quantiles - cumulative[interval]) / (cumulative[interval + 1]
                                                   - cumulative[interval])
    return (inverse_cube[interval] - within * (inverse_cube[interval]
                                               - inverse_cube[interval + 1])) ** (-1.0 / 3.0)


def sample_radii(count, radius, spread=0.0, curve=None, seed=0):
    """``count`` radii [m] in random order (``seed``): equal to ``radius`` (spread 0, no
    curve); uniform in radius (1 ± spread) with mean ``radius``; or the grading ``curve``
    (its own sizes; ``radius`` unused)."""
    if curve is None and spread == 0.0:
        return np.full(count, radius)
    quantiles = (np.arange(count) + 0.5) / count
    if curve is not None:
        radii = 0.5 * _number_quantiles(curve, quantiles)
    else:
        radii = radius * (1.0 + spread * (2.0 * quantiles - 1.0))
    return radii[np.random.RandomState(seed).permutation(count)]


def passing(radii, diameters):
    """Percent passing by mass [%] of spheres of ``radii`` [m] at sieve ``diameters`` [m]:
    the mass of the spheres of diameter <= d over the total."""
    diameter = 2.0 * np.sort(np.asarray(radii, dtype=np.float64))
    cumulative = np.cumsum(diameter ** 3)
    index = np.searchsorted(diameter, np.asarray(diameters, dtype=np.float64), side="right")
    return 100.0 * np.where(index > 0, cumulative[np.maximum(index - 1, 0)], 0.0) \
        / cumulative[-1]


def size_at_passing(radii, percent):
    """Diameter [m] at which ``percent`` of the mass passes (D10 at 10 ...): the mass-based
    curve through the mid-mass of each sphere, interpolated linearly."""
    percent = check_range("percent", percent, 0.0, 100.0)
    diameter = 2.0 * np.sort(np.asarray(radii, dtype=np.float64))
    mass = diameter ** 3
    middle = 100.0 * (np.cumsum(mass) - 0.5 * mass) / mass.sum()
    return float(np.interp(percent, middle, diameter))


def grading(radii):
    """The grading of a sample [m and -]: mass-based D10, D30, D50, D60, uniformity
    Cu = D60 / D10, curvature Cc = D30^2 / (D10 D60), and the radius range and mean."""
    radii = np.asarray(radii, dtype=np.float64)
    d10, d30, d50, d60 = (size_at_passing(radii, p) for p in (10.0, 30.0, 50.0, 60.0))
    return {"D10": d10, "D30": d30, "D50": d50, "D60": d60, "Cu": d60 / d10,
            "Cc": d30 * d30 / (d10 * d60), "radius_min": float(radii.min()),
            "radius_max": float(radii.max()), "radius_mean": float(radii.mean())}


#: Units of the entries of ``grading``.
GRADING_UNITS = {"D10": "m", "D30": "m", "D50": "m", "D60": "m", "Cu": "1", "Cc": "1",
                 "radius_min": "m", "radius_max": "m", "radius_mean": "m"}


def check_spread(spread):
    """``spread`` as float in [0, MAX_RADIUS_SPREAD] (ValueError naming radius_spread)."""
    return check_range("radius_spread", spread, 0.0, MAX_RADIUS_SPREAD)
