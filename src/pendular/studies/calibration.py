"""Calibration: Bayesian inference of a laboratory command's parameters from a measured curve.

``Calibration(test, options, fits, curve).run(out)`` fits the options ``fits`` (Fit: an option
of the command ``test`` with its prior range) so that the command, run with ``options`` for
everything else, reproduces ``curve`` (read_curve: a CSV of the test's columns, DATA_COLUMNS).
The sampler is GrainLearning's iterative Bayesian filter (Cheng et al. 2019): sequential Monte
Carlo over the curve's control points, the next iteration's samples drawn from a Gaussian
mixture trained on the weighted ensemble. Each iteration's runs are one campaign
(pendular.studies.campaign: local processes or a Dask cluster), so an interrupted calibration
started again reuses every finished run; the samples themselves are regenerated identically
(Halton's sequence, then mixtures drawn with a fixed seed from the same runs).

Honest uncertainty:

- every curve is compared at the data's control points, each column from its least value in
  the data and in units of its range there (0 to 1 over the data: the filter's covariance,
  scaled by each column's largest value, is then ``sigma`` itself, a variance in units of that
  range squared);
- the first iteration also runs its best sample (the least error to the data) with
  SEED_REPLICATES other seeds: the scatter between samples of different seeds at equal
  parameters, where the data are (the scatter grows with the friction, so a prior's centre far
  from the data would overstate it, or understate it). The data are one sample and
  each run another, so their curves differ by twice that variance at equal parameters. Each
  column has its own (q scatters less than the volumetric strain), which weighs it in the
  likelihood (the library's observation weights), and the filter's ``sigma`` is held at or
  above it (the library's lower bound), counted once per curve, not once per point, since the
  scatter of neighbouring points is correlated: a curve fitted closer than two samples repeat
  each other gives no narrower posterior. Every run uses the same sample seed (the test's
  --seed), so the runs differ by their parameters alone; the seed noise says how far that
  sample may stand from the data's;
- the filter's weights (corrected by the density its samples were drawn from, the library's
  ``proposal``) train the next iteration's mixture; the posterior reported is the prior times
  the likelihood at the seed noise itself, not at the filter's tempered ``sigma``, from every
  iteration's samples together, each divided by the mixture of all the iterations' densities
  (Calibration.posterior, pendular.studies.calibration_posterior);
- a parameter whose posterior standard deviation is above UNCONSTRAINED_FRACTION of the
  prior's is reported ``constrained`` false: the data do not pin it.
"""

from __future__ import annotations

import csv
import json
import math
import os
import warnings
from dataclasses import dataclass
from typing import Callable

import numpy as np

from pendular.homogenize.invariants import deviator_stress, mean_stress
from pendular.io.history import read_history
from pendular.io.schema import POSTERIOR_COLUMNS, summary_units
from pendular.procedures.registry import config_from_options, options_of
from pendular.procedures.run_options import RunOptions
from pendular.studies.calibration_posterior import Proposal, mixture_density, moments
from pendular.studies.campaign import Campaign, Run
from pendular.utils.atomic import replacing, write_json
from pendular.utils.parameters import spec_of

#: Fewest points of a measured curve.
MIN_POINTS = 3
#: Runs of the first iteration's best sample at other seeds (the seed noise): with its own,
#: eight samples, whose variance is known to about half itself (a chi-squared of 7 degrees of
#: freedom).
SEED_REPLICATES = 7
#: Target effective sample size of the filter, a fraction of the samples (GrainLearning's
#: default).
ESS_TARGET = 0.3
#: Components of the Gaussian mixture the next samples are drawn from.
MIXTURE_COMPONENTS = 2
#: Seed of the mixture's draws, plus the iteration: each iteration draws fresh deviates (one
#: seed for all would give every iteration the same standard normals, its errors repeated
#: rather than averaged), and a calibration started again draws the same samples.
SAMPLING_SEED = 0
#: A posterior standard deviation above this fraction of the prior's: unconstrained.
UNCONSTRAINED_FRACTION = 0.7
#: How far above the seed noise the filter's upper bound stays (a bounded search needs room).
NOISE_MARGIN = 1e-3
#: The smallest seed noise of a column [variance, in units of its range squared]: the filter
#: needs a positive lower bound where the seeds give identical curves (a prepared --sample).
MIN_NOISE = 1e-8
#: Options --fit cannot name: the runs' outputs, which calibrate turns off, and the sample's
#: seed, which is no property of the material (the seed runs vary it).
CALIBRATE_SETS = ("vtk_every", "vtk_frames", "checkpoint_every", "seed")


