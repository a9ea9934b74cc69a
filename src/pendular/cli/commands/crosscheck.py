"""Cross-check of pendular's drained triaxial shear against YADE's on the same packing.

pendular prepares (cached) and settles the sample at --confining (wet with --suction > 0:
bridges at every contact) and exports it to DIR/packing.txt; both codes shear that packing from
rest with x, y servoed and z compressed at the strain rate of pendular's default inertial
number, with the same time step, damping and servo settings (pendular.studies.crosscheck); with
--periodic in a periodic cell (YADE: PeriTriaxController) instead of six walls. Writes
DIR/crosscheck.json (both codes' peak and start-of-shear values and their differences),
DIR/crosscheck.png, DIR/yade_history.txt and DIR/pendular_history.h5. Stresses compression
positive [Pa]. Needs ``yade`` on PATH; docs/yade_crosscheck.md lists the differences.
"""

from __future__ import annotations

import sys

from pendular.cli import (UsageError, add_declared_options, add_device_option, declared_values,
    positive_int, print_summary, set_threads)
from pendular.dem.simulation import check_device
from pendular.procedures.run_options import RunOptions
from pendular.studies.crosscheck import OPTIONS, SHOWN, CrossCheck, crosscheck_from_options
from pendular.interop.yade.runner import find_yade
from pendular.utils.parameters import OptionError, ParameterError

#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular crosscheck --particles 1000 --suction 30000 --out runs/crosscheck",
           "the same packing sheared by pendular and YADE (when installed) side by side; "
           "crosscheck.json, crosscheck.png")


def add_arguments(parser):
    add_declared_options(parser, OPTIONS)
    parser.add_argument("--out", default="runs/crosscheck", help="output folder")
    parser.add_argument("--threads", type=positive_int("--threads", 1), default=1,
                        help="Numba threads of pendular and OpenMP threads of YADE")
    parser.add_argument("--concurrent", action="store_true",
                        help="run YADE while pendular shears (halves the wall time; each code's "
                             "timing then shares the machine with the other)")
    parser.add_argument("--quiet", action="store_true",
                        help="no progress bars, and the differences printed as JSON")
    add_device_option(parser, "pendular's settling and shear (the cached preparation on the "
                              "CPU)")


def config_from(args):
    """The cross-check's TriaxialConfig of parsed options (pendular.studies.crosscheck.
    crosscheck_from_options: ValueError naming the option)."""
    return crosscheck_from_options(declared_values(OPTIONS, args))


def check(args):
    """config_from, its errors as UsageError naming the flag."""
    try:
        return config_from(args)
    except (OptionError, ParameterError) as error:
        raise UsageError(error.on_command_line()) from None


def run(args):
    config = check(args)                # every option checked before YADE is looked for
    set_threads(args.threads)
    check_device(args.device)
    crosscheck = CrossCheck(config, settle=args.settle_steps > 0, packing=args.packing)
    try:
        find_yade()
    except RuntimeError as error:
        raise UsageError(str(error)) from None
    options = RunOptions(device=args.device, threads=args.threads, progress=not args.quiet,
                         concurrent=args.concurrent)
    result = crosscheck.run(args.out, options)
    print_summary(result, SHOWN, args.quiet)
    # with --quiet, stdout holds the JSON alone
    print(f"outputs in {args.out} (crosscheck.json, crosscheck.png)",
          file=sys.stderr if args.quiet else sys.stdout)
    return 0
