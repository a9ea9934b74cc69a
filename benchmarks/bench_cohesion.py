"""Cohesion of wet triaxial samples against the water content, pendular bridges alone and with
liquid clusters (after Richefeu, El Youssoufi & Radjaï 2006, who found in direct shear that
the cohesion of wet glass beads rises with the water content, then levels off).

    python benchmarks/bench_cohesion.py [--particles 1000] [--confining 750,1500,3000]
        [--suctions 300000,60000,30000,20000,15000,10000] [--max-strain 0.15] [--workers 2]
        [--out runs/cohesion]

One sample per confining stress (thesis Ch. 5.2.2 defaults, R = 24 µm, the same seed), saved
under ``out``/samples/; from it, drained triaxial compressions (thesis defaults but
``--max-strain``): dry, and at each suction with persisting suction-controlled bridges alone
(``--liquid pendular --persist-bridges``) and with liquid clusters (``--liquid clusters``: the
same bridges, plus the pore units filled on wetting from dry). A run whose summary.json is
complete is not run again, nor one the guard stopped
(pendular.procedures.guards.SampleCrushed: an overlap of a quarter radius, where the capillary
forces of the soft default spheres, E = 1 MPa, meet the highest stresses), whose history up
to there, and peak if reached, is kept. From the peaks (q, p) at the confining stresses of
each case, the Mohr–Coulomb line q = M p + q0 of triaxial compression gives the friction
angle, sin phi = 3 M / (6 + M), and the cohesion c = q0 (3 - sin phi) / (6 cos phi), in net
stress and in the effective stress p' = p + chi s (Eq. 3.43's form, u_a = 0; chi = tr chi / 3
at the peak: the bridges' Eq. 3.44, or chi with clusters, pendular.homogenize.clusters); and
each peak's distance to the dry envelope at its p'. Above ``--clusters-below`` no pore unit
fills, and the pendular run stands for the clusters' (continuity). The water content is the
wetted sample's, w = Sr e / Gs. Writes ``out``/cohesion.json and cohesion.png
(docs/liquid_clusters.md 'Shear').
"""

import argparse
import json
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

import numpy as np

from pendular import BridgeConfig, PrepareConfig, ShearConfig, TriaxialConfig, TriaxialTest
from pendular import read_history
from pendular.dem.sample import save_sample
from pendular.procedures.config import WATER_DENSITY, config_to_dict
from pendular.procedures.guards import SampleCrushed
from pendular.procedures.preparation import prepare_sample


def sample_file(out, particles, confining):
    """The prepared sample of ``particles`` spheres at ``confining`` [Pa] (made once)."""
    path = os.path.join(out, "samples", f"sample_{particles}_{confining:g}.h5")
    if not os.path.exists(path):
        config = PrepareConfig(particles=particles, confining=confining)
        sim, report = prepare_sample(config, progress=False, threads=1)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        save_sample(path, sim, report, {"sample": config_to_dict(config)},
                    identity={"seed": config.seed})
    return path


def case_name(liquid, suction, confining):
    return f"{liquid}_s{suction / 1e3:g}kPa_c{confining:g}Pa"