# ---------------------------------------------------------------- the data

@dataclass(frozen=True)
class CurveKind:
    """The columns of a test's measured curve: its ``control`` (rising through the file), the
    ``observed`` columns (each required), ``optional`` ones; ``units`` of each; ``read``:
    the same columns of a finished run's folder along its loading branch (a dict of arrays);
    ``reach(config)``: (the option that sets how far the test goes, that value) in the
    control's units, so that a test stopping before the data's end is refused before it
    runs (ValueError for a configuration whose curve is not one); ``from_data(control)``:
    the options calibrate sets from the data's control values (a test run at each point)."""

    control: str
    observed: tuple
    units: dict
    read: Callable
    reach: Callable
    optional: tuple = ()
    from_data: Callable | None = None

    @property
    def columns(self):
        return (self.control, *self.observed, *self.optional)


def _loading_branch(columns, control):
    """``columns`` (dict of arrays) up to the maximum of the ``control`` column: the loading
    branch of a path that unloads after it."""
    end = int(np.argmax(columns[control])) + 1
    return {name: np.asarray(values, dtype=float)[:end] for name, values in columns.items()}


def _history(folder):
    return read_history(folder, index="record")


def _triaxial_curve(folder):
    history = _history(folder)
    return _loading_branch({"axial_strain": history["axial_strain"].values,
                            "q": deviator_stress(history["sigma_wall"].values),
                            "volumetric_strain": history["volumetric_strain"].values},
                           "axial_strain")


def _oedometer_curve(folder):
    history = _history(folder)
    return _loading_branch({"axial_stress": history["sigma_wall"].values[:, 2],
                            "void_ratio": history["void_ratio"].values}, "axial_stress")


def _isotropic_curve(folder):
    history = _history(folder)
    return _loading_branch({"mean_stress": mean_stress(history["sigma_wall"].values),
                            "void_ratio": history["void_ratio"].values}, "mean_stress")


def _simple_shear_curve(folder):
    history = _history(folder)
    return _loading_branch({"shear_strain": history["shear_strain"].values,
                            "shear_stress": history["shear_stress"].values}, "shear_strain")


def _swcc_curve(folder):
    with open(os.path.join(folder, "swcc.json"), encoding="utf-8") as handle:
        drying = json.load(handle)["drying"]
    return {name: np.array([row[name] for row in drying], dtype=float)
            for name in ("suction", "saturation")}


def _tension_curve(folder):
    with open(os.path.join(folder, "tension.json"), encoding="utf-8") as handle:
        cases = sorted(json.load(handle)["cases"], key=lambda case: case["water_content_target"])
    return {"water_content": np.array([case["water_content_target"] for case in cases]),
            "tensile_strength": np.array([case["tensile_strength_pa"] for case in cases])}


def _tension_reach(config):
    void_ratios = sorted({e for e, _ in config.cases})
    if len(void_ratios) > 1:
        raise ValueError(f"--void-ratio {','.join(f'{e:g}' for e in void_ratios)}: give one "
                         "void ratio, that of the measured specimens")
    return "water_content", max(w for _, w in config.cases)


