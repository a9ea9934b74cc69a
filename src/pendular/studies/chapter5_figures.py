"""Figures of a Chapter 5 campaign (thesis Figs. 5.3–5.8) from its runs' histories.

Every function takes the campaign's ``runs`` rows (pendular.studies.chapter5) or the histories
read by ``load_histories`` and writes one PNG. Stresses in the histories are compression
positive [Pa]; the figures show stresses in kPa and strains in %.
"""

import math
import os

import h5py
import numpy as np

from pendular.homogenize.fabric import principal_anisotropy
from pendular.homogenize.invariants import deviator_stress, mean_stress

from pendular.io.plots import pyplot, save_figure

#: History columns the figures use (the rest of a history is not read).
COLUMNS = ("axial_strain", "volumetric_strain", "sigma_wall", "sigma_effective", "psi",
           "fabric", "fabric_bridges", "saturation")


def load_histories(out, runs):
    """{(suction, confining): {column: array}} of the runs' history.h5 files (COLUMNS present)."""
    histories = {}
    for run in runs:
        with h5py.File(os.path.join(out, run["folder"], "history.h5"), "r") as handle:
            group = handle["history"]
            histories[(run["suction"], run["confining"])] = {
                key: group[key][:] for key in COLUMNS if key in group}
    return histories


def invariants(sigma):
    """(p, q) [Pa] of (rows, 3) principal stresses or (rows, 3, 3) tensors (their diagonals),
    z axial (pendular.homogenize.invariants)."""
    sigma = np.asarray(sigma)
    if sigma.ndim == 3:
        sigma = np.diagonal(sigma, axis1=1, axis2=2)
    return mean_stress(sigma), deviator_stress(sigma)


def effective_invariants(history):
    """(p', q') [Pa] of a history: sigma_effective (Eq. 3.43) when wet, the wall stress when
    dry (psi = 0)."""
    return invariants(history.get("sigma_effective", history["sigma_wall"]))


def reference_confining(confining):
    """The lateral stress the single-confining figures show: 750 Pa (thesis) when run, else the
    median of those run."""
    values = sorted(set(confining))
    return 750.0 if 750.0 in values else values[len(values) // 2]


def _suction_label(suction):
    return "dry" if suction == 0 else f"s = {suction / 1000:g} kPa"


def plot_curves(path, histories, confining):
    """Fig. 5.3: (a) deviatoric stress q [kPa] and (b) volumetric strain against axial strain,
    one curve per suction at lateral stress ``confining``."""
    plt = pyplot()
    figure, (top, bottom) = plt.subplots(2, 1, figsize=(6.5, 7), sharex=True)
    for (suction, lateral), history in sorted(histories.items()):
        if lateral != confining:
            continue
        _, q = invariants(history["sigma_wall"])
        top.plot(100 * history["axial_strain"], q / 1000, label=_suction_label(suction))
        bottom.plot(100 * history["axial_strain"], 100 * history["volumetric_strain"])
    top.set_ylabel("q [kPa]")
    top.set_title(f"lateral stress {confining / 1000:g} kPa (thesis Fig. 5.3)")
    top.legend(fontsize=8)
    bottom.set_ylabel("volumetric strain [%] (contraction +)")
    bottom.set_xlabel("axial strain [%]")
    return save_figure(figure, path)


def plot_effective_curves(path, histories, confining):
    """Fig. 5.7: q/p in net stress and q'/p' in effective stress (Eq. 3.43) against axial
    strain at lateral stress ``confining``; with Eq. 3.43 the wet curves should merge with the
    dry one."""
    plt = pyplot()
    figure, axes = plt.subplots(figsize=(6.5, 4.5))
    for index, ((suction, lateral), history) in enumerate(sorted(histories.items())):
        if lateral != confining:
            continue
        strain = 100 * history["axial_strain"]
        p, q = invariants(history["sigma_wall"])
        if suction == 0:
            axes.plot(strain, q / p, "k-", lw=2, label="dry")
            continue
        p_eff, q_eff = effective_invariants(history)
        axes.plot(strain, q / p, ":", color=f"C{index}", label=f"net, {_suction_label(suction)}")
        axes.plot(strain, q_eff / p_eff, "-", color=f"C{index}",
                  label=f"effective, {_suction_label(suction)}")
    axes.set_xlabel("axial strain [%]")
    axes.set_ylabel("q/p, q'/p'")
    axes.set_title(f"lateral stress {confining / 1000:g} kPa (thesis Fig. 5.7)")
    axes.legend(fontsize=7)
    return save_figure(figure, path)


def directional(tensor, angles):
    """n . T . n for unit vectors n = (sin a, 0, cos a) in the x–z plane, a from the axial
    (z) direction [rad]: the directional value of a second-order tensor (polar plots)."""
    tensor = np.asarray(tensor)
    sin, cos = np.sin(angles), np.cos(angles)
    return (tensor[0, 0] * sin**2 + 2 * tensor[0, 2] * sin * cos + tensor[2, 2] * cos**2)


def record_at(history, strain):
    """Index of the record nearest axial ``strain``."""
    return int(np.argmin(np.abs(history["axial_strain"] - strain)))


def plot_polar(path, series, title, unit):
    """A polar diagram (axial direction up) of n . T . n in the x–z plane for each
    (label, tensor) of ``series``; ``unit`` labels the radial axis."""
    plt = pyplot()
    angles = np.linspace(0.0, 2 * math.pi, 361)
    figure = plt.figure(figsize=(5.5, 5.5))
    axes = figure.add_subplot(projection="polar")
    axes.set_theta_zero_location("N")
    for name, tensor in series:
        axes.plot(angles, directional(tensor, angles), label=name)
    axes.set_title(f"{title}\n[{unit}], axial direction up", fontsize=10)
    axes.legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.1, -0.15))
    return save_figure(figure, path)


