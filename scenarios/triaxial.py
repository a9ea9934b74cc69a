"""Drained triaxial test of thesis Chapter 5 (Table 5.2 defaults): prepare, shear, write outputs.

    python scenarios/triaxial.py [--particles N] [--confining PA] [--suction PA]
        [--contact-angle DEG] [--max-strain X] [--seed S] [--out DIR]
        [--bridges exact|toroidal] [--surface-tension N/M] [--persist-bridges]
        [--vtk-every N] [--checkpoint-every N] [--sample PATH]
        [--timestep-safety F] [--inertial-number I | --strain-rate R] [--damping L]
        [--skin-factor F] [--table-resolution NS,ND] [--records N] [--threads T] [--quiet]
    python scenarios/triaxial.py --resume DIR [--quiet] [--threads T]

Writes DIR/history.h5 (group ``history``, one row per record; file attributes hold every input),
DIR/summary.json and DIR/triaxial.png. Stresses compression positive [Pa]. Also:

- DIR/vtk/{particles,walls,bridges}.pvd: ParaView series of the shear (dem.vtk.VtkWriter), a
  frame every --vtk-every steps (default: about 50 frames; 0: none), the last state included.
- DIR/plots/: q_p.png (q/p), volumetric_strain.png and, wet, capillary_stress.png (diagonals of
  psi and of sigma_capillary) against axial strain.
- DIR/sample.h5: the prepared (and wetted) sample at the start of the shear, with the run's
  arguments, preparation report and wetting results (dem.sample.save_sample, ``config``).
- DIR/checkpoint.h5 with --checkpoint-every N: a checkpoint (dem.checkpoint) at the start of the
  shear and every N steps, written atomically; its extra_state holds the phase ("shear"), the
  shear's steps, start step, the arguments and the elapsed times. ``--resume DIR`` rebuilds the
  same simulation from DIR/sample.h5 with the arguments stored there, loads the checkpoint and
  runs the remaining steps: history.h5 is the one of an uninterrupted run, bit for bit.

--sample PATH starts from a sample prepared earlier (dem.sample.save_sample, e.g. a campaign's
DIR/samples/) instead of preparing one: it is servoed at --confining and let to equilibrate
(at most --wet-steps steps; its contacts' shear forces are not stored) before the wetting or the
shear; the other sample arguments (--particles, --radius, ...) must describe the same sample.

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

from dem.atomic import write_json
from dem.checkpoint import CheckpointWriter, load_checkpoint
from dem.figures import pyplot, save_figure
from dem.preparation import PrepareConfig, equilibrated, prepare_sample, servoed_simulation
from dem.measure import coordination, porosity
from dem.record import write_history
from dem.sample import load_sample, save_sample
from dem.vtk import VtkWriter
from dem.triaxial import ShearConfig, inertial_number, start_shear, summarize


#: Default number of ParaView frames over the shear.
VTK_FRAMES = 50
#: Arguments that a resumed run takes from its own command line, not from the stored run.
RESUME_OPTIONS = ("resume", "quiet", "threads", "stop_after")
#: Exit status of a run stopped by --stop-after (as a shell reports an interrupted command).
INTERRUPTED = 130


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
    parser.add_argument("--prep-friction", type=float, default=0.5,
                        help="contact friction during the radius growth [deg] (thesis 0.5; "
                             "higher gives a looser sample)")
    parser.add_argument("--young", type=float, default=1e6, help="YADE young E [Pa], kn = E R")
    parser.add_argument("--damping", type=float, default=0.2, help="Cundall local damping")
    parser.add_argument("--inertial-number", type=float, default=3e-4,
                        help="target inertial number setting the strain rate")
    parser.add_argument("--strain-rate", type=float, default=None,
                        help="axial strain rate [1/s] (overrides --inertial-number)")
    parser.add_argument("--timestep-safety", type=float, default=0.7,
                        help="time step as a fraction of the P-wave estimate")
    parser.add_argument("--skin-factor", type=float, default=0.3,
                        help="Verlet skin of the neighbour list / radius (0, 2]")
    parser.add_argument("--table-resolution", metavar="NS,ND", default=None,
                        help="bridge table nodes in suction and in distance (exact default "
                             "350,80; toroidal 64,80)")
    parser.add_argument("--records", type=int, default=500, help="history rows over the test")
    parser.add_argument("--threads", type=int, default=None, help="Numba threads")
    parser.add_argument("--quiet", action="store_true", help="no progress bars")
    parser.add_argument("--vtk-every", type=int, default=None,
                        help="steps between ParaView frames of the shear (default: about "
                             f"{VTK_FRAMES} frames; 0: no ParaView output)")
    parser.add_argument("--checkpoint-every", type=int, default=0,
                        help="steps between checkpoints DIR/checkpoint.h5 of the shear (0: none)")
    parser.add_argument("--sample", metavar="PATH", default=None,
                        help="start from this prepared sample (dem.sample.save_sample) instead "
                             "of preparing one")
    parser.add_argument("--resume", metavar="DIR", default=None,
                        help="continue the interrupted run of DIR from its checkpoint, with the "
                             "arguments stored there (only --quiet and --threads may be added)")
    # tests: stop the shear after this many steps as an interruption would (exit status 130)
    parser.add_argument("--stop-after", type=int, default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.vtk_every is not None and args.vtk_every < 0:
        parser.error(f"--vtk-every {args.vtk_every} is outside the valid range [0, inf)")
    if args.checkpoint_every < 0:
        parser.error(f"--checkpoint-every {args.checkpoint_every} is outside the valid range "
                     "[0, inf)")
    if args.stop_after is not None and args.stop_after < 0:
        parser.error(f"--stop-after {args.stop_after} is outside the valid range [0, inf)")
    if args.resume is not None:
        given = [name for name, value in vars(args).items()
                 if name not in RESUME_OPTIONS and value != parser.get_default(name)]
        if given:
            parser.error(f"--resume takes the run's arguments from {args.resume}; "
                         f"{', '.join('--' + n.replace('_', '-') for n in given)} cannot be "
                         "changed (only --quiet and --threads may be added)")
    if not math.isfinite(args.suction) or args.suction < 0.0:
        parser.error(f"--suction {args.suction} Pa is outside the valid range [0, inf) "
                     "(0: dry)")
    if args.wet_steps < 0:
        parser.error(f"--wet-steps {args.wet_steps} is outside the valid range [0, inf)")
    if args.table_resolution is not None:
        try:
            nodes = [int(v) for v in args.table_resolution.split(",")]
        except ValueError:
            nodes = []
        if len(nodes) != 2 or min(nodes) < 4:
            parser.error(f"--table-resolution {args.table_resolution!r}: two integers NS,ND, "
                         "each in [4, inf), expected")
    wet_only = {"--contact-angle": args.contact_angle is not None,
                "--table-resolution": args.table_resolution is not None,
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
    if args.resume is not None:
        return resume(args)
    try:
        prepare, shear, bridges = configs(args)
    except ValueError as error:
        sys.exit(f"triaxial.py: error: {error}")
    os.makedirs(args.out, exist_ok=True)
    progress = not args.quiet
    started = time.perf_counter()
    if args.sample is not None:
        sim, preparation = saved_sample(args.sample, prepare, args.wet_steps, progress)
    else:
        sim, preparation = prepare_sample(prepare, progress=progress)
    prepared = time.perf_counter()
    wetting = wet_sample(sim, bridges, prepare, args.wet_steps, progress) if bridges else {}
    before_shear = {"arguments": vars(args), "preparation": preparation, "wetting": wetting,
                    "preparation_time_s": prepared - started,
                    "pre_shear_time_s": time.perf_counter() - started}
    before_shear = json.loads(json.dumps(before_shear, default=_plain))
    # the sample the shear starts from: a resumed run rebuilds its simulation from it
    save_sample(os.path.join(args.out, "sample.h5"), sim, preparation, before_shear)
    run = Shear(sim, args, prepare, shear, before_shear)
    if run.checkpoint is not None:
        run.checkpoint.write(sim)
    return run.finish()


def resume(args):
    """Continue the run of ``args.resume`` from its checkpoint (module docstring)."""
    folder = args.resume
    checkpoint = os.path.join(folder, "checkpoint.h5")
    for path in (os.path.join(folder, "sample.h5"), checkpoint):
        if not os.path.exists(path):
            sys.exit(f"triaxial.py: error: --resume {folder}: {path} is missing (was the run "
                     "started with --checkpoint-every N > 0?)")
    particles, walls, _, before_shear = load_sample(os.path.join(folder, "sample.h5"))
    stored = dict(before_shear["arguments"])
    stored.update({name: getattr(args, name) for name in RESUME_OPTIONS})
    stored["out"] = folder
    stored["resume"] = None
    args = argparse.Namespace(**stored)
    if args.threads is not None:
        numba.set_num_threads(args.threads)
    prepare, shear, bridges = configs(args)
    sim = servoed_simulation(particles, walls, prepare, prepare.confining)
    if bridges is not None:
        bridges.insert(sim)
    run = Shear(sim, args, prepare, shear, before_shear)
    state = load_checkpoint(checkpoint, sim)
    if state.get("phase") != "shear" or state["steps"] != run.steps:
        sys.exit(f"triaxial.py: error: {checkpoint} does not belong to this run's shear")
    run.resumed(state)
    return run.finish()


def prepare_and_save(argv, path):
    """Prepare the sample of the arguments ``argv`` (no shear) and save it at ``path`` for
    --sample; returns ``path``."""
    args = parse_args(argv)
    prepare, _, _ = configs(args)
    sim, report = prepare_sample(prepare, progress=not args.quiet)
    config = json.loads(json.dumps({"arguments": vars(args)}, default=_plain))
    save_sample(path, sim, report, config)
    return path


def saved_sample(path, prepare, max_steps, progress):
    """(Simulation, preparation report) of the sample saved at ``path``, servoed at the
    confining stress of ``prepare`` and run until static (at most ``max_steps`` steps)."""
    if not os.path.exists(path):
        sys.exit(f"triaxial.py: error: --sample {path}: no such file")
    particles, walls, report, _ = load_sample(path)
    if len(particles) != prepare.particles:
        sys.exit(f"triaxial.py: error: --sample {path} has {len(particles)} particles, "
                 f"--particles says {prepare.particles}")
    sim = servoed_simulation(particles, walls, prepare, prepare.confining)
    started = time.perf_counter()
    steps = sim.run(max_steps, until=equilibrated(prepare), check_every=200,
                    progress="equilibrate sample" if progress else None)
    report = dict(report)
    report.update({"sample": os.path.abspath(path), "sample_equilibration_steps": steps,
                   "sample_equilibration_time_s": time.perf_counter() - started,
                   "porosity": porosity(sim.particles, sim.walls),
                   "coordination": coordination(sim.contacts, len(sim.particles)),
                   "sigma_wall": sim.walls.stress().tolist()})
    if "steps" not in report:
        report["steps"] = steps
    if "timestep" not in report:
        report["timestep"] = f"{prepare.timestep_safety} x P-wave time step min R / sqrt(E / rho)"
    return sim, report


def configs(args):
    """(PrepareConfig, ShearConfig, capillary operation or None) of the arguments."""
    prepare = PrepareConfig(particles=args.particles, radius=args.radius,
                            porosity=args.porosity, young=args.young,
                            friction_deg=args.friction, damping=args.damping,
                            prep_friction_deg=getattr(args, "prep_friction", 0.5),
                            timestep_safety=args.timestep_safety, confining=args.confining,
                            seed=args.seed, skin_factor=getattr(args, "skin_factor", 0.3))
    shear = ShearConfig(confining=args.confining, max_strain=args.max_strain,
                        inertial_number=args.inertial_number, strain_rate=args.strain_rate,
                        records=args.records)
    bridges = wet_bridges(args, prepare.radius) if args.suction > 0.0 else None
    return prepare, shear, bridges


def _plain(value):
    """JSON form of NumPy scalars and arrays."""
    return value.tolist() if hasattr(value, "tolist") else str(value)


class Shear:
    """The shear phase of a prepared sample: triaxial wall control, recorder, then (as asked)
    the ParaView writer and the checkpoint writer, always in this order, so that a resumed run
    builds the same simulation; ``finish()`` runs the remaining steps and writes the outputs."""

    def __init__(self, sim, args, prepare, shear, before_shear):
        self.sim, self.args, self.prepare, self.before_shear = sim, args, prepare, before_shear
        self.recorder, self.steps, self.rate = start_shear(sim, shear, prepare.radius,
                                                           prepare.density)
        self.start_step = sim.step
        self.shear_time = 0.0        # seconds spent shearing by earlier (interrupted) runs
        self.vtk_period = (max(1, self.steps // VTK_FRAMES) if args.vtk_every is None
                           else args.vtk_every)
        self.vtk = None
        if self.vtk_period > 0:
            self.vtk = VtkWriter(os.path.join(args.out, "vtk"), self.vtk_period)
            sim.writers.append(self.vtk)
        self.checkpoint = None
        if args.checkpoint_every > 0:
            self.checkpoint = CheckpointWriter(os.path.join(args.out, "checkpoint.h5"),
                                               args.checkpoint_every, self.extra_state)
            sim.writers.append(self.checkpoint)
        self._clock = time.perf_counter()

    def extra_state(self, sim):
        """What a resumed run needs besides the simulation (CheckpointWriter extra_state)."""
        return {"phase": "shear", "steps": self.steps, "start_step": self.start_step,
                "shear_time_s": self.shear_time + time.perf_counter() - self._clock,
                "arguments": self.before_shear["arguments"]}

    def resumed(self, state):
        """Take the progress of the checkpoint loaded into the simulation."""
        self.start_step = state["start_step"]
        self.shear_time = state["shear_time_s"]
        self._clock = time.perf_counter()

    def finish(self):
        """Run the rest of the shear (or stop early at --stop-after) and write the outputs."""
        sim, args, recorder = self.sim, self.args, self.recorder
        remaining = self.steps - (sim.step - self.start_step)
        stop = args.stop_after is not None and args.stop_after < remaining

        def status(s):
            sigma = s.walls.stress()
            lateral = 0.5 * (sigma[0] + sigma[1])
            return {"strain": f"{recorder.last('axial_strain'):.3f}",
                    "sz": f"{sigma[2]:.0f}Pa", "sr": f"{lateral:.0f}Pa",
                    "q/p": f"{3 * (sigma[2] - lateral) / (sigma[2] + 2 * lateral):.2f}"}

        self._clock = time.perf_counter()
        try:
            sim.run(args.stop_after if stop else remaining,
                    progress=None if args.quiet else "shear", status=status)
        except KeyboardInterrupt:
            stop = True
        if stop:             # as an interruption: the last checkpoint is where a resume starts
            if self.checkpoint is not None:
                print(f"triaxial.py: interrupted at step {sim.step}; continue with "
                      f"--resume {args.out}", file=sys.stderr)
            sys.exit(INTERRUPTED)
        if self.vtk is not None:
            self.vtk.close(sim)
        self.shear_time += time.perf_counter() - self._clock
        return self.write_outputs()

    def write_outputs(self):
        sim, args, prepare, rate = self.sim, self.args, self.prepare, self.rate
        preparation = self.before_shear["preparation"]
        history = self.recorder.arrays()
        summary = summarize(history)
        summary.update({
            "initial_porosity": preparation["porosity"],
            "initial_coordination": preparation["coordination"],
            "wall_time_s": self.before_shear["pre_shear_time_s"] + self.shear_time,
            "preparation_time_s": self.before_shear["preparation_time_s"],
            "shear_time_s": self.shear_time,
            "steps": self.steps,
            "preparation_steps": preparation["steps"],
            "particle_steps_per_s": len(sim.particles) * self.steps / self.shear_time,
            "dt": sim.dt,
            "strain_rate": rate,
            "inertial_number": inertial_number(rate, prepare.radius, prepare.density,
                                               args.confining),
            "max_unbalanced_force": float(np.max(history["unbalanced_force"][1:])),
            "mean_unbalanced_force": float(np.mean(history["unbalanced_force"][1:])),
            "threads": numba.get_num_threads(),
            **self.before_shear["wetting"],
        })
        attributes = {k: v for k, v in vars(args).items()
                      if v is not None and k not in ("resume", "stop_after")}
        attributes.update({"timestep": preparation["timestep"], "dt": sim.dt,
                           "strain_rate": rate, "density": prepare.density,
                           "shear_ratio": prepare.shear_ratio,
                           "prep_friction": prepare.prep_friction_deg,
                           "prep_stress": prepare.prep_stress, "vtk_every": self.vtk_period})
        if args.suction > 0.0:
            from capillary.coupling import CapillaryBridges   # a dry scene never loads it

            bridges = sim.operation(CapillaryBridges)
            attributes.update({"bridges": bridges.model, "contact_angle": bridges.contact_angle,
                               "surface_tension": bridges.surface_tension,
                               "persist_bridges": bridges.persist})
        write_history(os.path.join(args.out, "history.h5"), history, attributes)
        write_json(os.path.join(args.out, "summary.json"), summary)
        plot_history(history, os.path.join(args.out, "triaxial.png"))
        write_plots(history, os.path.join(args.out, "plots"))
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
    resolution = getattr(args, "table_resolution", None)     # absent from older runs' arguments
    table_options = (None if resolution is None else
                     dict(zip(("n_suction", "n_distance"), map(int, resolution.split(",")))))
    bridges = CapillaryBridges(args.suction, surface_tension=surface_tension,
                               contact_angle=args.contact_angle or 0.0,
                               model=args.bridges or "exact", persist=args.persist_bridges,
                               table_options=table_options)
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


def _diagonals(values):
    """(rows, 3) diagonal of a (rows, 3, 3) tensor history, or a (rows, 3) one as it is."""
    values = np.asarray(values)
    return np.diagonal(values, axis1=1, axis2=2) if values.ndim == 3 else values


def write_plots(history, folder):
    """The plots of a run into ``folder``: q_p.png (q/p), volumetric_strain.png and, when the
    history has capillary columns, capillary_stress.png (diagonal components of psi, Eq. 3.46,
    and of sigma_capillary, [Pa]), each against axial strain. Returns the paths written."""
    plt = pyplot()
    sigma = history["sigma_wall"]
    lateral = 0.5 * (sigma[:, 0] + sigma[:, 1])
    p = (sigma[:, 2] + 2 * lateral) / 3
    strain = history["axial_strain"]
    curves = {"q_p.png": ("q/p", [("q/p", (sigma[:, 2] - lateral)
                                   / np.where(p > 0, p, math.nan))]),
              "volumetric_strain.png": ("volumetric strain (contraction +)",
                                        [(None, history["volumetric_strain"])])}
    paths = []
    for name, (label, series) in curves.items():
        figure, axes = plt.subplots(figsize=(6, 4))
        for legend, values in series:
            axes.plot(strain, values, label=legend)
        axes.set_xlabel("axial strain")
        axes.set_ylabel(label)
        paths.append(save_figure(figure, os.path.join(folder, name)))
    capillary = [(key, title) for key, title in
                 (("psi", "psi = chi s + B [Pa] (Eq. 3.46)"),
                  ("sigma_capillary", "sigma_capillary [Pa] (tensile negative)"))
                 if key in history]
    if capillary:
        figure, panels = plt.subplots(len(capillary), 1, figsize=(6, 3.5 * len(capillary)),
                                      sharex=True, squeeze=False)
        for axes, (key, title) in zip(panels[:, 0], capillary):
            for axis, values in zip("xyz", _diagonals(history[key]).T):
                axes.plot(strain, values, label=f"{key}_{axis}{axis}")
            axes.set_ylabel(title)
            axes.legend()
        panels[-1, 0].set_xlabel("axial strain")
        paths.append(save_figure(figure, os.path.join(folder, "capillary_stress.png")))
    return paths


def plot_history(history, path):
    """q/p and volumetric strain against axial strain (thesis Fig. 5.3), one figure."""
    sigma = history["sigma_wall"]
    lateral = 0.5 * (sigma[:, 0] + sigma[:, 1])
    p = (sigma[:, 2] + 2 * lateral) / 3
    strain = history["axial_strain"]
    figure, (top, bottom) = pyplot().subplots(2, 1, figsize=(6, 7), sharex=True)
    top.plot(strain, (sigma[:, 2] - lateral) / np.where(p > 0, p, math.nan))
    top.set_ylabel("q/p")
    bottom.plot(strain, history["volumetric_strain"])
    bottom.set_ylabel("volumetric strain (contraction +)")
    bottom.set_xlabel("axial strain")
    save_figure(figure, path)


if __name__ == "__main__":
    main()
