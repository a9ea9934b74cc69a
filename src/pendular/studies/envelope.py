"""Mohr–Coulomb failure envelope from triaxial-compression peaks (thesis Fig. 5.4), and the
study ``pendular envelope`` that measures one.

In axisymmetric compression the Mohr–Coulomb line tau = sigma tan(phi) + c maps to
q = M p + q0 with M = 6 sin(phi) / (3 - sin(phi)) and q0 = c 6 cos(phi) / (3 - sin(phi)).
``mohr_coulomb_envelope`` fits that line to the peaks (p, q) by least squares and gives the
standard errors of phi and c: those of M and q0 from the residual scatter (n - 2 degrees of
freedom), carried to phi and c to first order (the delta method).

``envelope(runs, out, options)`` runs drained triaxial compressions at several confining
stresses as one campaign, as the pendular.procedures.run_options.RunOptions ``options`` say
(pendular.studies.campaign: local processes or a Dask cluster) and fits the
envelope to their peaks in net stresses and in the effective stresses of Eq. 3.43 (the wet
summaries' p' and q' at the peak of q; a dry test's effective stress is its net stress).
It writes into ``out``: summary.json (its keys declared in pendular.io.schema.SUMMARY_KEYS),
campaign.csv, the figures of pendular.studies.envelope_figures, and runs/confining<S>/ (each
triaxial's outputs).
"""

from __future__ import annotations

import dataclasses
import math
import os
import sys
from typing import NamedTuple

import numpy as np

from pendular.io.outputs import OutputFolder
from pendular.io.schema import summary_units
from pendular.procedures.registry import config_from_options, options_of
from pendular.procedures.preparation import PrepareConfig
from pendular.procedures.run_options import RunOptions
from pendular.studies.campaign import Campaign, Run, run_name, write_campaign_csv
from pendular.studies.envelope_figures import plot_mohr_circles, plot_peaks
from pendular.utils.atomic import write_json
from pendular.utils.parameters import OptionError, option_from, option_values, spec_of


class MohrCoulombFit(NamedTuple):
    """A fitted envelope: friction angle ``phi_deg`` [deg] and ``cohesion`` [Pa], the line
    q = ``slope`` p + ``intercept`` [Pa] in p–q, their standard errors (None without scatter
    to measure: as many points as parameters; ``cohesion_error`` and ``intercept_error`` 0
    through the origin), the ``points`` and the fit's ``degrees_of_freedom``."""

    phi_deg: float
    cohesion: float
    slope: float
    intercept: float
    phi_error_deg: float | None
    cohesion_error: float | None
    slope_error: float | None
    intercept_error: float | None
    points: int
    degrees_of_freedom: int


