"""Thesis Chapter 5 campaign: drained triaxial tests at every (suction, confining stress).

    python scenarios/chapter5.py [--particles N] [--suctions 0,15000,30000,300000]
        [--confining 250,500,750,1000] [--jobs J] [--out DIR]
        [--seed S] [--max-strain X] [--inertial-number I]

One sample is prepared per confining stress (dem.preparation.prepare_sample: radius growth to
5 kPa, then unloaded to the test value, the same seed for all) and saved as
DIR/samples/c{confining}.h5. Every (suction, confining) test (dry when the suction is 0) then
starts from its sample (scenarios/triaxial.py --sample) in DIR/runs/s{suction}_c{confining}/,
with the outputs of scenarios/triaxial.py (history.h5, summary.json, plots, vtk, sample.h5,
log.txt). Preparations and tests run in --jobs parallel processes, one Numba thread each when
J > 1.

DIR/campaign.json: ``runs`` (suction, confining, peak_axial_stress, peak_q, p_at_peak,
saturation_at_peak, peak_q_effective, p_effective_at_peak; a dry run's effective values are its
net ones) and ``envelopes`` keyed by suction (str), each {phi_deg, cohesion} fitted to (p, q) at
peak and {phi_eff_deg, cohesion_eff} to (p', q') at peak (Eq. 3.43; dem.envelope), where a
suction has at least two confining stresses. DIR/report.md compares with thesis Table 5.3 and
Fig. 5.5; DIR/plots/envelopes.png shows the failure points in net and effective stress.
"""

import argparse
import concurrent.futures
import contextlib
import json
import math
import multiprocessing
import os
import sys
import traceback

import h5py
import numpy as np
from tqdm import tqdm

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import triaxial  # noqa: E402  (scenarios/triaxial.py)
from dem.envelope import mohr_coulomb_fit  # noqa: E402
from dem.preparation import prepare_sample  # noqa: E402
from dem.sample import save_sample  # noqa: E402

#: Thesis Table 5.3: axial stress at peak [Pa], keyed (suction [Pa], lateral stress [Pa]).
TABLE_5_3 = {
    (0, 250): 591, (0, 500): 1207, (0, 750): 1843, (0, 1000): 2480,
    (15000, 250): 5388, (15000, 500): 6345, (15000, 750): 7201, (15000, 1000): 8018,
    (30000, 250): 5748, (30000, 500): 6593, (30000, 750): 7426, (30000, 1000): 8329,
    (300000, 250): 6380, (300000, 750): 8289,
}
#: Thesis Fig. 5.5: degree of saturation [-] by suction [Pa].
FIG_5_5 = {15000: 0.055, 30000: 0.022, 300000: 0.0005}
#: Thesis dry friction angle [deg].
DRY_FRICTION_DEG = 25.0
#: Strain at which Sr is also reported (Fig. 5.5's horizontal axis ends there).
LATE_STRAIN = 0.20


def _values(text, name):
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"--{name} {text!r}: comma-separated numbers expected")
    if not values:
        raise argparse.ArgumentTypeError(f"--{name} {text!r}: at least one value expected")
    return values


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--particles", type=int, default=10000, help="number of spheres")
    parser.add_argument("--suctions", default="0,15000,30000,300000",
                        help="matric suctions [Pa], comma-separated (0: dry)")
    parser.add_argument("--confining", default="250,500,750,1000",
                        help="lateral stresses [Pa], comma-separated")
    parser.add_argument("--jobs", type=int, default=1, help="parallel processes")
    parser.add_argument("--out", default="runs/chapter5", help="output folder")
    parser.add_argument("--seed", type=int, default=0, help="random seed of every sample")
    parser.add_argument("--max-strain", type=float, default=0.25, help="final axial strain")
    parser.add_argument("--inertial-number", type=float, default=3e-4,
                        help="target inertial number setting the strain rate")
    args = parser.parse_args(argv)
    try:
        args.suctions = _values(args.suctions, "suctions")
        args.confining = _values(args.confining, "confining")
    except argparse.ArgumentTypeError as error:
        parser.error(str(error))
    if any(not math.isfinite(s) or s < 0 for s in args.suctions):
        parser.error(f"--suctions {args.suctions}: every suction must be in [0, inf)")
    if any(not math.isfinite(c) or c <= 0 for c in args.confining):
        parser.error(f"--confining {args.confining}: every stress must be in (0, inf)")
    if len(set(args.suctions)) != len(args.suctions) or \
            len(set(args.confining)) != len(args.confining):
        parser.error("--suctions and --confining must not repeat a value")
    if args.jobs < 1:
        parser.error(f"--jobs {args.jobs} is outside the valid range [1, inf)")
    if args.particles < 2:
        parser.error(f"--particles {args.particles} is outside the valid range [2, inf)")
    return args


