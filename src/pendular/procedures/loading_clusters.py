"""Liquid clusters in a laboratory test at a suction (``--liquid clusters``;
docs/liquid_clusters.md 'In the DEM and the commands').

The sample is wetted from dry: persisting suction-controlled bridges and
pendular.capillary.liquid_clusters.LiquidClusters(bridges, saturated=False) join its forces
(``join_clusters``), the units whose filling suction is at least the suction fill
(LiquidClusters.set_suction) before the wetting's equilibrium, and again at the packing it
settles to. During the loading ``ClusterUpdates`` imposes the bridges' suction on the clusters
again every CLUSTER_RECORDS history records, at the packing as it stands (decomposed again,
the filled units carried over, pore filling, then Haines jumps where pores opened), writing a
frame of pores/ each time; between updates the clusters' forces are held, as in a stage of
the SWCC. ``cluster_summary``: the clusters' figures of a history row, with the effective
stress of bridges and clusters.
"""

from __future__ import annotations

import time

import numpy as np

from pendular.homogenize.invariants import mean_stress

#: History records between two updates of the clusters during a loading (the ParaView frames'
#: default spacing, pendular.procedures.loading.VTK_RECORDS): about 50 over a triaxial of 500
#: records, 0.2 % of axial strain apart at 10 %; each costs about one decomposition of the
#: packing (docs/liquid_clusters.md 'Cost').
CLUSTER_RECORDS = 10

#: The clusters' figures of a history row kept in a summary (``cluster_summary``).
CLUSTER_FIGURES = ("suction", "clusters", "liquid_in_bridges", "liquid_in_clusters",
                   "liquid_in_largest_cluster", "largest_cluster_percolates",
                   "saturation_pore_units", "saturation")


def join_clusters(sim, bridges):
    """LiquidClusters of the persisting suction-controlled ``bridges`` (already among
    ``sim``'s forces), the pore units empty (a sample wetted from dry), appended to the forces
    and set at the bridges' suction at ``sim``'s packing now."""
    from pendular.capillary.liquid_clusters import LiquidClusters   # a dry run never needs it

    clusters = LiquidClusters(bridges, saturated=False)
    sim.forces.append(clusters)
    clusters.set_suction(sim, bridges.suction)
    return clusters


def wetted_clusters(sim, clusters):
    """The clusters' figures once wetted (a wetting report's ``clusters_wet``)."""
    from pendular.homogenize.clusters import chi_with_clusters

    statistics = clusters.statistics(sim)
    figures = {"suction": clusters.suction,
               **{name: statistics[name] for name in CLUSTER_FIGURES[1:]},
               "chi_with_clusters": float(np.trace(chi_with_clusters(sim, clusters)) / 3.0)}
    figures["p_effective_with_clusters"] = float(
        mean_stress(sim.walls.stress()) + figures["chi_with_clusters"] * clusters.suction)
    return figures


class ClusterUpdates:
    """Writer: every ``period`` steps from step ``origin``, ``clusters`` take their bridges'
    suction again at the packing as it stands (LiquidClusters.set_suction), and ``frames``
    (pendular.io.vtk.PoreFrames, or None) gets a frame of the pore units with
    ``field_data(sim)`` (the loading's frame fields) and the suction; the first frame, the
    state of ``sim`` the loading starts from, at once. ``updates`` and ``time_s``: how many
    updates ran and their wall time [s]."""

    def __init__(self, sim, clusters, period, origin, frames=None, field_data=None):
        self.clusters, self.frames, self.field_data = clusters, frames, field_data
        self.period, self.origin = max(1, int(period)), int(origin)
        self.updates, self.time_s = 0, 0.0
        self._frame(sim)

    def apply(self, sim):
        if sim.step == self.origin or (sim.step - self.origin) % self.period:
            return
        started = time.perf_counter()
        self.clusters.set_suction(sim, self.clusters.bridges.suction)
        self.updates += 1
        self.time_s += time.perf_counter() - started
        self._frame(sim)

    def _frame(self, sim):
        if self.frames is not None:
            self.frames.write(len(self.frames.frames), self.clusters.units,
                              self.clusters.found.label,
                              {**self.field_data(sim), "suction": self.clusters.suction})


def cluster_summary(history, row: int, key: str) -> dict:
    """{``key``: the clusters' figures of ``history`` row ``row``}: CLUSTER_FIGURES,
    ``chi_with_clusters`` and the bridges' ``chi`` (each tr chi / 3), and
    ``p_effective_with_clusters`` = p + chi_with_clusters s (Eq. 3.43's form, u_a = 0; p the
    mean wall stress) [Pa]."""
    figures = {}
    for name in CLUSTER_FIGURES:
        value = np.asarray(history[name][row])
        figures[name] = (value.astype(bool).tolist() if name == "largest_cluster_percolates"
                         else int(value) if name == "clusters" else float(value))
    chi = float(np.trace(history["chi_with_clusters"][row]) / 3.0)
    figures.update({"chi_with_clusters": chi,
                    "chi": float(np.trace(history["chi"][row]) / 3.0),
                    "p_effective_with_clusters": float(
                        mean_stress(history["sigma_wall"][row]) + chi * figures["suction"])})
    return {key: figures}
