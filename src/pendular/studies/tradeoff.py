"""Speed against accuracy: one knob at a time, measured against a slow, fine reference run.

``write_study(Study(out, particles=..., max_strain=..., quick=...))`` (the study's runs and
outputs: pendular.studies.tradeoff_report); command
``pendular tradeoff --out DIR [--particles N] [--max-strain X] [--quick] [--docs FOLDER]``.

The reference test is a wet drained triaxial (30 kPa suction, 750 Pa lateral stress, thesis
Table 5.2 otherwise) of ``particles`` spheres to ``max_strain`` (the peak lies near 4 %). Every
run is a pendular.procedures.triaxial.TriaxialTest of a configuration built from the default one
(``Study.default``: the defaults of ``pendular triaxial``, exact bridge table 350 x 80)
with ``dataclasses.replace``; it starts from the same prepared sample (DIR/samples/, the
sample-size knob prepares one per size), runs on one Numba thread, and is compared with the
reference: the P-wave rule at time-step safety 0.35, inertial number 1e-4, bridge table
700 x 160 nodes, the other knobs at their defaults. Each knob (``KNOB_FIELDS``: the field of
the configuration it sets) is varied alone around the defaults:

    timestep_safety, timestep_rule (P-wave estimate / critical step of the contacts, at the
    default safety), inertial_number, damping, particles, table_resolution (exact bridges),
    bridges (exact / toroidal), records (history rows), skin_factor (neighbour list)

For each run: wall_time_s and cpu_time_s (sample equilibration, wetting and shear, and
writing the run's history and summary; the sample's preparation excluded, and no figures are
drawn), its particle-steps per second, and the relative errors of peak
q, of Sr at the peak of q and of q'/p' at the peak of q (Eq. 3.43) against the reference;
``error`` is the largest of the three. The noise floor: the reference settings run on
NOISE_SEEDS other samples (seeds seed + 1, ...), whose errors against the reference are the
scatter between samples that a knob's error is read against.

Writes DIR/tradeoff.json (``arguments``, ``suction``, ``confining``, ``reference``, ``rows``:
knob, value, settings, particles, wall_time_s, cpu_time_s, steps, wetting_steps,
particle_steps_per_s, peak_q, saturation_at_peak, stress_ratio_at_peak, axial_strain_at_peak,
peak_q_error, saturation_error, stress_ratio_error, error; ``noise``: the same for each other
seed, with ``seed`` for knob and value; ``noise_floor``: their largest errors),
DIR/tradeoff.md with a recommendation per use (quick look, paper figure) and DIR/tradeoff.png;
``docs`` copies the three there (docs/tradeoff.*). Each run lives in DIR/runs/<name>/ with its
timing.json (the result and the run's configuration); run again, a study reuses a finished
run only when its stored configuration equals the wanted one (pendular.procedures.config.config_json).

One sample cannot tell a knob's systematic effect from the chaos of a granular run (any change
of the step makes another trajectory, a few per cent apart at the peak). ``SeedStudy`` (command
``pendular tradeoff --out DIR --knob K [--seeds 6] [--jobs J]``) runs the reference and every
setting of one knob on several samples and reads each setting against the same sample's
reference (``seed_rows``); ``write_seed_study`` (pendular.studies.tradeoff_report) writes
DIR/seeds_K.json and DIR/seeds_K.md.
"""

from __future__ import annotations

import dataclasses
import json
import os
import time
from dataclasses import dataclass

import numpy as np

from pendular.utils.atomic import write_json
from pendular.dem.cloud import MAX_SEED
from pendular.procedures.preparation import PrepareConfig
from pendular.dem.sample import load_sample
from pendular.utils.parameters import (Option, OptionError, default_of, fail, option_field,
    option_of, parameter, validate)
from pendular.utils.validate import check_int

from pendular.procedures.config import sample_made_with
from pendular.studies.campaign import check_jobs, executor, prepare_one
from pendular.procedures.config import (MAX_AXIAL_STRAIN, BridgeConfig, ShearConfig,
    config_json, config_to_dict)