def label(value):
    """A stress as it appears in folder names and JSON keys: 30000.0 -> '30000'."""
    return str(int(value)) if float(value).is_integer() else repr(float(value))


def sample_path(out, confining):
    return os.path.join(out, "samples", f"c{label(confining)}.h5")


def run_folder(out, suction, confining):
    return os.path.join(out, "runs", f"s{label(suction)}_c{label(confining)}")


def _common(args):
    return ["--particles", str(args.particles), "--seed", str(args.seed),
            "--max-strain", repr(args.max_strain),
            "--inertial-number", repr(args.inertial_number), "--quiet"]


def _single_thread():
    """Worker initializer: one Numba thread per process."""
    import numba
    numba.set_num_threads(1)


def prepare_one(argv, path):
    """Worker: prepare the sample of triaxial.py's arguments ``argv`` and save it at ``path``."""
    args = triaxial.parse_args(argv)
    prepare, _, _ = triaxial.configs(args)
    sim, report = prepare_sample(prepare, progress=False)
    config = json.loads(json.dumps({"arguments": vars(args)}, default=triaxial._plain))
    save_sample(path, sim, report, config)
    return path


def run_one(argv, folder):
    """Worker: one triaxial test (triaxial.main) into ``folder``, its output in log.txt."""
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "log.txt"), "w") as log, \
            contextlib.redirect_stdout(log), contextlib.redirect_stderr(log):
        try:
            return triaxial.main(argv + ["--out", folder])
        except SystemExit as stop:
            raise RuntimeError(f"triaxial.py {' '.join(argv)} stopped: {stop.code}") from None


def saturation_at(folder, strain):
    """Sr of a wet run's history at the record nearest ``strain`` (None when dry or when the
    run ended more than 1 % short of it)."""
    with h5py.File(os.path.join(folder, "history.h5"), "r") as handle:
        history = handle["history"]
        if "saturation" not in history:
            return None
        axial = history["axial_strain"][:]
        if axial.max() < strain - 0.01:
            return None
        return float(history["saturation"][int(np.argmin(np.abs(axial - strain)))])


def envelopes(runs):
    """Mohr–Coulomb fits by suction (module docstring); a failed fit gives None and the error."""
    fits = {}
    for suction in sorted({r["suction"] for r in runs}):
        rows = sorted((r for r in runs if r["suction"] == suction), key=lambda r: r["confining"])
        if len({r["confining"] for r in rows}) < 2:
            continue
        fit = {}
        for names, keys in ((("phi_deg", "cohesion"), ("p_at_peak", "peak_q")),
                            (("phi_eff_deg", "cohesion_eff"),
                             ("p_effective_at_peak", "peak_q_effective"))):
            try:
                values = mohr_coulomb_fit([r[keys[0]] for r in rows], [r[keys[1]] for r in rows])
            except ValueError as error:
                values = (None, None)
                fit.setdefault("errors", []).append(f"{names[0]}: {error}")
            fit.update(zip(names, values))
        fits[label(suction)] = fit
    return fits


def _fmt(value, spec=".0f", scale=1.0):
    return "" if value is None else format(value * scale, spec)


