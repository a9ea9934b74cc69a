"""Soil-water characteristic curve of a DEM sample: drying then wetting at the confining stress.

A sample prepared as in thesis Ch. 5.2.2 is wetted at the lowest of --suctions
(suction-controlled bridges at contacts and, with --form-gap, across gaps where a bridge can
exist), dried through the list, then wetted back along it, each stage run to equilibrium.
Bridges persist across gaps up to their rupture distance and form again only at contact, so
the branches differ where bridges across gaps broke (pendular.procedures.swcc). Writes into --out:
swcc.json (drying and wetting rows: suction, saturation, bridges, porosity, volumetric strain,
chi), swcc.png (Sr against log suction with thesis Fig. 5.5 and the Chapter 4 packings),
history.h5 and sample.h5, with --checkpoint-every N checkpoint.h5; --resume DIR continues an
interrupted run bit for bit. --device gpu runs the preparation and the path on the GPU
(docs/gpu.md). --liquid clusters adds liquid clusters of filled pore units to the bridges,
the sample starting saturated: the main drying and wetting curves, with the clusters' figures
in the rows and pores/ for ParaView (docs/liquid_clusters.md; on either device).
"""

from __future__ import annotations

import sys

from pendular.cli import (INTERRUPTED, add_command_options, add_device_option,
    add_run_options, command_config, declared_values, print_summary, set_threads)
from pendular.cli.commands.triaxial import add_resume_options, check_resume_options, run_options
from pendular.procedures.options import CHECKPOINT_EVERY
from pendular.procedures.registry import COMMANDS
from pendular.procedures.swcc import SwccTest
from pendular.procedures.laboratory import Interrupted

#: The command's declaration (pendular.procedures.registry).
COMMAND = COMMANDS["swcc"]
EXAMPLE = COMMAND.example



def add_arguments(parser):
    add_command_options(parser, "swcc")
    parser.add_argument("--out", default=COMMAND.out, help="output folder")
    add_run_options(parser)
    add_device_option(parser, "the preparation and the path (the wetting across gaps stays on "
                              "the CPU)")
    add_resume_options(parser)


def config_from(args):
    """The SwccConfig of parsed options (ValueError naming the option)."""
    return command_config("swcc", args)


def run(args):
    set_threads(args.threads)
    try:
        if args.resume is not None:
            check_resume_options(args, add_arguments)
            result = SwccTest.resume(args.resume, run_options(args))
            args.out = args.resume
        else:
            every = declared_values((CHECKPOINT_EVERY,), args)["checkpoint_every"]
            result = SwccTest(config_from(args)).run(args.out,
                                                     run_options(args, checkpoint_every=every))
    except Interrupted as stop:
        print(f"{stop}", file=sys.stderr)
        return INTERRUPTED
    print_summary(result, COMMAND.shown, args.quiet, columns=COMMAND.columns)
    merged = sorted({row["suction"] for branch in ("drying", "wetting") for row in result[branch]
                     if row["pendular_overlaps"] > 0})
    if merged:
        print(f"warning: at suction(s) {', '.join(f'{s:g}' for s in merged)} Pa menisci merge on "
              "grains (pendular_overlaps > 0 in swcc.json): the sample is past the pendular "
              "regime that the bridges model there", file=sys.stderr)
    # with --quiet, stdout holds the JSON alone
    print(f"done in {result['wall_time_s']:.0f} s; outputs in {args.out}",
          file=sys.stderr if args.quiet else sys.stdout)
    return 0
