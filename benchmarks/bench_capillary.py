"""Cost of capillary bridges in the shear phase: pendular wet against dry on the same sample,
and against YADE's capillary triaxial (Law2_ScGeom_CapillaryPhys_Capillarity) in the same run.

    python benchmarks/bench_capillary.py [--sizes 10000] [--threads 1,2] [--suction 30000]
        [--steps 3000] [--warmup 1000] [--no-yade] [--no-yade-dry] [--out FILE]

For each size the prepared dry sample of benchmarks/bench_triaxial.py (thesis Ch. 5.2.2, 750 Pa,
cached under .cache/) is sheared twice by pendular: dry, and wet with suction-controlled
bridges at every contact (capillary.CapillaryBridges, appended to the forces of the dry sample
at the start of the shear, as YADE's law is here). Both runs first take ``warmup`` steps (the wetted
sample compacts under the capillary forces), then are timed in alternating chunks so that a
change of machine load hits both alike. YADE 2023 runs the same sample, time step and strain
rate with and without its capillary law, reading capillary files M(r=1) ... M(r=10) written
by pendular.interop.yade.capillary_files.write_yade (350 suctions x 80 distances, cached under .cache/). Prints
particle-steps/s, the wet/dry cost ratios of both codes and pendular / YADE (wet).
"""

import argparse
import copy
import json
import os
import tempfile
import time

import numpy as np

from bench_triaxial import write_results  # benchmarks/ (the script's folder)
from pendular.capillary import SURFACE_TENSION, CapillaryBridges
from pendular.dem.neighbors import NeighborList
from pendular.procedures.preparation import servoed_simulation
from pendular.interop.yade.formats import write_spheres
from pendular.homogenize.on_the_fly import capillary_force_stress
from pendular.procedures.config import ShearConfig
from pendular.procedures.triaxial import TriaxialShear
from pendular.interop.yade.runner import benchmark_sample as sample  # (config, particles, walls, report)
from pendular.interop.yade.runner import find_yade, run_yade_triaxial, yade_capillary_files


def shear_simulation(config, particles, walls, threads, suction):
    """The prepared sample under triaxial shear (no recorder), with bridges if ``suction``."""
    sim = servoed_simulation(copy.deepcopy(particles), copy.deepcopy(walls), config,
                             config.confining, threads=threads)
    bridges = None
    if suction:
        bridges = CapillaryBridges(suction, SURFACE_TENSION)
        sim.forces.append(bridges)
    rate = TriaxialShear(sim, ShearConfig(max_strain=0.25), config.confining, config.radius,
                         config.density).rate
    sim.writers.clear()     # time the physics, as the YADE runs (which record nothing)
    return sim, bridges, rate


def time_chunks(simulations, steps, warmup, chunks=6):
    """({name: [seconds of each chunk]}, {name: neighbour-list rebuilds}) of ``steps`` steps
    (one count for all, or {name: count}) of each of the named ``simulations`` after
    ``warmup`` steps, run in ``chunks`` alternating turns so that a change of machine load
    hits them alike (turn c of every simulation runs back to back)."""
    for sim in simulations.values():
        sim.run(warmup)
    totals = steps if isinstance(steps, dict) else {name: steps for name in simulations}
    seconds = {name: [] for name in simulations}
    rebuilds = {name: sim.operation(NeighborList).rebuilds for name, sim in simulations.items()}
    for chunk in range(chunks):
        for name, sim in simulations.items():
            total = totals[name]
            count = total // chunks + (1 if chunk < total % chunks else 0)
            started = time.perf_counter()
            sim.run(count)
            seconds[name].append(time.perf_counter() - started)
    return seconds, {name: sim.operation(NeighborList).rebuilds - rebuilds[name]
                     for name, sim in simulations.items()}


def time_alternately(simulations, steps, warmup, chunks=6):
    """({name: seconds}, {name: neighbour-list rebuilds}): time_chunks' turns summed."""
    seconds, rebuilds = time_chunks(simulations, steps, warmup, chunks)
    return {name: sum(turns) for name, turns in seconds.items()}, rebuilds


def time_pendular(config, particles, walls, threads, steps, warmup, suction):
    """Dry and wet shear of the same sample, timed in alternating chunks after ``warmup``."""
    runs = {"dry": shear_simulation(config, particles, walls, threads, 0.0),
            "wet": shear_simulation(config, particles, walls, threads, suction)}
    elapsed, rebuilds = time_alternately({name: run[0] for name, run in runs.items()}, steps,
                                         warmup)
    results = {}
    for name, (sim, bridges, rate) in runs.items():
        c = sim.contacts
        results[name] = {
            "particle_steps_per_s": len(particles) * steps / elapsed[name],
            "wall_time_s": elapsed[name],
            "rebuilds": rebuilds[name],
            "sigma_wall": sim.walls.stress().tolist(),
            "contacts": int(np.count_nonzero(c.overlap > 0.0)),
            "pairs": len(c),
        }
        if bridges is not None:
            capillary_stress = np.diag(capillary_force_stress(sim, bridges))
            results[name].update({"bridges": bridges.count(sim),
                                  "saturation": bridges.saturation(sim),
                                  "sigma_capillary": capillary_stress.tolist()})
    return results, runs["dry"][0].dt, runs["dry"][2]


