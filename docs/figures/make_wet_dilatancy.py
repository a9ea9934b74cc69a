"""Wet against dry dilatancy at a low confining stress, pendular and YADE on the same packing.

    python docs/figures/make_wet_dilatancy.py [--particles 1000] [--confining 500]
        [--suction 30000] [--max-strain 0.15] [--out runs/wet_dilatancy] [--reuse]

1. ``pendular crosscheck`` dry and at ``--suction`` (the same cached sample, wetted and settled
   at ``--confining``; both codes shear the exported packing, docs/yade_crosscheck.md) into
   OUT/dry and OUT/wet.
2. The mechanism's tests, pendular alone, on one sample of half as many spheres prepared by the
   first (``pendular triaxial`` into OUT/triaxial_*): dry; wet as the cross-check (bridges
   added to the static sample, which they compact, then equilibrated); wet with the bridges
   switched on at the first step of the shear (``--wetting at-shear``: the dry sample's density
   and contacts); wet with bridges kept to their rupture distance (``--persist-bridges``).

``--reuse`` takes the runs already finished in OUT. Writes docs/figures/wet_dilatancy.png
(volumetric strain, stress ratios, coordination and Sr against axial strain, the
cross-checks) and docs/figures/wet_dilatancy.json: per run (and code) the peak of q and its
companions, the largest dilation and dilatancy rate, the contact stress of Eq. 3.41 against the
net (wall) stress, the mean capillary stress (-p of the capillary forces' Love-Weber stress),
coordination, Sr and bridges (``measures``), and ``substitutions``, the same
as text for the docs (``{{ dilatancy_wet_yade_max_dilatancy_rate }}``). Stresses [Pa]
compression positive, strains contraction positive.
"""

import argparse
import datetime
import json
import os
import platform
import subprocess
import sys

import numpy as np

from pendular.homogenize.invariants import mean_stress, stress_ratio
from pendular.interop.yade.formats import read_spheres
from pendular.interop.yade.runner import yade_history
from pendular.io.history import read_history
from pendular.io.plots import pyplot, save_figure

HERE = os.path.dirname(os.path.abspath(__file__))
#: Strain window of the dilatancy rate -d(eps_v)/d(eps_a) [-].
RATE_WINDOW = 0.01
#: Axial strains [-] between which the energy balance is taken: after the peak, dilating.
ENERGY_WINDOW = (0.05, 0.10)


#: The mechanism's tests: run name -> ``pendular triaxial`` options beyond the sample's.
VARIANTS = {"dry": [], "wet": ["--suction", "SUCTION"],
            "wet_at_shear": ["--suction", "SUCTION", "--wetting", "at-shear"],
            "wet_persist": ["--suction", "SUCTION", "--persist-bridges"]}


def arrays(path):
    """A pendular history (file or run folder) as a dict of NumPy arrays."""
    ours = read_history(path, index="record")
    history = {name: np.asarray(ours[name]) for name in ours.data_vars}
    history["axial_strain"] = np.asarray(ours["axial_strain"])
    return history


def histories(folder):
    """{"pendular": ..., "yade": ...}: each a dict of NumPy arrays of one cross-check folder."""
    pendular = arrays(os.path.join(folder, "pendular_history.h5"))
    _, _, lo, hi = read_spheres(os.path.join(folder, "packing.txt"))
    yade = yade_history(os.path.join(folder, "yade_history.txt"), float(np.prod(hi - lo)))
    return {"pendular": pendular, "yade": yade}


def dilatancy_rate(strain, volumetric):
    """Largest -d(eps_v)/d(eps_a) over a window of RATE_WINDOW axial strain [-], and where."""
    ahead = np.searchsorted(strain, strain + RATE_WINDOW)
    valid = ahead < len(strain)
    rates = np.full(len(strain), -np.inf)
    rates[valid] = -(volumetric[ahead[valid]] - volumetric[valid]) / (
        strain[ahead[valid]] - strain[valid])
    k = int(np.argmax(rates))
    return float(rates[k]), float(strain[k] + 0.5 * RATE_WINDOW)


