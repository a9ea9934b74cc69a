"""What the contact stiffness E changes in what a user reads: overlaps, phi, E50, K0, Cc, cost.

    python benchmarks/bench_stiffness.py [--particles 300] [--cases E:SIGMA[:GROWTH[:SEED]],...]
        [--max-strain 0.06] [--out runs/stiffness] [--reuse]
        [--json docs/figures/material_stiffness.json]

Each case ``E:sigma[:growth[:seed]]`` (Young's modulus E [Pa] of the linear law kn = E R,
confining stress sigma [Pa], the stress [Pa] that ends the radius growth of the preparation, by
default the command's own 5 kPa, and the sample's seed, 0 by default) runs a dry drained
triaxial (``pendular triaxial --young E --confining sigma``, thesis Ch. 5.2.2's preparation)
and an oedometric compression of the same prepared sample from sigma to 10 sigma (``pendular
oedometer --sample``). The default cases: E = 1e6, 1e7, 1e8 Pa at the fixed ratios
sigma / E = 7.5e-4 and growth / E = 5e-3 (the thesis's 750 Pa and 5 kPa on 1 MPa); E = 1e7 at
sigma = 7,500 Pa grown to the default 5 kPa; E = 1e6, 1e7, 5e7 at sigma = 750 Pa as the command
prepares them (5e7 is the stiffest the 5 kPa growth accepts); the first on seeds 1 and 2, for
the scatter between samples. Per case: the mean and largest overlap over the radius of the
prepared sample's sphere pairs [-], the mean over sigma / E, its porosity (of the wall box) and
coordination, the peak friction angle phi [deg], the secant moduli q / eps_a at 0.1 % axial
strain and at half the peak (E50) [Pa] (and over sigma), K0 and the compression index Cc of the
oedometer at its load, the time step [s] and the shear's steps. docs/material_stiffness.md
quotes the table written into the JSON (its ``substitutions``, docs/conf.py).
"""

import argparse
import json
import os
import platform
import sys
import time

import numpy as np
from scipy.spatial import cKDTree

from pendular.cli import main as pendular
from pendular.dem.sample import load_sample
from pendular.io.history import read_history
from pendular.procedures.preparation import PrepareConfig
from pendular.studies.campaign import prepare_one

#: Axial strain [-] of the small-strain secant modulus.
SMALL_STRAIN = 1e-3
DEFAULT_CASES = ("1e6:750,1e7:7500:50000,1e8:75000:500000,1e7:7500,1e7:750,5e7:750,"
                 "1e6:750::1,1e6:750::2")


