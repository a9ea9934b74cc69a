"""Drained triaxial test of thesis Chapter 5 (Table 5.2 defaults): prepare, wet, shear, write.

Writes into --out: history.h5 (one row per record), summary.json, triaxial.png, plots/,
vtk/*.pvd (ParaView), sample.h5 (the sample the shear starts from), with
--checkpoint-every N checkpoint.h5 and, with --vtk-prep, vtk_prep/*.pvd (ParaView frames of the
preparation and wetting); --resume DIR continues an interrupted run. Stresses
compression positive [Pa]. Wet test (--suction > 0): bridges at every contact at the confining
stress, re-equilibrated, then sheared (pendular.procedures.triaxial); --wetting chooses when the bridges
appear. Constant water content (--water-content W): volume-controlled bridges holding W % of
the grains' mass, the liquid then conserved during the shear (--liquid) and the suction an
output. --direction extension pulls the axial walls apart (--max-strain the magnitude of the
extension); --b B holds b = (sigma_2 - sigma_3) / (sigma_1 - sigma_3) (true triaxial, sigma_1
axial, sigma_3 on x); --constant-p holds the mean stress at the confining stress as q rises
(pendular.procedures.loading.shear_stage).

The sample, wetting and output options are shared with ``pendular oedometer`` and ``pendular
isotropic`` (``add_sample_options``, ``add_wetting_options``, ``add_output_options``, built into
configurations by ``laboratory_fields``; ``run_test`` runs any of the three).
"""

from __future__ import annotations

import argparse
import sys

from pendular.procedures.preparation import PrepareConfig
from pendular.dem.simulation import DEVICES
from pendular.utils.parameters import add_options
from pendular.utils.validate import check_int, check_range

from pendular.cli import (INTERRUPTED, UsageError, add_run_options, add_size_options, positive_int,
    print_summary, set_threads, sizes_from)
from pendular.procedures.config import (AXIAL_STRAIN_LIMIT, MAX_AXIAL_STRAIN, MAX_RECORDS,
    MIN_AXIAL_STRAIN, BridgeConfig, LaboratoryConfig,
    ShearConfig, TriaxialConfig, check_steps_count)
from pendular.procedures.triaxial import Interrupted, TriaxialTest, check_device

#: Options a resumed run takes from its own command line, not from the stored run.
RESUME_OPTIONS = ("resume", "quiet", "threads", "device", "stop_after", "force")
#: Options of the preparation alone, which a run from a prepared --sample does not use.
PREPARATION_OPTIONS = ("porosity", "prep_friction")
#: Summary keys printed at the end.
SHOWN = ("peak_axial_stress", "min_axial_stress", "peak_q", "p_at_peak", "axial_strain_at_peak",
         "phi_peak_deg", "peak_q_effective", "p_effective_at_peak", "phi_peak_effective_deg",
         "peak_q_effective_complete", "p_effective_complete_at_peak", "mean_stress_deviation",
         "b_deviation", "axial_contact_lost", "initial_porosity", "saturation_at_peak",
         "suction_at_peak", "liquid_balance_error", "liquid_lost_fraction", "wall_time_s",
         "particle_steps_per_s")
#: Wetting options, each with its unset value: given without a wet test they are refused.
WET_ONLY = {"contact_angle": None, "table_resolution": None, "bridges": None,
            "surface_tension": None, "persist_bridges": False, "wetting": "isotropic"}


def add_arguments(parser):
    add_sample_options(parser)
    add_wetting_options(parser)
    add_options(parser, ShearConfig, ("max_strain", "direction", "b", "constant_p"))
    add_rate_options(parser)
    add_options(parser, ShearConfig, ("records",))
    add_output_options(parser, "runs/triaxial", frames=True)


def add_sample_options(parser):
    """The sample's options (preparation and material, or a prepared --sample)."""
    add_options(parser, PrepareConfig, ("particles", "confining", "seed", "periodic"))
    add_size_options(parser, PrepareConfig.radius)
    add_options(parser, PrepareConfig, ("porosity", "friction_deg", "prep_friction_deg", "young",
                                        "damping", "timestep_safety", "timestep_rule",
                                        "skin_factor"))
    add_options(parser, LaboratoryConfig, ("sample_path",))


def add_wetting_options(parser):
    """The options of a wet test (at a suction or a water content)."""
    parser.add_argument("--suction", type=float, default=0.0,
                        help="matric suction [Pa] (0: dry)")
    add_options(parser, BridgeConfig, ("contact_angle", "model", "surface_tension"))
    parser.add_argument("--water-content", type=float, default=None,
                        help="gravimetric water content [%%] held by volume-controlled bridges "
                             "at constant liquid volume, instead of --suction")
    add_options(parser, BridgeConfig, ("liquid",))
    add_options(parser, LaboratoryConfig, ("wetting",))
    add_options(parser, BridgeConfig, ("persist",))
    add_options(parser, LaboratoryConfig, ("wet_steps",))
    parser.add_argument("--table-resolution", metavar="NS,ND", default=None,
                        help="bridge table nodes in suction and in distance (exact default "
                             "350,80; toroidal 64,80)")


