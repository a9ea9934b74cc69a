"""Figures of a calibration (pendular.studies.calibration): the data against the last
iteration's ensemble and the best run, each fitted parameter's posterior (with the pairs of
two or more), the error per iteration."""

from __future__ import annotations

import os

import numpy as np

from pendular.io.plots import pyplot, save_figure

#: Labels of the curves' columns, with the factor from SI to the unit shown.
LABELS = {"axial_strain": ("axial strain εa [%]", 100.0), "q": ("deviator stress q [kPa]", 1e-3),
          "volumetric_strain": ("volumetric strain εv [%] (contraction +)", 100.0)}


def _label(name):
    return LABELS.get(name, (name, 1.0))


def curves_figure(calibration, summary, out):
    """Each observed column against the control: the data (points), the last iteration's
    runs (grey, darker by weight) and the best run (red)."""
    kind = calibration.curve.kind
    columns = calibration.curve.columns
    last = max(row["iteration"] for row in summary["rows"])
    rows = [row for row in summary["rows"] if row["iteration"] == last]
    top = max(row["weight"] for row in rows) or 1.0
    figure, axes = pyplot().subplots(len(columns), 1, figsize=(6, 3.5 * len(columns)),
                                     squeeze=False)
    x_label, x_factor = _label(kind.control)
    for row in rows:
        run = kind.read(os.path.join(out, "runs", row["run"]))
        for axis, name in zip(axes[:, 0], columns):
            axis.plot(x_factor * run[kind.control], _label(name)[1] * run[name], color="0.5",
                      lw=0.8, alpha=0.15 + 0.6 * row["weight"] / top)
    best = kind.read(os.path.join(out, summary["best_run"]))
    for axis, name in zip(axes[:, 0], columns):
        label, factor = _label(name)
        axis.plot(x_factor * best[kind.control], factor * best[name], color="C3",
                  label=f"best run ({os.path.basename(summary['best_run'])})")
        axis.plot(x_factor * calibration.curve.control, factor * calibration.curve.observed[name],
                  "o", color="k", ms=4, label="data")
        axis.plot([], [], color="0.5", label=f"iteration {last + 1} (darker: heavier)")
        axis.set_xlabel(x_label)
        axis.set_ylabel(label)
        axis.grid(alpha=0.3)
        axis.legend(fontsize=8)
    axes[0, 0].set_title("Calibration: " + ", ".join(
        f"{name} {p['mean']:.3g} ± {p['std']:.2g} {p['unit']}"
        for name, p in summary["parameters"].items()), fontsize=9)
    return figure


def posterior_figure(calibration, summary):
    """Each parameter's posterior on its prior range: the weighted histogram of every
    iteration's samples together (their posterior weights, Calibration.posterior), each sample
    a tick; below the diagonal the pairs, each sample sized by its weight."""
    fits = calibration.fits
    samples = calibration.row_samples(summary["rows"])
    weights = np.array([row["weight"] for row in summary["rows"]])
    size = len(fits)
    figure, axes = pyplot().subplots(size, size, figsize=(3.2 * size + 1, 3.0 * size + 0.5),
                                     squeeze=False)
    for i, fit in enumerate(fits):
        axis = axes[i, i]
        axis.hist(samples[:, i], bins=np.linspace(fit.low, fit.high, 21), weights=weights,
                  color="C0", alpha=0.7)
        axis.plot(samples[:, i], np.zeros(len(samples)), "|", color="k", ms=8)
        posterior = summary["parameters"][fit.name]
        axis.axvline(posterior["mean"], color="C3", lw=1)
        axis.set_xlim(fit.low, fit.high)
        axis.set_xlabel(f"{fit.name} [{fit.unit}]")
        axis.set_ylabel("posterior weight")
        note = "" if posterior["constrained"] else " (unconstrained)"
        axis.set_title(f"{posterior['mean']:.3g} ± {posterior['std']:.2g}{note}", fontsize=9)
        for j in range(size):
            if j > i:
                axes[i, j].axis("off")
            elif j < i:
                other, pair = fits[j], axes[i, j]
                pair.scatter(samples[:, j], samples[:, i], s=3 + 300 * weights, color="C0",
                             alpha=0.6)
                pair.set_xlim(other.low, other.high)
                pair.set_ylim(fit.low, fit.high)
                pair.set_xlabel(f"{other.name} [{other.unit}]")
                pair.set_ylabel(f"{fit.name} [{fit.unit}]")
    return figure


def errors_figure(summary):
    """The error of every run to the data by iteration, with the best and the weighted mean."""
    figure, axis = pyplot().subplots(figsize=(6, 4))
    rows = summary["rows"]
    axis.plot([row["iteration"] + 1 for row in rows], [row["error"] for row in rows], "o",
              color="0.5", ms=4, label="each run")
    steps = summary["iterations"]
    axis.plot([s["iteration"] + 1 for s in steps], [s["best_error"] for s in steps], "-o",
              color="C3", label="best")
    axis.plot([s["iteration"] + 1 for s in steps], [s["weighted_error"] for s in steps], "-s",
              color="C0", label="mean under the filter's weights")
    axis.set_yscale("log")
    axis.set_xlabel("iteration")
    axis.set_ylabel("RMS error (fraction of the data's range)")
    axis.set_xticks([s["iteration"] + 1 for s in steps])
    axis.grid(alpha=0.3, which="both")
    axis.legend(fontsize=8)
    return figure


def write_figures(calibration, summary, out, paths):
    """calibration.png, posterior.png and errors.png at ``paths`` (name -> path)."""
    save_figure(curves_figure(calibration, summary, out), paths["calibration.png"])
    save_figure(posterior_figure(calibration, summary), paths["posterior.png"])
    save_figure(errors_figure(summary), paths["errors.png"])
