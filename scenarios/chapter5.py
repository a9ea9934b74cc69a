"""Thesis Chapter 5 campaign: drained triaxial tests at every (suction, confining stress).

    python scenarios/chapter5.py [--particles N] [--suctions 0,15000,30000,300000]
        [--confining 250,500,750,1000] [--jobs J] [--out DIR]
        [--seed S] [--max-strain X] [--inertial-number I] [--scheduler ADDRESS]

One sample is prepared per confining stress (dem.preparation.prepare_sample: radius growth to
5 kPa, then unloaded to the test value, the same seed for all) and saved as
DIR/samples/c{confining}.h5. Every (suction, confining) test (dry when the suction is 0) then
starts from its sample (scenarios/triaxial.py --sample) in DIR/runs/s{suction}_c{confining}/,
with the outputs of scenarios/triaxial.py (history.h5, summary.json, plots, vtk, sample.h5,
log.txt with the run's progress bar). Preparations and tests run in --jobs parallel processes,
or on the Dask cluster of --scheduler (dask.distributed's concurrent.futures executor; its
workers must see the same file system, this repository and DIR, and should run one thread
each: ``dask worker ADDRESS --nthreads 1``), one Numba thread per run. The campaign's progress
bar shows each running run's progress. Run again with the same DIR, a campaign reuses its
samples and the runs that finished with the same arguments (an interrupted campaign goes on
where it stopped; delete a run's folder to redo it).

DIR/campaign.json: ``runs`` (suction, confining, peak_axial_stress, peak_q, p_at_peak,
saturation_at_peak, peak_q_effective, p_effective_at_peak; a dry run's effective values are its
net ones) and ``envelopes`` keyed by suction (str), each {phi_deg, cohesion} fitted to (p, q) at
peak and {phi_eff_deg, cohesion_eff} to (p', q') at peak (Eq. 3.43; dem.envelope), where a
suction has at least two confining stresses. DIR/report.md compares with thesis Table 5.3 and
Fig. 5.5. DIR/plots/ (chapter5_figures): envelopes.png (Figs. 5.4, 5.6), q_ev.png (5.3),
q_p_effective.png (5.7), polar_psi.png (5.5), polar_fabric.png, anisotropy.png (5.8).
"""

import argparse
import concurrent.futures
import contextlib
import json
import math
import multiprocessing
import os
import re
import sys
import traceback

import h5py
import numpy as np
from tqdm import tqdm

from dem.atomic import write_json, write_text
from dem.envelope import mohr_coulomb_fit

#: This folder: scenarios/triaxial.py and chapter5_figures.py.
SCENARIOS = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, SCENARIOS)
from chapter5_figures import campaign_figures  # noqa: E402

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
#: triaxial.py arguments that do not change a run's result (a finished run is reused whatever
#: they were).
RESULT_NEUTRAL = ("out", "quiet", "threads", "resume", "stop_after", "sample")
#: Seconds between updates of the campaign's progress bar.
PROGRESS_PERIOD = 5.0


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
    parser.add_argument("--prep-friction", type=float, default=0.5,
                        help="contact friction during the radius growth [deg] (thesis 0.5; "
                             "higher gives looser samples)")
    parser.add_argument("--scheduler", metavar="ADDRESS", default=None,
                        help="run on the Dask cluster of this scheduler (e.g. tcp://host:8786) "
                             "instead of --jobs local processes")
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
    """triaxial.py arguments shared by every sample and run of the campaign."""
    common = ["--particles", str(args.particles), "--seed", str(args.seed),
              "--max-strain", repr(args.max_strain),
              "--inertial-number", repr(args.inertial_number),
              "--prep-friction", repr(args.prep_friction)]
    if args.jobs > 1 or args.scheduler is not None:
        common += ["--threads", "1"]          # one core per run
    return common


def _triaxial():
    """scenarios/triaxial.py as a module, imported where the function runs (a Dask worker has
    the scenarios folder of the same file system, not on its path)."""
    if SCENARIOS not in sys.path:
        sys.path.insert(0, SCENARIOS)
    import triaxial
    return triaxial


def prepare_one(argv, path):
    """Worker: prepare the sample of triaxial.py's arguments ``argv`` and save it at ``path``."""
    return _triaxial().prepare_and_save(argv + ["--quiet"], path)


