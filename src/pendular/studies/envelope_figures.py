"""Figures of a strength envelope (pendular.studies.envelope): Mohr circles at the peaks with
the fitted Mohr–Coulomb line, and the peaks in p–q with the failure line, each in net and in
effective stresses (Eq. 3.43). Stresses in kPa, compression positive."""

from __future__ import annotations

import numpy as np

from pendular.io.plots import pyplot, save_figure

#: The two stresses of the figures: (key suffix, panel title).
STRESSES = (("", "net stress"), ("_effective", "effective stress (Eq. 3.43)"))


def fit_label(summary, suffix):
    """'φ = 25.1 ± 0.4°, c = 12 ± 30 Pa' of the fit of ``suffix`` ('' or '_effective'); the
    errors left out where the fit has none."""
    phi, cohesion = summary[f"phi{suffix}_deg"], summary[f"cohesion{suffix}"]
    phi_error = summary[f"phi{suffix}_error_deg"]
    cohesion_error = summary[f"cohesion{suffix}_error"]
    mark = "′" if suffix else ""
    return (f"φ{mark} = {phi:.2f}" + ("" if phi_error is None else f" ± {phi_error:.2f}")
            + f"°, c{mark} = {cohesion:.0f}"
            + ("" if cohesion_error is None else f" ± {cohesion_error:.0f}") + " Pa")


def title(summary):
    """The figures' title: the tests, their sample and suction."""
    suction = summary["suction"]
    wet = ("dry" if suction == 0 else f"suction {suction / 1e3:g} kPa" if suction is not None
           else f"water content {summary['water_content_percent']:g} %")
    return (f"Drained triaxial compression, {summary['particles']} spheres, {wet}: "
            f"σ3 = {', '.join(f'{c / 1e3:g}' for c in summary['confining'])} kPa")


def plot_mohr_circles(path, summary):
    """Mohr circles of each test at its peak (centre (σ1 + σ3)/2, radius (σ1 − σ3)/2) and
    the line τ = c + σ tan φ, net and effective side by side."""
    plt = pyplot()
    figure, panels = plt.subplots(1, 2, figsize=(12, 4.8))
    tests = summary["tests"]
    angle = np.linspace(0.0, np.pi, 181)
    for axes, (suffix, name) in zip(panels, STRESSES):
        top = max(t[f"sigma_1{suffix}_at_peak"] for t in tests) / 1e3
        radius_max = max(t[f"sigma_1{suffix}_at_peak"] - t[f"sigma_3{suffix}_at_peak"]
                         for t in tests) / 2e3
        for test in tests:
            high = test[f"sigma_1{suffix}_at_peak"] / 1e3
            low = test[f"sigma_3{suffix}_at_peak"] / 1e3
            centre, radius = (high + low) / 2.0, (high - low) / 2.0
            axes.plot(centre + radius * np.cos(angle), radius * np.sin(angle),
                      label=f"σ3 = {test['confining'] / 1e3:g} kPa")
        phi = np.radians(summary[f"phi{suffix}_deg"])
        cohesion = summary[f"cohesion{suffix}"] / 1e3
        sigma = np.array([min(0.0, -cohesion / np.tan(phi)) if phi > 0 else 0.0, 1.05 * top])
        axes.plot(sigma, cohesion + sigma * np.tan(phi), "k--", label=fit_label(summary, suffix))
        axes.set_xlim(min(0.0, sigma[0]), 1.05 * top)
        axes.set_ylim(0.0, 1.3 * radius_max)
        axes.set_aspect("equal", adjustable="box")
        axes.set_xlabel(f"normal stress σ{'′' if suffix else ''} [kPa]")
        axes.set_ylabel("shear stress τ [kPa]")
        axes.set_title(name, fontsize=10)
        axes.grid(alpha=0.3)
        axes.legend(fontsize=7, loc="upper left")
    figure.suptitle(title(summary), fontsize=10)
    return save_figure(figure, path)


def plot_peaks(path, summary):
    """The peaks (p, q) and (p′, q′) with the failure line q = M p + q0 of each fit."""
    plt = pyplot()
    figure, panels = plt.subplots(1, 2, figsize=(12, 4.8))
    tests = summary["tests"]
    for axes, (suffix, name) in zip(panels, STRESSES):
        right = 1.1 * max(t[f"p{suffix}_at_peak"] for t in tests) / 1e3
        p = np.array([t[f"p{suffix}_at_peak"] for t in tests]) / 1e3
        q = np.array([t[f"peak_q{suffix}"] for t in tests]) / 1e3
        axes.plot(p, q, "o", label="peaks")
        for x, y, test in zip(p, q, tests):
            axes.annotate(f"{test['confining'] / 1e3:g}", (x, y), textcoords="offset points",
                          xytext=(4, -10), fontsize=7)
        line = np.array([0.0, right])
        slope = summary[f"failure_line_slope{suffix}"]
        intercept = summary[f"failure_line_intercept{suffix}"] / 1e3
        axes.plot(line, intercept + slope * line, "k--",
                  label=f"M = {slope:.3f}; {fit_label(summary, suffix)}")
        mark = "′" if suffix else ""
        axes.set_xlabel(f"p{mark} at peak [kPa]")
        axes.set_ylabel(f"q{mark} at peak [kPa]")
        axes.set_xlim(0.0, right)
        axes.set_ylim(0.0, None)
        axes.set_title(name + " (labels: σ3 [kPa])", fontsize=10)
        axes.grid(alpha=0.3)
        axes.legend(fontsize=7, loc="upper left")
    figure.suptitle(title(summary), fontsize=10)
    return save_figure(figure, path)