def energy_balance(history):
    """Taylor's energy balance over ENERGY_WINDOW, the net stress working on the boundary and
    the contact stress (Eq. 3.41) dissipating: q deps_q + p deps_v = M p_contact deps_q, so
    M = (q/p - D) p / p_contact with D = -deps_v/deps_q (eps_q = eps_a - eps_v / 3, the slope
    of a least-squares line) and q, p, p_contact the window's means. Dry, p_contact = p and M is
    Taylor's (Cam clay's) frictional constant."""
    strain, volumetric = history["axial_strain"], history["volumetric_strain"]
    inside = (strain >= ENERGY_WINDOW[0]) & (strain <= ENERGY_WINDOW[1])
    sigma = history["sigma_wall"][inside]
    q = float(np.mean(sigma[:, 2] - 0.5 * (sigma[:, 0] + sigma[:, 1])))
    p = float(np.mean(mean_stress(sigma)))
    contact = float(np.mean(mean_stress(np.diagonal(history["sigma_contact"][inside],
                                                    axis1=-2, axis2=-1))))
    shear = strain[inside] - volumetric[inside] / 3.0
    dilatancy = -float(np.polyfit(shear, volumetric[inside], 1)[0])
    return {"energy_dilatancy": dilatancy, "energy_q_over_p": q / p,
            "energy_p_contact_over_p": contact / p,
            "energy_dissipation_m": (q / p - dilatancy) * p / contact}


def measures(history):
    """The numbers of one code's shear (module docstring)."""
    strain, volumetric = history["axial_strain"], history["volumetric_strain"]
    sigma = history["sigma_wall"]
    q = sigma[:, 2] - 0.5 * (sigma[:, 0] + sigma[:, 1])
    peak = int(np.argmax(q))
    most = int(np.argmin(volumetric))
    rate, at = dilatancy_rate(strain, volumetric)
    out = {"porosity_start": float(history["porosity"][0]), "peak_q": float(q[peak]),
           "axial_strain_at_peak": float(strain[peak]),
           "q_over_p_at_peak": float(stress_ratio(sigma)[peak]),
           "volumetric_strain_at_peak": float(volumetric[peak]),
           "largest_dilation": float(-volumetric[most]),
           "axial_strain_at_largest_dilation": float(strain[most]),
           "volumetric_strain_final": float(volumetric[-1]),
           "max_dilatancy_rate": rate, "axial_strain_at_max_dilatancy_rate": at}
    if "saturation" in history:
        out.update({f"saturation_{when}": float(history["saturation"][k])
                    for when, k in (("start", 0), ("peak", peak), ("final", -1))})
        out.update({f"bridges_{when}": int(history["bridges"][k])
                    for when, k in (("start", 0), ("peak", peak), ("final", -1))})
    if "sigma_contact" in history:
        contact = np.diagonal(history["sigma_contact"], axis1=-2, axis2=-1)
        ratio = mean_stress(contact) / mean_stress(sigma)
        out.update({"p_contact_over_p_start": float(ratio[0]),
                    "p_contact_over_p_peak": float(ratio[peak]),
                    "p_contact_over_p_final": float(ratio[-1]),
                    "q_over_p_contact_at_peak": float(stress_ratio(contact)[peak]),
                    **energy_balance(history)})
    if "sigma_capillary" in history:
        capillary = -mean_stress(np.diagonal(history["sigma_capillary"], axis1=-2, axis2=-1))
        out.update({f"p_capillary_{when}": float(capillary[k])
                    for when, k in (("start", 0), ("peak", peak), ("final", -1))})
    if "coordination" in history:
        out.update({f"coordination_{when}": float(history["coordination"][k])
                    for when, k in (("start", 0), ("peak", peak), ("final", -1))})
    return out


def figure(cases, path, title):
    """Four panels against axial strain [%]: eps_v, q/p (net, and pendular's contact stress),
    pendular's coordination, Sr of both codes."""
    plt = pyplot()
    fig, ((ev, ratio), (coord, sat)) = plt.subplots(2, 2, figsize=(10, 7), sharex=True)
    styles = {"pendular": "-", "yade": "--"}
    colours = {"dry": "C0", "wet": "C3"}
    for case, codes in cases.items():
        for code, h in codes.items():
            strain = 100.0 * h["axial_strain"]
            label = f"{case}, {'YADE' if code == 'yade' else code}"
            kw = {"color": colours[case], "ls": styles[code], "lw": 1.2}
            ev.plot(strain, 100.0 * h["volumetric_strain"], label=label, **kw)
            ratio.plot(strain, stress_ratio(h["sigma_wall"]), label=f"q/p net, {label}", **kw)
            if code == "pendular":
                if case == "wet":
                    contact = np.diagonal(h["sigma_contact"], axis1=-2, axis2=-1)
                    ratio.plot(strain, stress_ratio(contact), color="C2", lw=1.2,
                               label="q/p of the contact stress (Eq. 3.41), wet, pendular")
                coord.plot(strain, h["coordination"], label=label, **kw)
            if "saturation" in h:
                sat.plot(strain, 100.0 * h["saturation"], label=label, **kw)
    ev.set_ylabel("volumetric strain εv [%] (contraction +)")
    ratio.set_ylabel("stress ratio q/p [-]")
    coord.set_ylabel("coordination Z [-]")
    sat.set_ylabel("degree of saturation Sr [%]")
    for axes in (ev, ratio, coord, sat):
        axes.grid(alpha=0.3)
        axes.legend(fontsize=7)
    for axes in (coord, sat):
        axes.set_xlabel("axial strain εa [%]")
    fig.suptitle(title, fontsize=10)
    save_figure(fig, path)


