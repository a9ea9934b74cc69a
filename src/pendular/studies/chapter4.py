"""Thesis Chapter 4: regular packings, SWCC, chi_ij, B_ij, psi_ij, a_psi and Kim (2001).

``write_chapter4(out, points)`` (command ``pendular chapter4 [--out DIR] [--points N]``)

Writes the counterparts of Figs. 4.6-4.10, 4.12-4.15, 4.17 and 4.19 as DIR/fig4_*.png and the
printed tables as DIR/chapter4_tables.txt; prints Table 4.1 (computed next to printed), the key
numbers and the Kim (2001) comparison of Table 4.5. One bridge per contact (Tables 4.2-4.4),
surface tension 0.074 N/m (docs/physics.md 'Errata'), specific gravity 2.65, water content
gravimetric.
Solid lines: exact Young-Laplace bridges; dashed: toroidal approximation (Appendix A).
"""

import math
import time

import numpy as np
from scipy.optimize import brentq

from pendular.utils.atomic import write_text
from pendular.utils.parameters import Parameter
from pendular.homogenize import packing_state, regular_packing
from pendular.homogenize.cell_bridge import largest_filling_angle

from pendular.io.outputs import OutputFolder
from pendular.io.plots import pyplot, save_figure
from pendular.procedures.reference import (CHAPTER4_SURFACE_TENSION, KIM_2001, KIM_PACKINGS,
    KIM_RADIUS, KIM_SEPARATION, SPECIFIC_GRAVITY, TABLE_4_1_PRINTED)

SURFACE_TENSION = CHAPTER4_SURFACE_TENSION
METHODS = {"exact": "-", "toroidal": "--"}
VANISHING_SUCTION_STAR = 1e-6  # s R / gamma of the wettest state when the pendular limit needs s <= 0


def state(packing, radius=1e-4, contact_angle=0.0, method="exact", **state_input):
    return packing_state(packing, radius=radius, contact_angle=contact_angle, surface_tension=SURFACE_TENSION,
                         method=method, specific_gravity=SPECIFIC_GRAVITY, **state_input)


def limit_state(packing, radius=1e-4, contact_angle=0.0, method="exact"):
    """The wettest pendular state: at the largest filling angle (pendular limit), or, where the
    suction there would not be positive (large contact angles, Fig. 3.17), at vanishing suction."""
    angle = min(packing.max_filling_angle, largest_filling_angle(method, contact_angle))
    try:
        return state(packing, radius, contact_angle, method, filling_angle=angle)
    except ValueError:
        return state(packing, radius, contact_angle, method, suction=VANISHING_SUCTION_STAR * SURFACE_TENSION / radius)