def run_case(args):
    """Run one triaxial (if not done); its figures at the peak."""
    out, particles, liquid, suction, confining, max_strain = args
    folder = os.path.join(out, "runs", case_name(liquid, suction, confining))
    done = os.path.join(folder, "summary.json")
    if not (os.path.exists(done) and (json.load(open(done)).get("completed")
                                      or "crushed" in json.load(open(done)).get("error", ""))):
        bridges = None if suction == 0.0 else BridgeConfig(suction, persist=True)
        config = TriaxialConfig(
            sample=PrepareConfig(particles=particles, confining=confining),
            shear=ShearConfig(max_strain=max_strain), bridges=bridges, vtk_frames=0,
            sample_path=sample_file(out, particles, confining),
            liquid="clusters" if liquid == "clusters" else "pendular")
        try:
            TriaxialTest(config).run(folder, progress=False, plots=False, threads=1)
        except SampleCrushed:       # its history to there is kept: the peak, if before
            pass
    summary = json.load(open(done))
    history = read_history(os.path.join(folder, "history.h5"))
    peak = summary["peak_index"]
    row = {"liquid": liquid, "suction": suction, "confining": confining,
           "peak_q": summary["peak_q"], "p_at_peak": summary["p_at_peak"],
           "axial_strain_at_peak": summary["axial_strain_at_peak"],
           "peak_reached": summary["peak_reached"], "crushed": summary.get("error"),
           "wall_time_s": summary["wall_time_s"], "shear_time_s": summary["shear_time_s"],
           "steps": summary["steps"]}
    if suction > 0.0:
        chi_name = "chi_with_clusters" if liquid == "clusters" else "chi"
        chi = float(np.trace(history[chi_name].values[peak]) / 3.0)
        porosity = summary["porosity_after_wetting"]
        density = PrepareConfig(particles=particles).density
        row.update({"chi_at_peak": chi,
                    "p_effective_at_peak": summary["p_at_peak"] + chi * suction,
                    "saturation_wet": summary["initial_saturation"],
                    "water_content": summary["initial_saturation"] * porosity / (1 - porosity)
                    / (density / WATER_DENSITY)})
        if liquid == "clusters":
            row.update({"clusters_at_peak": summary["clusters_at_peak"],
                        "clusters_wet": summary["clusters_wet"],
                        "cluster_updates": summary["cluster_updates"],
                        "cluster_update_time_s": summary["cluster_update_time_s"]})
    else:
        row.update({"chi_at_peak": 0.0, "p_effective_at_peak": summary["p_at_peak"],
                    "water_content": 0.0})
    return row


def mohr_coulomb(p, q):
    """(c [Pa], phi [deg]) of the line q = M p + q0 through the peaks of triaxial
    compression (least squares)."""
    slope, intercept = np.polyfit(np.asarray(p), np.asarray(q), 1)
    sine = 3.0 * slope / (6.0 + slope)
    cohesion = intercept * (3.0 - sine) / (6.0 * np.sqrt(1.0 - sine ** 2))
    return float(cohesion), float(np.degrees(np.arcsin(sine)))


def envelopes(rows):
    """Per (liquid, suction): the peaks, c and phi in net and effective stress, w."""
    cases = {}
    for row in rows:
        cases.setdefault((row["liquid"], row["suction"]), []).append(row)
    table = []
    for (liquid, suction), group in sorted(cases.items(), key=lambda kv: (kv[0][0], -kv[0][1])):
        group.sort(key=lambda r: r["confining"])
        p = [r["p_at_peak"] for r in group]
        q = [r["peak_q"] for r in group]
        c, phi = mohr_coulomb(p, q)
        c_eff, phi_eff = mohr_coulomb([r["p_effective_at_peak"] for r in group], q)
        table.append({"liquid": liquid, "suction": suction,
                      "water_content": float(np.mean([r["water_content"] for r in group])),
                      "cohesion": c, "phi_deg": phi, "cohesion_effective": c_eff,
                      "phi_effective_deg": phi_eff,
                      "chi_at_peak": [r["chi_at_peak"] for r in group],
                      "confining": [r["confining"] for r in group], "peak_q": q,
                      "p_at_peak": p})
    return table


