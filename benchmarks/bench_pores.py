"""Pore units of a prepared sample: their cost, and how far each unit's pore volume is from the
void inside its tetrahedron (Monte Carlo).

    python benchmarks/bench_pores.py [--particles 1000] [--units 400] [--points 4000]
        [--repeat 3] [--out FILE]

The sample is the thesis-default one of ``particles`` spheres (Ch. 5.2.2 at 750 Pa, cached
under .cache/, as benchmarks/bench_grading.py). ``decompose`` is timed on it between walls and,
for the cost alone, on its positions taken as a periodic cell of the walls' box. For ``units``
units drawn at random, ``points`` uniform points in the tetrahedron give its void, which the
unit's pore volume (pendular.capillary.pores) is compared with: the error
shown relative to the mean pore volume of a unit, apart for the units where a grain crosses
the opposite face (``protrudes``).
"""

import argparse
import json
import time

import numpy as np
from scipy.spatial import cKDTree

from pendular.capillary import pores
from pendular.interop.yade.runner import cached_sample
from pendular.procedures.preparation import PrepareConfig


def best_time(function, repeat):
    """Shortest wall time [s] of ``repeat`` calls of ``function``, and its last result."""
    best = np.inf
    for _ in range(repeat):
        started = time.perf_counter()
        result = function()
        best = min(best, time.perf_counter() - started)
    return best, result


def void_fraction(vertices, centres, radii, points, rng):
    """Monte Carlo void fraction inside each tetrahedron of ``vertices`` (U, 4, 3)."""
    tree = cKDTree(centres)
    fractions = np.empty(len(vertices))
    for k, corners in enumerate(vertices):
        sample = rng.dirichlet(np.ones(4), points) @ corners
        distance, index = tree.query(sample, k=8)
        fractions[k] = 1.0 - (distance < radii[index]).any(axis=1).mean()
    return fractions


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--particles", type=int, default=1000)
    parser.add_argument("--units", type=int, default=400)
    parser.add_argument("--points", type=int, default=4000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--out", default=None)
    args = parser.parse_args(argv)
    particles, walls, _ = cached_sample(PrepareConfig(particles=args.particles, confining=750.0),
                                        progress=False)
    centres, radii = particles.position, particles.radius
    walls_time, units = best_time(lambda: pores.decompose(centres, radii), args.repeat)
    lo, hi = centres.min(axis=0), centres.max(axis=0) + 1e-9 * np.ptp(centres, axis=0)
    periodic_time, periodic = best_time(
        lambda: pores.decompose(centres - lo, radii, period=hi - lo), args.repeat)
    rng = np.random.default_rng(2026)
    chosen = rng.choice(units.count, size=min(args.units, units.count), replace=False)
    void = void_fraction(units.vertices[chosen], centres, radii, args.points, rng) \
        * units.volume[chosen]
    scale = units.pore_volume.mean()
    error = (units.pore_volume[chosen] - void) / scale
    noise = units.volume[chosen] / np.sqrt(args.points) / 2 / scale
    sliver = units.protrudes[chosen]
    row = {"particles": len(radii), "units": units.count, "periodic_units": periodic.count,
           "decompose_walls_s": walls_time, "decompose_periodic_s": periodic_time,
           "protruding_fraction": float(units.protrudes.mean()),
           "negative_pore_volume_fraction": float((units.pore_volume < 0).mean()),
           "mc_units": len(chosen), "mc_points_per_unit": args.points,
           "mc_noise_rms": float(np.sqrt(np.mean(noise ** 2))),
           "error_rms_regular": float(np.sqrt(np.mean(error[~sliver] ** 2))),
           "error_max_regular": float(np.abs(error[~sliver]).max()),
           "error_rms_protruding": float(np.sqrt(np.mean(error[sliver] ** 2)))
           if sliver.any() else None,
           "throat_radius_median_over_R": float(np.median(units.throat_radius
                                                          / radii.mean()))}
    print(json.dumps(row, indent=1))
    if args.out:
        with open(args.out, "w") as handle:
            json.dump(row, handle, indent=1)


if __name__ == "__main__":
    main()