def add_rate_options(parser):
    """The loading rate: an inertial number or a strain rate."""
    add_options(parser, ShearConfig, ("inertial_number", "strain_rate"))


def add_output_options(parser, out, frames=True):
    """Output folder (default ``out``), ParaView frames (--vtk-frames only when ``frames``: a
    path whose length is known before it runs), checkpoints, resume, run options."""
    parser.add_argument("--out", default=out, help="output folder")
    parser.add_argument("--force", action="store_true",
                        help="run settings refused as not quasi-static or too long (experts)")
    add_run_options(parser)
    parser.add_argument("--device", choices=DEVICES, default="cpu",
                        help="where the loading runs: cpu, or gpu (numba-cuda, pip install -e "
                             "'.[gpu]'; the preparation and wetting stay on the CPU; "
                             "docs/gpu.md); a run option: a checkpoint resumes on either")
    group = parser.add_mutually_exclusive_group() if frames else parser
    group.add_argument("--vtk-every", type=positive_int("--vtk-every"), default=None,
                       help="steps between ParaView frames of the loading (default: " + (
                           f"about {LaboratoryConfig.vtk_frames} frames" if frames else
                           "a frame every 10 history rows") + "; 0: no ParaView output)")
    if frames:
        group.add_argument("--vtk-frames", type=positive_int("--vtk-frames"), default=None,
                           help="ParaView frames over the shear (0: none; default "
                                f"{LaboratoryConfig.vtk_frames}; at most one a step); instead "
                                "of --vtk-every")
    parser.add_argument("--vtk-prep", metavar="N", nargs="?", const=True, default=False,
                        type=positive_int("--vtk-prep", low=1),
                        help="also write ParaView frames of the preparation and wetting into "
                             "DIR/vtk_prep/ (field data 'phase': 0 growth, 1 friction, 2 "
                             "unload, 3 equilibrate, 4 sample, 5 wetting), every N steps "
                             "(default: unload_steps / 20 = 500, a few tens of frames)")
    parser.add_argument("--checkpoint-every", type=positive_int("--checkpoint-every"),
                        default=0, help="steps between checkpoints DIR/checkpoint.h5 (0: none)")
    parser.add_argument("--resume", metavar="DIR", default=None,
                        help="continue the interrupted run of DIR from its checkpoint, with the "
                             "configuration stored there (only --quiet, --threads and --device "
                             "may be added)")
    # tests: stop the loading after this many steps as an interruption would (exit status 130)
    parser.add_argument("--stop-after", type=positive_int("--stop-after", low=1), default=None,
                        help=argparse.SUPPRESS)


def table_resolution(text):
    """(NS, ND) of --table-resolution, or None."""
    if text is None:
        return None
    try:
        nodes = tuple(int(v) for v in text.split(","))
    except ValueError:
        nodes = ()
    if len(nodes) != 2 or min(nodes) < 4:
        raise UsageError(f"--table-resolution {text!r}: two integers NS,ND, each in [4, inf), "
                         "expected")
    return nodes


def config_from(args):
    """The TriaxialConfig of parsed options (ValueError / UsageError naming the option)."""
    if not MIN_AXIAL_STRAIN <= args.max_strain <= MAX_AXIAL_STRAIN:      # NaN included
        raise UsageError(f"--max-strain = {args.max_strain:g} is outside the valid range "
                         f"[{MIN_AXIAL_STRAIN:g}, {MAX_AXIAL_STRAIN:g}]: {AXIAL_STRAIN_LIMIT}")
    if args.records is not None:
        check_int("--records", args.records, low=2, high=MAX_RECORDS)
    fields = laboratory_fields(args, add_arguments, lambda: ShearConfig(
        max_strain=args.max_strain, inertial_number=args.inertial_number,
        strain_rate=args.strain_rate, direction=args.direction, b=args.b,
        constant_p=args.constant_p,
        **({} if args.records is None else {"records": args.records})))
    frames = {} if args.vtk_frames is None else {"vtk_frames": args.vtk_frames}
    config = TriaxialConfig(**fields, **frames)
    # counts given beyond the shear's steps would silently give one a step (the defaults may)
    steps = config.shear_steps()
    phase = f"the shear to --max-strain {config.shear.max_strain:g}"
    if args.vtk_frames is not None:
        check_steps_count("--vtk-frames", args.vtk_frames, steps, phase)
    if args.records is not None:
        check_steps_count("--records", args.records, steps, phase, low=2)
    return config


