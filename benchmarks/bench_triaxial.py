"""Shear-phase speed of the dry triaxial: pendular against YADE on the same sample, same run.

    python benchmarks/bench_triaxial.py [--sizes 1000,10000] [--threads 1,2] [--steps 3000]
        [--repeats 1] [--contacts linear,hertz-mindlin] [--no-yade]
        [--out benchmarks/results_triaxial.json]

For each size, a sample is prepared with pendular (thesis Ch. 5.2.2, 750 Pa; cached under
.cache/), sheared with x, y servoed and z strained, and timed in particle-steps per second after
a warm-up. The same packing is exported as a YADE sphere file and sheared by YADE 2023
(pendular.yade_triaxial) with the equivalent engine list, time step and strain rate.
Prints a table of particle-steps/s, the cost per particle-step and the ratio pendular / YADE
for each thread count (with ``--repeats R``, the two codes run R times each, alternately, and
the table gives the medians and the ratio's median and range over the R turns: on a shared
machine either code's speed drifts by tens of per cent within minutes), and the fixed cost
of a step: the step time of a FIXED_COST_SPHERES scene with the same operations, which is
nearly all Python, Numba dispatch and kernel launches (its share of a step at each size is the
overhead outside the compiled work). ``--contacts`` times each contact law on its own sample
(prepared with that law), YADE with its FrictPhys or MindlinPhys law, the laws of one size in
turn (with ``--repeats``, interleaved): the table then adds each law's cost over the first
law's (pendular and YADE) in the same run.
"""

import argparse
import copy
import json
import os
import statistics
import tempfile
import time

import numba

from pendular.procedures.preparation import servoed_simulation
from pendular.interop.yade.formats import write_spheres
from pendular.procedures.config import ShearConfig
from pendular.procedures.triaxial import TriaxialShear
from pendular.interop.yade.runner import cached_sample, find_yade, run_yade_triaxial
from pendular.procedures.preparation import PrepareConfig
from pendular.studies.crosscheck import yade_wall_poisson


def sample(count, confining, contact="linear"):
    """(PrepareConfig, Particles, Walls, report) of the thesis-default sample (Table 5.2) of
    ``count`` spheres at ``confining`` [Pa] with the contact law ``contact`` (cached)."""
    config = PrepareConfig(particles=count, confining=confining, contact=contact)
    return (config, *cached_sample(config))


def time_pendular(config, particles, walls, threads, steps, warmup, force_threads=False):
    """Shear-phase speed with ``threads`` Numba threads available; the Simulation's own policy
    decides how many it uses (one below pendular.dem.simulation.SERIAL_BELOW particles) unless
    ``force_threads``."""
    numba.set_num_threads(threads)
    sim = servoed_simulation(copy.deepcopy(particles), copy.deepcopy(walls), config,
                             config.confining, threads=threads if force_threads else None)
    sim.run(warmup)         # settle the loaded packing (saved without its shear history)
    rate = TriaxialShear(sim, ShearConfig(max_strain=0.25), config.confining, config.radius,
                         config.density).rate
    sim.writers.clear()     # time the physics, as the YADE run (which records nothing)
    sim.run(warmup)
    started = time.perf_counter()
    sim.run(steps)
    elapsed = time.perf_counter() - started
    return {"particle_steps_per_s": len(particles) * steps / elapsed, "wall_time_s": elapsed,
            "sigma_wall": sim.walls.stress().tolist(), "threads_used": sim.threads}, sim.dt, rate


def time_yade(config, particles, walls, threads, steps, warmup, dt, rate):
    with tempfile.TemporaryDirectory() as folder:
        spheres = os.path.join(folder, "spheres.txt")
        write_spheres(spheres, particles.position, particles.radius, walls.lo, walls.hi)
        settings = {
            "spheres": spheres, "box_lo": walls.lo.tolist(), "box_hi": walls.hi.tolist(),
            "young": config.young, "poisson": config.shear_ratio,
            "friction_deg": config.friction_deg, "density": config.density,
            "damping": config.damping, "dt": dt, "confining": config.confining,
            "strain_rate": rate, "steps": steps, "warmup_steps": warmup,
            "record_every": steps, "contact": config.contact}
        if config.contact == "hertz-mindlin":
            settings.update(poisson=config.poisson, wall_poisson=yade_wall_poisson(config.poisson))
        result = run_yade_triaxial(settings, threads=threads)
    return result


#: Spheres of the scene whose step time stands for the fixed cost of a step.
FIXED_COST_SPHERES = 64


