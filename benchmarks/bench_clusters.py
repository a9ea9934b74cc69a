"""Liquid morphology of a static random packing (after Scheel et al. 2008): the share of the
liquid in bridges against the liquid content W, on wetting from dry and drying from
saturation, and what a step of the cluster model costs.

    python benchmarks/bench_clusters.py [--particles 1000] [--out FILE]

The sample is the thesis-default one of ``particles`` spheres (Ch. 5.2.2 at 750 Pa, cached
under .cache/, as benchmarks/bench_pores.py), held still. At each suction of a descending list
(wetting: the pore units fill at their filling suction; bridges form wherever a bridge of that
suction can exist, pendular.capillary.CapillaryBridges.form_across_gaps) then of the same list
ascending from a saturated pore space (drying: Haines jumps from the hull),
pendular.capillary.liquid_clusters.LiquidClusters gives the liquid account; W is the liquid
over the volume between the walls (Scheel et al.'s liquid content), with the fractions in
bridges, in clusters and in the largest cluster, the number of clusters and the percolation of
the largest, the number of trimers (pendular.capillary.trimers) and the fraction of the liquid in
their bridges, and ``merged_throats``: the throats whose three bridges' menisci meet, the filled
units' included (the trimers the bridges alone would hold), and the bridges' largest filling
angle. For Kim (2001)'s direct-tension cases, the mean capillary stress chi s at each
case's saturation on the wetting branch, bridges alone and with clusters (an estimate of how
much the clusters raise the tensile strength, not a pull). Timed: ``set_suction`` (decomposition, thresholds, filling, forces) and one DEM
step of the wet scene without and with the clusters.
"""

import argparse
import copy
import json
import time

import numpy as np

from pendular.capillary import CapillaryBridges
from pendular.capillary.bridge_state import BridgeState
from pendular.capillary.liquid_clusters import LiquidClusters
from pendular.capillary.pore_filling import unit_edges
from pendular.capillary.trimers import find_trimers
from pendular.homogenize.clusters import chi_with_clusters
from pendular.homogenize.on_the_fly import CapillaryHomogenization
from pendular.interop.yade.runner import cached_sample
from pendular.procedures.preparation import PrepareConfig, servoed_simulation

SUCTIONS = tuple(np.geomspace(300000.0, 3000.0, 25))
GAMMA = 0.073
#: Kim (2001)'s cases (void ratio, gravimetric water content), Gs = 2.65 (pendular tension).
KIM_CASES = ((0.72, 0.0047), (0.72, 0.0104), (0.72, 0.0211),
             (0.58, 0.0043), (0.58, 0.0104), (0.58, 0.0201))
SPECIFIC_GRAVITY = 2.65


def branch(sim, suctions, saturated, gap):
    """Rows of the liquid account along ``suctions`` from a saturated or a dry pore space."""
    sim = copy.deepcopy(sim)
    bridges = CapillaryBridges(suctions[0], GAMMA, persist=True)
    sim.forces.append(bridges)
    clusters = LiquidClusters(bridges, saturated=saturated)
    sim.forces.append(clusters)
    sim.evaluate_forces()
    rows, times = [], []
    for suction in suctions:
        bridges.set_suction(suction)
        sim.evaluate_forces()
        if not saturated:
            bridges.form_across_gaps(sim, gap)
        started = time.perf_counter()
        clusters.set_suction(sim, suction)
        times.append(time.perf_counter() - started)
        sim.evaluate_forces()
        account = clusters.account(sim)
        stats = clusters.statistics(sim)
        alone = np.trace(CapillaryHomogenization(bridges).chi(sim)) / 3.0
        rows.append({"suction": suction, "W": account.total / sim.walls.volume(),
                     "saturation_bridges_alone": bridges.saturation(sim),
                     "chi_bridges_alone": float(alone),
                     "chi_with_clusters": float(np.trace(chi_with_clusters(sim, clusters)) / 3),
                     **{k: stats[k] for k in ("saturation", "saturation_pore_units",
                                              "liquid_in_bridges", "liquid_in_clusters",
                                              "liquid_in_largest_cluster", "clusters",
                                              "trimers", "liquid_in_trimers",
                                              "filled_units", "pore_units",
                                              "largest_cluster_percolates")},
                     "merged_throats": merged_throats(sim, clusters),
                     "largest_filling_angle": largest_filling_angle(sim),
                     "bridges": bridges.count(sim)})
    return rows, times, sim


