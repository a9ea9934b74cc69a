"""Figures: matplotlib without a display, saved atomically, and the plots of the loading paths
(triaxial, oedometer, isotropic).

Every figure is written under a temporary name then renamed (a killed run never leaves a
truncated PNG). Stresses compression positive.
"""

import os

import numpy as np

from pendular.utils.atomic import replacing
from pendular.homogenize.invariants import (deviator_stress, lateral_stress, mean_stress,
    stress_ratio)


def pyplot():
    """matplotlib.pyplot on the Agg backend (no display needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save_figure(figure, path, dpi=120):
    """Lay out ``figure``, write it to ``path`` (PNG unless the extension says otherwise),
    creating the folder, atomically; close it; return ``path``."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    figure.tight_layout()
    extension = os.path.splitext(path)[1].lstrip(".") or "png"
    with replacing(path) as temporary:
        figure.savefig(temporary, dpi=dpi, format=extension)
    pyplot().close(figure)
    return path


#: Names in words of the diagonal components (x, y lateral; z axial).
AXIS_WORDS = ("lateral x", "lateral y", "axial z")


def _diagonals(values):
    """(rows, 3) diagonal of a (rows, 3, 3) tensor history, or a (rows, 3) one as it is."""
    values = np.asarray(values)
    return np.diagonal(values, axis1=1, axis2=2) if values.ndim == 3 else values


def run_label(parameters, initial_porosity=None):
    """One line of a run's parameters for figure titles: N, sigma_3 (an oedometer's start and
    end stress, an isotropic path's stresses), s, theta, porosity."""
    parts = [f"N = {parameters['particles']}"]
    if parameters.get("psd") is not None:
        parts[0] += " (graded)"
    elif parameters.get("radius_spread"):
        parts[0] += f", R(1 ± {parameters['radius_spread']:g})"
    if "axial_stress" in parameters:         # oedometer: from the confining stress to σv
        parts.append(f"σ0 = {parameters['confining'] / 1e3:g} → σv = "
                     f"{parameters['axial_stress'] / 1e3:g} kPa")
    elif "stresses" in parameters:           # isotropic stages [Pa]
        parts.append(f"p = {parameters['stresses']} Pa")
    else:
        parts.append(f"σ3 = {parameters['confining'] / 1e3:g} kPa")
    if parameters.get("water_content_percent") is not None:
        parts.append(f"w = {parameters['water_content_percent']:g} %")
    else:
        parts.append(f"s = {parameters.get('suction', 0.0) / 1e3:g} kPa")
    if (parameters.get("water_content_percent") is not None
            or parameters.get("suction", 0.0) > 0.0):
        parts.append(f"θ = {parameters.get('contact_angle', 0.0):g}°")
    if initial_porosity is not None:
        parts.append(f"n0 = {initial_porosity:.3f}")
    return ", ".join(parts)


#: The sign of q = sigma_z - sigma_lateral at the failure of a shear, by direction.
DIRECTION_SIGN = {"compression": 1.0, "extension": -1.0}


def _peak(history, direction="compression"):
    """Index of the peak of q (compression) or of -q (extension)."""
    return int(np.argmax(DIRECTION_SIGN[direction] * deviator_stress(history["sigma_wall"])))


def _strain_axes(axes, label):
    axes.set_xlabel("axial strain εa [%]")
    axes.set_ylabel(label)
    axes.grid(alpha=0.3)


