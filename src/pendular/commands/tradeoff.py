"""Speed against accuracy: a wet triaxial (30 kPa, 750 Pa) run with one knob changed at a time
(time-step safety and rule, inertial number, damping, sample size, table resolution, exact or
toroidal bridges, records, neighbour-list skin), each compared with a slow, fine reference on
peak q, Sr and q'/p' at the peak. Every run uses one Numba thread. Writes tradeoff.json,
tradeoff.md (table and recommendations for a quick look and a paper figure) and tradeoff.png
(pendular.tradeoff); finished runs in DIR/runs/ with an equal configuration are reused."""

import sys

from ..tradeoff import Study, write_study


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


def _log(message):
    print(f"tradeoff: {message}", file=sys.stderr, flush=True)


def run(args):
    study = Study(out=args.out, particles=args.particles, max_strain=args.max_strain,
                  seed=args.seed, quick=args.quick)
    data = write_study(study, docs=args.docs, log=_log)
    print(f"tradeoff: {len(data['rows'])} rows; outputs in {args.out} "
          "(tradeoff.json, tradeoff.md, tradeoff.png)")
    return 0