from pendular.procedures.triaxial import TriaxialConfig
from pendular.procedures.triaxial import TriaxialTest

SUCTION = 30000.0
CONFINING = 750.0
#: The exact bridge table of the default run (nodes in suction, in distance).
DEFAULT_TABLE = (350, 80)
#: What the slow, fine reference changes in the default run.
REFERENCE = {"timestep_rule": "pwave", "timestep_safety": 0.35, "inertial_number": 1e-4,
             "table_resolution": (700, 160)}
#: Settings of each knob (particles: multiples of the study's particles).
KNOBS = {"timestep_safety": [0.3, 0.5, 0.7, 0.9],
         "timestep_rule": ["pwave", "stiffness"],
         "inertial_number": [1e-4, 3e-4, 1e-3, 3e-3],
         "damping": [0.05, 0.1, 0.2, 0.4],
         "particles": [0.25, 0.5, 1.0, 2.0],
         "table_resolution": [(50, 20), (100, 40), (350, 80), (700, 160)],
         "bridges": ["exact", "toroidal"],
         "records": [50, 500, 2000],
         "skin_factor": [0.1, 0.3, 0.6, 1.0]}
#: Knob -> (part of the TriaxialConfig, field of that part) it sets, found by the option that
#: names the field (e.g. 'bridges' -> ('bridges', 'model')).
KNOB_FIELDS = {knob: option_field(knob, {"sample": PrepareConfig, "shear": ShearConfig,
                                         "bridges": BridgeConfig}) for knob in KNOBS}
QUICK_KNOBS = {"timestep_safety": [0.5, 0.7, 0.9], "inertial_number": [3e-4, 1e-3, 3e-3],
               "table_resolution": [(50, 20), (100, 40), (350, 80)]}
#: Error bounds of the recommendations.
PAPER_ERROR, QUICK_ERROR = 0.02, 0.10
#: CPU times within this factor of each other count as equal in the recommendations.
TIME_TIE = 1.05
#: The uses recommended for, and their error bounds.
USES = {"paper figure": PAPER_ERROR, "quick look": QUICK_ERROR}
#: Smallest sample of the study (the particles knob included).
MIN_PARTICLES = 50
#: Samples beside the reference's (seeds seed + 1 ...) run at the reference settings: their
#: scatter is the noise floor a knob's error is read against.
NOISE_SEEDS = 2


# ---------------------------------------------------------------- knobs on configurations

def setting(config, knob):
    """The value of ``knob`` in the TriaxialConfig ``config``."""
    part, name = KNOB_FIELDS[knob]
    return getattr(getattr(config, part), name)


def with_setting(config, knob, value):
    """``config`` with ``knob`` set to ``value`` (dataclasses.replace; validated)."""
    part, name = KNOB_FIELDS[knob]
    return dataclasses.replace(
        config, **{part: dataclasses.replace(getattr(config, part), **{name: value})})


def settings(config):
    """The knobs' values of ``config`` (the sample size aside), as JSON values."""
    return json.loads(json.dumps({knob: setting(config, knob) for knob in KNOB_FIELDS
                                  if knob != "particles"}))


def text(value):
    """A knob's value as shown: (350, 80) -> '350,80', 0.0001 -> '0.0001'."""
    if isinstance(value, (tuple, list)):
        return ",".join(str(v) for v in value)
    return str(value)


