"""Thesis Chapter 5 campaign: drained triaxial tests at every (suction, confining stress).

``Chapter5Campaign(Chapter5Grid(...)).run(out, options)`` (options: a
pendular.procedures.run_options.RunOptions, or its fields one by one: ``jobs=...``,
``scheduler=...``); command ``pendular chapter5`` (its default grid is the table
pendular/campaigns/chapter5.toml).

One sample is prepared per confining stress (pendular.procedures.preparation.prepare_sample: radius growth to
5 kPa, then unloaded to the test value, the same seed for all) and saved as
DIR/samples/c{confining}.h5. Every (suction, confining) test (dry when the suction is 0) then
starts from its sample (TriaxialConfig.sample_path) in DIR/runs/s{suction}_c{confining}/, with
the outputs of pendular.procedures.triaxial (history.h5, summary.json, plots, vtk, sample.h5, log.txt with
the run's progress bar). Preparations and tests run through pendular.studies.campaign: --jobs parallel
processes, or the Dask cluster of --scheduler (its workers must see the same file system and
should run one thread each: ``dask worker ADDRESS --nthreads 1``), one Numba thread per run
(--threads). Run again with the same DIR, a campaign reuses its samples and the runs that
finished with an equal configuration (an interrupted campaign goes on where it stopped); a run
that fails does not stop the others, and the campaign then ends naming it.

DIR/campaign.json: ``runs`` (suction, confining, peak_axial_stress, peak_q, p_at_peak,
saturation_at_peak, peak_q_effective, p_effective_at_peak, peak_q_effective_complete,
p_effective_complete_at_peak; a dry run's effective values are its net ones) and ``envelopes``
keyed by suction (str), each {phi_deg, cohesion} fitted to (p, q) at peak, {phi_eff_deg,
cohesion_eff} to (p', q') at peak (Eq. 3.43) and {phi_eff_complete_deg, cohesion_eff_complete}
to those of the complete effective stress (psi plus the liquid-gas interface term,
pendular.homogenize.on_the_fly), each also fitted through the origin (cohesion 0: phi_c0_deg,
phi_eff_c0_deg, phi_eff_complete_c0_deg; an effective stress that takes the capillary
cohesion in leaves none) (pendular.studies.envelope), where a suction has at least two confining
stresses. DIR/report.md compares with thesis Table 5.3 and
Fig. 5.5. DIR/plots/ (chapter5_figures): envelopes.png (Figs. 5.4, 5.6), q_ev.png (5.3),
q_p_effective.png (5.7), polar_psi.png (5.5), polar_fabric.png, anisotropy.png (5.8).
DIR/campaign.csv: one row per run, its options and its whole summary (pendular.studies.campaign).
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass

import h5py
import numpy as np

from pendular.utils.atomic import write_json, write_text
from pendular.procedures.preparation import PrepareConfig

from pendular.studies.campaign import Campaign, Run, read_table, write_campaign_csv
from pendular.studies.chapter5_figures import campaign_figures
from pendular.procedures.config import BridgeConfig, MIN_SAMPLE_PARTICLES, ShearConfig
from pendular.procedures.triaxial import TriaxialConfig
from pendular.procedures.options import SUCTION
from pendular.utils.parameters import option_from, option_of, spec_of
from pendular.studies.envelope import mohr_coulomb_fit
from pendular.io.outputs import OutputFolder
from pendular.procedures.reference import DRY_FRICTION_DEG, FIG_5_5, TABLE_5_3
from pendular.procedures.run_options import RunOptions

#: Strain at which Sr is also reported (Fig. 5.5's horizontal axis ends there).
LATE_STRAIN = 0.20
#: What a campaign owns in its folder (pendular.io.outputs); its samples/ and runs/ are kept and
#: reused by the next campaign there.
OUTPUTS = ("campaign.json", "campaign.csv", "report.md", "plots")
#: The Chapter 5 grid shipped with pendular (a campaign table).
TABLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "campaigns", "chapter5.toml")
#: The grid's suctions and confining stresses [Pa]: lists of the fields they set, each value in
#: that field's range (a confining stress above 0).
SUCTIONS = dataclasses.replace(SUCTION, flag="--suctions", many=True)
CONFINING = dataclasses.replace(spec_of(PrepareConfig, "confining"), low_inclusive=False,
                                many=True)


@dataclass
class Chapter5Grid:
    """The campaign's grid: suctions and confining stresses [Pa] (every combination) and the
    settings shared by every run (thesis Table 5.2 otherwise)."""

    suctions: list[float]
    confining: list[float]
    particles: int = 10000
    seed: int = 0
    max_strain: float = 0.25
    inertial_number: float = 3e-4
    prep_friction: float = 0.5

    def __post_init__(self):
        for name, spec in (("suctions", SUCTIONS), ("confining", CONFINING)):
            values = spec.check(name, getattr(self, name))
            if not values:
                raise ValueError(f"--{name}: at least one value expected")
            if len(set(values)) != len(values):
                raise ValueError("--suctions and --confining must not repeat a value")
            setattr(self, name, values)

    @classmethod
    def from_table(cls, path: str = TABLE, **overrides) -> Chapter5Grid:
        """The grid of a campaign table (``command = "triaxial"``, [sweep] suction and
        confining lists, [fixed] particles, seed, max_strain, inertial_number, prep_friction),
        with ``overrides`` (keyword arguments of Chapter5Grid; None values ignored). ValueError
        naming the table and any other key."""
        table = read_table(path)
        fixed, sweep = table.get("fixed", {}), table.get("sweep", {})
        settings = ("particles", "seed", "max_strain", "inertial_number", "prep_friction")
        unknown = ([f"command = {table['command']!r}"] if table.get("command", "triaxial")
                   != "triaxial" else [])
        unknown += [k for k in table if k not in ("command", "fixed", "sweep")]
        unknown += [f"fixed.{k}" for k in fixed if k not in settings]
        unknown += [f"sweep.{k}" for k in sweep if k not in ("suction", "confining")]
        if unknown:
            raise ValueError(f"table = {os.fspath(path)!r}: a Chapter 5 grid has no "
                             f"{', '.join(unknown)} (valid: [sweep] suction, confining; [fixed] "
                             f"{', '.join(settings)})")
        values = {"suctions": sweep.get("suction"), "confining": sweep.get("confining"),
                  **{k: fixed[k] for k in settings if k in fixed}}
        values.update({k: v for k, v in overrides.items() if v is not None})
        for name in ("suctions", "confining"):
            if values[name] is None:
                raise ValueError(f"table = {os.fspath(path)!r}: no {name} (give [sweep] "
                                 f"{name.rstrip('s')} = [...] or --{name})")
        return cls(**values)

    def sample(self, confining: float) -> PrepareConfig:
        """The PrepareConfig of the sample at ``confining`` [Pa]."""
        return PrepareConfig(particles=self.particles, confining=confining, seed=self.seed,
                             prep_friction_deg=self.prep_friction)

    def run(self, suction: float, confining: float, out: str) -> TriaxialConfig:
        """The TriaxialConfig of one cell, starting from its sample."""
        return TriaxialConfig(
            sample=self.sample(confining),
            shear=ShearConfig(max_strain=self.max_strain, inertial_number=self.inertial_number),
            bridges=BridgeConfig(suction) if suction > 0 else None,
            sample_path=sample_path(out, confining))


def grid_options(path: str = TABLE) -> tuple:
    """The options of a Chapter 5 campaign (``pendular chapter5``; how it runs apart): the
    settings of the grid of the table ``path``, each from the field it sets (its unit and
    range), None when not given: the table's value then, stated in its help."""
    table = Chapter5Grid.from_table(path)

    def listed(values):
        return ",".join(f"{value:g}" for value in values)

    suctions = dataclasses.replace(SUCTIONS, help="matric suctions, comma-separated, 0: dry "
                                                  f"(table: {listed(table.suctions)})")
    confining = dataclasses.replace(
        CONFINING, help=f"lateral stresses, comma-separated (table: {listed(table.confining)})")
    return (option_of(PrepareConfig, "particles", default=None, low=MIN_SAMPLE_PARTICLES,
                      help=f"number of spheres (table: {table.particles})"),
            option_from(suctions, None, aliases=("--suction",)),
            option_from(confining, None),
            option_of(PrepareConfig, "seed", default=None,
                      help=f"random seed of every sample (table: {table.seed})"),
            option_of(ShearConfig, "max_strain", default=None,
                      help=f"final axial strain (table: {table.max_strain:g})"),
            option_of(ShearConfig, "inertial_number", default=None,
                      help="target inertial number setting the strain rate (table: "
                           f"{table.inertial_number:g})"),
            option_of(PrepareConfig, "prep_friction_deg", default=None,
                      help=f"contact friction during the radius growth (table: "
                           f"{table.prep_friction:g}; higher gives looser samples)"))


