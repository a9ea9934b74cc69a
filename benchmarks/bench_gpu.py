"""Speed of the GPU path (pendular.gpu, issue 38) against the CPU path on the same machine,
written as JSON; prepared to run in about 6 minutes on one H100.

    python benchmarks/bench_gpu.py [--sizes 10000,100000,1000000] [--cpu-sizes 10000,100000]
        [--steps 2000] [--cpu-steps 100] [--out bench_gpu.json]
    NUMBA_ENABLE_CUDASIM=1 python benchmarks/bench_gpu.py --quick    # end to end, no GPU

The sample: spheres of radii within 5 % of 1 mm on a jittered simple cubic lattice, 1 %
overlaps, random velocities, in six walls with a stress servo on x and y and a constant strain
rate on z (a triaxial's shear; not a prepared sample: one of 10^6 spheres would take a day to
prepare on the CPU, and preparation does not run on the device yet), dry and wet
(suction-controlled bridges at contact, 30 kPa). For each size and scene: the first 20 steps
(JIT compiling, the first neighbour list) are not timed, then ``steps`` steps are, the device
synchronised at both ends; ``launch_us`` is the host's time to issue one step's launches
(when it nears the step's time, launches bound the speed, not the card).

The JSON: per row size, scene, device, particle-steps/s, ns per particle-step, rebuilds; the
ratios GPU / CPU where both ran; the goals of issue 38 marked met or not (dry >= 1e9 and wet
>= 5e8 particle-steps/s at 10^6, cost per particle-step at 10^6 within 1.2x of 10^5, >= 10x
the CPU at 10^5 and 10^6 (the CPU's rate at 10^6 taken as its rate at 10^5), and the wall
times that a 60,000-step shear (the steps a triaxial needs at the default inertial number)
would take at 10^5 and 10^6 wet, projected from the measured rates. Nothing is built on the
device beyond the kernels' JIT; the bridge table is built (or read from the cache) on the host.
"""

import argparse
import json
import math
import os
import platform
import time

import numba
import numpy as np

from pendular.capillary.bridges import CapillaryBridges
from pendular.dem.contact_law import ContactForces, normal_stiffness
from pendular.dem.integrate import Integrator
from pendular.dem.neighbors import NeighborList
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.walls import ConstantStrainRate, StressServo, WallForces

RADIUS = 1e-3
YOUNG = 1e8
SUCTION = 30000.0
WARMUP = 20
SHEAR_STEPS = 60000


def lattice_scene(count, wet, seed=1):
    """A CPU Simulation of about ``count`` spheres (module docstring)."""
    rng = np.random.default_rng(seed)
    side = max(2, round(count ** (1.0 / 3.0)))
    spacing = 1.98 * RADIUS
    nodes = np.arange(side) * spacing
    position = np.array(np.meshgrid(nodes, nodes, nodes, indexing="ij")).reshape(3, -1).T
    position += RADIUS + rng.uniform(-0.02, 0.02, position.shape) * RADIUS
    radius = RADIUS * rng.uniform(0.95, 1.05, len(position))
    particles = Particles(position, radius, 2650.0, velocity=rng.normal(0, 1e-3, position.shape))
    length = (side - 1) * spacing + 2 * RADIUS
    walls = Walls.box([0.01 * RADIUS] * 3, [length - 0.01 * RADIUS] * 3)
    dt = 0.2 * math.sqrt(particles.mass.min() / normal_stiffness(YOUNG, RADIUS, RADIUS))
    forces = [ContactForces(YOUNG, 0.3, 30.0), WallForces(YOUNG)]
    if wet:
        forces.append(CapillaryBridges(SUCTION))
    return Simulation(particles, walls, dt, neighbors=NeighborList(0.1 * RADIUS), forces=forces,
                      controls=[StressServo("xy", 1e5, 0.01),
                                ConstantStrainRate("z", 0.1, length)],
                      integrator=Integrator(0.2))


def time_gpu(sim, steps):
    """(seconds for ``steps`` steps, host seconds issuing one step's launches, rebuilds)."""
    from pendular.gpu import GpuSimulation
    from pendular.gpu.cuda import cuda

    gpu = GpuSimulation(sim)
    gpu.run(WARMUP)
    cuda.synchronize()
    started = time.perf_counter()
    gpu.run(steps, check_every=steps)
    cuda.synchronize()
    elapsed = time.perf_counter() - started
    issued = time.perf_counter()
    for _ in range(10):
        gpu.advance()
    launch = (time.perf_counter() - issued) / 10
    cuda.synchronize()
    return elapsed, launch, gpu.rebuilds


def time_cpu(sim, steps):
    """(seconds for ``steps`` steps on all of Numba's threads, rebuilds)."""
    sim.run(WARMUP)
    started = time.perf_counter()
    sim.run(steps, check_every=steps)
    return time.perf_counter() - started, sim.neighbors.rebuilds