@dataclass
class Study:
    """The study's inputs: output folder ``out``, ``particles`` of the reference sample
    (>= 50), ``max_strain`` in (0, 0.5], the samples' ``seed``; ``quick``: three knobs, three
    settings each (QUICK_KNOBS, a smoke test). Each field but ``out`` declares its option
    (OPTIONS)."""

    out: str
    particles: int = parameter(2000, kind=int, low=MIN_PARTICLES, flag="--particles",
                               help="spheres of the reference sample")
    max_strain: float = parameter(0.15, low=0.0, high=MAX_AXIAL_STRAIN, low_inclusive=False,
                                  flag="--max-strain", help="final axial strain")
    seed: int = parameter(0, kind=int, low=0, high=MAX_SEED - NOISE_SEEDS, flag="--seed",
                          help="random seed of the samples")
    quick: bool = parameter(False, kind=bool, flag="--quick",
                            help="three knobs, three settings each (a smoke test)")

    def __post_init__(self):
        validate(self)
        if not str(self.out).strip():
            raise ValueError(f"out = {self.out!r} is empty: give a folder name")

    def knobs(self):
        return QUICK_KNOBS if self.quick else KNOBS

    def sample(self, particles, seed=None):
        """The PrepareConfig of the prepared sample of ``particles`` spheres (every run of that
        size starts from it; ``seed``: another sample's, for the noise floor)."""
        return PrepareConfig(particles=particles, confining=CONFINING,
                             seed=self.seed if seed is None else seed)

    def default(self):
        """The knobs' centre: ``pendular triaxial``'s defaults, wet at SUCTION, from the saved
        sample of ``particles`` spheres in ``out``/samples, no ParaView output."""
        return TriaxialConfig(sample=self.sample(self.particles),
                              shear=ShearConfig(max_strain=self.max_strain),
                              bridges=BridgeConfig(SUCTION, table_resolution=DEFAULT_TABLE),
                              sample_path=sample_file(self.out, self.particles, self.seed),
                              vtk_every=0)

    def reference(self):
        """The slow, fine reference (REFERENCE applied to the default)."""
        config = self.default()
        for knob, value in REFERENCE.items():
            config = with_setting(config, knob, value)
        return config

    def reference_on(self, seed):
        """The reference settings on the sample of another ``seed``."""
        config = self.reference()
        return dataclasses.replace(
            config, sample=dataclasses.replace(config.sample, seed=seed),
            sample_path=sample_file(self.out, self.particles, seed))

    def variant(self, knob, value):
        """(configuration, value shown) of ``knob`` at ``value`` around the default; the
        particles knob takes a multiple of ``particles`` and its own sample."""
        config = self.default()
        if knob != "particles":
            return with_setting(config, knob, value), value
        count = max(MIN_PARTICLES, int(round(value * self.particles)))
        config = with_setting(config, "particles", count)
        return (dataclasses.replace(config, sample_path=sample_file(self.out, count, self.seed)),
                count)


def sample_file(out, particles, seed, setting=""):
    """The saved sample of ``particles`` spheres and ``seed`` in ``out``/samples (``setting``:
    the name of the knob setting it was prepared with, setting_name; "" for the default's)."""
    tail = f"_{setting}" if setting else ""
    return os.path.join(os.path.abspath(out), "samples", f"n{particles}_seed{seed}{tail}.h5")


def setting_name(knob, value):
    """A knob's setting as a file or folder name: 'table_resolution=350x80'."""
    return f"{knob}={text(value)}".replace(",", "x")


# ---------------------------------------------------------------- runs

def run_variant(config, folder, sample):
    """One wet triaxial of ``config`` in ``folder`` (TriaxialTest on one thread), its sample
    ``sample`` (PrepareConfig, saved at config.sample_path) prepared first when missing: its
    summary values with the measured times. A finished run whose timing.json holds an equal
    configuration is reused."""
    timing = os.path.join(folder, "timing.json")
    done = _read_json(timing)
    if done is not None and json.dumps(done.get("config"), sort_keys=True) == config_json(config):
        return {k: v for k, v in done.items() if k != "config"}
    if not sample_made_with(config.sample_path, sample):
        os.makedirs(os.path.dirname(config.sample_path), exist_ok=True)
        prepare_one(sample, config.sample_path)
    test = TriaxialTest(config)           # checks, and builds the bridge tables untimed
    wall, cpu = time.perf_counter(), time.process_time()
    summary = test.run(folder, progress=False, threads=1, plots=False)   # physics only
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    result = {"settings": settings(config), "particles": config.sample.particles,
              "wall_time_s": wall, "cpu_time_s": cpu, "steps": summary["steps"],
              "wetting_steps": summary.get("wetting_steps", 0),
              "particle_steps_per_s": summary["particle_steps_per_s"],
              "peak_q": summary["peak_q"], "saturation_at_peak": summary["saturation_at_peak"],
              "stress_ratio_at_peak": (summary["peak_q_effective"]
                                       / summary["p_effective_at_peak"]),
              "axial_strain_at_peak": summary["axial_strain_at_peak"]}
    write_json(timing, {**result, "config": config_to_dict(config)})
    return result