def grid_from_options(values: dict, path: str = TABLE) -> Chapter5Grid:
    """The Chapter5Grid of the table ``path`` with ``values`` of grid_options
    (pendular.utils.parameters.option_values) given (not None) instead of its own."""
    return Chapter5Grid.from_table(path, **values)


def label(value):
    """A stress as it appears in folder names and JSON keys: 30000.0 -> '30000'."""
    return str(int(value)) if float(value).is_integer() else repr(float(value))


def sample_path(out, confining):
    return os.path.join(out, "samples", f"c{label(confining)}.h5")


def run_folder(out, suction, confining):
    return os.path.join(out, "runs", f"s{label(suction)}_c{label(confining)}")


def check_history(folder):
    """ValueError naming ``folder``/history.h5 when it is missing or cannot be read (a run
    reused with a damaged history), with the remedy."""
    path = os.path.join(folder, "history.h5")
    remedy = f"delete the run folder {folder} to run it again"
    if not os.path.isfile(path):
        raise ValueError(f"history = {path!r}: no such file: {remedy}")
    try:
        with h5py.File(path, "r") as handle:
            history = handle["history"]
            for name in history:
                history[name][()]
    except (OSError, KeyError, TypeError, ValueError) as error:
        raise ValueError(f"history = {path!r} is not a readable pendular history ({error}): "
                         f"{remedy}") from None