def plot(table, rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    dry = next(r for r in table if r["liquid"] == "dry")
    for liquid, marker, colour in (("pendular", "o", "C0"), ("clusters", "s", "C1")):
        chosen = sorted([dry] + [r for r in table if r["liquid"] == liquid],
                        key=lambda r: r["water_content"])
        w = [100 * r["water_content"] for r in chosen]
        left.plot(w, [r["cohesion"] / 1e3 for r in chosen], marker=marker, color=colour,
                  label=f"{liquid}: c (net stress)")
        left.plot(w, [r["cohesion_effective"] / 1e3 for r in chosen], marker=marker,
                  color=colour, ls=":", mfc="none", label=f"{liquid}: c' (p' = p + chi s)")
    left.axhline(0.0, color="k", lw=0.5)
    left.set_xscale("symlog", linthresh=0.1)
    left.set_xlim(left=0.0)
    left.set_xlabel("water content w [%] (linear below 0.1 %)")
    left.set_ylabel("cohesion [kPa]")
    left.legend(fontsize=8)
    left.set_title("cohesion against water content")
    for row in rows:
        if row.get("same_as_pendular"):
            continue
        colour = {"dry": "k", "pendular": "C0", "clusters": "C1"}[row["liquid"]]
        right.plot(row["p_effective_at_peak"] / 1e3, row["peak_q"] / 1e3,
                   "s" if row["liquid"] == "clusters" else "o", color=colour, ms=4)
    p = np.linspace(0, max(r["p_effective_at_peak"] for r in rows), 50)
    sine = np.sin(np.radians(dry["phi_deg"]))
    right.plot(p / 1e3, (6 * sine / (3 - sine) * p + 6 * dry["cohesion"] * np.cos(
        np.radians(dry["phi_deg"])) / (3 - sine)) / 1e3, "k-", lw=0.8, label="dry envelope")
    right.set_xlabel("p' = p + chi s at the peak [kPa]")
    right.set_ylabel("peak q [kPa]")
    right.set_title("peaks (black dry, blue pendular, orange clusters)")
    right.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=120)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--particles", type=int, default=1000)
    parser.add_argument("--confining", default="750,1500,3000")
    parser.add_argument("--suctions",
                        default="300000,60000,30000,25000,20000,15000,12000,10000")
    parser.add_argument("--clusters-below", type=float, default=60000.0,
                        help="run --liquid clusters at the suctions up to this one [Pa] (above, "
                             "no pore unit fills: the pendular run, bit for bit)")
    parser.add_argument("--max-strain", type=float, default=0.15)
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--out", default="runs/cohesion")
    args = parser.parse_args(argv)
    confinings = [float(v) for v in args.confining.split(",")]
    suctions = [float(v) for v in args.suctions.split(",")]
    os.makedirs(args.out, exist_ok=True)
    for confining in confinings:           # the samples first, once
        sample_file(args.out, args.particles, confining)
    cases = [("dry", 0.0, c) for c in confinings]
    for s in suctions:
        cases += [(liquid, s, c) for liquid in ("clusters", "pendular") for c in confinings
                  if liquid == "pendular" or s <= args.clusters_below]
    started = time.perf_counter()
    jobs = [(args.out, args.particles, liquid, s, c, args.max_strain) for liquid, s, c in cases]
    with ProcessPoolExecutor(args.workers, mp_context=get_context("spawn")) as pool:
        rows = list(pool.map(run_case, jobs))
    # above --clusters-below no unit fills: the clusters' run is the pendular one bit for bit
    rows += [dict(row, liquid="clusters", same_as_pendular=True) for row in list(rows)
             if row["liquid"] == "pendular" and row["suction"] > args.clusters_below]
    table = envelopes(rows)
    dry = next(r for r in table if r["liquid"] == "dry")
    sine = np.sin(np.radians(dry["phi_deg"]))
    slope = 6.0 * sine / (3.0 - sine)
    intercept = 6.0 * dry["cohesion"] * np.cos(np.radians(dry["phi_deg"])) / (3.0 - sine)
    for row in rows:        # how far each peak lies from the dry envelope, in effective stress
        row["off_dry_envelope"] = row["peak_q"] / (slope * row["p_effective_at_peak"]
                                                   + intercept) - 1.0
    result = {"particles": args.particles, "confining": confinings, "suctions": suctions,
              "max_strain": args.max_strain, "runs": rows, "envelopes": table,
              "wall_time_s": time.perf_counter() - started, "command": " ".join(sys.argv)}
    with open(os.path.join(args.out, "cohesion.json"), "w") as handle:
        json.dump(result, handle, indent=1)
    plot(table, rows, os.path.join(args.out, "cohesion.png"))
    for row in table:
        print(f"{row['liquid']:9s} s = {row['suction'] / 1e3:6g} kPa  w = "
              f"{100 * row['water_content']:6.3f} %  c = {row['cohesion']:8.1f} Pa  phi = "
              f"{row['phi_deg']:5.1f}  c' = {row['cohesion_effective']:8.1f} Pa  phi' = "
              f"{row['phi_effective_deg']:5.1f}")


if __name__ == "__main__":
    main()
