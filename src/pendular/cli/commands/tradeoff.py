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

from pendular.studies.tradeoff import KNOBS, SeedStudy, Study, write_seed_study, write_study


def add_arguments(parser):
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--particles", type=int, default=2000,
                        help="spheres of the reference sample")
    parser.add_argument("--max-strain", type=float, default=0.15, help="final axial strain [-]")
    parser.add_argument("--seed", type=int, default=0, help="random seed of the samples")
    parser.add_argument("--quick", action="store_true",
                        help="three knobs, three settings each (a smoke test)")
    parser.add_argument("--docs", metavar="FOLDER", default=None,
                        help="also copy tradeoff.json/.md/.png into FOLDER")
    parser.add_argument("--knob", choices=[k for k in KNOBS if k != "particles"], default=None,
                        help="study this knob across --seeds samples instead")
    parser.add_argument("--seeds", type=int, default=None,
                        help="samples of the --knob study (seeds SEED ... SEED + SEEDS - 1; "
                             "default 6)")
    parser.add_argument("--jobs", type=int, default=1,
                        help="runs at a time in the --knob study (one thread each)")


def _log(message):
    print(f"tradeoff: {message}", file=sys.stderr, flush=True)


def run(args):
    if args.knob is not None:
        if args.quick or args.docs:
            raise ValueError("--knob studies one knob across samples: --quick and --docs "
                             "belong to the one-sample study")
        study = SeedStudy(out=args.out, knob=args.knob, seeds=6 if args.seeds is None
                          else args.seeds, particles=args.particles,
                          max_strain=args.max_strain, seed=args.seed, jobs=args.jobs)
        data = write_seed_study(study, log=_log)
        print(f"tradeoff: {len(data['runs'])} runs; outputs in {args.out} "
              f"(seeds_{args.knob}.json, seeds_{args.knob}.md)")
        return 0
    if args.seeds is not None or args.jobs != 1:
        raise ValueError("--seeds and --jobs belong to a --knob study: give --knob")
    study = Study(out=args.out, particles=args.particles, max_strain=args.max_strain,
                  seed=args.seed, quick=args.quick)
    data = write_study(study, docs=args.docs, log=_log)
    print(f"tradeoff: {len(data['rows'])} rows; outputs in {args.out} "
          "(tradeoff.json, tradeoff.md, tradeoff.png)")
    return 0