def saturation_at(folder, strain):
    """Sr of a wet run's history at the record nearest ``strain`` (None when dry or when the
    run ended more than 1 % short of it)."""
    with h5py.File(os.path.join(folder, "history.h5"), "r") as handle:
        history = handle["history"]
        if "saturation" not in history:
            return None
        axial = history["axial_strain"][:]
        if axial.max() < strain - 0.01:
            return None
        return float(history["saturation"][int(np.argmin(np.abs(axial - strain)))])


def envelopes(runs):
    """Mohr–Coulomb fits by suction (module docstring); a failed fit gives None and the error."""
    fits = {}
    for suction in sorted({r["suction"] for r in runs}):
        rows = sorted((r for r in runs if r["suction"] == suction), key=lambda r: r["confining"])
        if len({r["confining"] for r in rows}) < 2:
            continue
        fit = {}
        for names, keys in ((("phi_deg", "cohesion", "phi_c0_deg"), ("p_at_peak", "peak_q")),
                            (("phi_eff_deg", "cohesion_eff", "phi_eff_c0_deg"),
                             ("p_effective_at_peak", "peak_q_effective")),
                            (("phi_eff_complete_deg", "cohesion_eff_complete",
                              "phi_eff_complete_c0_deg"),
                             ("p_effective_complete_at_peak", "peak_q_effective_complete"))):
            p, q = [r[keys[0]] for r in rows], [r[keys[1]] for r in rows]
            try:
                values = mohr_coulomb_fit(p, q)
                values = (*values, mohr_coulomb_fit(p, q, through_origin=True)[0])
            except ValueError as error:
                values = (None, None, None)
                fit.setdefault("errors", []).append(f"{names[0]}: {error}")
            fit.update(zip(names, values))
        fits[label(suction)] = fit
    return fits


def secant_angle(p, q):
    """Friction angle [deg] of one peak's line through the origin; None where undefined."""
    try:
        return mohr_coulomb_fit([p], [q], through_origin=True)[0]
    except ValueError:
        return None


def _fmt(value, spec=".0f", scale=1.0):
    return "" if value is None else format(value * scale, spec)