def time_yade(config, particles, walls, threads, steps, warmup, dt, rate, suction, files):
    with tempfile.TemporaryDirectory() as folder:
        spheres = os.path.join(folder, "spheres.txt")
        write_spheres(spheres, particles.position, particles.radius, walls.lo, walls.hi)
        settings = {
            "spheres": spheres, "box_lo": walls.lo.tolist(), "box_hi": walls.hi.tolist(),
            "young": config.young, "poisson": config.shear_ratio,
            "friction_deg": config.friction_deg, "density": config.density,
            "damping": config.damping, "dt": dt, "confining": config.confining,
            "strain_rate": rate, "steps": steps, "warmup_steps": warmup,
            "record_every": steps}
        if suction:
            settings["capillary"] = {"suction": suction, "files": files,
                                     "surface_tension": SURFACE_TENSION}
        return run_yade_triaxial(settings, threads=threads,
                                 env={"OMP_WAIT_POLICY": "PASSIVE"})


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="10000")
    parser.add_argument("--threads", default="1,2")
    parser.add_argument("--suction", type=float, default=30000.0, help="matric suction [Pa]")
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--warmup", type=int, default=1000)
    parser.add_argument("--confining", type=float, default=750.0)
    parser.add_argument("--no-yade", action="store_true", help="pendular only")
    parser.add_argument("--no-yade-dry", action="store_true",
                        help="skip YADE's dry run (no YADE wet/dry ratio)")
    parser.add_argument("--out", default=None, help="JSON file for the results")
    args = parser.parse_args(argv)
    if not args.suction > 0:
        parser.error(f"--suction {args.suction} Pa must be > 0")
    sizes = [int(s) for s in args.sizes.split(",")]
    threads = [int(t) for t in args.threads.split(",")]
    use_yade = not args.no_yade
    files = None
    if use_yade:
        find_yade()
        files = yade_capillary_files()
    rows = []
    for count in sizes:
        config, particles, walls, report = sample(count, args.confining)
        for thread_count in threads:
            ours, dt, rate = time_pendular(config, particles, walls, thread_count, args.steps,
                                           args.warmup, args.suction)
            row = {"particles": count, "threads": thread_count, "suction": args.suction,
                   "dry": ours["dry"]["particle_steps_per_s"],
                   "wet": ours["wet"]["particle_steps_per_s"],
                   "pendular": ours, "dt": dt, "strain_rate": rate,
                   "porosity": report["porosity"]}
            row["wet_over_dry_cost"] = row["dry"] / row["wet"]
            if use_yade:
                wet = time_yade(config, particles, walls, thread_count, args.steps, args.warmup,
                                dt, rate, args.suction, files)
                row["yade_wet"] = wet["particle_steps_per_s"]
                row["yade"] = {"wet": wet}
                row["ours_over_yade_wet"] = row["wet"] / row["yade_wet"]
                if not args.no_yade_dry:
                    dry = time_yade(config, particles, walls, thread_count, args.steps,
                                    args.warmup, dt, rate, 0.0, files)
                    row["yade_dry"] = dry["particle_steps_per_s"]
                    row["yade"]["dry"] = dry
                    row["yade_wet_over_dry_cost"] = row["yade_dry"] / row["yade_wet"]
            rows.append(row)
            print(json.dumps(row), flush=True)
    print(f"\n{'particles':>9} {'threads':>7} {'dry [Mps/s]':>11} {'wet [Mps/s]':>11} "
          f"{'wet/dry cost':>12} {'YADE wet':>9} {'YADE wet/dry':>12} {'ours/YADE wet':>13}")
    for row in rows:
        def cell(key, width, scale=1.0, digits=2):
            return f"{row[key] * scale:{width}.{digits}f}" if key in row else f"{'-':>{width}}"
        print(f"{row['particles']:9d} {row['threads']:7d} {cell('dry', 11, 1e-6)} "
              f"{cell('wet', 11, 1e-6)} {cell('wet_over_dry_cost', 12)} "
              f"{cell('yade_wet', 9, 1e-6)} {cell('yade_wet_over_dry_cost', 12)} "
              f"{cell('ours_over_yade_wet', 13)}")
    if args.out:
        write_results(args.out, rows)


if __name__ == "__main__":
    main()