def saturation_curve(packing, points, radius=1e-4, contact_angle=0.0, method="exact"):
    """States from Sr ~ 1e-4 Sr_max to the wettest pendular state. With a gap the driest states have no
    bridge (or a negative suction); the curve then starts at the driest valid saturation (bisection)."""
    top = limit_state(packing, radius, contact_angle, method).saturation

    def attempt(fraction):
        try:
            return state(packing, radius, contact_angle, method, saturation=fraction * top)
        except ValueError:
            return None

    fractions = np.concatenate([np.geomspace(1e-4, 0.04, points // 4, endpoint=False),
                                np.linspace(0.04, 1.0, points - points // 4)])
    states = [attempt(fraction) for fraction in fractions]
    valid = [k for k, s in enumerate(states) if s is not None]
    first = valid[0]
    if first > 0:
        low, high = fractions[first - 1], fractions[first]
        for _ in range(40):
            middle = math.sqrt(low * high)
            low, high = (low, middle) if attempt(middle) is not None else (middle, high)
        return [attempt(high)] + [states[k] for k in valid]
    return [states[k] for k in valid]


def suction_curve(packing, points, radius=1e-4, contact_angle=0.0, method="exact", smallest=10.0, largest=1e7):
    """States from the wettest pendular state's suction (at least `smallest`) to `largest` [Pa], log-spaced."""
    lowest = max(limit_state(packing, radius, contact_angle, method).suction * (1.0 + 1e-9), smallest)
    return [state(packing, radius, contact_angle, method, suction=s) for s in np.geomspace(lowest, largest, points)]


def column(states, name):
    return np.array([getattr(s, name) for s in states])


def diagonal(states, name, axis=0):
    return np.array([getattr(s, name)[axis, axis] for s in states])


def percent(states, name="saturation"):
    return 100.0 * column(states, name)


# ---------------------------------------------------------------- tables and key numbers

def table_4_1():
    lines = ["Table 4.1 - BCC packings (H = 0): computed | printed in the thesis",
             " l'      n       Fx      Fy      Fz      a      |  n      Fx     Fy     Fz     a     differs"]
    for l_prime, *printed in TABLE_4_1_PRINTED:
        packing = regular_packing("bcc", l_prime)
        computed = [packing.porosity, *np.diag(packing.fabric), packing.anisotropy]
        decimals = [3, 3, 3, 3, 2 if abs(printed[-1]) >= 0.1 or printed[-1] == 0 else 3]
        differs = [name for name, c, p, d in zip(("n", "Fx", "Fy", "Fz", "a"), computed, printed, decimals)
                   if abs(round(c, d) - p) > 1.01 * 10.0**-d]
        lines.append(f" {l_prime:<6.4g} " + " ".join(f"{c:7.4f}" for c in computed) + "  | "
                     + " ".join(f"{p:6.3g}" for p in printed) + "   " + (", ".join(differs) or "-"))
    return lines


def pendular_limits():
    lines = ["Pendular limit (H = 0, contact angle θ = 0, R = 0.1 mm): largest filling angle and the state there",
             " packing  method     alpha_max  Sr       w        s [kPa]  s R/gamma  chi_ii"]
    for kind in ("scp", "fcp"):
        packing = regular_packing(kind)
        for method in METHODS:
            limit = limit_state(packing, method=method)
            lines.append(f" {kind.upper():8s} {method:9s} {limit.filling_angle:8.3f}  {limit.saturation:7.4f}  "
                         f"{limit.water_content:7.4f}  {limit.suction / 1e3:7.3f}  {limit.suction_star:8.4f}  "
                         f"{limit.chi[0, 0]:.4f}")
    return lines


def high_suction_limits():
    """psi at s = 1e4 kPa against 4 pi gamma R^2 cos(theta) N_LB F / V (Love-Weber of F = 2 pi gamma R cos theta)."""
    lines = ["High-suction limit of psi_ii (R = 0.1 mm, H = 0): computed at s = 1e4 kPa and the limit "
             "4 pi gamma R^2 cos θ N_LB F_ii / V (θ: contact angle)",
             " packing  θ [°]  method     psi_ii(1e4 kPa) [kPa]  limit [kPa]"]
    radius = 1e-4
    for kind in ("scp", "fcp"):
        packing = regular_packing(kind)
        for theta in (0.0, 30.0):
            limit = (4.0 * math.pi * SURFACE_TENSION * radius**2 * math.cos(math.radians(theta))
                     * packing.bridges_per_cell * packing.fabric[0, 0] / (packing.cell_volume * radius**3))
            for method in METHODS:
                high = state(packing, radius, theta, method, suction=1e7)
                lines.append(f" {kind.upper():8s} {theta:5.0f}  {method:9s}  {high.psi[0, 0] / 1e3:10.4f}"
                             f"             {limit / 1e3:.4f}")
    return lines


def crossover_suction(kind, method, contact_angle=30.0, radius=1e-4):
    """(suction [Pa] where chi s = B (Fig. 4.14) or None if chi s > B over the whole pendular range,
    the wettest pendular state)."""
    packing = regular_packing(kind)
    wettest = limit_state(packing, radius, contact_angle, method)
    lowest = wettest.suction * (1.0 + 1e-9)

    def excess(log_suction):
        s = state(packing, radius, contact_angle, method, suction=math.exp(log_suction))
        return s.chi[0, 0] * s.suction - s.B[0, 0]

    if excess(math.log(lowest)) > 0.0:
        return None, wettest
    return math.exp(brentq(excess, math.log(lowest), math.log(1e7), xtol=1e-10)), wettest


def crossovers():
    lines = ["Fig. 4.14 crossover (contact angle θ = 30°, R = 0.1 mm, H = 0): suction where chi s = B",
             " packing  method     crossover [kPa]   wettest pendular state: s [kPa], alpha [deg], Sr"]
    for kind in ("scp", "fcp"):
        for method in METHODS:
            value, wettest = crossover_suction(kind, method)
            text = f"{value / 1e3:10.4f}" if value else "      none"
            lines.append(f" {kind.upper():8s} {method:9s} {text}        {wettest.suction / 1e3:9.3g}  "
                         f"{wettest.filling_angle:7.3f}  {wettest.saturation:.4f}")
    return lines


def anisotropy_at_limits():
    lines = ["Fig. 4.19 end points (BCC, H = 0, contact angle θ = 0): fabric anisotropy a and a_psi at the pendular limit",
             " l'      a       alpha_max  | exact: Sr      a_psi   | toroidal: Sr   a_psi"]
    for l_prime in (2.1, 4.0 / math.sqrt(3.0), 2.4, 2.5, 2.6, 2.7):
        packing = regular_packing("bcc", l_prime)
        exact, toroidal = (limit_state(packing, method=method) for method in METHODS)
        lines.append(f" {l_prime:<6.4g} {packing.anisotropy:7.4f}  {packing.max_filling_angle:8.3f}  | "
                     f"{exact.saturation:8.4f}  {exact.a_psi:7.4f} | {toroidal.saturation:8.4f}  {toroidal.a_psi:7.4f}")
    return lines


def kim_comparison():
    lines = [f"Table 4.5 - Kim (2001) direct tension, F-75 sand, against psi (R = {KIM_RADIUS * 1e3} mm, "
             f"H/R = {KIM_SEPARATION}, Gs = {SPECIFIC_GRAVITY}); predicted tensile strength psi_ii [Pa] "
             "at contact angle θ = 0° and 20°",
             " e     w [%]  measured | packing (e)          exact θ=0°  exact θ=20°  toroidal θ=0°  toroidal θ=20°"]
    for void_ratio, water, measured in KIM_2001:
        kind, label = KIM_PACKINGS[void_ratio]
        packing = regular_packing(kind, separation=KIM_SEPARATION)
        predicted = []
        for method in METHODS:
            for theta in (0.0, 20.0):
                try:
                    predicted.append(f"{state(packing, KIM_RADIUS, theta, method, water_content=water).psi[0, 0]:9.1f}")
                except ValueError:
                    predicted.append("      n/a")
        lines.append(f" {void_ratio:.2f}  {100 * water:4.2f}  {measured:8.2f} | {label:13s} ({packing.void_ratio:.3f})"
                     f"  {predicted[0]}  {predicted[1]}    {predicted[2]}      {predicted[3]}")
    return lines


# ---------------------------------------------------------------- figures

def fig_4_6(plt, folder):
    fig, ax = plt.subplots(figsize=(5, 4))
    l_primes = np.linspace(2.0, 2.0 * math.sqrt(2.0), 200)
    ax.plot(l_primes, [regular_packing("bcc", lp).porosity for lp in l_primes], "k-", label="BCC")
    ax.axhline(regular_packing("scp").porosity, color="C0", ls="--", label="SCP")
    ax.axhline(regular_packing("fcp").porosity, color="C3", ls=":", label="FCP")
    ax.set(xlim=(2, 3), ylim=(0.25, 0.5), xlabel="l'", ylabel="porosity (n)", title="Fig. 4.6")
    ax.legend()
    save(fig, folder, "fig4_06_porosity.png")


def fig_4_7(plt, folder, points):
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for kind, color in (("scp", "C0"), ("fcp", "C3")):
        packing = regular_packing(kind)
        for method, style in METHODS.items():
            curve = saturation_curve(packing, points, method=method)
            for radius in (1e-4, 1e-6):
                scale = 1e-4 / radius
                ax.semilogy(percent(curve), scale * column(curve, "suction") / 1e3, style, color=color,
                            alpha=1.0 if radius == 1e-4 else 0.55,
                            label=f"{kind.upper()}, R = {radius * 1e3:g} mm" if method == "exact" else None)
    ax.set(xlim=(0, 25), ylim=(0.1, 1e6), xlabel="degree of saturation (Sr %)", ylabel="matric suction (kPa)",
           title="Fig. 4.7: H = 0, contact angle θ = 0 (solid exact, dashed toroidal)")
    ax.legend(fontsize=8)
    save(fig, folder, "fig4_07_swcc_particle_size.png")


def two_panels(plt, title):
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    fig.suptitle(title)
    return fig, axes


def panel_title(kind):
    """The title of a packing's panel: "(a) SCP" or "(b) FCP"."""
    return f"({'ab'[kind == 'fcp']}) {kind.upper()}"


def fig_4_8(plt, folder, points):
    fig, axes = two_panels(plt, "Fig. 4.8: contact angle θ (drying θ = 0°, wetting θ = 30°), H = 0")
    for ax, kind, xmax in zip(axes, ("scp", "fcp"), (30, 40)):
        packing = regular_packing(kind)
        for theta, color in ((0.0, "C0"), (30.0, "C3")):
            for method, style in METHODS.items():
                curve = saturation_curve(packing, points, contact_angle=theta, method=method)
                ax.semilogy(percent(curve), column(curve, "suction_star"), style, color=color,
                            label=f"contact angle θ = {theta:g}°" if method == "exact" else None)
        ax.set(xlim=(0, xmax), ylim=(0.01, 100), xlabel="degree of saturation (%)",
               ylabel="dimensionless matric suction s R / gamma", title=panel_title(kind))
        ax.legend()
    save(fig, folder, "fig4_08_swcc_contact_angle.png")


def separation_figure(plt, folder, points, title, separations, draw, name, **settings):
    """Figure ``name`` of two panels, SCP and FCP (Sr up to 20 and 30 %): a curve of each
    surface separation H/R of ``separations`` [-], exact and toroidal, each plotted by
    ``draw(ax, curve, style, color, label)``; ``settings``: the panels' other axes settings."""
    fig, axes = two_panels(plt, title)
    for ax, kind, xmax in zip(axes, ("scp", "fcp"), (20, 30)):
        for separation, color in zip(separations, ("C0", "C1", "C2", "C3")):
            packing = regular_packing(kind, separation=separation)
            for method, style in METHODS.items():
                curve = saturation_curve(packing, points, method=method)
                draw(ax, curve, style, color,
                     f"H/R = {separation:g}" if method == "exact" else None)
        ax.set(xlim=(0, xmax), title=panel_title(kind), **settings)
        ax.legend()
    save(fig, folder, name)


def fig_4_9(plt, folder, points):
    def draw(ax, curve, style, color, label):
        ax.semilogy(percent(curve), column(curve, "suction_star"), style, color=color,
                    label=label)

    separation_figure(plt, folder, points, "Fig. 4.9: separation distance, contact angle θ = 0",
                      (0.0, 0.05, 0.1), draw, "fig4_09_swcc_separation.png", ylim=(0.1, 100),
                      xlabel="degree of saturation (Sr %)",
                      ylabel="dimensionless matric suction s R / gamma")


def fig_4_10(plt, folder, points):
    def draw(ax, curve, style, color, label):
        ax.plot(percent(curve), diagonal(curve, "chi"), style, color=color, label=label)

    separation_figure(plt, folder, points, "Fig. 4.10: isotropic chi_ij, contact angle θ = 0",
                      (0.0, 0.05, 0.1, 0.2), draw, "fig4_10_chi.png", ylim=(0, 0.7),
                      xlabel="degree of saturation (%)", ylabel="chi_ij")


def fig_stress_components(plt, folder, points, kind, number, xmin):
    fig, axes = two_panels(plt, f"Fig. {number}: {kind.upper()}, R = 0.1 mm, H = 0")
    packing = regular_packing(kind)
    for theta, color in zip((0.0, 10.0, 20.0, 30.0), ("C0", "C1", "C2", "C3")):
        for method, style in METHODS.items():
            curve = suction_curve(packing, points, contact_angle=theta, method=method, smallest=xmin * 1e3)
            s = column(curve, "suction")
            label = f"contact angle θ = {theta:g}°" if method == "exact" else None
            axes[0].semilogx(s / 1e3, diagonal(curve, "chi") * s / 1e3, style, color=color, label=label)
            axes[1].semilogx(s / 1e3, diagonal(curve, "B") / 1e3, style, color=color, label=label)
    for ax, name, panel in zip(axes, ("chi_ij (ua - uw) (kPa)", "B_ij (kPa)"), "ab"):
        ax.set(xlim=(xmin, 1e4), xlabel="matric suction (kPa)", ylabel=name, title=f"({panel})")
        ax.set_ylim(bottom=0.0)
        ax.legend()
    save(fig, folder, f"fig{number.replace('.', '_')}_{kind}_stresses.png")


def fig_4_14(plt, folder, points):
    fig, axes = two_panels(plt, "Fig. 4.14: total capillary stress, R = 0.1 mm, contact angle θ = 30°, H = 0")
    for ax, kind, xmin in zip(axes, ("scp", "fcp"), (0.01, 1.0)):
        packing = regular_packing(kind)
        for method, style in METHODS.items():
            curve = suction_curve(packing, points, contact_angle=30.0, method=method, smallest=xmin * 1e3)
            s = column(curve, "suction")
            for values, name, color in ((diagonal(curve, "chi") * s, "chi_ij (ua - uw)", "C0"),
                                        (diagonal(curve, "B"), "B_ij", "C3"),
                                        (diagonal(curve, "psi"), "psi_ij", "k")):
                ax.semilogx(s / 1e3, values / 1e3, style, color=color, label=name if method == "exact" else None)
        ax.set(xlim=(xmin, 1e4), xlabel="matric suction (kPa)", ylabel="capillary stress (kPa)",
               title=panel_title(kind))
        ax.set_ylim(bottom=0.0)
        ax.legend()
    save(fig, folder, "fig4_14_total_capillary_stress.png")


def fig_4_15(plt, folder, points):
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for kind, name, color in (("fcp", "FCP", "C3"), ("bcc", "isotropic BCC", "C0")):
        packing = regular_packing(kind, separation=KIM_SEPARATION)
        for theta, width in ((0.0, 1.0), (20.0, 2.2)):
            for method, style in METHODS.items():
                curve = saturation_curve(packing, points, radius=KIM_RADIUS, contact_angle=theta, method=method)
                ax.plot(percent(curve, "water_content"), diagonal(curve, "psi"), style, color=color, lw=width,
                        label=f"predicted, {name} (e = {packing.void_ratio:.2f}), contact angle θ = {theta:g}°"
                        if method == "exact" else None)
    for void_ratio, marker in ((0.72, "o"), (0.58, "s")):
        rows = [(w, t) for e, w, t in KIM_2001 if e == void_ratio]
        ax.plot([100 * w for w, _ in rows], [t for _, t in rows], marker, color="k", mfc="none",
                label=f"Kim (2001), F-75, e = {void_ratio}")
    ax.set(xlim=(0, 3.5), ylim=(0, 1200), xlabel="gravimetric water content w (%)", ylabel="tensile strength (Pa)",
           title=f"Fig. 4.15: R = {KIM_RADIUS * 1e3} mm, H/R = {KIM_SEPARATION}")
    ax.legend(fontsize=7)
    save(fig, folder, "fig4_15_tensile_strength.png")


def fig_4_17(plt, folder, points):
    fig, axes = two_panels(plt, "Fig. 4.17: BCC l' = 2.7, R = 0.1 mm, H = 0, contact angle θ = 0: principal capillary stresses")
    packing = regular_packing("bcc", 2.7)
    for method, style in METHODS.items():
        curve = suction_curve(packing, points, method=method, smallest=1e3)
        s = column(curve, "suction")
        for ax, axis in zip(axes, (2, 0)):
            for values, name, color in ((diagonal(curve, "chi", axis) * s, "chi_ij (ua - uw)", "C0"),
                                        (diagonal(curve, "B", axis), "B_ij", "C3"),
                                        (diagonal(curve, "psi", axis), "psi_ij", "k")):
                ax.semilogx(s / 1e3, values / 1e3, style, color=color, label=name if method == "exact" else None)
    for ax, direction in zip(axes, ("axial (z)", "lateral (x)")):
        ax.set(xlim=(1, 1e4), xlabel="matric suction (kPa)", ylabel="capillary stress (kPa)", title=direction)
        ax.axhline(0.0, color="0.7", lw=0.8)
        ax.legend()
    save(fig, folder, "fig4_17_bcc_principal_stresses.png")


def fig_4_19(plt, folder, points):
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for l_prime, color in zip((2.7, 2.6, 2.5, 2.4, 4.0 / math.sqrt(3.0), 2.1), ("C0", "C1", "C2", "C3", "C4", "C5")):
        packing = regular_packing("bcc", l_prime)
        for method, style in METHODS.items():
            curve = saturation_curve(packing, points, method=method)
            ax.plot(percent(curve), column(curve, "a_psi"), style, color=color,
                    label=f"l' = {l_prime:.4g} (a = {packing.anisotropy:.3f})" if method == "exact" else None)
    ax.set(xlim=(0, 20), ylim=(-0.4, 0.8), xlabel="degree of saturation (%)", ylabel="anisotropy factor a_psi",
           title="Fig. 4.19: BCC, contact angle θ = 0, H = 0")
    ax.legend(fontsize=8)
    save(fig, folder, "fig4_19_anisotropy.png")


def save(fig, folder, name):
    """Write ``fig`` as ``name`` into the OutputFolder ``folder`` (which then owns it)."""
    save_figure(fig, folder.claim(name))
    print(f"  wrote {name}", flush=True)


#: States per curve of the figures.
POINTS = Parameter("1", "states per curve", 10, 400, kind=int, flag="--points")


def write_chapter4(out: str, points: int = 40) -> None:
    """Tables (printed and DIR/chapter4_tables.txt) and figures of thesis Chapter 4 into
    ``out`` (pendular.io.outputs.OutputFolder: ValueError naming the path when it cannot be an
    output folder); ``points`` states per curve (10-400)."""
    points = POINTS.check("points", points)
    with OutputFolder(out, "chapter4") as folder:
        start = time.time()
        sections = [table_4_1(), pendular_limits(), high_suction_limits(), crossovers(),
                    anisotropy_at_limits(), kim_comparison()]
        text = "\n\n".join("\n".join(lines) for lines in sections)
        print(text, flush=True)
        write_text(folder.claim("chapter4_tables.txt"), text + "\n")

        plt = pyplot()
        fig_4_6(plt, folder)
        fig_4_7(plt, folder, points)
        fig_4_8(plt, folder, points)
        fig_4_9(plt, folder, points)
        fig_4_10(plt, folder, points)
        fig_stress_components(plt, folder, points, "scp", "4.12", 0.01)
        fig_stress_components(plt, folder, points, "fcp", "4.13", 1.0)
        fig_4_14(plt, folder, points)
        fig_4_15(plt, folder, points)
        fig_4_17(plt, folder, points)
        fig_4_19(plt, folder, points)
    print(f"done in {time.time() - start:.0f} s; outputs in {out}")
