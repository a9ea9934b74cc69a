"""Cross-check of pendular's drained triaxial shear against YADE's on the same packing (issue 5).

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

import math

import numba

from pendular.cli import (UsageError, add_declared_options, positive_int, print_summary,
    set_threads)
from pendular.procedures.options import sample_sizes, size_options
from pendular.procedures.config import (AVERAGES, AXIAL_STRAIN_LIMIT, MAX_AXIAL_STRAIN,
    MIN_AXIAL_STRAIN, MIN_SAMPLE_PARTICLES)
from pendular.studies.crosscheck import (SHOWN, check_mirrored, check_packing, crosscheck_config,
    run_crosscheck)
from pendular.interop.yade.runner import find_yade


def add_arguments(parser):
    parser.add_argument("--particles", type=int, default=1000, help="number of spheres")
    parser.add_argument("--suction", type=float, default=0.0, help="matric suction [Pa] (0: dry)")
    parser.add_argument("--confining", type=float, default=750.0, help="lateral stress [Pa]")
    parser.add_argument("--max-strain", type=float, default=0.25, help="final axial strain")
    add_declared_options(parser, size_options())
    parser.add_argument("--seed", type=int, default=0, help="random seed of the sample")
    parser.add_argument("--out", default="runs/crosscheck", help="output folder")
    parser.add_argument("--periodic", action="store_true",
                        help="a periodic cell instead of six walls: pendular's cell servo "
                             "against YADE's PeriTriaxController")
    parser.add_argument("--mimic-yade", action="store_true",
                        help="pendular takes YADE's wall-control choices (pendular.procedures.config."
                             "YADE_CHOICES)")
    parser.add_argument("--records", type=int, default=200, help="history rows over the shear")
    parser.add_argument("--threads", type=positive_int("--threads", 1), default=1,
                        help="Numba threads of pendular and OpenMP threads of YADE")
    parser.add_argument("--settle-steps", type=int, default=200000,
                        help="most steps to bring the (wetted) sample to rest before export "
                             "(0: export it as loaded)")
    parser.add_argument("--packing", metavar="FILE", default=None,
                        help="shear this exported packing (DIR/packing.txt of an earlier "
                             "cross-check of the same sample and suction) instead of settling")
    parser.add_argument("--concurrent", action="store_true",
                        help="run YADE while pendular shears (halves the wall time; each code's "
                             "timing then shares the machine with the other)")
    parser.add_argument("--quiet", action="store_true",
                        help="no progress bars, and the differences printed as JSON")


def check(args):
    """UsageError naming the option outside its valid range."""
    if args.particles < MIN_SAMPLE_PARTICLES:
        raise UsageError(f"--particles {args.particles} is outside the valid range "
                         f"[{MIN_SAMPLE_PARTICLES}, inf): {AVERAGES}")
    if not math.isfinite(args.suction) or args.suction < 0.0:
        raise UsageError(f"--suction {args.suction} Pa is outside the valid range [0, inf)")
    if not (math.isfinite(args.confining) and args.confining > 0.0):
        raise UsageError(f"--confining {args.confining} Pa is outside the valid range (0, inf)")
    if not MIN_AXIAL_STRAIN <= args.max_strain <= MAX_AXIAL_STRAIN:
        raise UsageError(f"--max-strain {args.max_strain} is outside the valid range "
                         f"[{MIN_AXIAL_STRAIN:g}, {MAX_AXIAL_STRAIN:g}]: {AXIAL_STRAIN_LIMIT}")
    if args.periodic and args.suction > 0.0:
        raise UsageError(f"--suction {args.suction} Pa with --periodic: YADE's "
                         "PeriTriaxController servoes the stress of the contact forces alone "
                         "(without the capillary forces); valid: 0 with --periodic")
    if args.records < 2:
        raise UsageError(f"--records {args.records} is outside the valid range [2, inf)")
    if not 1 <= args.threads <= numba.config.NUMBA_NUM_THREADS:
        raise UsageError(f"--threads {args.threads} is outside the valid range "
                         f"[1, {numba.config.NUMBA_NUM_THREADS}]")
    if args.settle_steps < 0:
        raise UsageError(f"--settle-steps {args.settle_steps} is outside the valid range "
                         "[0, inf)")


def config_from(args):
    """The cross-check's TriaxialConfig of parsed options."""
    return crosscheck_config(particles=args.particles, suction=args.suction,
                             confining=args.confining, max_strain=args.max_strain,
                             records=args.records, mimic_yade=args.mimic_yade,
                             settle_steps=max(args.settle_steps, 1), seed=args.seed,
                             periodic=args.periodic, **sample_sizes(vars(args)))


def run(args):
    check(args)
    config = config_from(args)          # every option checked before YADE is looked for
    check_mirrored(config)
    if args.packing is not None:
        check_packing(config, args.packing)
    try:
        find_yade()
    except RuntimeError as error:
        raise UsageError(str(error)) from None
    set_threads(args.threads)
    result = run_crosscheck(config, args.out, settle=args.settle_steps > 0,
                            packing=args.packing, concurrent=args.concurrent,
                            threads=args.threads, progress=not args.quiet)
    print_summary(result, SHOWN, args.quiet)
    print(f"outputs in {args.out} (crosscheck.json, crosscheck.png)")
    return 0