def plot_history(history, path, title="", direction="compression"):
    """q [kPa] and volumetric strain [%] against axial strain [%] (thesis Fig. 5.3), the peak
    of q marked (in extension the least q); ``title``: the run's parameters (run_label)."""
    strain = 100.0 * history["axial_strain"]
    q = deviator_stress(history["sigma_wall"]) / 1e3
    peak = _peak(history, direction)
    figure, (top, bottom) = pyplot().subplots(2, 1, figsize=(6, 7), sharex=True)
    top.plot(strain, q, color="C0")
    top.plot(strain[peak], q[peak], "o", color="C3",
             label=f"{'peak' if direction == 'compression' else 'least'} q = {q[peak]:.3g} kPa "
                   f"at εa = {strain[peak]:.2f} %")
    top.legend()
    _strain_axes(top, "deviator stress q [kPa] (net stress)")
    bottom.plot(strain, 100.0 * history["volumetric_strain"], color="C2")
    bottom.axvline(strain[peak], color="C3", lw=0.8, ls=":")
    _strain_axes(bottom, "volumetric strain εv [%] (contraction +)")
    top.set_title(title, fontsize=9)
    save_figure(figure, path)


def write_plots(history, folder, title="", direction="compression"):
    """The plots of a triaxial run into ``folder``, each against axial strain [%] with the run's
    parameters as title: q_p.png (q/p of the net stress and, wet, q'/p' of the effective
    stress of Eq. 3.43), volumetric_strain.png and, wet, saturation.png (Sr [%]) and
    capillary_stress.png (diagonal components of psi, Eq. 3.46, and of the Love–Weber stress
    of the capillary forces, [kPa]); the peak of q (``direction`` 'extension': of -q) marked,
    none for ``direction`` None (a path without a failure). Returns the paths."""
    plt = pyplot()
    strain = 100.0 * history["axial_strain"]
    peak = None if direction is None else _peak(history, direction)
    paths = []

    def single(name, label, series):
        figure, axes = plt.subplots(figsize=(6, 4))
        for legend, values in series:
            axes.plot(strain, values, label=legend)
        if peak is not None:
            axes.axvline(strain[peak], color="C3", lw=0.8, ls=":", label="peak of q")
        _strain_axes(axes, label)
        axes.legend(fontsize=8)
        axes.set_title(title, fontsize=9)
        paths.append(save_figure(figure, os.path.join(folder, name)))

    ratios = [("q/p, net stress", stress_ratio(history["sigma_wall"]))]
    if "sigma_effective" in history:
        ratios.append(("q'/p', effective stress (Eq. 3.43)",
                       stress_ratio(_diagonals(history["sigma_effective"]))))
    if "sigma_effective_complete" in history:
        ratios.append(("q'/p', complete effective stress (ψ + interface)",
                       stress_ratio(_diagonals(history["sigma_effective_complete"]))))
    single("q_p.png", "stress ratio [-]", ratios)
    single("volumetric_strain.png", "volumetric strain εv [%] (contraction +)",
           [("εv", 100.0 * history["volumetric_strain"])])
    if "saturation" in history:
        single("saturation.png", "degree of saturation Sr [%]",
               [("Sr", 100.0 * history["saturation"])])
    capillary = [(key, title_) for key, title_ in
                 (("psi", "capillary stress ψ = χ s + B [kPa] (Eq. 3.46)"),
                  ("psi_interface", "liquid–gas interface stress [kPa]"),
                  ("sigma_capillary", "Love–Weber stress of the capillary forces [kPa] "
                                      "(tension negative)"))
                 if key in history]
    if capillary:
        figure, panels = plt.subplots(len(capillary), 1, figsize=(6.5, 3.5 * len(capillary)),
                                      sharex=True, squeeze=False)
        for axes, (key, label) in zip(panels[:, 0], capillary):
            for words, values in zip(AXIS_WORDS, _diagonals(history[key]).T):
                axes.plot(strain, values / 1e3, label=f"{key} {words}")
            axes.set_ylabel(label, fontsize=8)
            axes.grid(alpha=0.3)
            axes.legend(fontsize=8)
        panels[-1, 0].set_xlabel("axial strain εa [%]")
        panels[0, 0].set_title(title, fontsize=9)
        paths.append(save_figure(figure, os.path.join(folder, "capillary_stress.png")))
    return paths


def _effective_diagonals(history):
    """(rows, 3) diagonal of the effective stress (Eq. 3.43) of a wet history, or None."""
    return _diagonals(history["sigma_effective"]) if "sigma_effective" in history else None