#: The measured curve of each test (compression positive, SI, strains as fractions).
DATA_COLUMNS = {
    "triaxial": CurveKind("axial_strain", ("q",), {"axial_strain": "1", "q": "Pa",
                                                   "volumetric_strain": "1"},
                          _triaxial_curve, lambda c: ("max_strain", c.shear.max_strain),
                          optional=("volumetric_strain",)),
    "oedometer": CurveKind("axial_stress", ("void_ratio",),
                           {"axial_stress": "Pa", "void_ratio": "1"}, _oedometer_curve,
                           lambda c: ("axial_stress", c.axial_stress)),
    "isotropic": CurveKind("mean_stress", ("void_ratio",),
                           {"mean_stress": "Pa", "void_ratio": "1"}, _isotropic_curve,
                           lambda c: ("stresses", max(c.stresses))),
    "simple-shear": CurveKind("shear_strain", ("shear_stress",),
                              {"shear_strain": "1", "shear_stress": "Pa"}, _simple_shear_curve,
                              lambda c: ("max_strain", c.max_strain)),
    "swcc": CurveKind("suction", ("saturation",), {"suction": "Pa", "saturation": "1"},
                      _swcc_curve, lambda c: ("suctions", max(c.suctions))),
    # one specimen per water content of the data [%], at one void ratio
    "tension": CurveKind("water_content", ("tensile_strength",),
                         {"water_content": "1", "tensile_strength": "Pa"}, _tension_curve,
                         _tension_reach,
                         from_data=lambda control: {"water_content": list(100.0 * control)}),
}


@dataclass
class MeasuredCurve:
    """A measured curve: its ``path``, ``control`` values (rising) and ``observed`` {column:
    values}, in the file's units (SI)."""

    path: str
    kind: CurveKind
    control: np.ndarray
    observed: dict

    @property
    def columns(self):
        return list(self.observed)

    def scaled(self, name, values):
        """``values`` of column ``name`` from its least value in the data, in units of its
        range there (of its largest magnitude for a flat column): 0 to 1 over the data, the
        unit of the error."""
        data = self.observed[name]
        scale = float(np.ptp(data)) or float(np.max(np.abs(data))) or 1.0
        return (np.asarray(values, dtype=float) - float(np.min(data))) / scale


def _number(text, path, line, column):
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"data = {path!r}: line {line}, column {column}: {text.strip()!r} is "
                         "not a number") from None
    if not math.isfinite(value):
        raise ValueError(f"data = {path!r}: line {line}, column {column}: {text.strip()!r} is "
                         "not a finite number (NaN or infinite)")
    return value


def read_curve(path, test):
    """The MeasuredCurve of the CSV ``path`` of ``test`` (a key of DATA_COLUMNS): a header
    naming its columns, then one row per point. ValueError naming the file, the line and the
    column for unknown or missing columns, a file of another test, a value that is not a finite
    number, control values that do not rise, fewer than MIN_POINTS points."""
    path = os.fspath(path)
    kind = DATA_COLUMNS[test]
    source = f"data = {path!r}"
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            rows = [(number, row) for number, row in enumerate(csv.reader(handle), start=1)
                    if any(cell.strip() for cell in row)]
    except FileNotFoundError:
        raise ValueError(f"{source}: no such file") from None
    except (OSError, UnicodeDecodeError) as error:
        raise ValueError(f"{source}: cannot be read ({error})") from None
    expected = f"valid columns for {test}: {', '.join(kind.columns)}" + (
        f" ({', '.join(kind.optional)} optional)" if kind.optional else "")
    if not rows:
        raise ValueError(f"{source} is empty; {expected}")
    line, header = rows[0]
    names = [cell.strip() for cell in header]
    unknown = [name for name in names if name not in kind.columns]
    if unknown:
        other = [name for name, each in DATA_COLUMNS.items()
                 if name != test and set(names) <= set(each.columns)
                 and {each.control, *each.observed} <= set(names)]
        if other:
            raise ValueError(f"{source}: line {line}: columns {', '.join(names)} are a curve of "
                             f"{other[0]}, not of {test}; {expected}")
        column = names.index(unknown[0]) + 1
        raise ValueError(f"{source}: line {line}, column {column}: unknown column "
                         f"{unknown[0]!r}; {expected}")
    repeated = sorted({name for name in names if names.count(name) > 1})
    if repeated:
        raise ValueError(f"{source}: line {line}: column {repeated[0]!r} given twice")
    missing = [name for name in (kind.control, *kind.observed) if name not in names]
    if missing:
        raise ValueError(f"{source}: line {line}: column {missing[0]!r} missing; {expected}")
    values = {name: [] for name in names}
    for line, row in rows[1:]:
        if len(row) != len(names):
            raise ValueError(f"{source}: line {line}: {len(row)} values, {len(names)} columns "
                             "in the header")
        for column, (name, text) in enumerate(zip(names, row), start=1):
            values[name].append(_number(text, path, line, column))
    if len(rows) - 1 < MIN_POINTS:
        raise ValueError(f"{source}: {len(rows) - 1} points; valid: at least {MIN_POINTS}")
    control = np.array(values[kind.control])
    falling = np.flatnonzero(np.diff(control) <= 0.0)
    if len(falling):
        index = int(falling[0]) + 1
        raise ValueError(f"{source}: line {rows[index + 1][0]}, column "
                         f"{names.index(kind.control) + 1}: {kind.control} = "
                         f"{control[index]:g} does not rise above the line before's "
                         f"{control[index - 1]:g}; valid: control values rising through the "
                         "file")
    observed = {name: np.array(values[name]) for name in kind.columns[1:] if name in values}
    return MeasuredCurve(path, kind, control, observed)


