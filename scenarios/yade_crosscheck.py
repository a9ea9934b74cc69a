"""Cross-check of pendular's drained triaxial shear against YADE's on the same packing (issue 5).

    python scenarios/yade_crosscheck.py [--particles N] [--suction PA] [--confining PA]
        [--max-strain X] [--out DIR] [--mimic-yade] [--records N] [--threads T]
        [--settle-steps N] [--packing FILE] [--concurrent] [--quiet]

1. A sample of N spheres is prepared by pendular (thesis Ch. 5.2.2 at --confining; cached under
   .cache/ as benchmarks/bench_triaxial.py does), servoed on its six walls at --confining and,
   wet (--suction > 0), given capillary bridges at every contact
   (capillary.coupling.CapillaryBridges, suction control, 0.073 N/m, contact angle 0); it is
   run until static (unbalanced force and wall stresses as in the preparation).
2. This static (wetted) packing is exported (DIR/packing.txt, dem.yade_io.write_spheres: centres,
   radii, wall box). Both codes start the shear from it in the same state: velocities zero,
   contacts found afresh (no shear-spring history), every touching pair getting a bridge at the
   first step (YADE: Law2_ScGeom_CapillaryPhys_Capillarity with menisci created at contact from
   the files of capillary.BridgeTable.write_yade, cached under .cache/). The wet state is thus
   identical in both codes at the start of the shear (same contacts, bridges, Sr, stresses),
   and only the shear's dynamics can differ. --packing FILE starts from a packing exported by an
   earlier cross-check of the same sample and suction instead (no settling).
3. Both shear it with x, y servoed at --confining and z compressed at the strain rate of
   pendular's default inertial number, with the same time step, local damping, servo gain
   (1 - stressDamping), memory (0.8) and wall speed cap (max_vel), recording every
   shear_steps / --records steps. YADE (benchmarks/yade_triaxial.py, 1 OpenMP thread by default)
   runs with its own TriaxialStressController choices; pendular runs its defaults, or YADE's
   choices with --mimic-yade (dem.triaxial.YADE_CHOICES: axial rate on the current height,
   per-axis wall speed cap, wall stiffness refreshed every 10 steps). Each code runs until the
   engineering axial strain reaches --max-strain. docs/yade_crosscheck.md lists the differences.

Writes DIR/crosscheck.json: ``pendular`` and ``yade`` summaries (peak q, p, axial and volumetric
strain, Sr, bridges / menisci and porosity at the peak of q, the same at the start of the shear,
steps, seconds_per_step and particle_steps_per_s of the shear measured in this run, recording
included), ``peak_q_rel_diff`` and ``saturation_rel_diff`` ((pendular - YADE) / YADE at the
peak), ``volumetric_strain_at_peak_diff`` (pendular - YADE), ``start_sigma_rel_diff`` and
``start_saturation_rel_diff``, plus the settings; DIR/crosscheck.png (q/p, volumetric strain and,
wet, Sr against axial strain, both codes); DIR/yade_history.txt and DIR/pendular_history.h5.
Stresses compression positive [Pa], strains compression positive. Needs ``yade`` on PATH.
"""

import argparse
import concurrent.futures
import json
import math
import os
import shutil
import sys
import time

import numba
import numpy as np

from dem.atomic import write_json
from dem.figures import pyplot, save_figure
from dem.preparation import equilibrated, servoed_simulation
from dem.record import write_history
from dem.state import Particles, Walls
from dem.triaxial import YADE_CHOICES, ShearConfig, start_shear, summarize
from dem.walls import ConstantStrainRate, StressServo
from dem.yade_io import read_plot_data, read_spheres, write_spheres

REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(REPOSITORY, "benchmarks"))
from bench_capillary import SURFACE_TENSION, yade_capillary_files  # noqa: E402
from bench_triaxial import sample  # noqa: E402
from yade_runner import find_yade, run_yade_triaxial  # noqa: E402


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--particles", type=int, default=1000, help="number of spheres")
    parser.add_argument("--suction", type=float, default=0.0, help="matric suction [Pa] (0: dry)")
    parser.add_argument("--confining", type=float, default=750.0, help="lateral stress [Pa]")
    parser.add_argument("--max-strain", type=float, default=0.25, help="final axial strain")
    parser.add_argument("--out", default="/work/runs/crosscheck", help="output folder")
    parser.add_argument("--mimic-yade", action="store_true",
                        help="pendular takes YADE's wall-control choices (dem.triaxial."
                             "YADE_CHOICES)")
    parser.add_argument("--records", type=int, default=200, help="history rows over the shear")
    parser.add_argument("--threads", type=int, default=1,
                        help="Numba threads of pendular and OpenMP threads of YADE")
    parser.add_argument("--settle-steps", type=int, default=200000,
                        help="most steps to bring the (wetted) sample to rest before export")
    parser.add_argument("--packing", metavar="FILE", default=None,
                        help="shear this exported packing (DIR/packing.txt of an earlier "
                             "cross-check of the same sample and suction) instead of settling")
    parser.add_argument("--concurrent", action="store_true",
                        help="run YADE while pendular shears (halves the wall time; each code's "
                             "timing then shares the machine with the other)")
    parser.add_argument("--quiet", action="store_true", help="no progress bars")
    args = parser.parse_args(argv)
    if args.particles < 2:
        parser.error(f"--particles {args.particles} is outside the valid range [2, inf)")
    if not math.isfinite(args.suction) or args.suction < 0.0:
        parser.error(f"--suction {args.suction} Pa is outside the valid range [0, inf)")
    if not args.confining > 0.0:
        parser.error(f"--confining {args.confining} Pa is outside the valid range (0, inf)")
    if not 0.0 < args.max_strain < 0.9:
        parser.error(f"--max-strain {args.max_strain} is outside the valid range (0, 0.9)")
    if args.records < 2:
        parser.error(f"--records {args.records} is outside the valid range [2, inf)")
    if not 1 <= args.threads <= numba.config.NUMBA_NUM_THREADS:
        parser.error(f"--threads {args.threads} is outside the valid range "
                     f"[1, {numba.config.NUMBA_NUM_THREADS}]")
    if args.settle_steps < 0:
        parser.error(f"--settle-steps {args.settle_steps} is outside the valid range [0, inf)")
    return args


def bridges_operation(suction):
    """Pendular's capillary operation of the cross-check (suction control, bridges at contact)."""
    from capillary.coupling import CapillaryBridges   # a dry cross-check never loads it

    return CapillaryBridges(suction, SURFACE_TENSION)


def static_packing(args, path):
    """Prepare (or load) the sample, bring it to rest at the confining stress (wetted if
    ``args.suction``), write it to ``path``; return (PrepareConfig, settle report)."""
    prepare, particles, walls, _ = sample(args.particles, args.confining)
    sim = servoed_simulation(particles, walls, prepare, prepare.confining)
    bridges = bridges_operation(args.suction).insert(sim) if args.suction else None
    started = time.perf_counter()
    steps = sim.run(args.settle_steps, until=equilibrated(prepare), check_every=200,
                    progress=None if args.quiet else "settle")
    write_spheres(path, sim.particles.position, sim.particles.radius, sim.walls.lo,
                  sim.walls.hi)
    report = {"settle_steps": steps, "settle_time_s": time.perf_counter() - started,
              "sigma_wall": sim.walls.stress().tolist()}
    if bridges is not None:
        report.update(saturation=bridges.saturation(sim), bridges=bridges.count(sim))
    return prepare, report


def pendular_shear(args, prepare, packing):
    """The shear of the exported packing by pendular: (Simulation, ShearConfig, recorder,
    steps, strain rate [1/s]), not yet run."""
    position, radius, lo, hi = read_spheres(packing)
    sim = servoed_simulation(Particles(position, radius, prepare.density), Walls.box(lo, hi),
                             prepare, prepare.confining)
    if args.suction:
        bridges_operation(args.suction).insert(sim)
    shear = ShearConfig(confining=args.confining, max_strain=args.max_strain,
                        records=args.records, **(YADE_CHOICES if args.mimic_yade else {}))
    recorder, steps, rate = start_shear(sim, shear, prepare.radius, prepare.density)
    return sim, shear, recorder, steps, rate


