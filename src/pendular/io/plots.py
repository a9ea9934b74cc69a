"""Figures: matplotlib without a display, saved atomically, and the plots of every laboratory
test (triaxial, oedometer, isotropic, cyclic, simple shear, path, direct tension, SWCC).

Every figure is written under a temporary name then renamed (a killed run never leaves a
truncated PNG). Stresses compression positive.
"""

import math
import os

import numpy as np

from pendular.utils.atomic import replacing
from pendular.homogenize.invariants import (deviator_stress, lateral_stress, mean_stress,
    shear_deviator)


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
    end stress, an isotropic path's stresses, a shear's constant p), b, s, the contact angle,
    ``initial_porosity`` (n0: the porosity the loading starts from, after any wetting)."""
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
    elif parameters.get("constant_p"):
        parts.append(f"constant p = {parameters['confining'] / 1e3:g} kPa")
    else:
        parts.append(f"σ3 = {parameters['confining'] / 1e3:g} kPa")
    if parameters.get("b") is not None:
        parts.append(f"b = {parameters['b']:g}")
    if parameters.get("water_content_percent") is not None:
        parts.append(f"w = {parameters['water_content_percent']:g} %")
    else:
        parts.append(f"s = {parameters.get('suction', 0.0) / 1e3:g} kPa")
    if (parameters.get("water_content_percent") is not None
            or parameters.get("suction", 0.0) > 0.0):
        parts.append(f"contact angle θ = {parameters.get('contact_angle', 0.0):g}°")
    if initial_porosity is not None:
        parts.append(f"n0 = {initial_porosity:.3f}")
    return ", ".join(parts)


#: What q is, by whether the test holds an intermediate principal stress (b != 0).
Q_WORDS = {False: "deviator stress", True: "von Mises stress"}
#: Least span of a stress path's p axis, over the span of its q axis.
MIN_P_SPAN = 0.5
#: The sign of q = sigma_z - sigma_lateral at the failure of a shear, by direction.
DIRECTION_SIGN = {"compression": 1.0, "extension": -1.0}


def _peak(history, direction="compression", b=None):
    """Index of the peak of q (compression) or of -q (extension); q of a test at ``b``
    (invariants.shear_deviator)."""
    return int(np.argmax(DIRECTION_SIGN[direction]
                         * shear_deviator(history["sigma_wall"], b)))


def _strain_axes(axes, label):
    axes.set_xlabel("axial strain εa [%]")
    axes.set_ylabel(label)
    axes.grid(alpha=0.3)


def history_figure(history, title="", direction="compression", b=None):
    """The figure of plot_history: q [kPa] (von Mises at ``b`` != 0) above the volumetric
    strain [%], both against the axial strain [%], tick labels on both panels."""
    strain = 100.0 * history["axial_strain"]
    q = shear_deviator(history["sigma_wall"], b) / 1e3
    peak = _peak(history, direction, b)
    figure, (top, bottom) = pyplot().subplots(2, 1, figsize=(6, 7), sharex=True)
    top.plot(strain, q, color="C0", label="net stress")
    top.plot(strain[peak], q[peak], "o", color="C3",
             label=f"{'peak' if direction == 'compression' else 'least'} q = {q[peak]:.3g} kPa "
                   f"at εa = {strain[peak]:.2f} %")
    top.legend(fontsize=8)
    _strain_axes(top, f"{Q_WORDS[bool(b)]} q [kPa]")
    top.tick_params(labelbottom=True)          # sharex hides them on the upper panel
    bottom.plot(strain, 100.0 * history["volumetric_strain"], color="C2")
    bottom.axvline(strain[peak], color="C3", lw=0.8, ls=":")
    _strain_axes(bottom, "volumetric strain εv [%]\n(contraction +)")
    top.set_title(f"Drained triaxial {direction}\n{title}", fontsize=9)
    return figure


def plot_history(history, path, title="", direction="compression", b=None):
    """q [kPa] and volumetric strain [%] against axial strain [%] (thesis Fig. 5.3), the peak
    of q marked (in extension the least q); ``title``: the run's parameters (run_label);
    ``b``: the test's, q then the von Mises deviatoric stress."""
    return save_figure(history_figure(history, title, direction, b), path)


