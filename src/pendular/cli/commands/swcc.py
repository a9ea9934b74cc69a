"""Soil-water characteristic curve of a DEM sample: drying then wetting at the confining stress.

A sample prepared as in thesis Ch. 5.2.2 is wetted at the lowest of --suctions
(suction-controlled bridges at contacts and, with --form-gap, across gaps where a bridge can
exist), dried through the list, then wetted back along it, each stage run to equilibrium.
Bridges persist across gaps up to their rupture distance and form again only at contact, so
the branches differ where bridges across gaps broke (pendular.procedures.swcc). Writes into --out:
swcc.json (drying and wetting rows: suction, saturation, bridges, porosity, volumetric strain,
chi), swcc.png (Sr against log suction with thesis Fig. 5.5 and the Chapter 4 packings),
history.h5 and sample.h5.
"""

from __future__ import annotations

import sys

from pendular.procedures.preparation import PrepareConfig

from pendular.cli import (UsageError, add_run_options, add_size_options, print_summary,
    set_threads, sizes_from)
from pendular.procedures.config import SwccConfig
from pendular.procedures.swcc import SwccTest

#: Columns of the drying and wetting tables printed at the end (swcc.json's stage rows).
SHOWN_COLUMNS = ("suction", "saturation", "bridges", "porosity", "volumetric_strain", "chi")


def add_arguments(parser):
    parser.add_argument("--particles", type=int, default=1000, help="number of spheres")
    parser.add_argument("--confining", type=float, default=750.0,
                        help="isotropic stress held during the path [Pa]")
    parser.add_argument("--suctions", default="3000,10000,30000,100000,300000",
                        help="suctions of the drying path [Pa], comma separated, ascending; "
                             "wetting goes back along them")
    parser.add_argument("--contact-angle", type=float, default=0.0, help="wetting angle [deg]")
    parser.add_argument("--surface-tension", type=float, default=SwccConfig.surface_tension,
                        help="liquid surface tension [N/m]")
    parser.add_argument("--form-gap", type=float, default=SwccConfig.form_gap,
                        help="at wetting, bridges also form across gaps up to this many mean "
                             "radii [-] (0: at contacts only; 1: wherever a bridge of the "
                             "lowest suction can exist)")
    parser.add_argument("--stage-steps", type=int, default=SwccConfig.stage_steps,
                        help="most steps per stage to reach equilibrium [-]")
    parser.add_argument("--record-every", type=int, default=SwccConfig.record_every,
                        help="steps between history records [-]")
    add_size_options(parser, PrepareConfig.radius)
    parser.add_argument("--friction", type=float, default=18.0, help="contact friction [deg]")
    parser.add_argument("--prep-friction", type=float, default=0.5,
                        help="contact friction during the radius growth [deg]")
    parser.add_argument("--seed", type=int, default=0, help="random seed of the sample")
    parser.add_argument("--out", default="runs/swcc", help="output folder")
    add_run_options(parser)


def suctions_of(text):
    """Floats of --suctions (UsageError naming it)."""
    try:
        return [float(item) for item in text.split(",")]
    except ValueError:
        raise UsageError(f"--suctions = {text!r} is not a comma-separated list of numbers") \
            from None


def config_from(args):
    """The SwccConfig of parsed options (ValueError / UsageError naming the option)."""
    sample = PrepareConfig(particles=args.particles, confining=args.confining,
                           friction_deg=args.friction, prep_friction_deg=args.prep_friction,
                           seed=args.seed, **sizes_from(args))
    return SwccConfig(sample=sample, suctions=suctions_of(args.suctions),
                      surface_tension=args.surface_tension, contact_angle=args.contact_angle,
                      form_gap=args.form_gap, stage_steps=args.stage_steps,
                      record_every=args.record_every)


def run(args):
    set_threads(args.threads)
    result = SwccTest(config_from(args)).run(args.out, progress=not args.quiet,
                                            threads=args.threads)
    if args.quiet:
        print(f"{'branch':<8} {'suction [Pa]':>12} {'Sr [%]':>8} {'bridges':>8} "
              f"{'porosity':>9} {'eps_v':>9} {'chi':>8}")
        for branch in ("drying", "wetting"):
            for row in result[branch]:
                print(f"{branch:<8} {row['suction']:>12g} {100 * row['saturation']:>8.3f} "
                      f"{row['bridges']:>8d} {row['porosity']:>9.4f} "
                      f"{row['volumetric_strain']:>9.2e} {row['chi']:>8.4f}")
    else:
        print_summary(result, ("drying", "wetting"), columns=SHOWN_COLUMNS)
    merged = sorted({row["suction"] for branch in ("drying", "wetting") for row in result[branch]
                     if row["pendular_overlaps"] > 0})
    if merged:
        print(f"warning: at suction(s) {', '.join(f'{s:g}' for s in merged)} Pa menisci merge on "
              "grains (pendular_overlaps > 0 in swcc.json): the sample is past the pendular "
              "regime that the bridges model there", file=sys.stderr)
    print(f"done in {result['wall_time_s']:.0f} s; outputs in {args.out}")
    return 0