def laboratory_fields(args, add_arguments, path):
    """The fields of a LaboratoryConfig from options of ``add_sample_options``,
    ``add_wetting_options`` and ``add_output_options`` (the command's ``add_arguments``, for
    its defaults), with the path's own, built by ``path()`` after the sample and before the
    bridges: {'shear': ShearConfig} or the path's fields as a dict. UsageError naming the
    option for a wetting option without a wet test, a preparation option with --sample."""
    check_range("--suction", args.suction, 0.0, unit="Pa")
    water = args.water_content
    if water is not None and args.suction > 0.0:
        raise UsageError("--suction and --water-content: give one (at a water content the "
                         "suction is an output)")
    if water is not None and (args.bridges == "toroidal" or args.persist_bridges):
        raise UsageError("--water-content uses volume-controlled exact bridges: "
                         "--bridges toroidal and --persist-bridges do not apply")
    if args.liquid is not None and water is None:
        raise UsageError("--liquid needs --water-content")
    wet_only = [name for name, unset in WET_ONLY.items() if getattr(args, name) != unset]
    if args.suction == 0.0 and water is None and wet_only:
        raise UsageError(f"{', '.join('--' + n.replace('_', '-') for n in wet_only)} need(s) a "
                         "wet test: give --suction > 0")
    if args.sample is not None:
        defaults = _defaults(add_arguments)
        preparation = [name for name in PREPARATION_OPTIONS
                       if getattr(args, name) != getattr(defaults, name)]
        if preparation:
            raise UsageError(f"{', '.join('--' + n.replace('_', '-') for n in preparation)} "
                             f"do(es) not apply with --sample {args.sample}: the sample is "
                             "already prepared (only its equilibrium and the loading run); "
                             "leave out --sample to prepare one")
    sample = PrepareConfig(particles=args.particles, porosity=args.porosity,
                           **sizes_from(args),
                           young=args.young, friction_deg=args.friction, damping=args.damping,
                           prep_friction_deg=args.prep_friction,
                           timestep_safety=args.timestep_safety,
                           timestep_rule=args.timestep_rule, confining=args.confining,
                           seed=args.seed, skin_factor=args.skin_factor,
                           periodic=args.periodic)
    own = path()
    own = {"shear": own} if isinstance(own, ShearConfig) else own
    bridges = None
    options = {"surface_tension": args.surface_tension, "contact_angle": args.contact_angle,
               "model": args.bridges, "liquid": args.liquid}
    options = {k: v for k, v in options.items() if v is not None}
    if args.suction > 0.0:
        bridges = BridgeConfig(args.suction, persist=args.persist_bridges,
                               table_resolution=table_resolution(args.table_resolution),
                               **options)
    elif water is not None:
        check_range("--water-content", water, 0.0, 100.0, low_inclusive=False, unit="%")
        bridges = BridgeConfig(water_content=water / 100.0, control="volume",
                               table_resolution=table_resolution(args.table_resolution),
                               **options)
    return {"sample": sample, "bridges": bridges, "sample_path": args.sample,
            "wet_steps": args.wet_steps, "vtk_every": args.vtk_every,
            "checkpoint_every": args.checkpoint_every, "wetting": args.wetting, **own}


def run(args):
    return run_test(args, TriaxialTest, config_from, SHOWN, add_arguments)


def run_test(args, test, config_from, shown, add_arguments):
    """Run (or with --resume continue) the LaboratoryTest subclass ``test`` of the options
    ``args`` (configuration by ``config_from``; ``add_arguments``: the command's options, for
    their defaults); print the summary's ``shown`` keys (print_summary: JSON with --quiet);
    the exit status."""
    set_threads(args.threads)
    progress = not args.quiet
    try:
        if args.resume is not None:
            defaults = vars(_defaults(add_arguments))
            given = [name for name, value in vars(args).items()
                     if name not in RESUME_OPTIONS and value != defaults.get(name)]
            if given:
                raise UsageError(f"--resume takes the run's configuration from {args.resume}; "
                                 f"{', '.join('--' + n.replace('_', '-') for n in given)} "
                                 "cannot be changed (only --quiet, --threads and --device may be "
                                 "added)")
            summary = test.resume(args.resume, progress=progress, threads=args.threads,
                                  stop_after=args.stop_after, device=args.device)
            out = args.resume
        else:
            config = config_from(args)
            check_device(config, args.device)       # before the test loads its tables
            summary = test(config, force=args.force).run(
                args.out, progress=progress, threads=args.threads, stop_after=args.stop_after,
                vtk_prep=args.vtk_prep, device=args.device)
            out = args.out
    except Interrupted as stop:
        print(f"{stop}", file=sys.stderr)
        return INTERRUPTED
    print_summary(summary, shown, args.quiet)
    if not args.quiet and summary.get("peak_reached") is False:
        print("note: q still rises at the end of the test (peak_reached false in "
              "summary.json): the values 'at peak' are those of the highest record; a larger "
              "--max-strain reaches the peak")
    print(f"outputs in {out}")
    return 0


def _defaults(add_arguments):
    """The options' default values (those of an empty command line) of the command whose
    options ``add_arguments`` declares."""
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return parser.parse_args([])