def write_report(path, runs, fits, args):
    rows = {(r["suction"], r["confining"]): r for r in runs}
    suctions = sorted({r["suction"] for r in runs} | {s for s, _ in TABLE_5_3})
    confining = sorted({r["confining"] for r in runs} | {c for _, c in TABLE_5_3})
    lines = [f"# Chapter 5 campaign: {args.particles} spheres, seed {args.seed}, "
             f"max strain {args.max_strain}, inertial number {args.inertial_number}", "",
             "## Axial stress at peak (Table 5.3)", "",
             "| suction [Pa] | confining [Pa] | ours [Pa] | thesis [Pa] | difference |",
             "|---:|---:|---:|---:|---:|"]
    for suction in suctions:
        for lateral in confining:
            ours = rows.get((suction, lateral))
            thesis = TABLE_5_3.get((suction, lateral))
            if ours is None and thesis is None:
                continue
            value = None if ours is None else ours["peak_axial_stress"]
            difference = ("" if value is None or thesis is None
                          else f"{100 * (value - thesis) / thesis:+.1f} %")
            lines.append(f"| {label(suction)} | {label(lateral)} | {_fmt(value)} | "
                         f"{'' if thesis is None else thesis} | {difference} |")
    lines += ["", "## Degree of saturation (Fig. 5.5)", "",
              f"| suction [Pa] | confining [Pa] | Sr at peak [%] | Sr at {LATE_STRAIN:.0%} strain "
              "[%] | thesis Fig. 5.5 [%] |", "|---:|---:|---:|---:|---:|"]
    for r in runs:
        if r["suction"] == 0:
            continue
        thesis = FIG_5_5.get(r["suction"])
        lines.append(f"| {label(r['suction'])} | {label(r['confining'])} | "
                     f"{_fmt(r['saturation_at_peak'], '.3f', 100)} | "
                     f"{_fmt(r['saturation_at_20_percent'], '.3f', 100)} | "
                     f"{_fmt(thesis, '.2f', 100)} |")
    lines += ["", "## Failure envelopes (Mohr–Coulomb in p–q)", "",
              f"Thesis: dry friction angle {DRY_FRICTION_DEG:.0f} deg; with the effective stress "
              "of Eq. 3.43 every suction should fall on the dry line (Fig. 5.6b).", "",
              "| suction [Pa] | phi net [deg] | c net [Pa] | phi' [deg] | c' [Pa] |",
              "|---:|---:|---:|---:|---:|"]
    for key, fit in fits.items():
        lines.append(f"| {key} | {_fmt(fit['phi_deg'], '.2f')} | {_fmt(fit['cohesion'], '.1f')} "
                     f"| {_fmt(fit['phi_eff_deg'], '.2f')} | {_fmt(fit['cohesion_eff'], '.1f')} |")
        for error in fit.get("errors", []):
            lines.append(f"| {key} | fit failed: {error} | | | |")
    if not fits:
        lines.append("(no suction has two confining stresses)")
    lines += ["", "## Runs", "",
              "| suction [Pa] | confining [Pa] | q peak [Pa] | p at peak [Pa] | q' peak [Pa] | "
              "p' at peak [Pa] | folder |", "|---:|---:|---:|---:|---:|---:|---|"]
    for r in runs:
        lines.append(f"| {label(r['suction'])} | {label(r['confining'])} | {r['peak_q']:.0f} | "
                     f"{r['p_at_peak']:.0f} | {r['peak_q_effective']:.0f} | "
                     f"{r['p_effective_at_peak']:.0f} | {r['folder']} |")
    lines += ["", "## Figures", "", "![p-q failure envelopes](plots/envelopes.png)", ""]
    lines += [f"- {r['folder']}/plots/q_p.png" for r in runs]
    with open(path, "w") as handle:
        handle.write("\n".join(lines) + "\n")


def plot_envelopes(path, runs, fits):
    """Failure points (p, q) and (p', q') with each suction's fit and the dry line."""
    plt = triaxial._pyplot()
    os.makedirs(os.path.dirname(path), exist_ok=True)
    figure, panels = plt.subplots(1, 2, figsize=(11, 4.5))
    p_max = max(max(r["p_at_peak"], r["p_effective_at_peak"]) for r in runs) * 1.1
    dry = fits.get("0")
    for axes, (pk, qk, phik, ck, title) in zip(panels, (
            ("p_at_peak", "peak_q", "phi_deg", "cohesion", "net stress"),
            ("p_effective_at_peak", "peak_q_effective", "phi_eff_deg", "cohesion_eff",
             "effective stress (Eq. 3.43)"))):
        for index, suction in enumerate(sorted({r["suction"] for r in runs})):
            rows = [r for r in runs if r["suction"] == suction]
            color = f"C{index}"
            axes.plot([r[pk] for r in rows], [r[qk] for r in rows], "o", color=color,
                      label=f"s = {label(suction)} Pa")
            fit = fits.get(label(suction))
            if fit and fit[phik] is not None and suction != 0:
                axes.plot(*_line(fit[phik], fit[ck], p_max), "--", color=color, lw=1)
        if dry and dry["phi_deg"] is not None:
            axes.plot(*_line(dry["phi_deg"], dry["cohesion"], p_max), "k-", lw=1.5,
                      label=f"dry line, phi = {dry['phi_deg']:.1f} deg")
        axes.set_xlim(0, p_max)
        axes.set_ylim(bottom=0)
        axes.set_xlabel("p' [Pa]" if "effective" in pk else "p [Pa]")
        axes.set_ylabel("q' [Pa]" if "effective" in pk else "q [Pa]")
        axes.set_title(title)
        axes.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)


