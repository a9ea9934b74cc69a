"""Drained triaxial test of thesis Chapter 5 (Table 5.2 defaults): prepare, shear, write outputs.

    python scenarios/triaxial.py [--particles N] [--confining PA] [--suction PA]
        [--contact-angle DEG] [--max-strain X] [--seed S] [--out DIR]
        [--bridges exact|toroidal] [--surface-tension N/M] [--persist-bridges]

Writes DIR/history.h5 (group ``history``, one row per record; file attributes hold every input),
DIR/summary.json and DIR/triaxial.png. Stresses compression positive [Pa].

Wet test (--suction > 0, thesis Ch. 5.2): the sample is prepared dry, then capillary bridges
(capillary.coupling.CapillaryBridges, suction-controlled, formed at every contact) are added at
the confining stress and the sample is let to equilibrate with them (six walls servoed) before
the shear. The history then also holds saturation, suction [Pa], sigma_capillary (Love–Weber
stress of the capillary forces, tensile negative), bridges, pendular_overlaps and, at every
record, the effective stress homogenised from the bridges (homogenize.on_the_fly): chi
(Eq. 3.44), B [Pa] (Eq. 3.45), psi = chi s + B [Pa] (Eq. 3.46, positive), sigma_effective
= diag(sigma_wall) + psi [Pa] (Eq. 3.43, u_a = 0), fabric_bridges (Eq. 3.53), anisotropy_bridges
(Eq. 3.54) and a_psi (Eq. 4.5); summary.json adds peak_q_effective and p_effective_at_peak (q'
and p' at the peak of q). Every history has the contact fabric and its anisotropy (Eq. 3.51).
Without --suction the scene is dry and never imports the capillary package.
"""

import argparse
import json
import math
import os
import sys
import time

import numba
import numpy as np

from dem.preparation import PrepareConfig, equilibrated, prepare_sample
from dem.measure import porosity
from dem.record import write_history
from dem.triaxial import ShearConfig, inertial_number, start_shear, summarize


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--particles", type=int, default=10000, help="number of spheres")
    parser.add_argument("--confining", type=float, default=750.0, help="lateral stress [Pa]")
    parser.add_argument("--suction", type=float, default=0.0, help="matric suction [Pa]")
    parser.add_argument("--contact-angle", type=float, default=None,
                        help="wetting angle [deg] (wet test; default 0)")
    parser.add_argument("--bridges", choices=("exact", "toroidal"), default=None,
                        help="bridge model of the wet test: exact Young-Laplace tables "
                             "(default) or the toroidal approximation (equal spheres)")
    parser.add_argument("--surface-tension", type=float, default=None,
                        help="liquid surface tension [N/m] (wet test; default 0.073)")
    parser.add_argument("--persist-bridges", action="store_true",
                        help="bridges live up to their rupture distance instead of breaking "
                             "when contact is lost")
    parser.add_argument("--wet-steps", type=int, default=200000,
                        help="most steps to equilibrate the wetted sample before the shear")
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
    if not math.isfinite(args.suction) or args.suction < 0.0:
        parser.error(f"--suction {args.suction} Pa is outside the valid range [0, inf) "
                     "(0: dry)")
    if args.wet_steps < 0:
        parser.error(f"--wet-steps {args.wet_steps} is outside the valid range [0, inf)")
    wet_only = {"--contact-angle": args.contact_angle is not None,
                "--bridges": args.bridges is not None,
                "--surface-tension": args.surface_tension is not None,
                "--persist-bridges": args.persist_bridges}
    if args.suction == 0.0 and any(wet_only.values()):
        parser.error(f"{', '.join(k for k, v in wet_only.items() if v)} need(s) a wet test: "
                     "give --suction > 0")
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
        bridges = wet_bridges(args, prepare.radius) if args.suction > 0.0 else None
    except ValueError as error:
        sys.exit(f"triaxial.py: error: {error}")
    os.makedirs(args.out, exist_ok=True)
    progress = not args.quiet
    started = time.perf_counter()
    sim, preparation = prepare_sample(prepare, progress=progress)
    prepared = time.perf_counter()
    wetting = wet_sample(sim, bridges, prepare, args.wet_steps, progress) if bridges else {}
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
        **wetting,
    })
    attributes = {k: v for k, v in vars(args).items() if v is not None}
    attributes.update({"timestep": preparation["timestep"], "dt": sim.dt, "strain_rate": rate,
                       "density": prepare.density, "shear_ratio": prepare.shear_ratio,
                       "prep_friction": prepare.prep_friction_deg,
                       "prep_stress": prepare.prep_stress})
    if bridges is not None:
        attributes.update({"bridges": bridges.model, "contact_angle": bridges.contact_angle,
                           "surface_tension": bridges.surface_tension,
                           "persist_bridges": bridges.persist})
    write_history(os.path.join(args.out, "history.h5"), history, attributes)
    with open(os.path.join(args.out, "summary.json"), "w") as handle:
        json.dump(summary, handle, indent=2)
    plot_history(history, os.path.join(args.out, "triaxial.png"))
    shown = ("peak_axial_stress", "peak_q", "p_at_peak", "axial_strain_at_peak",
             "peak_q_effective", "p_effective_at_peak", "initial_porosity",
             "saturation_at_peak", "wall_time_s", "particle_steps_per_s")
    print(json.dumps({k: summary[k] for k in shown if k in summary}, indent=2))
    return summary


def wet_bridges(args, radius):
    """The capillary operation of the wet test, its input checked against the sample's radius
    (imported here: a dry test never loads the capillary package)."""
    from capillary.coupling import CapillaryBridges

    surface_tension = 0.073 if args.surface_tension is None else args.surface_tension
    bridges = CapillaryBridges(args.suction, surface_tension=surface_tension,
                               contact_angle=args.contact_angle or 0.0,
                               model=args.bridges or "exact", persist=args.persist_bridges)
    bridges.load_tables(radius, radius)
    return bridges


def wet_sample(sim, bridges, prepare, max_steps, progress):
    """Add the bridges to the dry sample held at the confining stress and run until it is
    static again (unbalanced force and wall stresses as in the preparation)."""
    bridges.insert(sim)
    started = time.perf_counter()
    steps = sim.run(max_steps, until=equilibrated(prepare), check_every=200,
                    progress="wet" if progress else None)
    return {"wetting_steps": steps, "wetting_time_s": time.perf_counter() - started,
            "initial_saturation": bridges.saturation(sim),
            "initial_bridges": bridges.count(sim),
            "wet_porosity": porosity(sim.particles, sim.walls)}


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