def write_curve(path, folder, test, control):
    """Write the curve of the finished run ``folder`` of ``test`` as a data file read_curve
    reads: every column of DATA_COLUMNS[test] at the ``control`` values (rising, within the
    run's loading branch), interpolated along that branch as a calibration compares a run with
    the data. A synthetic curve with known parameters, for testing a calibration. ValueError
    for control values the run does not span."""
    kind = DATA_COLUMNS[test]
    columns = kind.read(os.fspath(folder))
    control = np.asarray(control, dtype=float)
    reached = columns[kind.control]
    if np.any(np.diff(control) <= 0.0) or control[0] < reached.min() \
            or control[-1] > reached.max():
        raise ValueError(f"control values {control[0]:g} ... {control[-1]:g}: valid: rising, "
                         f"within the run's {kind.control} {reached.min():g} ... "
                         f"{reached.max():g}")
    order = np.argsort(reached, kind="stable")
    values = {name: np.interp(control, reached[order], columns[name][order])
              for name in kind.columns[1:] if name in columns}
    with replacing(os.fspath(path)) as temporary, open(temporary, "w", newline="",
                                                       encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow([kind.control, *values])
        for index, point in enumerate(control):
            writer.writerow([repr(float(point)), *(repr(float(column[index]))
                                                    for column in values.values())])


# ---------------------------------------------------------------- what is fitted

@dataclass(frozen=True)
class Fit:
    """A fitted option: its ``key``, prior range [``low``, ``high``] in its ``unit``."""

    key: str
    low: float
    high: float
    unit: str
    integer: bool = False

    @property
    def name(self):
        """The option as --fit names it: friction, contact-angle."""
        return self.key.replace("_", "-")

    def value(self, sample):
        """The option's value of a sample (an integer option rounded)."""
        return int(round(sample)) if self.integer else float(sample)


def numeric_options(test):
    """{key: Option} of the options of ``test`` that --fit can name: one number each."""
    return {option.key: option for option in options_of(test)
            if option.kind in (int, float) and not option.many and not option.positional
            and option.key not in CALIBRATE_SETS}


def parse_fit(text, test):
    """The Fit of ``text`` 'NAME=LOW:HIGH' (NAME an option of ``test`` as its flag writes it,
    LOW < HIGH in its unit). ValueError naming --fit for anything else; the range itself is
    checked against the option's declaration by Calibration."""
    name, equals, bounds = text.partition("=")
    low_text, colon, high_text = bounds.partition(":")
    if not equals or not colon:
        raise ValueError(f"--fit {text!r}: NAME=LOW:HIGH expected (e.g. friction=10:50)")
    key = name.strip().removeprefix("--").replace("-", "_")
    options = numeric_options(test)
    if key not in options:
        raise ValueError(f"--fit {text!r}: {name.strip()!r} is not a numeric option of {test}; "
                         f"valid: {', '.join(k.replace('_', '-') for k in options)}")
    try:
        low, high = float(low_text), float(high_text)
    except ValueError:
        raise ValueError(f"--fit {text!r}: LOW and HIGH must be numbers") from None
    if not (math.isfinite(low) and math.isfinite(high)):
        raise ValueError(f"--fit {text!r}: LOW and HIGH must be finite numbers")
    if not low < high:
        raise ValueError(f"--fit {text!r}: the range [{low:g}, {high:g}] is empty; valid: "
                         "LOW < HIGH")
    option = options[key]
    spec = option.valid or (spec_of(*option.field) if option.field else None)
    unit = spec.unit if spec is not None else ""
    return Fit(key, low, high, unit, integer=option.kind is int)


# ---------------------------------------------------------------- the calibration

def _sample_name(iteration, index):
    return f"iter{iteration}_sample{index:03d}"


def _seed_name(seed):
    return f"iter0_seed{seed}"


class Calibration:
    """A calibration of ``fits`` of command ``test`` to ``curve``, every other option from
    ``options`` (key -> value, as config_from_options takes them); ``iterations`` of
    ``samples`` runs (module docstring). Everything is checked here, before anything runs:
    ValueError naming the option (a --fit's range against the option's declaration, with
    the fixed options), the data file."""

    def __init__(self, test, options, fits, curve, *, iterations=3, samples=12):
        if test not in DATA_COLUMNS:
            raise ValueError(f"--test {test}: calibrate compares curves of "
                             f"{', '.join(DATA_COLUMNS)}")
        if not fits:
            raise ValueError("--fit: give at least one NAME=LOW:HIGH")
        self.test, self.curve = test, curve
        self.fits = list(fits)
        keys = [fit.key for fit in self.fits]
        repeated = sorted({key for key in keys if keys.count(key) > 1})
        if repeated:
            raise ValueError(f"--fit {repeated[0].replace('_', '-')} given twice")
        self.options = {key: value for key, value in options.items() if value is not None}
        for key in self.options:
            if key in keys:
                raise ValueError(f"--{key.replace('_', '-')}: fitted (--fit), so it cannot be "
                                 "fixed too")
        from_data = curve.kind.from_data(curve.control) if curve.kind.from_data else {}
        for key in from_data:
            if key in self.options or key in keys:
                raise ValueError(f"--{key.replace('_', '-')}: set by calibrate from the data's "
                                 f"{curve.kind.control} column; leave it out")
        self.options.update(from_data)
        # no ParaView frames nor checkpoints in the runs (where the test writes them)
        declared = {option.key for option in options_of(test)}
        self.options.update({key: 0 for key in ("vtk_every", "checkpoint_every")
                             if key in declared})
        self.iterations = int(iterations)
        self.samples = int(samples)
        if self.iterations < 1:
            raise ValueError(f"--iterations {iterations}: valid range [1, inf)")
        if self.samples < 2 * len(self.fits) + 2:
            raise ValueError(f"--samples {samples}: valid range [{2 * len(self.fits) + 2}, inf) "
                             f"for {len(self.fits)} fitted parameter(s)")
        fixed = self.config({})         # the fixed options' errors name them alone
        for fit in self.fits:           # the prior's ends are configurations the test takes
            for end in (fit.low, fit.high):
                try:
                    self.config({fit.key: fit.value(end)})
                except ValueError as error:
                    text = error.on_command_line() if hasattr(error, "on_command_line") else error
                    raise ValueError(f"--fit {fit.name}={fit.low:g}:{fit.high:g}: {text}") \
                        from None
        try:        # each iteration is a campaign: one of the configurations a Run takes
            Run(_sample_name(0, 0), fixed)
        except TypeError as error:
            raise ValueError(f"--test {test}: a campaign cannot run it ({error})") from None
        self.check_reach()

    def config(self, values):
        """The configuration of the test at fitted ``values`` {key: value}."""
        return config_from_options(self.test, {**self.options, **values})

    def check_reach(self):
        """ValueError when the test stops before the data's last control point (at the
        prior's ends too, where a fitted option sets how far it goes)."""
        last = float(self.curve.control[-1])
        for values in ({}, *({fit.key: fit.value(end)} for fit in self.fits
                             for end in (fit.low, fit.high))):
            key, reach = self.curve.kind.reach(self.config(values))
            if reach < last * (1.0 - 1e-9):
                raise ValueError(f"--{key.replace('_', '-')} {reach:g} is below the data's "
                                 f"last {self.curve.kind.control} {last:g} "
                                 f"({self.curve.path}): the test must reach it")

    def sample_values(self, sample):
        return {fit.key: fit.value(value) for fit, value in zip(self.fits, sample)}

    # ------------------------------------------------------------ simulated curves

    def simulated(self, folder):
        """The run's curve at the data's control points: (columns, points), each column
        scaled as the data's (MeasuredCurve.scaled), or None when its history does not span
        them (a path starting above the data's first stress, stopping before its last)."""
        columns = self.curve.kind.read(folder)
        control = columns[self.curve.kind.control]
        span = np.ptp(self.curve.control)
        if (control.min() > self.curve.control[0] + 1e-9 * span
                or control.max() < self.curve.control[-1] - 1e-9 * span):
            return None
        order = np.argsort(control, kind="stable")
        return np.array([self.curve.scaled(name, np.interp(self.curve.control, control[order],
                                                           columns[name][order]))
                         for name in self.curve.columns])

    def observed(self):
        """The data's columns (columns, points), each 0 to 1 over its range
        (MeasuredCurve.scaled)."""
        return np.array([self.curve.scaled(name, self.curve.observed[name])
                         for name in self.curve.columns])

    # ------------------------------------------------------------ the loop

    def run(self, out, options=None, *, log=print, **settings):
        """Run the calibration into ``out`` (its runs in ``out``/runs/, each iteration a
        Campaign.run as the RunOptions ``options`` say, ``settings`` its fields one by one:
        local processes or a Dask cluster, threads, device); the result dict of
        summary.json. ``out`` is held by the caller (an OutputFolder)."""
        from grainlearning import GaussianMixtureModel, IterativeBayesianFilter

        options = RunOptions.of(options, **settings)
        observed = self.observed()
        system = self.system(self.samples)
        sampling = GaussianMixtureModel(max_num_components=MIXTURE_COMPONENTS,
                                        random_state=SAMPLING_SEED)
        ibf = IterativeBayesianFilter(self.filter(), sampling)
        ibf.initialize(system)
        low, high = [fit.low for fit in self.fits], [fit.high for fit in self.fits]
        proposals = [Proposal.uniform(low, high)]   # each iteration's, a Halton design first
        rows, history, noise, simulated_all, drawn = [], [], None, [], []
        for iteration in range(self.iterations):
            # an integer option's samples run, and are weighed, at their rounded values
            samples = np.array([[fit.value(v) for fit, v in zip(self.fits, sample)]
                                for sample in ibf.param_data_list[-1]], dtype=float)
            runs = [Run(_sample_name(iteration, index), self.config(self.sample_values(sample)))
                    for index, sample in enumerate(samples)]
            log(f"iteration {iteration + 1} of {self.iterations}: {len(runs)} runs")
            curves = self.campaign_curves(runs, out, log, options)
            kept = [i for i in range(len(samples)) if _sample_name(iteration, i) in curves]
            if len(kept) < 2:
                raise ValueError(f"iteration {iteration + 1}: fewer than two of its runs "
                                 "finished (their errors are in their log.txt)")
            simulated = np.array([curves[_sample_name(iteration, i)] for i in kept])
            errors = np.sqrt(np.mean((simulated - observed[None]) ** 2, axis=(1, 2)))
            if iteration == 0:
                best = kept[int(np.argmin(errors))]
                seeds = self.seed_runs(self.sample_values(samples[best]))
                log(f"seed noise: {len(seeds)} runs of {_sample_name(0, best)} at other seeds")
                replicates = self.campaign_curves(seeds, out, log, options)
                noise = self.seed_noise([curves[_sample_name(0, best)],
                                         *(replicates[run.name] for run in seeds
                                           if run.name in replicates)])
                system.inv_obs_weight = list(noise)
                system.compute_inv_normalized_sigma()
            system.param_data = samples[kept]
            system.num_samples = len(kept)
            system.set_sim_data(simulated)
            system.sigma_lower_bound = system.sigma_tol = _noise_sigma(noise)
            # the library anneals its upper bound from one iteration to the next: never
            # below the seed noise
            system.sigma_max = max(float(np.atleast_1d(system.sigma_max)[0]),
                                   _noise_sigma(noise) * (1.0 + NOISE_MARGIN))
            if iteration > 0:                   # the first's: a uniform design
                density = proposals[iteration].density(samples[kept])
                ibf.proposal = density / density.sum()
            sampling.random_state = SAMPLING_SEED + iteration      # the next one's draws
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                ibf.solve(system)
            if iteration + 1 < self.iterations:       # the density the next one draws from
                proposals.append(Proposal.of_sampling(sampling, low, high))
            drawn.append(len(samples))
            simulated_all.append(simulated)
            weights = np.asarray(ibf.posterior, dtype=float)
            for index, error in zip(kept, errors):
                rows.append({"iteration": iteration, "sample": index,
                             "run": _sample_name(iteration, index),
                             **self.sample_values(samples[index]), "error": float(error)})
            history.append({"iteration": iteration, "runs": len(kept),
                            "sigma": float(np.atleast_1d(system.sigma_max)[0]),
                            "best_error": float(errors.min()),
                            "weighted_error": float(np.dot(weights, errors))})
            log(f"iteration {iteration + 1}: best error {errors.min():.3g}, the filter's "
                + ", ".join(f"{fit.name} {m:.4g} ± {s:.2g}" for fit, (m, s) in
                            zip(self.fits, moments(samples[kept], weights))))
        pooled = self.posterior(self.row_samples(rows), np.concatenate(simulated_all), noise,
                                proposals, drawn)
        for row, weight in zip(rows, pooled):
            row["weight"] = float(weight)
        return self.summary(rows, history, noise)

    def system(self, num_samples, noise=None):
        """GrainLearning's DynamicSystem of the data for ``num_samples`` samples, each column
        weighed by its seed ``noise`` where given (seed_noise)."""
        from grainlearning import DynamicSystem

        return DynamicSystem(obs_data=self.observed(), ctrl_data=self.curve.control,
                             num_samples=num_samples,
                             param_min=[fit.low for fit in self.fits],
                             param_max=[fit.high for fit in self.fits],
                             param_names=[fit.key for fit in self.fits],
                             obs_names=self.curve.columns,
                             inv_obs_weight=None if noise is None else list(noise))

    @staticmethod
    def filter():
        """GrainLearning's sequential Monte Carlo filter, its covariance scaled by each
        column's largest value: ``sigma`` in units of the data's range squared."""
        from grainlearning import SMC

        return SMC(ess_target=ESS_TARGET, scale_cov_with_max=True)

    def row_samples(self, rows):
        """The fitted values of ``rows`` (one row each, the fits' order)."""
        return np.array([[row[fit.key] for fit in self.fits] for row in rows], dtype=float)

    def posterior(self, samples, simulated, noise, proposals, drawn):
        """The posterior weights of every iteration's ``samples`` (their ``simulated`` curves)
        together: GrainLearning's likelihood at the seed ``noise`` (each column's), divided by
        the mixture of the iterations' ``proposals`` (calibration_posterior), each weighed by
        the samples it ``drawn``."""
        system = self.system(len(samples), noise)
        system.param_data = samples
        system.set_sim_data(simulated)
        density = mixture_density(proposals, drawn, samples)
        inference = self.filter()
        inference.data_assimilation_loop(_noise_sigma(noise), system, density / density.sum())
        return np.asarray(inference.get_posterior_at_time(-1), dtype=float)

    def campaign_curves(self, runs, out, log, options):
        """{run name: its curve (simulated)} of ``runs`` run as one campaign into ``out`` as
        the RunOptions ``options`` say (Campaign.run), without figures of their own (the
        calibration draws its own); a run that failed or whose history does not span the data
        is left out, and said so through ``log``."""
        result = Campaign(runs).run(out, RunOptions.of(options, plots=False))
        curves = {}
        for run in runs:
            if run.name not in result.summaries:
                log(f"run {run.name} left out: {result.failed.get(run.name)}")
                continue
            curve = self.simulated(os.path.join(out, "runs", run.name))
            if curve is None:
                log(f"run {run.name} left out: its history does not span the data's "
                    f"{self.curve.kind.control}")
            else:
                curves[run.name] = curve
        return curves

    def seed_runs(self, values):
        """Runs of the fitted ``values`` {key: value} at SEED_REPLICATES seeds after the
        test's own."""
        base = _seed_of(self.config(values))
        return [Run(_seed_name(offset), self.config({**values, "seed": base + offset}))
                for offset in range(1, SEED_REPLICATES + 1)]

    def seed_noise(self, curves):
        """Each column's least uncertainty (an array, the data's columns): the variance of the
        difference between two samples' curves (twice the variance between the seeds'
        curves: the data are one sample, a run another), in units of the column's range
        squared, averaged over the points and counted once per curve (times the points:
        neighbouring points scatter together)."""
        if len(curves) < 2:
            return np.full(len(self.curve.columns), MIN_NOISE)
        spread = 2.0 * np.var(np.array(curves), axis=0, ddof=1)
        return np.maximum(np.mean(spread, axis=-1) * spread.shape[-1], MIN_NOISE)

    def summary(self, rows, history, noise):
        best = min(rows, key=lambda row: row["error"])
        parameters = {}
        weights = np.array([row["weight"] for row in rows])
        for fit, (mean, std) in zip(self.fits, moments(self.row_samples(rows), weights)):
            prior_std = (fit.high - fit.low) / math.sqrt(12.0)
            parameters[fit.name] = {"mean": float(mean), "std": float(std),
                                    "best": best[fit.key], "unit": fit.unit,
                                    "low": fit.low, "high": fit.high,
                                    "prior_std": prior_std,
                                    "constrained": bool(std <= UNCONSTRAINED_FRACTION
                                                        * prior_std)}
        return {"test": self.test, "data": os.path.abspath(self.curve.path),
                "columns": self.curve.columns, "parameters": parameters,
                "best_run": os.path.join("runs", best["run"]), "best_error": best["error"],
                "seed_noise": dict(zip(self.curve.columns, map(float, noise))),
                "iterations": history,
                "runs": len(rows) + SEED_REPLICATES, "rows": rows}


def _noise_sigma(noise):
    """The filter's ``sigma`` at which each column's variance is its seed ``noise``: their
    geometric mean (the library scales the columns' weights to a unit determinant)."""
    return float(np.exp(np.mean(np.log(noise))))


def _seed_of(config):
    """The sample seed of a configuration (its preparation's)."""
    sample = getattr(config, "sample", None)
    return int(getattr(sample, "seed", 0))


def write_posterior(path, rows, fits):
    """posterior.csv: one row per sample of every iteration: iteration, sample, run, the fitted
    options, weight, error (their units: summary.json's ``units["posterior"]``)."""
    columns = ["iteration", "sample", "run", *(fit.key for fit in fits), "weight", "error"]
    with replacing(path) as temporary, open(temporary, "w", newline="",
                                            encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=columns)
        writer.writeheader()
        writer.writerows({key: row[key] for key in columns} for row in rows)


def write_summary(path, summary, fits):
    """summary.json: the summary without its rows (posterior.csv holds them), with the units
    of its keys and of posterior.csv's columns (``units["posterior"]``)."""
    data = {key: value for key, value in summary.items() if key != "rows"}
    data["units"] = {**summary_units("calibrate"),
                     "posterior": {**{name: column.units
                                      for name, column in POSTERIOR_COLUMNS.items()},
                                   **{fit.key: fit.unit for fit in fits}}}
    write_json(path, data)
    return data