def pair_overlaps(sample_path):
    """Overlaps over the smaller radius [-] of the touching sphere pairs of a sample.h5, its
    porosity [-] (spheres over the wall box) and coordination 2 Nc / N [-]."""
    particles, walls, _, _ = load_sample(sample_path)
    position, radius = particles.position, particles.radius
    pairs = cKDTree(position).query_pairs(2.0 * radius.max(), output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    overlap = radius[i] + radius[j] - np.linalg.norm(position[i] - position[j], axis=1)
    touching = overlap > 0.0
    relative = overlap[touching] / np.minimum(radius[i], radius[j])[touching]
    box = np.asarray(walls.position, dtype=np.float64).reshape(3, 2)
    volume = float(np.prod(box[:, 1] - box[:, 0]))
    solid = float(np.sum(4.0 / 3.0 * np.pi * radius ** 3))
    return relative, 1.0 - solid / volume, 2.0 * touching.sum() / len(radius)


def deviator(history):
    """Axial strain [-] and q = sigma_z - (sigma_x + sigma_y) / 2 of the walls [Pa] of a
    triaxial's history."""
    sigma = np.asarray(history["sigma_wall"], dtype=np.float64)
    return (np.asarray(history["axial_strain"], dtype=np.float64),
            sigma[:, 2] - 0.5 * (sigma[:, 0] + sigma[:, 1]))


def secant_modulus_at_half_peak(history):
    """E50 [Pa]: q / axial strain where q first reaches half its peak (linear interpolation)."""
    strain, q = deviator(history)
    half = 0.5 * q.max()
    k = int(np.argmax(q >= half))
    if k == 0:
        return float("nan")
    t = (half - q[k - 1]) / (q[k] - q[k - 1])
    return float(half / (strain[k - 1] + t * (strain[k] - strain[k - 1])))


def secant_modulus_at(history, at):
    """q / axial strain [Pa] at the axial strain ``at`` [-] (linear interpolation)."""
    strain, q = deviator(history)
    return float(np.interp(at, strain, q) / at)


def run(command, folder, argv, reuse):
    """``pendular command argv --out folder`` unless ``reuse`` and it has finished there; its
    summary.json (a dict) and wall time [s] (None when reused)."""
    path = os.path.join(folder, "summary.json")
    seconds = None
    if not (reuse and os.path.isfile(path)):
        start = time.perf_counter()
        status = pendular([command, *argv, "--out", folder])
        if status:
            raise SystemExit(f"pendular {command} {' '.join(argv)} ended with {status}")
        seconds = time.perf_counter() - start
    with open(path, encoding="utf-8") as handle:
        return json.load(handle), seconds


def run_case(young, sigma, prep_stress, seed, particles, max_strain, out, reuse):
    """The triaxial and the oedometer of one case; its row of the table (a dict). The sample is
    the command's own (radius growth to PrepareConfig's prep_stress, 5 kPa) or, with
    ``prep_stress`` [Pa], prepared here with that growth stress."""
    folder = os.path.join(out, f"E{young:g}_s{sigma:g}"
                          + (f"_prep{prep_stress:g}" if prep_stress else "")
                          + (f"_seed{seed}" if seed else ""))
    common = ["--particles", str(particles), "--young", f"{young:g}", "--confining", f"{sigma:g}",
              "--seed", str(seed), "--quiet", "--threads", "1"]
    given = []
    if prep_stress:
        given = ["--sample", os.path.join(folder, "prepared.h5")]
        if not (reuse and os.path.isfile(given[1])):
            os.makedirs(folder, exist_ok=True)
            prepare_one(PrepareConfig(particles=particles, confining=sigma, young=young,
                                      prep_stress=prep_stress, seed=seed), given[1])
    triaxial, triaxial_s = run("triaxial", os.path.join(folder, "triaxial"),
                               ["--max-strain", f"{max_strain:g}", *common, *given], reuse)
    sample = os.path.join(folder, "triaxial", "sample.h5")
    oedometer, oedometer_s = run("oedometer", os.path.join(folder, "oedometer"),
                                 ["--sample", sample, "--axial-stress", f"{10 * sigma:g}",
                                  *common], reuse)
    history = read_history(os.path.join(folder, "triaxial"))
    e50 = secant_modulus_at_half_peak(history)
    e_small = secant_modulus_at(history, SMALL_STRAIN)
    overlaps, porosity, coordination = pair_overlaps(sample)
    return {"young": young, "confining": sigma, "sigma_over_young": sigma / young,
            "prep_stress": prep_stress or PrepareConfig().prep_stress, "seed": seed,
            "mean_overlap_over_radius": float(overlaps.mean()),
            "max_overlap_over_radius": float(overlaps.max()),
            "mean_overlap_over_sigma_over_young": float(overlaps.mean() * young / sigma),
            "max_overlap_over_mean": float(overlaps.max() / overlaps.mean()),
            "porosity": porosity, "coordination": coordination,
            "phi_peak_deg": triaxial["phi_peak_deg"], "peak_q": triaxial["peak_q"],
            "axial_strain_at_peak": triaxial["axial_strain_at_peak"],
            "e50": e50, "e50_over_sigma": e50 / sigma, "e_small": e_small,
            "e_small_over_sigma": e_small / sigma,
            "k0": oedometer["k0"], "compression_index": oedometer["compression_index"],
            "constrained_modulus": oedometer["constrained_modulus"],
            "dt": triaxial["dt"], "shear_steps": triaxial["steps"],
            "triaxial_wall_s": triaxial_s, "oedometer_wall_s": oedometer_s}


UNITS = {"case": "E:sigma[:growth[:seed]]", "young": "Pa", "confining": "Pa",
         "sigma_over_young": "1", "prep_stress": "Pa", "seed": "1",
         "mean_overlap_over_radius": "1", "max_overlap_over_radius": "1",
         "mean_overlap_over_sigma_over_young": "1", "max_overlap_over_mean": "1",
         "porosity": "1", "coordination": "1",
         "phi_peak_deg": "deg", "peak_q": "Pa", "axial_strain_at_peak": "1", "e50": "Pa",
         "e50_over_sigma": "1", "e_small": "Pa", "e_small_over_sigma": "1", "k0": "1",
         "compression_index": "1",
         "constrained_modulus": "Pa", "dt": "s", "shear_steps": "1", "triaxial_wall_s": "s",
         "oedometer_wall_s": "s"}


#: Columns quoted one by one by docs/material_stiffness.md.
QUOTED = ("mean_overlap_over_sigma_over_young", "max_overlap_over_mean", "coordination",
          "phi_peak_deg", "e_small_over_sigma", "e50_over_sigma", "k0", "compression_index",
          "shear_steps")


def substitutions(rows):
    """The table as Markdown (``stiffness_table``) and each quoted value as text (three
    significant digits, whole numbers from 100 on), named stiffness_<case>_<column> with the
    case written E_sigma[_growth[_seed]] as on the command line, ':' as '_'."""
    text = {"stiffness_table": markdown(rows)}
    for row in rows:
        label = row["case"].replace(":", "_").replace(".", "p").replace("+", "")
        for key in QUOTED:
            value = row[key]
            text[f"stiffness_{label}_{key}"] = (f"{value:,.0f}" if abs(value) >= 100.0
                                                else f"{value:#.3g}")
    return text


def markdown(rows):
    """The table of docs/material_stiffness.md."""
    lines = ["| E (Pa) | σ (Pa) | σ/E | growth stress (Pa) | seed | mean δ/R | max δ/R "
             "| mean δ/R ÷ (σ/E) | n | Z | φ (°) | E_0.1%/σ | E50/σ | K0 | Cc | dt (s) "
             "| shear steps |",
             "|" + "---|" * 17]
    for r in rows:
        lines.append(
            f"| {r['young']:.0e} | {r['confining']:g} | {r['sigma_over_young']:.1e} "
            f"| {r['prep_stress']:g} | {r['seed']} "
            f"| {r['mean_overlap_over_radius']:.2e} | {r['max_overlap_over_radius']:.2e} "
            f"| {r['mean_overlap_over_sigma_over_young']:.2f} | {r['porosity']:.3f} "
            f"| {r['coordination']:.2f} | {r['phi_peak_deg']:.1f} | {r['e_small_over_sigma']:.0f} "
            f"| {r['e50_over_sigma']:.0f} "
            f"| {r['k0']:.3f} | {r['compression_index']:.4f} | {r['dt']:.2e} "
            f"| {r['shear_steps']:,} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--particles", type=int, default=300)
    parser.add_argument("--cases", default=DEFAULT_CASES,
                        help="E:sigma[:growth stress[:seed]] cases [Pa], comma-separated")
    parser.add_argument("--max-strain", type=float, default=0.06)
    parser.add_argument("--out", default="runs/stiffness", help="folder of the runs")
    parser.add_argument("--json", default=None, help="JSON file for the table")
    parser.add_argument("--machine", default=f"{platform.machine()}, {os.cpu_count()} cores",
                        help="the machine, in words, for the JSON")
    parser.add_argument("--reuse", action="store_true",
                        help="take the runs already finished in --out instead of running them")
    args = parser.parse_args(argv)
    rows = []
    for case in args.cases.split(","):
        young, sigma, prep, seed = (case.split(":") + ["", ""])[:4]
        rows.append({"case": case, **run_case(float(young), float(sigma),
                                               float(prep) if prep else None, int(seed or 0),
                                               args.particles, args.max_strain, args.out,
                                               args.reuse)})
        print(markdown(rows[-1:]).splitlines()[-1], file=sys.stderr, flush=True)
    if args.json:
        with open(args.json, "w") as handle:
            json.dump({"command": f"python benchmarks/bench_stiffness.py --particles "
                                  f"{args.particles} --cases {args.cases} --max-strain "
                                  f"{args.max_strain:g}",
                       "particles": args.particles, "max_strain": args.max_strain,
                       "machine": args.machine,
                       "date": time.strftime("%Y-%m-%d", time.gmtime()),
                       "units": UNITS, "cases": rows,
                       "substitutions": substitutions(rows)},
                      handle, indent=1)
    print(markdown(rows))


if __name__ == "__main__":
    main()