def write_report(path, runs, fits, args, figures, out):
    """DIR/report.md: every Table 5.3 cell and Sr beside the thesis's, the envelopes, the runs
    and the ``figures`` ({name: path}, linked relative to ``out``)."""
    rows = {(r["suction"], r["confining"]): r for r in runs}
    suctions = sorted({r["suction"] for r in runs} | {s for s, _ in TABLE_5_3})
    confining = sorted({r["confining"] for r in runs} | {c for _, c in TABLE_5_3})
    lines = [f"# Chapter 5 campaign: {args.particles} spheres, seed {args.seed}, "
             f"max strain {args.max_strain}, inertial number {args.inertial_number}", "",
             "## Axial stress at peak (Table 5.3)", "",
             "| suction [Pa] | confining [Pa] | ours [Pa] | thesis [Pa] | difference |",
             "|---:|---:|---:|---:|---:|"]
    for suction in suctions:
        for lateral in confining:
            ours = rows.get((suction, lateral))
            thesis = TABLE_5_3.get((suction, lateral))
            if ours is None and thesis is None:
                continue
            value = None if ours is None else ours["peak_axial_stress"]
            difference = ("" if value is None or thesis is None
                          else f"{100 * (value - thesis) / thesis:+.1f} %")
            lines.append(f"| {label(suction)} | {label(lateral)} | {_fmt(value)} | "
                         f"{'' if thesis is None else thesis} | {difference} |")
    lines += ["", "## Degree of saturation (Fig. 5.5)", "",
              f"| suction [Pa] | confining [Pa] | Sr at peak [%] | Sr at {LATE_STRAIN:.0%} strain "
              "[%] | thesis Fig. 5.5 [%] |", "|---:|---:|---:|---:|---:|"]
    for r in runs:
        if r["suction"] == 0:
            continue
        thesis = FIG_5_5.get(r["suction"])
        lines.append(f"| {label(r['suction'])} | {label(r['confining'])} | "
                     f"{_fmt(r['saturation_at_peak'], '.3f', 100)} | "
                     f"{_fmt(r['saturation_at_20_percent'], '.3f', 100)} | "
                     f"{_fmt(thesis, '.2f', 100)} |")
    lines += ["", "## Failure envelopes (Mohr–Coulomb in p–q)", "",
              f"Thesis: dry friction angle {DRY_FRICTION_DEG:.0f} deg; with the effective stress "
              "of Eq. 3.43 every suction should fall on the dry line (Fig. 5.6b). phi'c: the "
              "complete effective stress (psi plus the liquid-gas interface term). Offsets "
              "from the dry line: the free fits against the dry free fit; c0, the fits "
              "through the origin (cohesion 0) against the dry one.", "",
              "| suction [Pa] | phi net [deg] | c net [Pa] | phi' [deg] | c' [Pa] | "
              "phi' - phi dry [deg] | phi'c [deg] | c'c [Pa] | phi'c - phi dry [deg] | "
              "c0: phi' - phi dry [deg] | c0: phi'c - phi dry [deg] |",
              "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    dry = fits.get(label(0.0), {})

    def offset(phi, key="phi_deg"):
        return None if dry.get(key) is None or phi is None else phi - dry[key]

    for key, fit in fits.items():
        lines.append(f"| {key} | {_fmt(fit['phi_deg'], '.2f')} | {_fmt(fit['cohesion'], '.1f')} "
                     f"| {_fmt(fit['phi_eff_deg'], '.2f')} | {_fmt(fit['cohesion_eff'], '.1f')} "
                     f"| {_fmt(offset(fit['phi_eff_deg']), '+.2f')} "
                     f"| {_fmt(fit['phi_eff_complete_deg'], '.2f')} "
                     f"| {_fmt(fit['cohesion_eff_complete'], '.1f')} "
                     f"| {_fmt(offset(fit['phi_eff_complete_deg']), '+.2f')} "
                     f"| {_fmt(offset(fit['phi_eff_c0_deg'], 'phi_c0_deg'), '+.2f')} "
                     f"| {_fmt(offset(fit['phi_eff_complete_c0_deg'], 'phi_c0_deg'), '+.2f')} |")
        for error in fit.get("errors", []):
            lines.append(f"| {key} | fit failed: {error} | | | |")
    if not fits:
        lines.append("(no suction has two confining stresses)")
    lines += ["", "## Runs", "",
              "Secant angles: each peak's own line through the origin (one failure point "
              "against the dry line).", "",
              "| suction [Pa] | confining [Pa] | q peak [Pa] | p at peak [Pa] | q' peak [Pa] | "
              "p' at peak [Pa] | q'c peak [Pa] | p'c at peak [Pa] | secant phi' [deg] | "
              "secant phi'c [deg] | folder |",
              "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    for r in runs:
        secant = secant_angle(r["p_effective_at_peak"], r["peak_q_effective"])
        secant_complete = secant_angle(r["p_effective_complete_at_peak"],
                                       r["peak_q_effective_complete"])
        lines.append(f"| {label(r['suction'])} | {label(r['confining'])} | {r['peak_q']:.0f} | "
                     f"{r['p_at_peak']:.0f} | {r['peak_q_effective']:.0f} | "
                     f"{r['p_effective_at_peak']:.0f} | {r['peak_q_effective_complete']:.0f} | "
                     f"{r['p_effective_complete_at_peak']:.0f} | "
                     f"{_fmt(secant, '.2f')} | {_fmt(secant_complete, '.2f')} | "
                     f"{r['folder']} |")
    lines += ["", "## Figures", ""]
    lines += [f"![{name}]({os.path.relpath(figure, out)})" for name, figure in figures.items()]
    lines += ["", "Each run's own plots: " + ", ".join(f"{r['folder']}/plots" for r in runs)]
    write_text(path, "\n".join(lines) + "\n")


def run_row(suction, lateral, summary, folder, out):
    """The campaign.json row of one run (module docstring)."""
    wet = suction > 0
    return {"suction": suction, "confining": lateral,
            "peak_axial_stress": summary["peak_axial_stress"],
            "peak_q": summary["peak_q"], "p_at_peak": summary["p_at_peak"],
            "saturation_at_peak": summary.get("saturation_at_peak", 0.0 if not wet else None),
            "peak_q_effective": summary["peak_q_effective"] if wet else summary["peak_q"],
            "p_effective_at_peak": (summary["p_effective_at_peak"] if wet
                                    else summary["p_at_peak"]),
            "peak_q_effective_complete": (summary["peak_q_effective_complete"] if wet
                                          else summary["peak_q"]),
            "p_effective_complete_at_peak": (summary["p_effective_complete_at_peak"] if wet
                                             else summary["p_at_peak"]),
            "axial_strain_at_peak": summary["axial_strain_at_peak"],
            "saturation_at_20_percent": saturation_at(folder, LATE_STRAIN) if wet else None,
            "folder": os.path.relpath(folder, out)}


@dataclass(frozen=True)
class Chapter5Campaign:
    """The Chapter 5 campaign of ``grid`` (Chapter5Grid), run as every command runs:
    ``run(out, options) -> summary``."""

    grid: Chapter5Grid

    def run(self, out: str, options: RunOptions | None = None, **settings) -> dict:
        """Run the campaign into ``out`` as ``options`` say (RunOptions; ``settings``: its
        fields one by one): ``jobs`` local processes or the Dask cluster at ``scheduler``,
        ``threads`` Numba threads per run (None: 1), on ``device``, progress bars unless
        ``progress`` is False (Campaign.run); writes campaign.json, campaign.csv, report.md
        and plots/ (module docstring); returns the campaign.json content with ``reused``,
        the number of finished runs reused. ValueError naming the runs that failed (the
        others are kept and reused when started again)."""
        options = RunOptions.of(options, **settings)
        grid, given_out = self.grid, out
        out = os.path.abspath(out)          # workers elsewhere see the same paths
        tests = [(s, c) for s in grid.suctions for c in grid.confining]
        runs = [Run(os.path.basename(run_folder(out, s, c)), grid.run(s, c, out))
                for s, c in tests]
        samples = [(grid.sample(c), sample_path(out, c)) for c in grid.confining]
        # keep: the samples and finished runs of an earlier campaign there are reused
        with OutputFolder(given_out, "chapter5", keep=True) as folder:
            for name in OUTPUTS:
                folder.claim(name)
            result = Campaign(runs, samples).run(out, options)
            campaign = write_campaign(out, given_out, grid, options, tests, runs, result)
        return {**campaign, "reused": len(result.reused)}


def write_campaign(out, given_out, grid, options, tests, runs, result):
    """campaign.csv, campaign.json, plots/ and report.md of the finished campaign ``result``
    (CampaignResult of ``runs``, one per (suction, confining) of ``tests``) in ``out``
    (``given_out`` as the command was given it), run as ``options`` say; the campaign.json
    content. ValueError naming the runs that failed or a reused run's damaged history."""
    write_campaign_csv(os.path.join(out, "campaign.csv"), result)
    result.check()
    for s, c in tests:                  # reused runs too: the figures read them all
        check_history(run_folder(out, s, c))
    rows = [run_row(s, c, result.summaries[run.name], run_folder(out, s, c), out)
            for (s, c), run in zip(tests, runs)]
    fits = envelopes(rows)
    arguments = {"particles": grid.particles, "suctions": grid.suctions,
                 "confining": grid.confining, "jobs": options.jobs,
                 "out": os.fspath(given_out), "seed": grid.seed,
                 "max_strain": grid.max_strain, "inertial_number": grid.inertial_number,
                 "prep_friction": grid.prep_friction, "scheduler": options.scheduler}
    campaign = {"arguments": arguments, "runs": rows, "envelopes": fits,
                "thesis": {"table_5_3": [{"suction": s, "confining": c,
                                          "peak_axial_stress": v}
                                         for (s, c), v in TABLE_5_3.items()],
                           "fig_5_5_saturation": {label(s): v for s, v in FIG_5_5.items()},
                           "dry_friction_deg": DRY_FRICTION_DEG}}
    write_json(os.path.join(out, "campaign.json"), campaign)
    figures = campaign_figures(out, rows, fits, label, LATE_STRAIN)
    write_report(os.path.join(out, "report.md"), rows, fits, grid, figures, out)
    return campaign