def run_one(argv, folder):
    """Worker: one triaxial test (triaxial.main) into ``folder``; its output, progress bar
    included, goes to ``folder``/log.txt."""
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "log.txt"), "w") as log, \
            contextlib.redirect_stdout(log), contextlib.redirect_stderr(log):
        try:
            return _triaxial().main(argv + ["--out", folder])
        except SystemExit as stop:
            raise RuntimeError(f"triaxial.py {' '.join(argv)} stopped: {stop.code}") from None


def made_with(path, argv):
    """Whether the sample file ``path`` (dem.sample.save_sample, its config holding the
    triaxial.py arguments) was made with the arguments ``argv``, up to those that do not change
    a result (RESULT_NEUTRAL)."""
    if not os.path.exists(path):
        return False
    with h5py.File(path, "r") as handle:
        stored = json.loads(handle.attrs["config"]).get("arguments", {})
    triaxial = _triaxial()
    wanted, default = (json.loads(json.dumps(vars(triaxial.parse_args(a)), default=str))
                       for a in (argv, []))
    # an option newer than the stored file was at its default value there
    return all(stored.get(key, default[key]) == value for key, value in wanted.items()
               if key not in RESULT_NEUTRAL)


def finished_summary(argv, folder):
    """summary.json of a run of ``folder`` that ended with the arguments ``argv``, or None: a
    campaign run again reuses its finished runs."""
    if not (os.path.exists(os.path.join(folder, "summary.json"))
            and os.path.exists(os.path.join(folder, "history.h5"))
            and made_with(os.path.join(folder, "sample.h5"), argv)):
        return None
    with open(os.path.join(folder, "summary.json")) as handle:
        return json.load(handle)


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


def write_report(path, runs, fits, args, figures, out):
    """DIR/report.md: every Table 5.3 cell and Sr beside the thesis's, the envelopes, the runs
    and the ``figures`` ({name: path}, linked relative to ``out``)."""
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
              "| suction [Pa] | phi net [deg] | c net [Pa] | phi' [deg] | c' [Pa] | "
              "phi' - phi dry [deg] |", "|---:|---:|---:|---:|---:|---:|"]
    dry_phi = fits.get(label(0.0), {}).get("phi_deg")
    for key, fit in fits.items():
        offset = (None if dry_phi is None or fit["phi_eff_deg"] is None
                  else fit["phi_eff_deg"] - dry_phi)
        lines.append(f"| {key} | {_fmt(fit['phi_deg'], '.2f')} | {_fmt(fit['cohesion'], '.1f')} "
                     f"| {_fmt(fit['phi_eff_deg'], '.2f')} | {_fmt(fit['cohesion_eff'], '.1f')} "
                     f"| {_fmt(offset, '+.2f')} |")
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
    lines += ["", "## Figures", ""]
    lines += [f"![{name}]({os.path.relpath(figure, out)})" for name, figure in figures.items()]
    lines += ["", "Each run's own plots: " + ", ".join(f"{r['folder']}/plots" for r in runs)]
    write_text(path, "\n".join(lines) + "\n")


@contextlib.contextmanager
def executor(jobs, scheduler):
    """Where the runs go: None (here, one after the other), a spawn process pool of ``jobs``
    workers, or the concurrent.futures executor of the Dask cluster at ``scheduler``."""
    if scheduler is not None:
        try:
            from dask.distributed import Client
        except ImportError:
            sys.exit("chapter5.py: error: --scheduler needs dask.distributed: "
                     "pip install 'pendular[dask]'")
        with Client(scheduler) as client:
            pool = client.get_executor(pure=False)
            try:
                yield pool
            finally:
                pool.shutdown()
    elif jobs == 1:
        yield None
    else:
        # fresh interpreters (no fork of a running Numba threading layer)
        with concurrent.futures.ProcessPoolExecutor(
                jobs, mp_context=multiprocessing.get_context("spawn")) as pool:
            yield pool


def run_progress(folder):
    """The last progress a run's log.txt shows ('shear 42%'), or '' before it starts."""
    try:
        with open(os.path.join(folder, "log.txt"), "rb") as handle:
            handle.seek(0, os.SEEK_END)
            handle.seek(max(0, handle.tell() - 4096))
            tail = handle.read().decode(errors="replace")
    except OSError:
        return ""
    for line in reversed(re.split(r"[\r\n]+", tail)):
        match = re.match(r"\s*(\w[\w ]*?):\s*(\d+)%", line)
        if match:
            return f"{match.group(1)} {match.group(2)}%"
    return ""