def _read_json(path):
    try:
        with open(path) as handle:
            return json.load(handle)
    except (OSError, ValueError):
        return None


def errors(result, reference):
    """Relative errors of one run against the reference; ``error`` is the largest."""
    values = {f"{key}_error": abs(result[field] - reference[field]) / abs(reference[field])
              for key, field in (("peak_q", "peak_q"), ("saturation", "saturation_at_peak"),
                                 ("stress_ratio", "stress_ratio_at_peak"))}
    values["error"] = max(values.values())
    return values


def measure(study, log=None):
    """(reference result, rows, noise rows) of the Study ``study``: the reference on other
    samples, every knob's runs and, per use, the run combining each knob's recommended setting
    (module docstring). ``log(text)`` hears of each run."""
    log = log or (lambda message: None)
    default = study.default()

    def run(name, config):
        return run_variant(config, os.path.join(study.out, "runs", name),
                           study.sample(config.sample.particles, config.sample.seed))

    reference = run("reference", study.reference())
    noise = []
    for seed in range(study.seed + 1, study.seed + 1 + NOISE_SEEDS):
        log(f"reference settings, seed {seed} (noise floor)")
        result = run(f"reference_seed{seed}", study.reference_on(seed))
        noise.append({"seed": seed, **result, **errors(result, reference)})
    rows = []
    for knob, values in study.knobs().items():
        for value in values:
            config, value = study.variant(knob, value)
            name = "default" if config == default else setting_name(knob, value)
            log(f"{knob} = {text(value)}")
            result = run(name, config)
            rows.append({"knob": knob, "value": value, **result, **errors(result, reference)})
    for use, bound in USES.items():
        config = default
        for knob, row in recommendation(rows, bound).items():
            if knob != "particles":
                config = with_setting(config, knob, row["value"])
        log(f"combined settings for a {use}: {settings(config)}")
        result = run(f"combined_{use.replace(' ', '_')}", config)
        rows.append({"knob": "combined", "value": use, **result, **errors(result, reference)})
    return reference, rows, noise


def noise_floor(noise):
    """The largest of each relative error over the noise rows (other samples, reference
    settings): the sample-to-sample scatter."""
    return {key: max(r[key] for r in noise)
            for key in ("peak_q_error", "saturation_error", "stress_ratio_error", "error")}


def recommendation(rows, bound):
    """Per knob (the combined rows aside), the cheapest setting whose error is within ``bound``;
    settings within TIME_TIE of the cheapest CPU time count as equally cheap, and the one with
    the smallest error among them is taken."""
    chosen = {}
    for knob in dict.fromkeys(r["knob"] for r in rows if r["knob"] != "combined"):
        within = [r for r in rows if r["knob"] == knob and r["error"] <= bound]
        if within:
            cheapest = min(r["cpu_time_s"] for r in within)
            chosen[knob] = min((r for r in within if r["cpu_time_s"] <= TIME_TIE * cheapest),
                               key=lambda r: r["error"])
    return chosen


# ---------------------------------------------------------------- one knob across samples

#: Knobs that also set how a sample is prepared: the seed study runs each of their values on
#: samples prepared with it too (the whole chain that value gives).
PREPARATION_KNOBS = ("timestep_safety", "timestep_rule", "damping")
#: The quantities compared, (result field, label).
QUANTITIES = (("peak_q", "peak q"), ("saturation_at_peak", "Sr at peak"),
              ("stress_ratio_at_peak", "q'/p' at peak"))


#: The knobs a seed study takes (the sample size is not one: each size is a sample of its own).
SEED_KNOBS = tuple(knob for knob in KNOBS if knob != "particles")