def polar_figures(folder, histories, confining, strain):
    """Fig. 5.5 (psi, kPa, by suction) and the contact and bridge fabric (by suction) at axial
    ``strain``, lateral stress ``confining``; returns the paths written."""
    chosen = [(suction, history) for (suction, lateral), history in sorted(histories.items())
              if lateral == confining]
    paths = []
    at = f"at axial strain {100 * strain:g} %, lateral stress {confining / 1000:g} kPa"
    wet = [(s, h) for s, h in chosen if "psi" in h]
    if wet:
        series = [(f"{_suction_label(s)}, Sr = {100 * h['saturation'][record_at(h, strain)]:.2f} %",
                   h["psi"][record_at(h, strain)] / 1000) for s, h in wet]
        paths.append(plot_polar(os.path.join(folder, "polar_psi.png"), series,
                                f"capillary stress psi (Eq. 3.46) {at} (thesis Fig. 5.5)",
                                "kPa"))
    series = [(f"contacts, {_suction_label(s)}", h["fabric"][record_at(h, strain)])
              for s, h in chosen]
    series += [(f"bridges, {_suction_label(s)}", h["fabric_bridges"][record_at(h, strain)])
               for s, h in wet]
    paths.append(plot_polar(os.path.join(folder, "polar_fabric.png"), series,
                            f"fabric tensors (Eqs. 3.50, 3.53) {at}", "-"))
    return paths


def plot_anisotropy(path, history, suction, confining):
    """Fig. 5.8: anisotropy factor a = 5/2 (T_z - T_x) / tr T of the effective stress (Eq. 3.43)
    and of the capillary stress psi (Eq. 4.5) against axial strain."""
    plt = pyplot()
    figure, axes = plt.subplots(figsize=(6.5, 4.5))
    strain = 100 * history["axial_strain"]
    for key, name in (("sigma_effective", "effective stress"), ("psi", "capillary stress")):
        axes.plot(strain, [principal_anisotropy(t) for t in history[key]], label=name)
    axes.set_xlabel("axial strain [%]")
    axes.set_ylabel("anisotropy factor")
    axes.set_title(f"{_suction_label(suction)}, lateral stress {confining / 1000:g} kPa "
                   "(thesis Fig. 5.8)")
    axes.legend()
    return save_figure(figure, path)