def yade_settings(args, prepare, packing, sim, rate, period, folder):
    """The YADE driver's configuration for the same shear (benchmarks/yade_triaxial.py)."""
    lateral = sim.operation(StressServo)
    axial = sim.operation(ConstantStrainRate)
    # YADE imposes the rate on the current height: its own number of steps to max_strain
    yade_axial = ConstantStrainRate("z", rate, axial.reference_length, on_current_length=True)
    settings = {
        "spheres": packing, "young": prepare.young, "poisson": prepare.shear_ratio,
        "friction_deg": prepare.friction_deg, "density": prepare.density,
        "damping": prepare.damping, "dt": sim.dt, "confining": args.confining,
        "strain_rate": rate, "steps": yade_axial.steps_to(args.max_strain, sim.dt),
        "warmup_steps": 0, "record_every": period, "record_initial": True,
        "skin": prepare.skin_factor * prepare.radius,
        "stress_damping": 1.0 - lateral.gain, "strain_damping": 0.0,
        "max_vel": lateral.max_velocity,
        "history": os.path.join(folder, "yade_history.txt"),
        "output": os.path.join(folder, "yade_result.json")}
    if args.suction:
        settings["capillary"] = {"suction": args.suction, "files": yade_capillary_files(),
                                 "surface_tension": SURFACE_TENSION}
    return settings


def yade_history(path, box_volume):
    """The YADE history in the layout of pendular's (sigma_wall (rows, 3) [Pa],
    axial_strain, volumetric_strain, porosity, and saturation and bridges when wet)."""
    data = read_plot_data(path)
    history = {"step": data["i"], "axial_strain": data["eps_axial"],
               "sigma_wall": np.column_stack([data["sx"], data["sy"], data["sz"]]),
               "volumetric_strain": 1.0 - data["lx"] * data["ly"] * data["lz"] / box_volume,
               "porosity": data["porosity"]}
    if "saturation" in data:
        history.update(saturation=data["saturation"], bridges=data["menisci"])
    return history


def code_summary(history, particles, steps, seconds):
    """Peak and start-of-shear values of one code's history, with its cost per step."""
    summary = summarize(history)
    peak = summary.pop("peak_index")
    for name, key in (("volumetric_strain", "volumetric_strain"), ("porosity", "porosity"),
                      ("bridges", "bridges")):
        if key in history:
            summary[f"{name}_at_peak"] = float(history[key][peak])
    summary["start"] = {"sigma_wall": history["sigma_wall"][0].tolist(),
                        "porosity": float(history["porosity"][0])}
    for key in ("saturation", "bridges"):
        if key in history:
            summary["start"][key] = float(history[key][0])
    summary.update({"final_axial_strain": float(history["axial_strain"][-1]),
                    "steps": int(steps), "shear_time_s": seconds,
                    "seconds_per_step": seconds / steps,
                    "particle_steps_per_s": particles * steps / seconds})
    return summary


def relative(ours, theirs):
    """(ours - theirs) / |theirs|, None when either is missing."""
    if ours is None or theirs is None:
        return None
    return (ours - theirs) / abs(theirs)


def comparison(pendular, yade):
    """The agreement fields of crosscheck.json."""
    start_p, start_y = pendular["start"], yade["start"]
    return {
        "peak_q_rel_diff": relative(pendular["peak_q"], yade["peak_q"]),
        "saturation_rel_diff": relative(pendular.get("saturation_at_peak"),
                                        yade.get("saturation_at_peak")),
        "volumetric_strain_at_peak_diff": (pendular["volumetric_strain_at_peak"]
                                           - yade["volumetric_strain_at_peak"]),
        "axial_strain_at_peak_diff": (pendular["axial_strain_at_peak"]
                                      - yade["axial_strain_at_peak"]),
        "start_sigma_rel_diff": max(abs(relative(a, b)) for a, b in
                                    zip(start_p["sigma_wall"], start_y["sigma_wall"])),
        "start_saturation_rel_diff": relative(start_p.get("saturation"),
                                              start_y.get("saturation")),
        "cost_ratio_yade_over_pendular": yade["seconds_per_step"] / pendular["seconds_per_step"],
    }


