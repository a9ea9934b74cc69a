"""Drained triaxial test of thesis Chapter 5 (Table 5.2 defaults): prepare, shear, write outputs.

    python scenarios/triaxial.py [--particles N] [--confining PA] [--suction PA]
        [--contact-angle DEG] [--max-strain X] [--seed S] [--out DIR]

Writes DIR/history.h5 (group ``history``, one row per record; file attributes hold every input),
DIR/summary.json and DIR/triaxial.png. Stresses compression positive [Pa].
"""

import argparse
import json
import math
import os
import sys
import time

import numba
import numpy as np

from dem.preparation import PrepareConfig, prepare_sample
from dem.record import write_history
from dem.triaxial import ShearConfig, inertial_number, start_shear, summarize


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--particles", type=int, default=10000, help="number of spheres")
    parser.add_argument("--confining", type=float, default=750.0, help="lateral stress [Pa]")
    parser.add_argument("--suction", type=float, default=0.0, help="matric suction [Pa]")
    parser.add_argument("--contact-angle", type=float, default=None, help="wetting angle [deg]")
    parser.add_argument("--max-strain", type=float, default=0.25, help="final axial strain")
    parser.add_argument("--seed", type=int, default=0, help="random seed of the sample")
    parser.add_argument("--out", default="runs/triaxial", help="output folder")
    parser.add_argument("--radius", type=float, default=0.024e-3, help="sphere radius [m]")
    parser.add_argument("--porosity", type=float, default=0.40,
                        help="porosity of the initial cloud box (0.30-0.60)")
    parser.add_argument("--friction", type=float, default=18.0, help="contact friction [deg]")
    parser.add_argument("--young", type=float, default=1e6, help="YADE young E [Pa], kn = E R")
    parser.add_argument("--damping", type=float, default=0.2, help="Cundall local damping")
    parser.add_argument("--inertial-number", type=float, default=3e-4,
                        help="target inertial number setting the strain rate")
    parser.add_argument("--strain-rate", type=float, default=None,
                        help="axial strain rate [1/s] (overrides --inertial-number)")
    parser.add_argument("--timestep-safety", type=float, default=0.7,
                        help="time step as a fraction of the P-wave estimate")
    parser.add_argument("--records", type=int, default=500, help="history rows over the test")
    parser.add_argument("--threads", type=int, default=None, help="Numba threads")
    parser.add_argument("--quiet", action="store_true", help="no progress bars")
    args = parser.parse_args(argv)
    if args.suction != 0.0 or args.contact_angle is not None:
        parser.error("--suction and --contact-angle are not yet supported "
                     "(capillary bridges come with the capillary issue); run dry with --suction 0")
    if args.threads is not None:
        if not 1 <= args.threads <= numba.config.NUMBA_NUM_THREADS:
            parser.error(f"--threads {args.threads} is outside the valid range "
                         f"[1, {numba.config.NUMBA_NUM_THREADS}]")
        numba.set_num_threads(args.threads)
    return args


def main(argv=None):
    args = parse_args(argv)
    try:
        prepare = PrepareConfig(particles=args.particles, radius=args.radius,
                                porosity=args.porosity, young=args.young,
                                friction_deg=args.friction, damping=args.damping,
                                timestep_safety=args.timestep_safety, confining=args.confining,
                                seed=args.seed)
        shear = ShearConfig(confining=args.confining, max_strain=args.max_strain,
                            inertial_number=args.inertial_number, strain_rate=args.strain_rate,
                            records=args.records)
    except ValueError as error:
        sys.exit(f"triaxial.py: error: {error}")
    os.makedirs(args.out, exist_ok=True)
    progress = not args.quiet
    started = time.perf_counter()
    sim, preparation = prepare_sample(prepare, progress=progress)
    prepared = time.perf_counter()
    recorder, steps, rate = start_shear(sim, shear, prepare.radius, prepare.density)

    def status(s):
        sigma = s.walls.stress()
        lateral = 0.5 * (sigma[0] + sigma[1])
        return {"strain": f"{recorder.last('axial_strain'):.3f}",
                "sz": f"{sigma[2]:.0f}Pa", "sr": f"{lateral:.0f}Pa",
                "q/p": f"{3 * (sigma[2] - lateral) / (sigma[2] + 2 * lateral):.2f}"}

    shear_start = time.perf_counter()
    sim.run(steps, progress="shear" if progress else None, status=status)
    shear_time = time.perf_counter() - shear_start
    history = recorder.arrays()
    summary = summarize(history)
    summary.update({
        "initial_porosity": preparation["porosity"],
        "initial_coordination": preparation["coordination"],
        "wall_time_s": time.perf_counter() - started,
        "preparation_time_s": prepared - started,
        "shear_time_s": shear_time,
        "steps": steps,
        "preparation_steps": preparation["steps"],
        "particle_steps_per_s": len(sim.particles) * steps / shear_time,
        "dt": sim.dt,
        "strain_rate": rate,
        "inertial_number": inertial_number(rate, prepare.radius, prepare.density,
                                           args.confining),
        "max_unbalanced_force": float(np.max(history["unbalanced_force"][1:])),
        "mean_unbalanced_force": float(np.mean(history["unbalanced_force"][1:])),
        "threads": numba.get_num_threads(),
    })
    attributes = {k: v for k, v in vars(args).items() if v is not None}
    attributes.update({"timestep": preparation["timestep"], "dt": sim.dt, "strain_rate": rate,
                       "density": prepare.density, "shear_ratio": prepare.shear_ratio,
                       "prep_friction": prepare.prep_friction_deg,
                       "prep_stress": prepare.prep_stress})
    write_history(os.path.join(args.out, "history.h5"), history, attributes)
    with open(os.path.join(args.out, "summary.json"), "w") as handle:
        json.dump(summary, handle, indent=2)
    plot_history(history, os.path.join(args.out, "triaxial.png"))
    print(json.dumps({k: summary[k] for k in ("peak_axial_stress", "peak_q", "p_at_peak",
                                              "axial_strain_at_peak", "initial_porosity",
                                              "wall_time_s", "particle_steps_per_s")}, indent=2))
    return summary


def plot_history(history, path):
    """q/p and volumetric strain against axial strain (thesis Fig. 5.3)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sigma = history["sigma_wall"]
    lateral = 0.5 * (sigma[:, 0] + sigma[:, 1])
    p = (sigma[:, 2] + 2 * lateral) / 3
    strain = history["axial_strain"]
    figure, (top, bottom) = plt.subplots(2, 1, figsize=(6, 7), sharex=True)
    top.plot(strain, (sigma[:, 2] - lateral) / np.where(p > 0, p, math.nan))
    top.set_ylabel("q/p")
    bottom.plot(strain, history["volumetric_strain"])
    bottom.set_ylabel("volumetric strain (contraction +)")
    bottom.set_xlabel("axial strain")
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)


if __name__ == "__main__":
    main()