def _stage_ends(history):
    """Rows that end a stage of a multi-stage history (column ``stage``), else the last row."""
    if "stage" not in history:
        return np.array([len(history["step"]) - 1])
    stage = np.asarray(history["stage"])
    return np.flatnonzero(np.append(stage[1:] != stage[:-1], True))


def plot_stress_path(history, path, title=""):
    """The stress path q [kPa] against p [kPa] of the net wall stress and, wet, q' against p'
    of the effective stress (Eq. 3.43); q = sigma_z - (sigma_x + sigma_y) / 2, negative in
    extension."""
    figure, axes = pyplot().subplots(figsize=(6, 5))
    sigma = np.asarray(history["sigma_wall"])
    axes.plot(mean_stress(sigma) / 1e3, deviator_stress(sigma) / 1e3, label="q–p, net stress")
    effective = _effective_diagonals(history)
    if effective is not None:
        axes.plot(mean_stress(effective) / 1e3, deviator_stress(effective) / 1e3,
                  label="q'–p', effective stress (Eq. 3.43)")
    axes.set_xlabel("mean stress p [kPa]")
    axes.set_ylabel("deviator stress q [kPa]")
    axes.grid(alpha=0.3)
    axes.legend(fontsize=8)
    axes.set_title(title, fontsize=9)
    return save_figure(figure, path)


def plot_compression(history, path, title="", stress="axial"):
    """Void ratio e against the stress on a log scale [kPa], the net stress and, wet, the
    effective one (Eq. 3.43), stage ends marked: ``stress`` 'axial' (oedometer: e–log
    sigma_v, with K0 = sigma_lateral / sigma_axial against sigma_v below) or 'mean'
    (isotropic: e–log p, with the volumetric strain [%] against p below)."""
    sigma = np.asarray(history["sigma_wall"])
    effective = _effective_diagonals(history)
    pick = (lambda s: s[:, 2]) if stress == "axial" else mean_stress
    name = "σv" if stress == "axial" else "p"
    void = np.asarray(history["void_ratio"])
    ends = _stage_ends(history)
    figure, (top, bottom) = pyplot().subplots(2, 1, figsize=(6, 7.5), sharex=True)
    curves = [(f"net {name}", pick(sigma) / 1e3, "C0")]
    if effective is not None:
        curves.append((f"effective {name}' (Eq. 3.43)", pick(effective) / 1e3, "C1"))
    for label, values, color in curves:
        top.plot(values, void, color=color, label=label)
        top.plot(values[ends], void[ends], "o", color=color, ms=4)
    top.set_xscale("log")
    from matplotlib.ticker import FuncFormatter

    def minor(value, _):
        return f"{value:g}" if f"{value:.0e}"[0] in "25" else ""

    for axes in (top, bottom):   # kPa as plain numbers, minor ticks 2 and 5 labelled too
        axes.xaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
        axes.xaxis.set_minor_formatter(FuncFormatter(minor))
    top.set_ylabel("void ratio e [-]")
    top.grid(alpha=0.3, which="both")
    top.legend(fontsize=8)
    top.set_title(title, fontsize=9)
    net = pick(sigma) / 1e3
    if stress == "axial":
        bottom.plot(net, np.asarray(history["k0"]), color="C0",
                    label="K0 = σ_lateral / σ_axial, net")
        if effective is not None:
            bottom.plot(pick(effective) / 1e3, lateral_stress(effective) / effective[:, 2],
                        color="C1", label="K0', effective")
        bottom.set_ylabel("K0 [-]")
    else:
        bottom.plot(net, 100.0 * np.asarray(history["volumetric_strain"]), color="C0",
                    label="εv")
        bottom.set_ylabel("volumetric strain εv [%] (contraction +)")
    bottom.set_xlabel(f"{'axial stress σv' if stress == 'axial' else 'mean stress p'} [kPa] "
                      "(log scale)")
    bottom.grid(alpha=0.3, which="both")
    bottom.legend(fontsize=8)
    return save_figure(figure, path)