def write_plots(history, folder, title="", direction="compression", b=None):
    """The plots of a triaxial run into ``folder``, each against axial strain [%] with the run's
    parameters in the title: q_p.png (q/p of the net stress and, wet, q'/p' of the effective
    stress of Eq. 3.43), volumetric_strain.png and, wet, saturation.png (Sr [%]) and
    capillary_stress.png (capillary_figure); undrained, excess_pore_pressure.png (Delta u
    [kPa]) and, wet, suction.png (s [kPa]); the peak of q (``direction`` 'extension': of -q)
    marked, none for ``direction`` None (a path without a failure); q von Mises at ``b`` != 0.
    Returns the paths."""
    plt = pyplot()
    strain = 100.0 * history["axial_strain"]
    peak = None if direction is None else _peak(history, direction, b)
    paths = []

    def single(name, heading, label, series):
        figure, axes = plt.subplots(figsize=(6, 4))
        for legend, values in series:
            axes.plot(strain, values, label=legend)
        if peak is not None:
            axes.axvline(strain[peak], color="C3", lw=0.8, ls=":", label="peak of q")
        _strain_axes(axes, label)
        axes.legend(fontsize=8)
        axes.set_title(f"{heading}\n{title}", fontsize=9)
        paths.append(save_figure(figure, os.path.join(folder, name)))

    def ratio(sigma):
        return shear_deviator(sigma, b) / mean_stress(sigma)

    ratios = [("q/p, net stress", ratio(history["sigma_wall"]))]
    if "sigma_effective" in history:
        ratios.append(("q′/p′, effective stress (Eq. 3.43)",
                       ratio(_diagonals(history["sigma_effective"]))))
    if "sigma_effective_complete" in history:
        ratios.append(("q′/p′, complete effective stress (ψ + interface term)",
                       ratio(_diagonals(history["sigma_effective_complete"]))))
    single("q_p.png", "Stress ratio", "stress ratio q/p [-]", ratios)
    single("volumetric_strain.png", "Volumetric strain",
           "volumetric strain εv [%]\n(contraction +)",
           [("εv", 100.0 * history["volumetric_strain"])])
    if "saturation" in history:
        single("saturation.png", "Degree of saturation", "degree of saturation Sr [%]",
               [("Sr", 100.0 * history["saturation"])])
    if "excess_pore_pressure" in history:           # an undrained shear
        single("excess_pore_pressure.png", "Undrained: excess pore pressure "
               "Δu = Δp_total − Δp′ (σ3 held)", "excess pore pressure Δu [kPa]",
               [("Δu", history["excess_pore_pressure"] / 1000.0)])
        if "suction" in history:                    # at a constant water content
            single("suction.png", "Suction at constant water content (undrained)",
                   "suction s [kPa]", [("s", history["suction"] / 1000.0)])
    figure = capillary_figure(history, title)
    if figure is not None:
        paths.append(save_figure(figure, os.path.join(folder, "capillary_stress.png")))
    return paths


#: Panels of the capillary stress figure: history column, symbol (y label and legends), what
#: the panel shows (its title).
CAPILLARY_PANELS = (
    ("psi", "ψ", "capillary stress ψ = χ s + B (Eq. 3.46)"),
    ("psi_interface", "interface term", "liquid–gas interface term of the complete "
                                        "capillary stress"),
    ("sigma_capillary", "σ$_\\mathrm{cap}$", "σ$_\\mathrm{cap}$: Love–Weber stress of the "
                                               "capillary forces (tension negative)"),
)


