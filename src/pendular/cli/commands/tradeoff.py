"""Speed against accuracy: a wet triaxial (30 kPa, 750 Pa) run with one knob changed at a time
(time-step safety and rule, inertial number, damping, sample size, table resolution, exact or
toroidal bridges, records, neighbour-list skin), each compared with a slow, fine reference on
peak q, Sr and q'/p' at the peak. Every run uses one Numba thread. Writes tradeoff.json,
tradeoff.md (table and recommendations for a quick look and a paper figure) and tradeoff.png
(pendular.studies.tradeoff); finished runs in DIR/runs/ with an equal configuration are reused.
With --knob K: that knob across --seeds samples instead (seeds_K.json, seeds_K.md: its error
against each sample's own reference, the references' scatter between samples, and for a
knob of the preparation the samples prepared with each setting), --jobs runs at a time."""

import sys

from pendular.studies.tradeoff import OPTIONS, SeedStudy, study_of
from pendular.studies.tradeoff_report import write_seed_study, write_study

from pendular.cli import add_declared_options, declared_values

#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular tradeoff --quick --out runs/tradeoff",
           "speed against accuracy of each numerical setting on a small sample; tradeoff.json, "
           "tradeoff.md")


def add_arguments(parser):
    parser.add_argument("--out", required=True, help="output folder")
    add_declared_options(parser, OPTIONS)


def _log(message):
    print(f"tradeoff: {message}", file=sys.stderr, flush=True)


def run(args):
    values = declared_values(OPTIONS, args)
    study = study_of(args.out, values)
    if isinstance(study, SeedStudy):
        data = write_seed_study(study, log=_log)
        print(f"tradeoff: {len(data['runs'])} runs; outputs in {args.out} "
              f"(seeds_{study.knob}.json, seeds_{study.knob}.md)")
        return 0
    data = write_study(study, docs=values["docs"], log=_log)
    print(f"tradeoff: {len(data['rows'])} rows; outputs in {args.out} "
          "(tradeoff.json, tradeoff.md, tradeoff.png)")
    return 0
