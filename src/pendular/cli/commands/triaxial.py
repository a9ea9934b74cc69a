"""Drained triaxial test of thesis Chapter 5 (Table 5.2 defaults): prepare, wet, shear, write.

Writes into --out: history.h5 (one row per record), summary.json, triaxial.png, plots/,
``vtk/*.pvd`` (ParaView), sample.h5 (the sample the shear starts from), with --checkpoint-every
N checkpoint.h5 and, with --vtk-prep, ``vtk_prep/*.pvd`` (ParaView frames of the preparation
and wetting); --resume DIR continues an interrupted run. Stresses compression positive [Pa].
Wet test (--suction > 0): bridges at every contact at the confining stress, re-equilibrated,
then sheared (pendular.procedures.triaxial); --wetting chooses when the bridges appear.
Constant water content (--water-content W): volume-controlled bridges holding W % of the
grains' mass, the liquid then conserved during the shear (--rupture-liquid) and the suction an
output. --direction extension pulls the axial walls apart (--max-strain the magnitude of the
extension); --b B holds b = (sigma_2 - sigma_3) / (sigma_1 - sigma_3) (true triaxial, sigma_1
axial, sigma_3 on x); --constant-p holds the mean stress at the confining stress as q rises
(pendular.procedures.triaxial.shear_stage). --drainage undrained holds the volume (the lateral
walls follow the axial ones): summary excess_pore_pressure_at_peak [Pa] of a saturated sample
and effective_stress_path; wet, the water content is held too (volume-controlled bridges,
closed liquid) and the suction and Sr change. --liquid clusters (at a suction or a water
content, between walls or in a periodic cell; on the GPU between walls): liquid clusters of filled pore
units beside persisting bridges, updated as the packing deforms
(pendular.procedures.loading_clusters); ``pores/*.pvd`` holds the pore units coloured by
cluster.

The sample, wetting and output options are shared with every laboratory command (``pendular
oedometer``, ``isotropic``, ``simple-shear``, ``cyclic``, ``path``): pendular.procedures.options
declares them, each test's module (pendular.procedures.registry) its own and how they build
the configuration; ``loading_command`` makes such a command and ``run_test`` runs it.
"""

from __future__ import annotations

import argparse
import sys

from pendular.cli import (INTERRUPTED, UsageError, add_command_options, add_device_option,
    add_run_options, command_config, positive_int, print_summary, set_threads)
from pendular.dem.simulation import check_device
from pendular.procedures.laboratory import Interrupted
from pendular.procedures.registry import COMMANDS
from pendular.procedures.run_options import RunOptions

#: Options a resumed run takes from its own command line, not from the stored run.
RESUME_OPTIONS = ("resume", "quiet", "threads", "device", "stop_after", "force", "no_plots")
def loading_command(name):
    """(add_arguments, config_from, run, EXAMPLE) of the laboratory command ``name`` (a key
    of pendular.procedures.registry.COMMANDS): its declared options, its test, the summary
    keys it prints, its worked example and its output folder."""
    command = COMMANDS[name]

    def add_arguments(parser):
        add_command_options(parser, name)
        add_output_options(parser, command.out)

    def config_from(args):
        """The configuration of parsed options (ValueError naming the option)."""
        return command_config(name, args)

    def run(args):
        return run_test(args, command.test, config_from, command.shown, add_arguments)

    return add_arguments, config_from, run, command.example


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
    parser.add_argument("--no-plots", action="store_true",
                        help="write no figures (the test's figure and plots/); the history, "
                             "summary, sample and ParaView series are written as always "
                             "(sweeps and scripts that read the data)")
    add_resume_options(parser)


def add_resume_options(parser):
    """--resume DIR and, for the tests, --stop-after N (stop the loading after N steps as an
    interruption would, exit status 130)."""
    parser.add_argument("--resume", metavar="DIR", default=None,
                        help="continue the interrupted run of DIR from its checkpoint, with the "
                             "configuration stored there (only --quiet, --threads, --device "
                             "and, on a laboratory test, --no-plots may be added)")
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
                         "cannot be changed (only --quiet, --threads, --device and, on a "
                         "laboratory test, --no-plots may be added)")


add_arguments, config_from, run, EXAMPLE = loading_command("triaxial")


def run_test(args, test, config_from, shown, add_arguments):
    """Run (or with --resume continue) the LaboratoryTest subclass ``test`` of the options
    ``args`` (configuration by ``config_from``; ``add_arguments``: the command's options, for
    their defaults); print the summary's ``shown`` keys (print_summary: JSON with --quiet);
    the exit status."""
    set_threads(args.threads)
    try:
        if args.resume is not None:
            check_resume_options(args, add_arguments)
            summary = test.resume(args.resume, run_options(args, plots=not args.no_plots))
            out = args.resume
        else:
            config = config_from(args)
            check_device(args.device)               # before the test loads its tables
            options = run_options(args, force=args.force, vtk_prep=args.vtk_prep,
                                  plots=not args.no_plots)
            summary = test(config, force=options.force).run(args.out, options)
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


def run_options(args, **more):
    """The RunOptions of the parsed options ``args`` (--device, --threads, --quiet and the
    hidden --stop-after), with ``more`` (a command's own: force, vtk_prep, ...)."""
    return RunOptions(device=args.device, threads=args.threads, progress=not args.quiet,
                      stop_after=args.stop_after, **more)


def _defaults(add_arguments):
    """The options' default values (those of an empty command line) of the command whose
    options ``add_arguments`` declares."""
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return parser.parse_args([])