def capillary_figure(history, title=""):
    """The diagonal components (lateral x, y; axial z) [kPa] against axial strain [%] of the
    capillary stress ψ (Eq. 3.46), the liquid–gas interface term and the Love–Weber stress of
    the capillary forces, one panel each that the history holds; None for a dry history."""
    panels = [panel for panel in CAPILLARY_PANELS if panel[0] in history]
    if not panels:
        return None
    strain = 100.0 * history["axial_strain"]
    figure, axes_list = pyplot().subplots(len(panels), 1, figsize=(6.5, 3.2 * len(panels) + 0.6),
                                          sharex=True, squeeze=False)
    for axes, (key, symbol, what) in zip(axes_list[:, 0], panels):
        for words, values in zip(AXIS_WORDS, _diagonals(history[key]).T):
            axes.plot(strain, values / 1e3, label=f"{symbol}, {words}")
        axes.set_ylabel(f"{symbol} [kPa]")
        axes.set_title(what, fontsize=9)
        axes.grid(alpha=0.3)
        axes.legend(fontsize=8)
        axes.tick_params(labelbottom=True)
    axes_list[-1, 0].set_xlabel("axial strain εa [%]")
    figure.suptitle(f"Capillary stresses\n{title}", fontsize=9)
    return figure


def _effective_diagonals(history):
    """(rows, 3) diagonal of the effective stress (Eq. 3.43) of a wet history, or None."""
    return _diagonals(history["sigma_effective"]) if "sigma_effective" in history else None


def _stage_ends(history):
    """Rows that end a stage of a multi-stage history (column ``stage``), else the last row."""
    if "stage" not in history:
        return np.array([len(history["step"]) - 1])
    stage = np.asarray(history["stage"])
    return np.flatnonzero(np.append(stage[1:] != stage[:-1], True))


def stress_path_figure(history, title="", direction=None, b=None):
    """The figure of plot_stress_path: q against p [kPa] of the net wall stress and, wet, q′
    against p′ of the effective stress (Eq. 3.43) and of the complete one (ψ + interface
    term) on the same axes, each path's start and (``direction`` of a shear) its peak of q
    marked; q von Mises at ``b`` != 0. The p axis spans at least half the q axis's span
    (MIN_P_SPAN), so that a path at constant p is drawn upright, not spread over a sliver."""
    figure, axes = pyplot().subplots(figsize=(6, 5.5))
    peak = None if direction is None else _peak(history, direction, b)
    paths = [("net stress: q–p", np.asarray(history["sigma_wall"]), "C0")]
    effective = _effective_diagonals(history)
    if effective is not None:
        paths.append(("effective stress (Eq. 3.43): q′–p′", effective, "C1"))
    if "sigma_effective_complete" in history:
        paths.append(("complete effective stress (ψ + interface term): q′–p′",
                      _diagonals(history["sigma_effective_complete"]), "C2"))
    drawn_p, drawn_q = [], []
    for label, sigma, color in paths:
        p, q = mean_stress(sigma) / 1e3, shear_deviator(sigma, b) / 1e3
        drawn_p.append(p)
        drawn_q.append(q)
        axes.plot(p, q, color=color, label=label)
        axes.plot(p[0], q[0], "s", color=color, ms=4)
        if peak is not None:
            axes.plot(p[peak], q[peak], "o", color=color, mfc="none")
    wet = len(paths) > 1
    p_low, p_high = min(map(np.nanmin, drawn_p)), max(map(np.nanmax, drawn_p))
    span = MIN_P_SPAN * (max(map(np.nanmax, drawn_q)) - min(map(np.nanmin, drawn_q)))
    if p_high - p_low < span:
        middle = 0.5 * (p_low + p_high)
        axes.set_xlim(middle - 0.5 * span, middle + 0.5 * span)
    axes.set_xlabel(f"mean stress {'p, p′' if wet else 'p'} [kPa]")
    axes.set_ylabel(f"{Q_WORDS[bool(b)]} {'q, q′' if wet else 'q'} [kPa]")
    axes.grid(alpha=0.3)
    axes.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.12),
                title=("square: start, circle: peak of q" if peak is not None
                       else "square: start"), title_fontsize=8)
    axes.set_title(f"Stress path{'s, net and effective' if wet else ''}\n{title}", fontsize=9)
    return figure


