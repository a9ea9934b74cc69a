"""Cost per particle-step against sample size: the dry (or wet) shear of 1,000 to 100,000
spheres timed in alternating chunks of the same run.

    python benchmarks/bench_sizes.py [--sizes 1000,10000,30000,100000] [--threads 1]
        [--suction 0] [--steps 3000] [--chunks 20] [--out FILE]

For each size a sample is prepared with pendular (thesis Ch. 5.2.2, 750 Pa, cached under
.cache/; 100,000 spheres take about 11 minutes on one core) and sheared as in
benchmarks/bench_triaxial.py (``--suction``: with exact bridges at every contact, as
benchmarks/bench_capillary.py). Every size runs the same ``steps`` (the same strain: a longer
shear of the small sample would take it far past the strains of a test), in ``chunks`` turns
that alternate between the sizes, so that the speed changes of a shared machine (a factor two
within minutes on the 2-core development VM) hit every size alike. Prints
ns per particle-step at each size and its ratio to the smallest size's (issue 15's goal:
at most 1.3 at 100,000 against 1,000, one thread).
"""

import argparse
import json

import numba

from bench_capillary import shear_simulation, time_alternately  # benchmarks/ (this folder)
from bench_triaxial import write_results
from pendular.interop.yade.runner import benchmark_sample


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="1000,10000,30000,100000")
    parser.add_argument("--threads", default="1")
    parser.add_argument("--suction", type=float, default=0.0,
                        help="matric suction [Pa]; 0: dry")
    parser.add_argument("--steps", type=int, default=3000, help="timed steps of each size")
    parser.add_argument("--chunks", type=int, default=20)
    parser.add_argument("--warmup", type=int, default=300, help="steps before timing")
    parser.add_argument("--confining", type=float, default=750.0)
    parser.add_argument("--out", default=None, help="JSON file for the results")
    args = parser.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",")]
    samples = {count: benchmark_sample(count, args.confining)[:3] for count in sizes}
    rows = []
    for threads in (int(t) for t in args.threads.split(",")):
        numba.set_num_threads(threads)
        runs = {count: shear_simulation(config, particles, walls, threads, args.suction)[0]
                for count, (config, particles, walls) in samples.items()}
        elapsed, rebuilds = time_alternately(runs, args.steps, args.warmup, args.chunks)
        cost = {count: 1e9 * elapsed[count] / (count * args.steps) for count in sizes}
        for count in sizes:
            row = {"particles": count, "threads": threads, "suction": args.suction,
                   "steps": args.steps, "rebuilds": rebuilds[count],
                   "pairs_per_particle": len(runs[count].contacts) / count,
                   "cost_per_particle_step_ns": cost[count],
                   "cost_over_smallest": cost[count] / cost[sizes[0]]}
            rows.append(row)
            print(json.dumps(row), flush=True)
    print(f"\n{'particles':>9} {'threads':>7} {'pairs':>5} {'[ns/particle-step]':>19} "
          f"{'x smallest':>10}")
    for row in rows:
        print(f"{row['particles']:9d} {row['threads']:7d} {row['pairs_per_particle']:5.2f} "
              f"{row['cost_per_particle_step_ns']:19.0f} {row['cost_over_smallest']:10.2f}")
    if args.out:
        write_results(args.out, rows)


if __name__ == "__main__":
    main()