def mohr_coulomb_envelope(p, q, through_origin=False):
    """MohrCoulombFit of the least-squares line q = M p + q0 through peak points (p, q) [Pa]
    (module docstring). With ``through_origin`` the cohesion is fixed at 0 (a dry,
    cohesionless material). ValueError for fewer points than parameters or a slope outside
    the Mohr–Coulomb range [0, 3)."""
    p = np.asarray(p, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    unknowns = 1 if through_origin else 2
    if p.shape != q.shape or p.ndim != 1 or p.size < unknowns:
        raise ValueError(f"need matching p and q with at least {unknowns} points, got "
                         f"{p.size} and {q.size}")
    design = p[:, None] if through_origin else np.column_stack([p, np.ones_like(p)])
    normal = design.T @ design
    coefficients = np.linalg.solve(normal, design.T @ q)
    slope = float(coefficients[0])
    intercept = 0.0 if through_origin else float(coefficients[1])
    if not 0.0 <= slope < 3.0:
        raise ValueError(f"fitted slope M = {slope:.3f} is outside the Mohr–Coulomb range [0, 3)")
    sin_phi = 3.0 * slope / (6.0 + slope)
    cos_phi = math.sqrt(1.0 - sin_phi * sin_phi)
    phi = math.asin(sin_phi)
    cohesion = intercept * (3.0 - sin_phi) / (6.0 * cos_phi)
    freedom = p.size - unknowns
    errors = (None, None, None, None)
    if freedom > 0:
        residual = q - design @ coefficients
        covariance = float(residual @ residual) / freedom * np.linalg.inv(normal)
        # d phi / d M, and c = q0 g(sin phi) with g(s) = (3 - s) / (6 sqrt(1 - s^2))
        dsin = 18.0 / (6.0 + slope) ** 2
        dphi = dsin / cos_phi
        gradient = np.array([intercept * (3.0 * sin_phi - 1.0) / (6.0 * cos_phi ** 3) * dsin,
                             (3.0 - sin_phi) / (6.0 * cos_phi)])[:unknowns]
        slope_error = math.sqrt(covariance[0, 0])
        intercept_error = 0.0 if through_origin else math.sqrt(covariance[1, 1])
        cohesion_error = (0.0 if through_origin
                          else math.sqrt(float(gradient @ covariance @ gradient)))
        errors = (math.degrees(dphi * slope_error), cohesion_error, slope_error,
                  intercept_error)
    return MohrCoulombFit(math.degrees(phi), cohesion, slope, intercept, *errors, int(p.size),
                          freedom)


def mohr_coulomb_fit(p, q, through_origin=False):
    """(phi [deg], cohesion [Pa]) of mohr_coulomb_envelope."""
    fit = mohr_coulomb_envelope(p, q, through_origin)
    return fit.phi_deg, fit.cohesion


# ---------------------------------------------------------------- the study

#: Fewest confining stresses of an envelope: a line through the peaks needs two (and a third
#: to measure its scatter).
MIN_TESTS = 2
#: The envelope's confining stresses, one triaxial each.
CONFINING = option_from(dataclasses.replace(
    spec_of(PrepareConfig, "confining"), low_inclusive=False,
    help=f"confining stresses of the triaxial tests, comma-separated, at least {MIN_TESTS}, "
         "each once (e.g. 250,500,1000,2000)"), None, many=True, distinct=True, checked=True)
#: What the study owns in its folder (pendular.io.outputs); runs/ is kept and its finished
#: runs reused by the next envelope there.
OUTPUTS = ("summary.json", "campaign.csv", "mohr_circles.png", "peaks_pq.png")
#: A test's peak figures in summary.json's ``tests`` (its summary.json's keys).
PEAK_KEYS = ("peak_q", "p_at_peak", "peak_axial_stress", "axial_strain_at_peak",
             "phi_peak_deg", "peak_reached", "saturation_at_peak", "suction_at_peak")
#: Triaxial options an envelope leaves out: its tests are conventional compressions.
NOT_CONVENTIONAL = ("direction", "b", "constant_p")


def envelope_options():
    """The options of ``pendular envelope``: the triaxial's (but NOT_CONVENTIONAL), its
    --confining a list."""
    return tuple(CONFINING if option.key == "confining" else option
                 for option in options_of("triaxial") if option.key not in NOT_CONVENTIONAL)


def envelope_runs(options, force=False):
    """The Runs of an envelope (one triaxial per confining stress, named confining<S>) from
    ``options``: key -> value of envelope_options (a command line's, a dict; ``confining`` a
    list or comma text). OptionError or ParameterError naming the option (fewer than
    MIN_TESTS confining stresses, one twice, one outside its range, a triaxial option, an
    option an envelope has not)."""
    option_values(envelope_options(), options, "an envelope")       # unknown keys refused
    options = dict(options)
    given = options.pop("confining", None)
    if given is None:
        raise OptionError(lambda name: f"{name('confining')} is missing: give the confining "
                                       f"stresses, at least {MIN_TESTS} (e.g. 250,500,1000,2000)")
    stresses = CONFINING.read(given)
    if len(stresses) < MIN_TESTS:
        raise OptionError(lambda name: f"{name('confining')} = {given!r}: at least {MIN_TESTS} "
                                       "confining stresses expected, comma-separated (a line "
                                       "through the peaks needs two)")
    runs = []
    for stress in stresses:
        config = config_from_options("triaxial", {**options, "confining": stress})
        runs.append(Run(run_name({"confining": stress}, ["confining"]), config, force))
    return runs


def peak_row(summary, folder, out, dry):
    """summary.json's ``tests`` entry of one triaxial of ``summary``: its run folder (relative
    to ``out``), peak figures and the principal stresses at the peak of q, net and
    effective (sigma_1 = p + 2q/3, sigma_3 = p - q/3; ``dry``: the effective stress is the net
    one). ValueError naming the run where a figure is missing."""
    missing = [key for key in ("peak_q", "p_at_peak") + (() if dry else (
        "peak_q_effective", "p_effective_at_peak"))
               if isinstance(summary.get(key), bool)
               or not isinstance(summary.get(key), (int, float))]
    if missing:
        raise ValueError(f"{folder}/summary.json has no {', '.join(missing)}: the envelope "
                         "needs each test's peak")
    row = {"run": os.path.relpath(folder, out)}
    row.update({key: summary[key] for key in PEAK_KEYS if key in summary})
    q_effective, p_effective = ((summary["peak_q"], summary["p_at_peak"]) if dry else
                                (summary["peak_q_effective"], summary["p_effective_at_peak"]))
    row.update({"peak_q_effective": q_effective, "p_effective_at_peak": p_effective,
                "phi_peak_effective_deg": summary.get("phi_peak_effective_deg",
                                                      summary["phi_peak_deg"])})
    for suffix, q, p in (("", summary["peak_q"], summary["p_at_peak"]),
                         ("_effective", q_effective, p_effective)):
        row[f"sigma_1{suffix}_at_peak"] = p + 2.0 * q / 3.0
        row[f"sigma_3{suffix}_at_peak"] = p - q / 3.0
    return row


def fit_keys(fit, suffix):
    """Summary keys of a MohrCoulombFit, ``suffix`` '' (net) or '_effective'."""
    return {f"phi{suffix}_deg": fit.phi_deg, f"cohesion{suffix}": fit.cohesion,
            f"phi{suffix}_error_deg": fit.phi_error_deg,
            f"cohesion{suffix}_error": fit.cohesion_error,
            f"failure_line_slope{suffix}": fit.slope,
            f"failure_line_intercept{suffix}": fit.intercept,
            f"failure_line_slope{suffix}_error": fit.slope_error,
            f"failure_line_intercept{suffix}_error": fit.intercept_error}


def envelope_summary(rows, config):
    """summary.json of an envelope: the fits to the ``rows`` (peak_row) in net and effective
    stresses, each also through the origin, and the tests; ``config`` one test's
    TriaxialConfig (its suction, or its water content)."""
    rows = sorted(rows, key=lambda row: row["confining"])
    bridges = config.bridges
    at_water_content = bridges is not None and bridges.water_content is not None
    summary = {"confining": [row["confining"] for row in rows],
               "suction": None if at_water_content else config.suction,
               "particles": config.sample.particles}
    if at_water_content:                    # the suction is an output of each test
        summary["water_content_percent"] = 100.0 * bridges.water_content
    for suffix, p, q in (("", "p_at_peak", "peak_q"),
                         ("_effective", "p_effective_at_peak", "peak_q_effective")):
        points = ([row[p] for row in rows], [row[q] for row in rows])
        summary.update(fit_keys(mohr_coulomb_envelope(*points), suffix))
        summary[f"phi{suffix}_through_origin_deg"] = mohr_coulomb_envelope(
            *points, through_origin=True).phi_deg
    summary["fit_points"] = len(rows)
    summary["degrees_of_freedom"] = len(rows) - 2
    if len(rows) == 2:
        summary["fit_error_note"] = ("two confining stresses: the line passes through both "
                                     "peaks, so no scatter measures its errors (give three or "
                                     "more)")
    if config.bridges is None:
        summary["effective_note"] = "dry tests: the effective stress is the net stress"
    summary["peak_not_reached"] = [row["confining"] for row in rows
                                   if row.get("peak_reached") is False]
    summary["tests"] = rows
    summary["units"] = {key: unit for key, unit in summary_units("envelope").items()
                        if key in summary}
    return summary


def envelope(runs, out, options=None, **settings):
    """Run the triaxials ``runs`` (envelope_runs) as one campaign into ``out`` as the
    RunOptions ``options`` say (``settings``: its fields one by one; local processes or a
    Dask cluster, Numba threads per run, device: pendular.studies.campaign.Campaign.run),
    reusing finished ones, and write
    summary.json, campaign.csv and the figures (module docstring); returns (summary, runs
    reused). ValueError naming the runs that failed (the others are kept and reused)."""
    options = RunOptions.of(options, **settings)
    given_out = out
    out = os.path.abspath(os.fspath(out))       # workers elsewhere see the same paths
    campaign = Campaign(runs)
    config = runs[0].config
    # keep: the finished runs of an earlier envelope there are reused; runs/ is never owned
    with OutputFolder(given_out, "envelope", keep=True) as folder:
        for name in OUTPUTS:
            folder.claim(name)
        result = campaign.run(out, options)
        write_campaign_csv(os.path.join(out, "campaign.csv"), result)
        result.check()
        rows = []
        for run in runs:
            row = peak_row(result.summaries[run.name], campaign.folder(out, run.name), out,
                           config.bridges is None)
            rows.append({"confining": run.config.confining, **row,
                         "reused": run.name in result.reused})
        summary = envelope_summary(rows, config)
        write_json(os.path.join(out, "summary.json"), summary)
        plot_mohr_circles(os.path.join(out, "mohr_circles.png"), summary)
        plot_peaks(os.path.join(out, "peaks_pq.png"), summary)
    if summary["peak_not_reached"] and options.progress:
        print("note: q still rises at the end of the test at confining "
              f"{', '.join(f'{c:g}' for c in summary['peak_not_reached'])} Pa (peak_reached "
              "false): their peaks are the highest records; a larger --max-strain reaches them",
              file=sys.stderr)
    return summary, len(result.reused)