def plot_stress_path(history, path, title="", direction=None, b=None):
    """The stress path q [kPa] against p [kPa] of the net wall stress and, wet, q′ against p′
    of the effective stress (Eq. 3.43) beside it (stress_path_figure); q = sigma_z -
    (sigma_x + sigma_y) / 2, negative in extension (von Mises at ``b`` != 0); ``direction``
    of a shear marks its peak."""
    return save_figure(stress_path_figure(history, title, direction, b), path)


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


def plot_cyclic(history, cycles, path, title=""):
    """The loops of a cyclic triaxial path (pendular.procedures.cyclic): left, q [kPa] against
    the axial strain [%], the first loading in grey and each cycle (history column ``cycle``)
    in its own colour; right, the secant modulus [kPa] and the damping ratio [-] of each
    cycle (``cycles``: the summary's rows) against its number, wet the effective ones
    (Eq. 3.43) dashed. ``title``: the run's parameters."""
    plt = pyplot()
    strain = 100.0 * np.asarray(history["axial_strain"])
    q = deviator_stress(history["sigma_wall"]) / 1e3
    cycle = np.asarray(history["cycle"])
    count = int(cycle.max()) if len(cycle) else 0
    colours = plt.get_cmap("viridis")(np.linspace(0.0, 0.9, max(count, 1)))
    figure, (loops, measures) = plt.subplots(1, 2, figsize=(11, 4.8))
    first = np.flatnonzero(cycle == 0)
    loops.plot(strain[first], q[first], color="0.6", lw=1.0, label="first loading")
    for k in range(1, count + 1):
        rows = np.flatnonzero(cycle == k)
        if len(rows) and rows[0] > 0:
            rows = np.concatenate([rows[:1] - 1, rows])         # from the top of the loop
        loops.plot(strain[rows], q[rows], color=colours[k - 1], lw=1.0,
                   label=f"cycle {k}" if count <= 10 or k in (1, count) else None)
    loops.axhline(0.0, color="0.8", lw=0.6)
    _strain_axes(loops, "deviator stress q [kPa] (net stress)")
    loops.legend(fontsize=8)
    numbers = [row["cycle"] for row in cycles]
    modulus = [np.nan if row["secant_modulus"] is None else row["secant_modulus"] / 1e3
               for row in cycles]
    damping = [np.nan if row["damping_ratio"] is None else row["damping_ratio"]
               for row in cycles]
    measures.plot(numbers, modulus, "o-", color="C0",
                  label="secant modulus (q_max - q_min) / (εmax - εmin)")
    ratio = measures.twinx()
    ratio.plot(numbers, damping, "s-", color="C3", label="damping ratio W_D / (4π W_S)")
    if cycles and "secant_modulus_effective" in cycles[0]:
        measures.plot(numbers, [np.nan if row["secant_modulus_effective"] is None
                                else row["secant_modulus_effective"] / 1e3 for row in cycles],
                      "o--", color="C0", mfc="none", label="secant modulus, effective")
        ratio.plot(numbers, [np.nan if row["damping_ratio_effective"] is None
                             else row["damping_ratio_effective"] for row in cycles],
                   "s--", color="C3", mfc="none", label="damping ratio, effective")
    measures.set_xlabel("cycle [-]")
    measures.set_ylabel("secant modulus E_sec [kPa]", color="C0")
    ratio.set_ylabel("damping ratio D [-]", color="C3")
    measures.grid(alpha=0.3)
    if numbers:
        measures.set_xticks(numbers if len(numbers) <= 12 else numbers[::len(numbers) // 10])
    handles = [h for axes in (measures, ratio) for h in axes.get_legend_handles_labels()[0]]
    measures.legend(handles, [h.get_label() for h in handles], fontsize=8)
    figure.suptitle(title, fontsize=9)
    return save_figure(figure, path)


def plot_path(history, path, title=""):
    """A loading path of any stages (pendular.procedures.path): left, the stress path q
    against p [kPa] of the net wall stress and, wet, q' against p' of the effective stress
    (Eq. 3.43), each stage's end marked; right, the wall stresses sigma_x, sigma_y, sigma_z
    [kPa] (wet, the effective ones dashed) and the axial and volumetric strains [%] against
    the history row, the stages' ends dotted. ``title``: the run's parameters."""
    sigma = np.asarray(history["sigma_wall"])
    effective = _effective_diagonals(history)
    row = np.arange(len(sigma))
    ends = _stage_ends(history)
    figure, axes = pyplot().subplot_mosaic([["path", "stress"], ["path", "strain"]],
                                           figsize=(11, 6.5))
    curves = [("q–p, net stress", sigma, "C0")]
    if effective is not None:
        curves.append(("q'–p', effective stress (Eq. 3.43)", effective, "C1"))
    for label, values, color in curves:
        p, q = mean_stress(values) / 1e3, deviator_stress(values) / 1e3
        axes["path"].plot(p, q, color=color, label=label)
        axes["path"].plot(p[ends], q[ends], "o", color=color, ms=4)
    axes["path"].plot([], [], "o", color="0.4", ms=4, label="end of a stage")
    axes["path"].set_xlabel("mean stress p [kPa]")
    axes["path"].set_ylabel("deviator stress q = σz − (σx + σy)/2 [kPa]")
    for axis, words in enumerate(AXIS_WORDS):
        axes["stress"].plot(row, sigma[:, axis] / 1e3, color=f"C{axis}", label=f"σ {words}")
        if effective is not None:
            axes["stress"].plot(row, effective[:, axis] / 1e3, color=f"C{axis}", ls="--",
                                label=f"σ' {words}")
    axes["stress"].set_ylabel("wall stress [kPa]\n(compression +)")
    axes["strain"].plot(row, 100.0 * np.asarray(history["axial_strain"]), color="C0",
                        label="axial strain εa")
    axes["strain"].plot(row, 100.0 * np.asarray(history["volumetric_strain"]), color="C2",
                        label="volumetric strain εv")
    axes["strain"].set_ylabel("strain [%] (compression +)")
    axes["strain"].set_xlabel("history row [-]")
    for name in ("stress", "strain"):
        if len(ends) <= 50:                    # more would grey the panel
            for end in ends[:-1]:
                axes[name].axvline(end, color="0.6", lw=0.6, ls=":")
    for name, panel in axes.items():
        panel.grid(alpha=0.3)
        panel.legend(fontsize=7, ncol=2 if name == "stress" else 1)
    figure.suptitle(title, fontsize=9)
    return save_figure(figure, path)


def plot_simple_shear(history, path, title="", summary=None):
    """A simple shear's records (pendular.procedures.simple_shear) against the shear strain
    gamma [%]: the shear stress tau [kPa] with its largest value marked, tau / sigma_n with
    its peak and friction angle marked (each "peak" only where ``summary``, the
    simple_shear_summary, says the test went past it; "largest" otherwise), the normal stress
    sigma_n = sigma_zz [kPa]; drained, the volumetric strain [%] from the shear's start, at
    constant volume (where it stays 0) the stress path tau against sigma_n instead;
    ``title``: the run's parameters."""
    summary = summary or {}
    gamma = 100.0 * np.asarray(history["shear_strain"])
    tau = np.asarray(history["shear_stress"]) / 1e3
    normal = np.asarray(history["normal_stress"]) / 1e3
    volume = 1.0 - np.asarray(history["volumetric_strain"])
    volumetric = 100.0 * (1.0 - volume / volume[0])
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(normal > 0.0, tau / normal, np.nan)
    figure, (top, second, third, bottom) = pyplot().subplots(4, 1, figsize=(6, 11))
    top.plot(gamma, tau, color="C0")
    largest = int(np.argmax(tau))
    word = "peak" if summary.get("peak_shear_stress_reached") else "largest"
    top.plot(gamma[largest], tau[largest], "o", color="C3",
             label=f"{word} τ = {tau[largest]:.3g} kPa at γ = {gamma[largest]:.2f} %")
    top.legend(fontsize=8)
    top.set_ylabel("shear stress τ [kPa]")
    second.plot(gamma, ratio, color="C4")
    if np.isfinite(ratio).any():
        peak = int(np.nanargmax(ratio))
        word = "peak" if summary.get("peak_reached") else "largest"
        second.plot(gamma[peak], ratio[peak], "o", color="C3",
                    label=f"{word} τ/σn = {ratio[peak]:.3g} (φ = "
                          f"{np.degrees(np.arctan(ratio[peak])):.1f}°) at γ = "
                          f"{gamma[peak]:.2f} %")
        second.legend(fontsize=8)
    second.set_ylabel("stress ratio τ/σn [-]")
    third.plot(gamma, normal, color="C1")
    third.set_ylabel("normal stress σn = σzz [kPa]\n(compression +)")
    third.ticklabel_format(axis="y", useOffset=False)
    third.set_ylim(0.0, 1.1 * max(float(np.max(normal)), 0.0) or 1.0)   # held: a flat line
    for axes in (top, second, third):
        axes.set_xlabel("shear strain γ [%]")
    if np.ptp(volumetric) > 0.0:
        bottom.plot(gamma, volumetric, color="C2")
        bottom.set_ylabel("volumetric strain εv [%]\n(contraction +)")
        bottom.set_xlabel("shear strain γ [%]")
    else:                                    # constant volume: the stress path instead
        bottom.plot(normal, tau, color="C0")
        bottom.plot(normal[0], tau[0], "s", color="C0", ms=4, label="start")
        bottom.legend(fontsize=8)
        bottom.set_xlabel("normal stress σn [kPa]")
        bottom.set_ylabel("shear stress τ [kPa]")
    for axes in (top, second, third, bottom):
        axes.grid(alpha=0.3)
    top.set_title(f"Simple shear (x with z, periodic cell)\n{title}", fontsize=9)
    figure.tight_layout()
    return save_figure(figure, path)


# ---------------------------------------------------------------- direct tension

def plot_label(config) -> str:
    """One line of the run's parameters for the figures' titles."""
    sample = config.sample
    return (f"N = {sample.particles}, R = {sample.radius * 1e3:g} mm, contact angle "
            f"θ = {config.contact_angle:g}°, γ = {config.surface_tension:g} N/m")


def case_label(summary: dict) -> str:
    """A case in words: its target void ratio and water content."""
    return (f"e = {summary['void_ratio_target']:g}, "
            f"w = {100 * summary['water_content_target']:g} %")


def plot_curves(summaries: list[dict], histories: dict, folder: str,
                config) -> None:
    """Tensile stress against axial extension, one figure per case (tension_<case>.png) and
    one with all (tension_all.png)."""
    plt = pyplot()
    every, all_axes = plt.subplots(figsize=(6, 4))
    for summary in summaries:
        history = histories[summary["case"]]
        figure, axes = plt.subplots(figsize=(6, 4))
        for target in (axes, all_axes):
            target.plot(-100.0 * history["axial_strain"], history["tensile_stress"],
                        label=case_label(summary))
        axes.set(xlabel="axial extension [%]", ylabel="tensile stress [Pa]",
                 title=f"Direct tension, {case_label(summary)}\n{plot_label(config)}")
        axes.title.set_fontsize(9)
        axes.grid(alpha=0.3)
        save_figure(figure, os.path.join(folder, f"tension_{summary['case']}.png"))
    all_axes.set(xlabel="axial extension [%]", ylabel="tensile stress [Pa]",
                 title=f"Direct tension, every case\n{plot_label(config)}")
    all_axes.title.set_fontsize(9)
    all_axes.grid(alpha=0.3)
    all_axes.legend(fontsize=7)
    save_figure(every, os.path.join(folder, "tension_all.png"))


def plot_strength(summaries: list[dict], config, measured, predictions, path: str) -> None:
    """Tensile strength against water content: DEM, the measurements ``measured``
    [(void ratio, water content [-], tensile strength [Pa])] (Kim 2001) and ``predictions``
    {void ratio: (water contents [-], tensile strengths [Pa], the packing in words)} of the
    regular packing of the same void ratio (pendular.homogenize.packing_state, thesis Ch. 4);
    ``config``: the run's TensionConfig, for the title."""
    figure, axes = pyplot().subplots(figsize=(6, 4.5))
    void_ratios = sorted({s["void_ratio_target"] for s in summaries}, reverse=True)
    for colour, e in zip(("C0", "C3", "C2", "C1"), void_ratios):
        mine = [s for s in summaries if s["void_ratio_target"] == e]
        waters = [100 * s["water_content"] for s in mine]
        axes.plot(waters, [s["tensile_strength_pa"] for s in mine], "o-", color=colour,
                  label=f"DEM, e = {mine[0]['void_ratio']:.3f}")
        kim = [(100 * w, t) for ke, w, t in measured if math.isclose(ke, e)]
        if kim:
            axes.plot(*zip(*kim), "s", mfc="none", color=colour, label=f"Kim (2001), e = {e}")
        grid, curve, packing = predictions[e]
        axes.plot(100 * np.asarray(grid), curve, "--", color=colour,
                  label=f"regular packing prediction (Ch. 4), {packing}")
    axes.set(xlabel="gravimetric water content w [%]", ylabel="tensile strength [Pa]",
             xlim=(0, None), ylim=(0, None),
             title=f"Tensile strength against water content\n{plot_label(config)}")
    axes.title.set_fontsize(9)
    axes.grid(alpha=0.3)
    axes.legend(fontsize=7)
    save_figure(figure, path)


# ---------------------------------------------------------------- SWCC

def plot_swcc(path, result):
    """swcc.png: Sr [%] against suction [kPa] (log), both branches, thesis Fig. 5.5's points
    and the regular packings' curves."""
    plt = pyplot()
    figure, axes = plt.subplots(figsize=(6.5, 4.5))
    for branch, style in (("drying", "o-"), ("wetting", "s--")):
        rows = result[branch]
        axes.plot([r["suction"] / 1e3 for r in rows], [100 * r["saturation"] for r in rows],
                  style, label=f"DEM, {branch}")
    suctions = [r["suction"] for r in result["drying"]]
    for kind, values in result["regular_packings"].items():
        points = [(s / 1e3, 100 * v) for s, v in zip(suctions, values) if v is not None]
        if points:
            axes.plot(*zip(*points), ":", lw=1, label=f"{kind.upper()} packing (Ch. 4)")
    thesis = sorted((float(s), v) for s, v in result["thesis_fig_5_5"].items())
    axes.plot([s / 1e3 for s, _ in thesis], [100 * v for _, v in thesis], "k*", ms=10,
              label="thesis Fig. 5.5 (its DEM samples)")
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_xlabel("suction [kPa]")
    axes.set_ylabel("degree of saturation Sr [%]")
    sample = result["config"]["fields"]["sample"]["fields"]
    axes.set_title(f"SWCC, {sample['particles']} spheres, confining {sample['confining']:g} Pa",
                   fontsize=9)
    axes.grid(alpha=0.3, which="both")
    axes.legend(fontsize=7)
    return save_figure(figure, path)