def row(count, wet, device, seconds, steps, rebuilds, launch=None):
    rate = count * steps / seconds
    out = {"particles": count, "scene": "wet" if wet else "dry", "device": device,
           "steps": steps, "seconds": seconds, "particle_steps_per_s": rate,
           "ns_per_particle_step": 1e9 / rate, "rebuilds": rebuilds}
    if launch is not None:
        out["launch_us"] = 1e6 * launch
        out["step_us"] = 1e6 * seconds / steps
    return out


def goals(rows):
    """Issue 38's goals of point 5, each with its measured value and whether it is met (None:
    not measured in this run)."""
    def rate(count, scene, device):
        found = [r["particle_steps_per_s"] for r in rows
                 if r["particles"] == count and r["scene"] == scene and r["device"] == device]
        return found[0] if found else None

    sizes = sorted({r["particles"] for r in rows if r["device"] == "gpu"})
    big = sizes[-1] if sizes else None
    mid = sizes[-2] if len(sizes) > 1 else None
    cpu_sizes = sorted({r["particles"] for r in rows if r["device"] == "cpu"})
    out = {}

    def goal(name, value, target, met):
        out[name] = {"value": value, "target": target,
                     "met": None if value is None else bool(met(value))}

    goal("dry_particle_steps_per_s_at_largest", rate(big, "dry", "gpu"), 1e9, lambda v: v >= 1e9)
    goal("wet_particle_steps_per_s_at_largest", rate(big, "wet", "gpu"), 5e8, lambda v: v >= 5e8)
    for scene in ("dry", "wet"):
        high, low = rate(big, scene, "gpu"), rate(mid, scene, "gpu")
        goal(f"{scene}_cost_ratio_largest_to_next", None if None in (high, low) else low / high,
             1.2, lambda v: v <= 1.2)
        for count in (mid, big):
            cpu_count = count if count in cpu_sizes else (cpu_sizes[-1] if cpu_sizes else None)
            gpu_rate, cpu_rate = rate(count, scene, "gpu"), rate(cpu_count, scene, "cpu")
            goal(f"{scene}_gpu_over_cpu_at_{count}",
                 None if None in (gpu_rate, cpu_rate) else gpu_rate / cpu_rate, 10.0,
                 lambda v: v >= 10.0)
    for count, limit in ((mid, None), (big, 600.0)):
        wet_rate = rate(count, "wet", "gpu")
        seconds = None if wet_rate is None else SHEAR_STEPS * count / wet_rate
        goal(f"wet_shear_{SHEAR_STEPS}_steps_seconds_at_{count}", seconds, limit,
             (lambda v: True) if limit is None else (lambda v, limit=limit: v <= limit))
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="10000,100000,1000000")
    parser.add_argument("--cpu-sizes", default="10000,100000")
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--cpu-steps", type=int, default=100)
    parser.add_argument("--quick", action="store_true",
                        help="27 and 64 spheres, 20 steps: the script end to end (simulator)")
    parser.add_argument("--out", default="bench_gpu.json")
    args = parser.parse_args(argv)
    if args.quick:
        args.sizes, args.cpu_sizes, args.steps, args.cpu_steps = "27,64", "27", 20, 20
    sizes = [int(s) for s in args.sizes.split(",") if s]
    cpu_sizes = [int(s) for s in args.cpu_sizes.split(",") if s]
    rows = []
    for wet in (False, True):
        for size in sizes:
            sim = lattice_scene(size, wet)
            seconds, launch, rebuilds = time_gpu(sim, args.steps)
            rows.append(row(len(sim.particles), wet, "gpu", seconds, args.steps, rebuilds,
                            launch))
            print(json.dumps(rows[-1]), flush=True)
        for size in cpu_sizes:
            sim = lattice_scene(size, wet)
            seconds, rebuilds = time_cpu(sim, args.cpu_steps)
            rows.append(row(len(sim.particles), wet, "cpu", seconds, args.cpu_steps, rebuilds))
            print(json.dumps(rows[-1]), flush=True)
    from pendular.gpu.cuda import cuda, simulated

    card = "simulator" if simulated() else cuda.get_current_device().name
    card = card.decode() if isinstance(card, bytes) else str(card)
    result = {"card": card, "date": time.strftime("%Y-%m-%d"), "host": platform.node(),
              "cpu_count": os.cpu_count(), "numba_threads": numba.config.NUMBA_NUM_THREADS,
              "quick": args.quick, "rows": rows, "goals": goals(rows)}
    with open(args.out, "w") as handle:
        json.dump(result, handle, indent=2)
    print(json.dumps(result["goals"], indent=2))


if __name__ == "__main__":
    main()
