"""Cost of a graded sample in the wet shear: radii R(1 ± S) against equal spheres, same run.

    python benchmarks/bench_grading.py [--sizes 10000] [--spread 0.3] [--threads 1]
        [--suction 30000] [--steps 3000] [--warmup 1000] [--out FILE]

For each size two samples are prepared with pendular (thesis Ch. 5.2.2, 750 Pa, cached under
.cache/): equal spheres of radius R and radii uniform in R(1 ± S) rescaled to the mean R. Both
are sheared wet (suction-controlled exact bridges at every contact, as
benchmarks/bench_capillary.py) and timed in alternating chunks after ``warmup`` steps, so a
change of machine load hits both alike. The graded sample has a smaller time step (the P-wave
estimate of its smallest sphere), so the comparison is per particle-step; its shear also needs
more steps per unit strain, which the table reports separately (dt ratio).
"""

import argparse
import json

import numba

from bench_capillary import shear_simulation, time_alternately  # benchmarks/ (this folder)
from bench_triaxial import write_results
from pendular.procedures.preparation import PrepareConfig
from pendular.interop.yade.runner import cached_sample


def time_wet_shears(samples, threads, steps, warmup, suction):
    """Particle-steps/s of the wet shear of each (config, particles, walls) in ``samples``."""
    numba.set_num_threads(threads)
    runs = {name: shear_simulation(config, particles, walls, threads, suction)
            for name, (config, particles, walls) in samples.items()}
    elapsed, rebuilds = time_alternately({name: run[0] for name, run in runs.items()}, steps,
                                         warmup)
    return {name: {"particle_steps_per_s": len(sim.particles) * steps / elapsed[name],
                   "wall_time_s": elapsed[name], "dt": sim.dt, "rebuilds": rebuilds[name],
                   "bridges": bridges.count(sim), "pairs": len(sim.contacts),
                   "radius_ratio": float(sim.particles.radius.max() / sim.particles.radius.min())}
            for name, (sim, bridges, _) in runs.items()}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="10000")
    parser.add_argument("--spread", type=float, default=0.3, help="radii uniform in R(1 ± S)")
    parser.add_argument("--threads", default="1")
    parser.add_argument("--suction", type=float, default=30000.0, help="matric suction [Pa]")
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--warmup", type=int, default=1000)
    parser.add_argument("--confining", type=float, default=750.0)
    parser.add_argument("--out", default=None, help="JSON file for the results")
    args = parser.parse_args(argv)
    rows = []
    for count in (int(s) for s in args.sizes.split(",")):
        samples = {}
        for name, spread in (("equal", 0.0), ("graded", args.spread)):
            config = PrepareConfig(particles=count, confining=args.confining,
                                   radius_spread=spread)
            particles, walls, _ = cached_sample(config)
            samples[name] = (config, particles, walls)
        for threads in (int(t) for t in args.threads.split(",")):
            runs = time_wet_shears(samples, threads, args.steps, args.warmup, args.suction)
            row = {"particles": count, "threads": threads, "spread": args.spread,
                   "suction": args.suction, **runs,
                   "graded_over_equal_cost": (runs["equal"]["particle_steps_per_s"]
                                              / runs["graded"]["particle_steps_per_s"]),
                   "graded_over_equal_dt": runs["graded"]["dt"] / runs["equal"]["dt"]}
            rows.append(row)
            print(json.dumps(row), flush=True)
    print(f"\n{'particles':>9} {'threads':>7} {'equal [Mps/s]':>13} {'graded [Mps/s]':>14} "
          f"{'cost ratio':>10} {'dt ratio':>8}")
    for row in rows:
        print(f"{row['particles']:9d} {row['threads']:7d} "
              f"{row['equal']['particle_steps_per_s'] * 1e-6:13.2f} "
              f"{row['graded']['particle_steps_per_s'] * 1e-6:14.2f} "
              f"{row['graded_over_equal_cost']:10.2f} {row['graded_over_equal_dt']:8.2f}")
    if args.out:
        write_results(args.out, rows)


if __name__ == "__main__":
    main()