def substitutions(numbers):
    """Every measure as text (strains and Sr in %; three significant digits, whole numbers
    from 100 on), named dilatancy_<run>_<code>_<measure>."""
    text = {}
    for run, codes in numbers.items():
        for code, values in codes.items():
            for key, value in values.items():
                if key.startswith(("volumetric", "largest", "axial", "saturation")):
                    value = 100.0 * value
                text[f"dilatancy_{run}_{code}_{key}"] = (
                    f"{value:,.0f}" if abs(value) >= 100.0 else f"{value:#.3g}")
    return text


def run(argv, folder, reuse, done):
    """``python -m pendular argv --out folder`` unless ``reuse`` and ``done`` is there."""
    if not (reuse and os.path.isfile(os.path.join(folder, done))):
        subprocess.run([sys.executable, "-m", "pendular", *argv, "--out", folder], check=True)
    return "pendular " + " ".join(argv) + " --out " + folder


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--particles", type=int, default=1000)
    parser.add_argument("--confining", type=float, default=500.0, help="[Pa]")
    parser.add_argument("--suction", type=float, default=30000.0, help="[Pa]")
    parser.add_argument("--max-strain", type=float, default=0.15)
    parser.add_argument("--out", default=os.path.join("runs", "wet_dilatancy"))
    parser.add_argument("--reuse", action="store_true",
                        help="take the runs already finished in --out")
    parser.add_argument("--machine", default=f"{platform.machine()}, {os.cpu_count()} cores")
    args = parser.parse_args(argv)
    common = ["--confining", f"{args.confining:g}", "--max-strain", f"{args.max_strain:g}",
              "--quiet"]
    commands, cases, numbers = {}, {}, {}
    for case, suction in (("dry", 0.0), ("wet", args.suction)):
        folder = os.path.join(args.out, case)
        commands[f"crosscheck_{case}"] = run(
            ["crosscheck", "--particles", str(args.particles), "--suction", f"{suction:g}",
             "--concurrent", *common], folder, args.reuse, "crosscheck.json")
        cases[case] = histories(folder)
        numbers[f"crosscheck_{case}"] = {code: measures(h) for code, h in cases[case].items()}
    sample = os.path.join(args.out, "triaxial_dry", "sample.h5")
    for name, options in VARIANTS.items():
        options = [f"{args.suction:g}" if o == "SUCTION" else o for o in options]
        given = [] if name == "dry" else ["--sample", sample]
        folder = os.path.join(args.out, f"triaxial_{name}")
        commands[name] = run(["triaxial", "--particles", str(args.particles // 2), *given,
                              *options, "--threads", "1", *common],
                             folder, args.reuse, "summary.json")
        numbers[name] = {"pendular": measures(arrays(folder))}
    title = (f"{args.particles} spheres, σ3 = {args.confining:g} Pa, dry and s = "
             f"{args.suction / 1000:g} kPa: pendular (solid) and YADE (dashed), same packing")
    figure(cases, os.path.join(HERE, "wet_dilatancy.png"), title)
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d")
    record = {"script": "python docs/figures/make_wet_dilatancy.py", "commands": commands,
              "date": date, "machine": args.machine, "rate_window": RATE_WINDOW,
              "substitutions": {**substitutions(numbers), "dilatancy_date": date,
                                "dilatancy_machine": args.machine},
              "measures": numbers}
    with open(os.path.join(HERE, "wet_dilatancy.json"), "w", encoding="utf-8") as handle:
        json.dump(record, handle, indent=1, ensure_ascii=False)
        handle.write("\n")
    print(json.dumps(numbers, indent=1))


if __name__ == "__main__":
    main()
