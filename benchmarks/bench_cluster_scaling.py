"""What one step of the cluster model costs as the packing grows, up to 10^6 spheres.

    python benchmarks/bench_cluster_scaling.py [--copies 1,2,3,4,6,10] [--suction 10000]
        [--out FILE]

The packing is the thesis-default 1,000-sphere sample (Ch. 5.2.2 at 750 Pa, cached under
.cache/, as benchmarks/bench_pores.py) tiled n x n x n times, each copy one box length from the
next (``--copies`` lists n: n = 10 is 10^6 spheres). The seams are packings like any other
place, so the cost per sphere is that of a random packing of the same size. Timed, once per
size, each part of LiquidClusters.set_suction on a sample wetted from dry
(pendular.capillary.liquid_clusters): the pore units (``decompose``: Qhull and the geometry of
each unit), the filling thresholds, the pore filling and the Haines jumps at ``--suction``, the
clusters (connected filled units) and the clusters' forces; then the per-step work that
follows (adding the clusters' forces to the grains). Peak memory is the process's maximum
resident set after each size.
"""

import argparse
import json
import resource
import time

import numpy as np

from pendular.capillary.cluster_forces import UnitForces, cluster_forces
from pendular.capillary.clusters import find_clusters
from pendular.capillary.pore_filling import drain, filling_thresholds, imbibe
from pendular.capillary.pores import decompose
from pendular.interop.yade.runner import cached_sample
from pendular.procedures.preparation import PrepareConfig

GAMMA = 0.073          # [N/m] water
CONTACT_ANGLE = 0.0


def tiled(position, radius, box, copies):
    """(positions, radii) of ``copies``^3 copies of a sample, each shifted by whole box
    lengths ``box`` (3,) [m]."""
    shifts = np.stack(np.meshgrid(*[np.arange(copies)] * 3, indexing="ij"), -1).reshape(-1, 3)
    return ((position[None] + (shifts * box)[:, None]).reshape(-1, 3),
            np.tile(radius, len(shifts)))


def timed(parts, name, function, *args):
    """``function(*args)``, its wall time [s] stored in ``parts[name]``."""
    started = time.perf_counter()
    result = function(*args)
    parts[name] = time.perf_counter() - started
    return result


def model_step(position, radius, suction):
    """Wall time [s] of each part of one step of the model from dry at ``suction`` [Pa]."""
    parts = {}
    units = timed(parts, "decompose", decompose, position, radius)
    thresholds = timed(parts, "thresholds", filling_thresholds, units, radius, GAMMA,
                       CONTACT_ANGLE)
    carried = np.zeros(units.count, bool)
    filled = timed(parts, "fill_and_drain", lambda: drain(
        units, thresholds, imbibe(thresholds, carried, suction), suction))
    found = timed(parts, "clusters", find_clusters, units, filled)
    forces = timed(parts, "forces", lambda: cluster_forces(
        units, UnitForces(units.vertices, radius[units.grains]), filled, suction,
        len(radius)))
    grain_force = np.zeros_like(position)
    timed(parts, "add_forces_per_step", np.add, grain_force, forces, grain_force)
    return parts, units.count, int(np.count_nonzero(filled)), int(found.count)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--copies", default="1,2,3,4,6,10",
                        help="n of each size (n^3 copies of the 1,000-sphere sample)")
    parser.add_argument("--suction", type=float, default=10000.0, help="[Pa]")
    parser.add_argument("--out", default=None)
    args = parser.parse_args(argv)
    particles, walls, _ = cached_sample(PrepareConfig(particles=1000, confining=750.0),
                                        progress=False)
    box = walls.position[1::2] - walls.position[0::2]
    rows = []
    for copies in (int(n) for n in args.copies.split(",")):
        position, radius = tiled(particles.position, particles.radius, box, copies)
        parts, units, filled, clusters = model_step(position, radius, args.suction)
        total = sum(value for name, value in parts.items() if name != "add_forces_per_step")
        rows.append({"spheres": len(radius), "units": units, "filled_units": filled,
                     "clusters": clusters, "set_suction_s": total,
                     "set_suction_us_per_sphere": 1e6 * total / len(radius),
                     "parts_s": parts,
                     "max_resident_GB": resource.getrusage(
                         resource.RUSAGE_SELF).ru_maxrss / 2**20})
        print(json.dumps(rows[-1]), flush=True)
    if args.out:
        with open(args.out, "w") as handle:
            json.dump({"suction_pa": args.suction, "rows": rows}, handle, indent=1)


if __name__ == "__main__":
    main()