def _line(phi_deg, cohesion, p_max):
    """p and q of the Mohr–Coulomb line q = M p + q0 (dem.envelope) over [0, p_max]."""
    sin_phi = math.sin(math.radians(phi_deg))
    slope = 6 * sin_phi / (3 - sin_phi)
    q0 = cohesion * 6 * math.cos(math.radians(phi_deg)) / (3 - sin_phi)
    p = np.array([0.0, p_max])
    return p, slope * p + q0


def _executor(jobs):
    if jobs == 1:
        return None
    # fresh interpreters (no fork of a running Numba threading layer), one thread each
    return concurrent.futures.ProcessPoolExecutor(
        jobs, mp_context=multiprocessing.get_context("spawn"), initializer=_single_thread)


def _map(executor, function, tasks, description):
    """Run ``function(*task)`` for every task (in the pool or here), with a progress bar;
    returns the results in the order of ``tasks``."""
    results = [None] * len(tasks)
    bar = tqdm(total=len(tasks), desc=description, unit="run")
    try:
        if executor is None:
            for index, task in enumerate(tasks):
                results[index] = function(*task)
                bar.update()
        else:
            futures = {executor.submit(function, *task): i for i, task in enumerate(tasks)}
            for future in concurrent.futures.as_completed(futures):
                results[futures[future]] = future.result()
                bar.update()
    finally:
        bar.close()
    return results


def main(argv=None):
    args = parse_args(argv)
    out = args.out
    os.makedirs(os.path.join(out, "samples"), exist_ok=True)
    common = _common(args)
    if args.jobs > 1:
        os.environ["NUMBA_NUM_THREADS"] = "1"   # the spawned workers' Numba
    executor = _executor(args.jobs)
    try:
        preparations = [(common + ["--confining", repr(c)], sample_path(out, c))
                        for c in args.confining]
        _map(executor, prepare_one, preparations, "prepare")
        tests = [(s, c) for s in args.suctions for c in args.confining]
        tasks = []
        for suction, lateral in tests:
            argv_run = common + ["--confining", repr(lateral), "--sample",
                                 sample_path(out, lateral)]
            if suction > 0:
                argv_run += ["--suction", repr(suction)]
            tasks.append((argv_run, run_folder(out, suction, lateral)))
        summaries = _map(executor, run_one, tasks, "triaxial")
    finally:
        if executor is not None:
            executor.shutdown()
    runs = []
    for (suction, lateral), summary, (_, folder) in zip(tests, summaries, tasks):
        wet = suction > 0
        row = {"suction": suction, "confining": lateral,
               "peak_axial_stress": summary["peak_axial_stress"],
               "peak_q": summary["peak_q"], "p_at_peak": summary["p_at_peak"],
               "saturation_at_peak": summary.get("saturation_at_peak", 0.0 if not wet else None),
               "peak_q_effective": summary["peak_q_effective"] if wet else summary["peak_q"],
               "p_effective_at_peak": (summary["p_effective_at_peak"] if wet
                                       else summary["p_at_peak"]),
               "axial_strain_at_peak": summary["axial_strain_at_peak"],
               "saturation_at_20_percent": saturation_at(folder, LATE_STRAIN) if wet else None,
               "folder": os.path.relpath(folder, out)}
        runs.append(row)
    fits = envelopes(runs)
    campaign = {"arguments": vars(args), "runs": runs, "envelopes": fits,
                "thesis": {"table_5_3": [{"suction": s, "confining": c, "peak_axial_stress": v}
                                         for (s, c), v in TABLE_5_3.items()],
                           "fig_5_5_saturation": {label(s): v for s, v in FIG_5_5.items()},
                           "dry_friction_deg": DRY_FRICTION_DEG}}
    with open(os.path.join(out, "campaign.json"), "w") as handle:
        json.dump(campaign, handle, indent=2)
    plot_envelopes(os.path.join(out, "plots", "envelopes.png"), runs, fits)
    write_report(os.path.join(out, "report.md"), runs, fits, args)
    print(f"chapter5.py: {len(runs)} runs; {os.path.join(out, 'campaign.json')}, "
          f"{os.path.join(out, 'report.md')}")
    return campaign


if __name__ == "__main__":
    try:
        main()
    except KeyboardInterrupt:
        sys.exit(130)
    except Exception:  # noqa: BLE001  (a worker's failure: show its traceback and stop)
        traceback.print_exc()
        sys.exit(1)