def _map(pool, function, tasks, description):
    """Run ``function(*task)`` for every task (in ``pool`` or here) with a progress bar whose
    status shows each running run's own progress (tasks whose last item is a run folder);
    returns the results in the order of ``tasks``."""
    results = [None] * len(tasks)
    if not tasks:
        return results
    with tqdm(total=len(tasks), desc=description, unit="run") as bar:
        if pool is None:
            for index, task in enumerate(tasks):
                bar.set_postfix_str(os.path.basename(task[-1]))
                results[index] = function(*task)
                bar.update()
            return results
        pending = {pool.submit(function, *task): i for i, task in enumerate(tasks)}
        while pending:
            done, _ = concurrent.futures.wait(pending, timeout=PROGRESS_PERIOD,
                                              return_when=concurrent.futures.FIRST_COMPLETED)
            for future in done:
                results[pending.pop(future)] = future.result()
                bar.update()
            running = (tasks[i][-1] for i in sorted(pending.values()))
            bar.set_postfix_str(", ".join(f"{os.path.basename(f)} {p}" for f in running
                                          for p in [run_progress(f)] if p))
    return results


def run_row(suction, lateral, summary, folder, out):
    """The campaign.json row of one run (module docstring)."""
    wet = suction > 0
    return {"suction": suction, "confining": lateral,
            "peak_axial_stress": summary["peak_axial_stress"],
            "peak_q": summary["peak_q"], "p_at_peak": summary["p_at_peak"],
            "saturation_at_peak": summary.get("saturation_at_peak", 0.0 if not wet else None),
            "peak_q_effective": summary["peak_q_effective"] if wet else summary["peak_q"],
            "p_effective_at_peak": (summary["p_effective_at_peak"] if wet
                                    else summary["p_at_peak"]),
            "axial_strain_at_peak": summary["axial_strain_at_peak"],
            "saturation_at_20_percent": saturation_at(folder, LATE_STRAIN) if wet else None,
            "folder": os.path.relpath(folder, out)}


def main(argv=None):
    args = parse_args(argv)
    out = os.path.abspath(args.out)       # workers elsewhere see the same paths
    common = _common(args)
    triaxial = _triaxial()
    for suction in args.suctions:       # refuse bad input here, not in a worker
        for lateral in args.confining:
            argv_run = common + ["--confining", repr(lateral)]
            if suction > 0:
                argv_run += ["--suction", repr(suction)]
            try:
                triaxial.configs(triaxial.parse_args(argv_run))
            except ValueError as error:
                sys.exit(f"chapter5.py: error: {error}")
    os.makedirs(os.path.join(out, "samples"), exist_ok=True)
    preparations = [(common + ["--confining", repr(c)], sample_path(out, c))
                    for c in args.confining
                    if not made_with(sample_path(out, c), common + ["--confining", repr(c)])]
    tests = [(s, c) for s in args.suctions for c in args.confining]
    summaries, tasks, keys = {}, [], []
    for suction, lateral in tests:
        folder = run_folder(out, suction, lateral)
        argv_run = common + ["--confining", repr(lateral), "--sample", sample_path(out, lateral)]
        if suction > 0:
            argv_run += ["--suction", repr(suction)]
        summaries[(suction, lateral)] = finished_summary(argv_run, folder)
        if summaries[(suction, lateral)] is None:
            tasks.append((argv_run, folder))
            keys.append((suction, lateral))
    if len(keys) < len(tests):
        print(f"chapter5.py: {len(tests) - len(keys)} finished runs in {out} reused, "
              f"{len(keys)} to run")
    with executor(args.jobs, args.scheduler) as pool:
        _map(pool, prepare_one, preparations, "prepare")
        summaries.update(zip(keys, _map(pool, run_one, tasks, "triaxial")))
    runs = [run_row(s, c, summaries[(s, c)], run_folder(out, s, c), out) for s, c in tests]
    fits = envelopes(runs)
    campaign = {"arguments": vars(args), "runs": runs, "envelopes": fits,
                "thesis": {"table_5_3": [{"suction": s, "confining": c, "peak_axial_stress": v}
                                         for (s, c), v in TABLE_5_3.items()],
                           "fig_5_5_saturation": {label(s): v for s, v in FIG_5_5.items()},
                           "dry_friction_deg": DRY_FRICTION_DEG}}
    write_json(os.path.join(out, "campaign.json"), campaign)
    figures = campaign_figures(out, runs, fits, label, LATE_STRAIN)
    write_report(os.path.join(out, "report.md"), runs, fits, args, figures, out)
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