def plot(histories, path):
    """q/p, volumetric strain and (wet) Sr against axial strain, one curve per code."""
    wet = all("saturation" in h for h in histories.values())
    figure, panels = pyplot().subplots(3 if wet else 2, 1, figsize=(6, 9 if wet else 6.5),
                                  sharex=True)
    for name, history in histories.items():
        sigma = history["sigma_wall"]
        lateral = 0.5 * (sigma[:, 0] + sigma[:, 1])
        p = (sigma[:, 2] + 2.0 * lateral) / 3.0
        strain = history["axial_strain"]
        panels[0].plot(strain, (sigma[:, 2] - lateral) / np.where(p > 0, p, math.nan),
                       label=name)
        panels[1].plot(strain, history["volumetric_strain"], label=name)
        if wet:
            panels[2].plot(strain, history["saturation"], label=name)
    panels[0].set_ylabel("q/p")
    panels[1].set_ylabel("volumetric strain (contraction +)")
    if wet:
        panels[2].set_ylabel("degree of saturation Sr")
    panels[-1].set_xlabel("axial strain")
    panels[0].legend()
    save_figure(figure, path)


def main(argv=None):
    args = parse_args(argv)
    find_yade()
    numba.set_num_threads(args.threads)
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    packing = os.path.join(out, "packing.txt")
    if args.packing is None:
        prepare, settled = static_packing(args, packing)
    else:
        if not os.path.exists(args.packing):
            sys.exit(f"yade_crosscheck.py: error: --packing {args.packing}: no such file")
        if os.path.abspath(args.packing) != packing:
            shutil.copyfile(args.packing, packing)
        prepare, settled = sample(args.particles, args.confining)[0], {"from": args.packing}
    sim, shear, recorder, steps, rate = pendular_shear(args, prepare, packing)
    settings = yade_settings(args, prepare, packing, sim, rate, recorder.period, out)
    box_volume = sim.walls.volume()
    with concurrent.futures.ThreadPoolExecutor(max_workers=1) as pool:
        def run_yade():
            return run_yade_triaxial(settings, threads=args.threads,
                                     env={"OMP_WAIT_POLICY": "PASSIVE"})
        yade_run = pool.submit(run_yade) if args.concurrent else None
        started = time.perf_counter()
        sim.run(steps, progress=None if args.quiet else "pendular shear")
        pendular_seconds = time.perf_counter() - started
        yade_result = (yade_run or pool.submit(run_yade)).result()
    ours = recorder.arrays()
    write_history(os.path.join(out, "pendular_history.h5"), ours,
                  {"mimic_yade": args.mimic_yade, "dt": sim.dt, "strain_rate": rate})
    theirs = yade_history(settings["history"], box_volume)
    count = len(sim.particles)
    pendular = code_summary(ours, count, steps, pendular_seconds)
    yade = code_summary(theirs, count, yade_result["steps"], yade_result["wall_time_s"])
    yade["version"] = yade_result["yade_version"]
    result = {
        "particles": count, "suction": args.suction, "confining": args.confining,
        "max_strain": args.max_strain, "mimic_yade": args.mimic_yade,
        "threads": args.threads, "concurrent": args.concurrent,
        "dt": sim.dt, "strain_rate": rate, "damping": prepare.damping,
        "servo": {"gain": sim.operation(StressServo).gain,
                  "memory": sim.operation(StressServo).memory,
                  "max_velocity": sim.operation(StressServo).max_velocity},
        "shear_config": {k: v for k, v in vars(shear).items()},
        "setup": ("pendular prepares and settles the sample at the confining stress (wetted: "
                  "bridges at every contact, settled again); both codes shear the exported "
                  "packing from rest with contacts and bridges formed afresh"),
        "settle": settled, "packing": packing,
        **comparison(pendular, yade),
        "pendular": pendular, "yade": yade,
    }
    write_json(os.path.join(out, "crosscheck.json"), result)
    plot({"pendular": ours, "YADE": theirs}, os.path.join(out, "crosscheck.png"))
    shown = ("peak_q_rel_diff", "saturation_rel_diff", "volumetric_strain_at_peak_diff",
             "start_sigma_rel_diff", "cost_ratio_yade_over_pendular")
    print(json.dumps({k: result[k] for k in shown}, indent=2))
    return result


if __name__ == "__main__":
    main()