def _line(phi_deg, cohesion, p_max):
    """p and q of the Mohr–Coulomb line q = M p + q0 (pendular.studies.envelope) over [0, p_max]."""
    sin_phi = math.sin(math.radians(phi_deg))
    slope = 6 * sin_phi / (3 - sin_phi)
    q0 = cohesion * 6 * math.cos(math.radians(phi_deg)) / (3 - sin_phi)
    p = np.array([0.0, p_max])
    return p, slope * p + q0


def _kpa(points):
    """(p, q) [Pa] as kPa."""
    return tuple(np.asarray(values) / 1000 for values in points)


def plot_envelopes(path, runs, fits, label):
    """Figs. 5.4 and 5.6: failure points (p, q), (p', q') of Eq. 3.43 and those of the
    complete effective stress (psi plus the interface term), with each suction's fit and the
    dry line; ``label(suction)`` is the key of ``fits``."""
    plt = pyplot()
    figure, panels = plt.subplots(1, 3, figsize=(16, 4.5))
    p_max = max(max(r["p_at_peak"], r["p_effective_at_peak"],
                    r["p_effective_complete_at_peak"]) for r in runs) * 1.1
    dry = fits.get(label(0.0))
    for axes, (pk, qk, phik, ck, title) in zip(panels, (
            ("p_at_peak", "peak_q", "phi_deg", "cohesion", "net stress (Figs. 5.4, 5.6a)"),
            ("p_effective_at_peak", "peak_q_effective", "phi_eff_deg", "cohesion_eff",
             "effective stress, Eq. 3.43 (Fig. 5.6b)"),
            ("p_effective_complete_at_peak", "peak_q_effective_complete",
             "phi_eff_complete_deg", "cohesion_eff_complete",
             "complete effective stress (psi + interface)"))):
        for index, suction in enumerate(sorted({r["suction"] for r in runs})):
            rows = [r for r in runs if r["suction"] == suction]
            color = f"C{index}"
            axes.plot([r[pk] / 1000 for r in rows], [r[qk] / 1000 for r in rows], "o",
                      color=color,
                      label=_suction_label(suction))
            fit = fits.get(label(suction))
            if fit and fit[phik] is not None and suction != 0:
                axes.plot(*_kpa(_line(fit[phik], fit[ck], p_max)), "--", color=color, lw=1)
        if dry and dry["phi_deg"] is not None:
            axes.plot(*_kpa(_line(dry["phi_deg"], dry["cohesion"], p_max)), "k-", lw=1.5,
                      label=f"dry line, phi = {dry['phi_deg']:.1f} deg")
        axes.set_xlim(0, p_max / 1000)
        axes.set_ylim(bottom=0)
        axes.set_xlabel("p' [kPa]" if "effective" in pk else "p [kPa]")
        axes.set_ylabel("q' [kPa]" if "effective" in pk else "q [kPa]")
        axes.set_title(title)
        axes.legend(fontsize=8)
    return save_figure(figure, path)


def campaign_figures(out, runs, fits, label, strain=0.20):
    """Every campaign figure into ``out``/plots; returns {name: path}. The single-confining
    figures show 750 Pa (reference_confining); polar plots at axial ``strain`` (Fig. 5.5: 20 %;
    the nearest record in shorter runs); Fig. 5.8 at 30 kPa when run, else the lowest wet
    suction."""
    folder = os.path.join(out, "plots")
    histories = load_histories(out, runs)
    confining = reference_confining([r["confining"] for r in runs])
    figures = {"envelopes": plot_envelopes(os.path.join(folder, "envelopes.png"), runs, fits,
                                           label),
               "curves": plot_curves(os.path.join(folder, "q_ev.png"), histories, confining),
               "effective_curves": plot_effective_curves(
                   os.path.join(folder, "q_p_effective.png"), histories, confining)}
    for path in polar_figures(folder, histories, confining, strain):
        figures[os.path.splitext(os.path.basename(path))[0]] = path
    wet = sorted(s for (s, c), h in histories.items() if c == confining and "psi" in h)
    if wet:
        suction = 30000.0 if 30000.0 in wet else wet[0]
        figures["anisotropy"] = plot_anisotropy(os.path.join(folder, "anisotropy.png"),
                                                histories[(suction, confining)], suction,
                                                confining)
    return figures