def write_results(path, rows):
    """Benchmark rows and the machine's thread counts as JSON."""
    with open(path, "w") as handle:
        json.dump({"rows": rows, "numba_threads_available": numba.config.NUMBA_NUM_THREADS,
                   "cpu_count": os.cpu_count()}, handle, indent=2)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="1000,10000")
    parser.add_argument("--threads", default="1,2")
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--warmup", type=int, default=300)
    parser.add_argument("--repeats", type=int, default=1,
                        help="turns of each code, alternately (medians reported)")
    parser.add_argument("--confining", type=float, default=750.0)
    parser.add_argument("--contacts", default="linear",
                        help="contact laws, comma separated (linear, hertz-mindlin)")
    parser.add_argument("--no-yade", action="store_true")
    parser.add_argument("--out", default=None, help="JSON file for the results")
    args = parser.parse_args(argv)
    if args.repeats < 1:
        parser.error(f"--repeats {args.repeats}: give at least 1")
    sizes = [int(s) for s in args.sizes.split(",")]
    threads = [int(t) for t in args.threads.split(",")]
    use_yade = not args.no_yade
    if use_yade:
        find_yade()
    fixed = {}
    config, particles, walls, _ = sample(FIXED_COST_SPHERES, args.confining)
    for thread_count in threads:
        tiny, _, _ = time_pendular(config, particles, walls, thread_count, args.steps,
                                   args.warmup, force_threads=True)
        fixed[thread_count] = tiny["wall_time_s"] / args.steps
    contacts = args.contacts.split(",")
    rows = []
    for count in sizes:
        samples = {contact: sample(count, args.confining, contact) for contact in contacts}
        for thread_count in threads:
            turns = {contact: [] for contact in contacts}
            for _ in range(args.repeats):
                for contact in contacts:       # the laws in turn: the same load on each
                    config, particles, walls, _ = samples[contact]
                    ours, dt, rate = time_pendular(config, particles, walls, thread_count,
                                                   args.steps, args.warmup)
                    yade = (time_yade(config, particles, walls, thread_count, args.steps,
                                      args.warmup, dt, rate) if use_yade else None)
                    turns[contact].append((ours, yade, dt, rate))
            first = None
            for contact in contacts:
                report = samples[contact][3]
                speeds = [ours["particle_steps_per_s"] for ours, _, _, _ in turns[contact]]
                ours, _, dt, rate = turns[contact][-1]
                step_time = count / statistics.median(speeds)
                fixed_cost = fixed.get(ours["threads_used"], fixed[thread_count])
                row = {"particles": count, "threads": thread_count, "contact": contact,
                       "threads_used": ours["threads_used"],
                       "pendular": statistics.median(speeds), "pendular_turns": speeds,
                       "cost_per_particle_step_ns": 1e9 * step_time / count,
                       "fixed_cost_per_step_us": 1e6 * fixed_cost,
                       "fixed_cost_share": fixed_cost / step_time,
                       "dt": dt, "strain_rate": rate, "porosity": report["porosity"],
                       "coordination": report.get("coordination")}
                if use_yade:
                    yade_speeds = [yade["particle_steps_per_s"] for _, yade, _, _ in
                                   turns[contact]]
                    ratios = [a / b for a, b in zip(speeds, yade_speeds)]
                    row.update(yade=statistics.median(yade_speeds), yade_turns=yade_speeds,
                               ratio=statistics.median(ratios), ratio_range=[min(ratios),
                                                                             max(ratios)])
                if first is None:
                    first = row
                else:   # this law's cost per particle-step over the first law's, turn by turn
                    costs = [a / b for a, b in zip(first["pendular_turns"], speeds)]
                    row["cost_over_first"] = statistics.median(costs)
                    row["cost_over_first_turns"] = costs
                    if use_yade:
                        row["yade_cost_over_first"] = statistics.median(
                            [a / b for a, b in zip(first["yade_turns"], row["yade_turns"])])
                rows.append(row)
                print(json.dumps(row), flush=True)
    print(f"\n{'particles':>9} {'contact':>13} {'threads':>7} {'used':>4} {'pendular [Mps/s]':>17} "
          f"{'[ns/particle-step]':>19} {'fixed cost share':>16} {'YADE [Mps/s]':>13} "
          f"{'ratio':>6} {'ratio range':>12} {'cost/first':>10} {'YADE cost/first':>15}")
    for row in rows:
        yade = f"{row['yade'] / 1e6:13.2f}" if "yade" in row else f"{'-':>13}"
        ratio = f"{row['ratio']:6.2f}" if "ratio" in row else f"{'-':>6}"
        spread = (f"{row['ratio_range'][0]:5.2f}-{row['ratio_range'][1]:<6.2f}"
                  if "ratio" in row and args.repeats > 1 else "")
        over = f"{row['cost_over_first']:10.2f}" if "cost_over_first" in row else f"{'-':>10}"
        yade_over = (f"{row['yade_cost_over_first']:15.2f}" if "yade_cost_over_first" in row
                     else f"{'-':>15}")
        print(f"{row['particles']:9d} {row['contact']:>13} {row['threads']:7d} "
              f"{row['threads_used']:4d} {row['pendular'] / 1e6:17.2f} "
              f"{row['cost_per_particle_step_ns']:19.0f} {row['fixed_cost_share']:16.1%} "
              f"{yade} {ratio} {spread:12} {over} {yade_over}")
    print("fixed cost per step [us] (a " + str(FIXED_COST_SPHERES) + "-sphere scene): "
          + ", ".join(f"{t} thread(s) {1e6 * v:.1f}" for t, v in fixed.items()))
    if args.out:
        write_results(args.out, rows)


if __name__ == "__main__":
    main()
