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
from pendular.utils.parameters import add_options, fields_from, spec_of

#: The fields set by their options as they are (--suctions, a comma list, by hand).
OWN = ("contact_angle", "surface_tension", "form_gap", "stage_steps", "record_every")
#: The sample's options whose defaults are PrepareConfig's (--particles, 1000 here, by hand).
SAMPLE = ("friction_deg", "prep_friction_deg", "seed")

#: Columns of the drying and wetting tables printed at the end (swcc.json's stage rows).
SHOWN_COLUMNS = ("suction", "saturation", "bridges", "porosity", "volumetric_strain", "chi")


def add_arguments(parser):
    parser.add_argument("--particles", type=int, default=1000, help="number of spheres")
    add_options(parser, PrepareConfig, ("confining",))
    suctions = spec_of(SwccConfig, "suctions")         # a comma list: by hand
    parser.add_argument(suctions.flag, default=",".join(
        f"{v:g}" for v in SwccConfig().suctions), help=f"{suctions.help} [{suctions.unit}], "
        "comma separated")
    add_options(parser, SwccConfig, OWN)
    add_size_options(parser, PrepareConfig.radius)
    add_options(parser, PrepareConfig, SAMPLE)
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
    sample = PrepareConfig(particles=args.particles, **sizes_from(args),
                           **fields_from(args, PrepareConfig, ("confining", *SAMPLE)))
    return SwccConfig(sample=sample, suctions=suctions_of(args.suctions),
                      **fields_from(args, SwccConfig, OWN))


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