@dataclass
class SeedStudy:
    """``knob`` across ``seeds`` samples (seeds seed ... seed + seeds - 1) of ``particles``
    spheres, which the one-sample Study cannot tell from chaos: on each sample the reference
    and every setting of the knob (KNOBS), each compared with the same sample's reference
    (paired: the knob's effect without the scatter between samples); the references'
    scatter across samples; and, for a knob of the preparation (PREPARATION_KNOBS), each
    setting also on samples prepared with it. ``jobs`` runs at a time, one thread each.
    ``knob`` and ``seeds`` declare their options (OPTIONS); the sample's settings are the
    one-sample Study's."""

    out: str
    knob: str = parameter(kind=str, choices=SEED_KNOBS, flag="--knob",
                          help="study this knob across --seeds samples instead")
    seeds: int = parameter(6, kind=int, low=2, high=100, flag="--seeds",
                           help="samples of the --knob study (seeds SEED ... SEED + SEEDS - 1)")
    particles: int = default_of(Study, "particles")
    max_strain: float = default_of(Study, "max_strain")
    seed: int = default_of(Study, "seed")
    jobs: int = 1

    def __post_init__(self):
        validate(self)
        self.jobs = check_jobs(self.jobs)
        Study(self.out, self.particles, self.max_strain, self.seed)   # checks the rest
        try:                                    # the last sample's seed within MAX_SEED
            self.seed = check_int("seed", self.seed, high=MAX_SEED - self.seeds + 1)
        except ValueError as error:
            raise fail(Study, "seed", str(error)) from None

    def study(self, seed):
        """The one-sample Study of the sample of ``seed`` (its default, reference, variants)."""
        return Study(self.out, self.particles, self.max_strain, seed)

    def runs(self):
        """(name, configuration, PrepareConfig of its sample) of every run: per seed the
        reference, each setting on the default sample and, for a knob of the preparation,
        each setting other than the default's on a sample prepared with it."""
        runs = []
        for seed in range(self.seed, self.seed + self.seeds):
            study = self.study(seed)
            default = study.default()
            runs.append((f"seed{seed}_reference", study.reference(),
                         study.sample(self.particles, seed)))
            for value in KNOBS[self.knob]:
                config, _ = study.variant(self.knob, value)
                name = f"seed{seed}_{setting_name(self.knob, value)}"
                runs.append((name, config, study.sample(self.particles, seed)))
                if self.knob in PREPARATION_KNOBS and value != setting(default, self.knob):
                    path = sample_file(self.out, self.particles, seed,
                                       setting_name(self.knob, value))
                    runs.append((f"{name}_prepared", dataclasses.replace(config, sample_path=path),
                                 config.sample))
        return runs


#: Runs at a time of a seed study (pendular.studies.campaign.check_jobs).
JOBS = Option("jobs", "runs at a time in the --knob study (one thread each)", default=1,
              kind=int)
#: The options of ``pendular tradeoff`` (its output folder apart): the one-sample Study's,
#: the folder its report is also copied into, and a SeedStudy's.
OPTIONS = (option_of(Study, "particles"), option_of(Study, "max_strain"),
           option_of(Study, "seed"), option_of(Study, "quick"),
           Option("docs", "also copy tradeoff.json/.md/.png into FOLDER", kind=str,
                  metavar="FOLDER"),
           option_of(SeedStudy, "knob", default=None), option_of(SeedStudy, "seeds", unset=True),
           JOBS)


def study_of(out, values):
    """The Study in ``out`` of ``values`` of OPTIONS (pendular.utils.parameters.option_values)
    or, with a ``knob``, the SeedStudy; OptionError naming the options that belong to the
    other one."""
    sample = {key: values[key] for key in ("particles", "max_strain", "seed")}
    if values["knob"] is not None:
        if values["quick"] or values["docs"]:
            raise OptionError(lambda name: f"{name('knob')} studies one knob across samples: "
                                           f"{name('quick')} and {name('docs')} belong to the "
                                           "one-sample study")
        seeds = default_of(SeedStudy, "seeds") if values["seeds"] is None else values["seeds"]
        return SeedStudy(out=out, knob=values["knob"], seeds=seeds, jobs=values["jobs"],
                         **sample)
    if values["seeds"] is not None or values["jobs"] != JOBS.default:
        raise OptionError(lambda name: f"{name('seeds')} and {name('jobs')} belong to a "
                                       f"{name('knob')} study: give {name('knob')}")
    return Study(out=out, quick=values["quick"], **sample)


