"""Drained triaxial test of thesis Chapter 5 (Table 5.2 defaults): prepare, wet, shear, write.

Writes into --out: history.h5 (one row per record), summary.json, triaxial.png, plots/,
vtk/*.pvd (ParaView), sample.h5 (the sample the shear starts from), with
--checkpoint-every N checkpoint.h5 and, with --vtk-prep, vtk_prep/*.pvd (ParaView frames of the
preparation and wetting); --resume DIR continues an interrupted run. Stresses
compression positive [Pa]. Wet test (--suction > 0): bridges at every contact at the confining
stress, re-equilibrated, then sheared (pendular.procedures.triaxial); --wetting chooses when the bridges
appear. Constant water content (--water-content W): volume-controlled bridges holding W % of
the grains' mass, the liquid then conserved during the shear (--rupture-liquid) and the suction an
output. --direction extension pulls the axial walls apart (--max-strain the magnitude of the
extension); --b B holds b = (sigma_2 - sigma_3) / (sigma_1 - sigma_3) (true triaxial, sigma_1
axial, sigma_3 on x); --constant-p holds the mean stress at the confining stress as q rises
(pendular.procedures.loading.shear_stage). --drainage undrained holds the volume (the lateral
walls follow the axial ones): summary excess_pore_pressure_at_peak [Pa] of a saturated sample
and effective_stress_path; wet, the water content is held too (volume-controlled bridges,
closed liquid) and the suction and Sr change.

The sample, wetting and output options are shared with every laboratory command (``pendular
oedometer``, ``isotropic``, ``simple-shear``, ``cyclic``, ``path``): pendular.procedures.options
declares them and builds the configuration; ``loading_command`` makes such a command and
``run_test`` runs it.
"""

from __future__ import annotations

import argparse
import sys

from pendular.cli import (INTERRUPTED, UsageError, add_command_options, add_device_option,
    add_run_options, command_config, positive_int, print_summary, set_threads)
from pendular.dem.simulation import check_device
from pendular.procedures.triaxial import Interrupted, TriaxialTest

#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular triaxial --particles 1000 --suction 30000 --confining 750 --out runs/wet",
           "a wet drained triaxial compression at 30 kPa suction and 750 Pa confining stress: "
           "the peak of q and its friction angles (net and effective), the critical state when "
           "reached, in summary.json; q and the volumetric strain in triaxial.png")

#: Options a resumed run takes from its own command line, not from the stored run.
RESUME_OPTIONS = ("resume", "quiet", "threads", "device", "stop_after", "force")
#: Summary keys printed at the end.
SHOWN = ("peak_axial_stress", "min_axial_stress", "peak_q", "p_at_peak", "axial_strain_at_peak",
         "principal_difference_at_peak", "phi_peak_deg", "peak_q_effective",
         "p_effective_at_peak", "phi_peak_effective_deg", "peak_q_effective_complete",
         "p_effective_complete_at_peak", "phi_cs_deg", "M_cs", "void_ratio_cs",
         "critical_state_note", "phi_peak_note",
         "mean_stress_deviation", "b_deviation", "axial_contact_lost", "initial_porosity",
         "porosity_after_wetting", "saturation_at_peak", "suction_at_peak",
         "excess_pore_pressure_at_peak", "excess_pore_pressure_final", "p_min",
         "max_volume_change", "suction_final", "saturation_final",
         "liquid_balance_error", "liquid_lost_fraction", "wall_time_s", "particle_steps_per_s")


def loading_command(name, test, shown):
    """(add_arguments, config_from, run) of the laboratory command ``name`` (a key of
    pendular.procedures.options.COMMANDS) running the LaboratoryTest subclass ``test`` and
    printing the summary's ``shown`` keys; its output folder runs/<name>."""
    def add_arguments(parser):
        add_command_options(parser, name)
        add_output_options(parser, "runs/" + name.replace("-", "_"))

    def config_from(args):
        """The configuration of parsed options (ValueError naming the option)."""
        return command_config(name, args)

    def run(args):
        return run_test(args, test, config_from, shown, add_arguments)

    return add_arguments, config_from, run


def add_output_options(parser, out):
    """How a run is watched: output folder (default ``out``), --force, run options, device,
    ParaView frames of the preparation, resume."""
    parser.add_argument("--out", default=out, help="output folder")
    parser.add_argument("--force", action="store_true",
                        help="run settings refused as not quasi-static or too long (experts)")
    add_run_options(parser)
    add_device_option(parser, "the preparation or a loaded sample's equilibrium, the wetting "
                              "and the loading (a checkpoint resumes on either device)")
    parser.add_argument("--vtk-prep", metavar="N", nargs="?", const=True, default=False,
                        type=positive_int("--vtk-prep", low=1),
                        help="also write ParaView frames of the preparation and wetting into "
                             "DIR/vtk_prep/ (field data 'phase': 0 growth, 1 friction, 2 "
                             "unload, 3 equilibrate, 4 sample, 5 wetting), every N steps "
                             "(default: unload_steps / 20 = 500, a few tens of frames)")
    add_resume_options(parser)


def add_resume_options(parser):
    """--resume DIR and, for the tests, --stop-after N (stop the loading after N steps as an
    interruption would, exit status 130)."""
    parser.add_argument("--resume", metavar="DIR", default=None,
                        help="continue the interrupted run of DIR from its checkpoint, with the "
                             "configuration stored there (only --quiet, --threads and --device "
                             "may be added)")
    parser.add_argument("--stop-after", type=positive_int("--stop-after", low=1), default=None,
                        help=argparse.SUPPRESS)


def check_resume_options(args, add_arguments):
    """UsageError naming the options of ``args`` given beside --resume that would change the
    stored run (any but RESUME_OPTIONS away from its default; ``add_arguments``: the
    command's options, for their defaults)."""
    defaults = vars(_defaults(add_arguments))
    given = [name for name, value in vars(args).items()
             if name not in RESUME_OPTIONS and value != defaults.get(name)]
    if given:
        raise UsageError(f"--resume takes the run's configuration from {args.resume}; "
                         f"{', '.join('--' + n.replace('_', '-') for n in given)} "
                         "cannot be changed (only --quiet, --threads and --device may be "
                         "added)")


add_arguments, config_from, run = loading_command("triaxial", TriaxialTest, SHOWN)


def run_test(args, test, config_from, shown, add_arguments):
    """Run (or with --resume continue) the LaboratoryTest subclass ``test`` of the options
    ``args`` (configuration by ``config_from``; ``add_arguments``: the command's options, for
    their defaults); print the summary's ``shown`` keys (print_summary: JSON with --quiet);
    the exit status."""
    set_threads(args.threads)
    progress = not args.quiet
    try:
        if args.resume is not None:
            check_resume_options(args, add_arguments)
            summary = test.resume(args.resume, progress=progress, threads=args.threads,
                                  stop_after=args.stop_after, device=args.device)
            out = args.resume
        else:
            config = config_from(args)
            check_device(args.device)               # before the test loads its tables
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
    # with --quiet, stdout holds the JSON alone
    print(f"outputs in {out}", file=sys.stderr if args.quiet else sys.stdout)
    return 0


def _defaults(add_arguments):
    """The options' default values (those of an empty command line) of the command whose
    options ``add_arguments`` declares."""
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return parser.parse_args([])