def largest_filling_angle(sim):
    """[deg] the largest filling angle of the bridges (at contact, on a packing of one size)."""
    state = BridgeState.of(sim.contacts)
    return float(max(state.filling_i.max(initial=0.0), state.filling_j.max(initial=0.0)))


def merged_throats(sim, clusters):
    """Number of throats whose three bridges' menisci meet, whether or not their units are
    filled (pendular.capillary.trimers.find_trimers with no unit holding liquid)."""
    contacts = sim.contacts
    return find_trimers(clusters.units, unit_edges(clusters.units),
                        np.zeros(clusters.units.count, bool), BridgeState.of(contacts),
                        contacts.pair_i, contacts.pair_j, clusters.pair_edge(contacts)).count


def kim_estimate(rows):
    """Per Kim case: the mean capillary stress chi s [Pa] at its saturation w Gs / e on the
    wetting branch ``rows``, bridges alone and with clusters (log-log interpolation in the
    saturation), and their ratio. At theta = 0 tr B = 0, so chi s is psi's mean."""
    def at(saturation_key, chi_key, target):
        s = np.array([r[saturation_key] for r in rows])
        psi = np.array([r[chi_key] * r["suction"] for r in rows])
        order = np.argsort(s)
        return float(np.exp(np.interp(np.log(target), np.log(s[order]), np.log(psi[order]))))
    estimates = []
    for void_ratio, water in KIM_CASES:
        saturation = water * SPECIFIC_GRAVITY / void_ratio
        pendular = at("saturation_bridges_alone", "chi_bridges_alone", saturation)
        clustered = at("saturation", "chi_with_clusters", saturation)
        estimates.append({"void_ratio": void_ratio, "water_content": water,
                          "saturation": saturation, "psi_bridges_alone": pendular,
                          "psi_with_clusters": clustered, "ratio": clustered / pendular})
    return estimates


def step_time(sim, repeat=20):
    """Mean wall time [s] of one step of ``sim`` (a copy)."""
    sim = copy.deepcopy(sim)
    sim.run(2)
    started = time.perf_counter()
    sim.run(repeat)
    return (time.perf_counter() - started) / repeat


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--particles", type=int, default=1000)
    parser.add_argument("--out", default=None)
    args = parser.parse_args(argv)
    config = PrepareConfig(particles=args.particles, confining=750.0)
    particles, walls, _ = cached_sample(config, progress=False)
    sim = servoed_simulation(particles, walls, config, config.confining)
    gap = float(np.mean(particles.radius))
    wetting, wetting_times, wet = branch(sim, SUCTIONS, False, gap)
    drying, drying_times, _ = branch(sim, SUCTIONS[::-1], True, gap)
    pendular = copy.deepcopy(wet)
    pendular.forces = [op for op in pendular.forces if not isinstance(op, LiquidClusters)]
    result = {"particles": len(particles.radius), "wetting": wetting, "drying": drying,
              "set_suction_s": {"mean": float(np.mean(wetting_times + drying_times)),
                                "max": float(np.max(wetting_times + drying_times))},
              "step_s": {"pendular": step_time(pendular), "clusters": step_time(wet)},
              "kim_estimate": kim_estimate(wetting)}
    print(json.dumps(result, indent=1))
    if args.out:
        with open(args.out, "w") as handle:
            json.dump(result, handle, indent=1)


if __name__ == "__main__":
    main()