def _run_named(name, config, sample, out):
    return name, run_variant(config, os.path.join(out, "runs", name), sample)


def _prepare_missing(path, sample):
    if not sample_made_with(path, sample):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        prepare_one(sample, path)
    return path


def run_seed_study(study, log=None):
    """Every run of the SeedStudy ``study`` (its samples prepared first, as many at a time as
    its jobs): {name: result}, each result with its sample's porosity and coordination."""
    log = log or (lambda message: None)
    runs = study.runs()
    samples = {config.sample_path: sample for _, config, sample in runs}
    results = {}
    with executor(study.jobs) as pool:
        submit = (lambda f, *a: pool.submit(f, *a)) if pool else _now
        for future in [submit(_prepare_missing, p, s) for p, s in samples.items()]:
            log(f"sample {os.path.basename(_result(future))}")
        for future in [submit(_run_named, name, config, sample, study.out)
                       for name, config, sample in runs]:
            name, result = _result(future)
            log(f"{name}: peak q {result['peak_q']:.1f} Pa")
            results[name] = result
    for name, config, _ in runs:
        report = load_sample(config.sample_path)[2]
        results[name].update(porosity=report["porosity"], coordination=report["coordination"])
    return results


def _now(function, *arguments):
    """The submit of running here, one after the other: the value itself (see _result)."""
    return function(*arguments)


def _result(future):
    """The value of a pool's future, or of _now's."""
    return future.result() if hasattr(future, "result") else future


def _stats(values):
    return {"mean": float(np.mean(values)), "sd": float(np.std(values, ddof=1)),
            "largest": float(np.max(np.abs(values)))}


def seed_rows(study, results):
    """(rows, scatter): per setting (and setting on samples prepared with it), over the
    samples: CPU time, steps, the samples' porosity and coordination and, per quantity,
    ``paired`` (on the default samples): the statistics (_stats) of its relative error against
    the same sample's reference, and ``against_references``: of its relative difference from
    the references' mean. ``scatter``: the references' mean and relative standard deviation
    across samples, per quantity. ``within_scatter``: every quantity's mean error (paired, or
    against the references for a setting's own samples) within that standard deviation."""
    seeds = range(study.seed, study.seed + study.seeds)
    reference = [results[f"seed{s}_reference"] for s in seeds]
    scatter = {}
    for field, _ in QUANTITIES:
        values = [r[field] for r in reference]
        scatter[field] = {"mean": float(np.mean(values)),
                          "relative_sd": float(np.std(values, ddof=1) / abs(np.mean(values)))}
    rows = []
    for value in KNOBS[study.knob]:
        for prepared in (False, True):
            suffix = setting_name(study.knob, value) + ("_prepared" * prepared)
            own = [results.get(f"seed{s}_{suffix}") for s in seeds]
            if None in own:
                continue
            row = {"value": value, "prepared_with_it": prepared,
                   "cpu_time_s": float(np.mean([r["cpu_time_s"] for r in own])),
                   "steps": float(np.mean([r["steps"] + r["wetting_steps"] for r in own])),
                   "porosity": float(np.mean([r["porosity"] for r in own])),
                   "coordination": float(np.mean([r["coordination"] for r in own]))}
            for field, _ in QUANTITIES:
                row[field] = {"against_references": _stats(
                    [r[field] / scatter[field]["mean"] - 1.0 for r in own])}
                if not prepared:
                    row[field]["paired"] = _stats(
                        [r[field] / ref[field] - 1.0 for r, ref in zip(own, reference)])
            measure = "against_references" if prepared else "paired"
            row["within_scatter"] = all(abs(row[f][measure]["mean"]) <= scatter[f]["relative_sd"]
                                        for f, _ in QUANTITIES)
            rows.append(row)
    return rows, scatter
