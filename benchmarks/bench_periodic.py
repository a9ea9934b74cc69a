"""Cost of the periodic cell in the triaxial shear: periodic against walled, dry and wet, same run.

    python benchmarks/bench_periodic.py [--sizes 1000,10000] [--threads 1]
        [--suction 30000] [--steps 3000] [--warmup 1000] [--chunks 30] [--out FILE]

For each size two samples are prepared with pendular (thesis Ch. 5.2.2, 750 Pa, cached under
.cache/): in six walls and in a periodic cell (pendular.dem.cell). Each is sheared dry and wet
(suction-controlled exact bridges at every contact, as benchmarks/bench_capillary.py), and the
four shears are timed in ``chunks`` alternating turns after ``warmup`` steps, so a change of
machine load hits them alike (on the 2-core development VM the speed changes by up to 2x within
minutes: use many short chunks). Prints particle-steps/s and the periodic / walled cost per
particle-step over the whole run, the median of that ratio over the turns (each turn runs the
four shears back to back: a burst of load on the machine that hits one shear's turn moves
the whole-run ratio, not the median), and the ratio per pair of the neighbour list (a
periodic sample has no loose wall layers, so it holds more pairs per particle); the JSON rows
add the neighbour-list rebuilds and pairs per particle of each shear.
"""

import argparse
import json

import numba
import numpy as np

from bench_capillary import shear_simulation, time_chunks  # benchmarks/ (this folder)
from bench_triaxial import write_results
from pendular.procedures.preparation import PrepareConfig
from pendular.interop.yade.runner import cached_sample


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="1000,10000")
    parser.add_argument("--threads", default="1")
    parser.add_argument("--suction", type=float, default=30000.0, help="matric suction [Pa]")
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--warmup", type=int, default=1000)
    parser.add_argument("--chunks", type=int, default=30, help="alternating turns per shear")
    parser.add_argument("--confining", type=float, default=750.0)
    parser.add_argument("--out", default=None, help="JSON file for the results")
    args = parser.parse_args(argv)
    rows = []
    for count in (int(s) for s in args.sizes.split(",")):
        samples = {}
        for box, periodic in (("walled", False), ("periodic", True)):
            config = PrepareConfig(particles=count, confining=args.confining, periodic=periodic)
            samples[box] = (config, *cached_sample(config)[:2])
        for threads in (int(t) for t in args.threads.split(",")):
            numba.set_num_threads(threads)
            runs = {f"{box} {kind}": shear_simulation(config, particles, walls, threads,
                                                      suction)
                    for box, (config, particles, walls) in samples.items()
                    for kind, suction in (("dry", 0.0), ("wet", args.suction))}
            turns, rebuilds = time_chunks({name: run[0] for name, run in runs.items()},
                                          args.steps, args.warmup, args.chunks)
            speed = {name: count * args.steps / sum(seconds) for name, seconds in turns.items()}
            pairs = {name: len(run[0].contacts) / count for name, run in runs.items()}
            cost = {kind: speed[f"walled {kind}"] / speed[f"periodic {kind}"]
                    for kind in ("dry", "wet")}
            # both boxes run the same steps in each turn: the turn's cost ratio is its time ratio
            median_cost = {kind: float(np.median(np.divide(turns[f"periodic {kind}"],
                                                           turns[f"walled {kind}"])))
                           for kind in ("dry", "wet")}
            row = {"particles": count, "threads": threads, "suction": args.suction,
                   "particle_steps_per_s": speed, "rebuilds": rebuilds,
                   "pairs_per_particle": pairs, "periodic_over_walled_cost": cost,
                   "periodic_over_walled_cost_median_of_turns": median_cost,
                   "periodic_over_walled_cost_per_pair": {
                       kind: cost[kind] * pairs[f"walled {kind}"] / pairs[f"periodic {kind}"]
                       for kind in ("dry", "wet")}}
            rows.append(row)
            print(json.dumps(row), flush=True)
    print(f"\n{'particles':>9} {'threads':>7} {'walled dry':>10} {'periodic dry':>12} "
          f"{'ratio':>6} {'median':>6} {'walled wet':>10} {'periodic wet':>12} {'ratio':>6} "
          f"{'median':>6}  [M particle-steps/s; ratio: run, median of turns]   "
          "ratio per pair: dry, wet")
    for row in rows:
        speed, ratio = row["particle_steps_per_s"], row["periodic_over_walled_cost"]
        median = row["periodic_over_walled_cost_median_of_turns"]
        per_pair = row["periodic_over_walled_cost_per_pair"]
        print(f"{row['particles']:9d} {row['threads']:7d} {speed['walled dry'] * 1e-6:10.2f} "
              f"{speed['periodic dry'] * 1e-6:12.2f} {ratio['dry']:6.2f} {median['dry']:6.2f} "
              f"{speed['walled wet'] * 1e-6:10.2f} {speed['periodic wet'] * 1e-6:12.2f} "
              f"{ratio['wet']:6.2f} {median['wet']:6.2f}  {per_pair['dry']:49.2f}, "
              f"{per_pair['wet']:.2f}")
    if args.out:
        write_results(args.out, rows)


if __name__ == "__main__":
    main()
