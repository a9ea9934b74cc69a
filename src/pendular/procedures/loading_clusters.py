"""Liquid clusters in a laboratory test (``--liquid clusters``; docs/liquid_clusters.md 'In
the DEM and the commands'), and the clusters' options of every command, declared once
(``liquid_parameter``, ``entry_suction_parameter``).

At a suction the sample is wetted from dry: persisting suction-controlled bridges and
pendular.capillary.liquid_clusters.LiquidClusters(bridges, saturated=False) join its forces
(``join_clusters``), the units whose filling suction is at least the suction fill
(LiquidClusters.set_suction) before the wetting's equilibrium, and again at the packing it
settles to. At a water content the suction is the one that holds the closed liquid
(``wet_clusters_at_water_content``, LiquidClusters.hold_volume). During the loading
``ClusterUpdates`` steps the model again every CLUSTER_RECORDS history records, at the packing
as it stands (decomposed again, the filled units carried over, pore filling, then Haines jumps
where pores opened), writing a frame of pores/ each time; at every history record in between,
the filled units' forces follow their grains (LiquidClusters.follow_packing: the same units,
filled state and suction, the forces at the grains' positions then). A checkpoint holds the
clusters' state (LiquidClusters.state_dict) and ClusterUpdates' progress; a resumed loading
builds the same scene (``rejoin_clusters``) and takes both back. ``cluster_summary``: the
clusters' figures of a history row, with the effective stress of bridges and clusters;
``refuse_clusters``: what a configuration with clusters cannot run with.
"""

from __future__ import annotations

import time

import numpy as np

from pendular.capillary.throats import ENTRY_ESTIMATES
from pendular.homogenize.invariants import mean_stress
from pendular.utils.parameters import fail, parameter
from pendular.utils.validate import check_int, check_range

#: History records between two updates of the clusters during a loading (10 over a triaxial
#: of 500 records), each about one decomposition of the packing: the period that keeps a wet
#: triaxial with clusters within twice its pendular cost (docs/liquid_clusters.md 'Cost',
#: against its accuracy). At every record in between, the clusters' forces follow the grains.
CLUSTER_RECORDS = 50

#: The clusters' figures of a history row kept in a summary (``cluster_summary``).
CLUSTER_FIGURES = ("suction", "clusters", "liquid_in_bridges", "liquid_in_clusters",
                   "liquid_in_largest_cluster", "largest_cluster_percolates", "trimers",
                   "liquid_in_trimers", "saturation_pore_units", "saturation")


#: Liquid regimes (``--liquid``): pendular bridges alone, or liquid clusters beside them
#: (pendular.capillary.liquid_clusters).
LIQUID_REGIMES = ("pendular", "clusters")


def liquid_parameter(where):
    """The field of a test's liquid regime (``--liquid``, LIQUID_REGIMES): pendular bridges
    alone (default), or liquid clusters of filled pore units beside them
    (docs/liquid_clusters.md); ``where``: how the test's clusters start, in words."""
    return parameter("pendular", kind=str, choices=LIQUID_REGIMES, flag="--liquid",
                     help="liquid regime: pendular bridges alone, or clusters of filled pore "
                          f"units beside them ({where}; docs/liquid_clusters.md)")


def entry_suction_parameter():
    """The field of the liquid clusters' throat entry estimate (``--entry-suction``,
    pendular.capillary.throats.ENTRY_ESTIMATES): the inscribed circle's (default) or the
    Mayer–Stowe–Princen balance over the throat's section (docs/liquid_clusters.md)."""
    return parameter("inscribed", kind=str, choices=ENTRY_ESTIMATES, flag="--entry-suction",
                     help="with --liquid clusters, the suction at which gas enters a throat: "
                          "through its inscribed circle, or by the Mayer-Stowe-Princen "
                          "balance over its section (lower for wetting liquids; "
                          "docs/liquid_clusters.md)")


def refuse_entry_suction(config):
    """ParameterError naming --entry-suction where ``config`` sets it without liquid
    clusters (a configuration with ``liquid`` and ``entry_suction`` fields)."""
    if config.entry_suction != "inscribed" and config.liquid != "clusters":
        raise fail(config, "entry_suction", f"entry_suction = {config.entry_suction!r} needs "
                   "liquid clusters (--liquid clusters): the pendular bridges have no throats")


def refuse_clusters(config) -> str | None:
    """Why the LaboratoryConfig ``config`` with liquid clusters cannot run (naming --liquid
    and the option it cannot run with), or None."""
    bridges = config.bridges
    if bridges is None:
        return ("--liquid clusters needs a wet test: give --suction > 0 or --water-content "
                "(--suction 0 is dry)")
    if config.undrained:
        return ("--liquid clusters holds the liquid in suction-controlled bridges and "
                "clusters: not with --drainage undrained (volume-controlled bridges)")
    if bridges.model != "exact":
        return f"--liquid clusters needs the exact bridges, not --bridges {bridges.model}"
    return None


def refuse_clusters_device(config, device: str) -> None:
    """ValueError naming --device when ``config`` (a LaboratoryConfig or SwccConfig) with
    liquid clusters in a periodic cell would run (or resume) on the GPU: the device's cell
    stress holds no clusters' virial (pendular.gpu.clusters; between walls the GPU runs
    them)."""
    if config.liquid == "clusters" and device != "cpu" and config.sample.periodic:
        raise ValueError(f"--liquid clusters runs on the GPU between walls only: --device "
                         f"{device} does not apply in a periodic cell (--periodic, "
                         "simple-shear), whose stress would need the clusters' virial on the "
                         "device")


def join_clusters(sim, bridges, entry):
    """LiquidClusters of the persisting suction-controlled ``bridges`` (already among
    ``sim``'s forces), the pore units empty (a sample wetted from dry), their throats' entry
    estimate ``entry`` (--entry-suction), appended to the forces and set at the bridges'
    suction at ``sim``'s packing now."""
    from pendular.capillary.liquid_clusters import LiquidClusters   # a dry run never needs it

    clusters = LiquidClusters(bridges, saturated=False, entry=entry)
    sim.forces.append(clusters)
    clusters.set_suction(sim, bridges.suction)
    return clusters


def cluster_bridges(bridges_config, suction=None):
    """The persisting suction-controlled bridges (pendular.capillary.CapillaryBridges) that
    liquid clusters join: at a suction the configuration's (``bridges_config``: BridgeConfig,
    persist set), at a water content the exact ones at ``suction`` [Pa] with its surface
    tension and contact angle."""
    from pendular.capillary import CapillaryBridges

    if bridges_config.water_content is None:
        return bridges_config.build()
    return CapillaryBridges(suction, bridges_config.surface_tension,
                            bridges_config.contact_angle, persist=True)


def rejoin_clusters(sim, bridges_config, suction, entry):
    """The LiquidClusters of a resumed loading (their throats' entry estimate ``entry``),
    appended to ``sim``'s forces after their bridges (``cluster_bridges`` of
    ``bridges_config`` at the wetting's formation ``suction`` [Pa], None at a suction) as the
    wetting appended them; the checkpoint then gives both their state. Until then the
    clusters stand at the bridges' suction at ``sim``'s packing (the sample's), which the
    loading path's first record reads before the checkpoint replaces it and that record."""
    from pendular.capillary.liquid_clusters import LiquidClusters

    bridges = cluster_bridges(bridges_config, suction)
    clusters = LiquidClusters(bridges, saturated=False, entry=entry)
    sim.forces += [bridges, clusters]
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


def hold_water(sim, bridges_config, pairs, target, settle, entry, *, max_gap=0.0,
               settle_filled=True):
    """(bridges, clusters, first, found, steps): the static sample ``sim`` wetted in place to
    the closed liquid volume ``target`` [m^3] (a water content) held by persisting
    suction-controlled bridges and liquid clusters (``bridges_config``: a configuration with
    its surface tension and contact angle; ``entry``: the throats' entry estimate), the pore
    units empty at first (liquid added to dry grains). The suction is found at the dry packing (``first``,
    LiquidClusters.hold_volume; bridges on ``pairs``, (pair_i, pair_j, gap [m] or None: at
    contact), and with ``max_gap`` [m] > 0 across every gap of the neighbour list up to
    it), the sample run until static (``settle(sim)``, the steps), the suction found again
    at the packing reached (``found``) and, with ``settle_filled`` where units are filled,
    the sample run until static once more; ``steps`` in all. NotPendular where bridges at
    contact cannot hold ``target`` within the pendular limit."""
    from pendular.capillary import (BridgeTable, CapillaryBridges, formation_suction,
                                    sample_radius_ratios)
    from pendular.capillary.liquid_clusters import LiquidClusters

    pair_i, pair_j, gap = pairs
    radius = sim.particles.radius
    table = BridgeTable.cached(bridges_config.contact_angle,
                               radius_ratios=sample_radius_ratios(radius))
    # the bridges' alone: the clusters hold more at a suction, so theirs is higher (and the
    # neighbour list at this one's reach holds every pair that can take liquid)
    start = formation_suction(table, radius[pair_i], radius[pair_j], target,
                              bridges_config.surface_tension, gap=gap)
    bridges = CapillaryBridges(start, bridges_config.surface_tension,
                               bridges_config.contact_angle, persist=True)
    clusters = LiquidClusters(bridges, saturated=False, entry=entry)
    sim.forces += [bridges, clusters]
    sim.evaluate_forces()
    first = clusters.hold_volume(sim, target, max_gap)
    steps = settle(sim)
    found = clusters.hold_volume(sim, target)
    if settle_filled and clusters.filled.any():
        steps += settle(sim)
    return bridges, clusters, first, found, steps


def wet_clusters_at_water_content(dry, bridges_config, target, settle, entry):
    """(bridges, clusters, report) of the static sample ``dry`` wetted in place to the closed
    liquid volume ``target`` [m^3] (``hold_water``, bridges at every contact; the sample run
    until static once more where units are filled). Report: the steps, the suction found at
    the packing reached (``formation_suction_pa``) and the volume (``liquid_initial``).
    ValueError naming --water-content where bridges at contact cannot hold it within the
    pendular limit."""
    from pendular.capillary.validation import NotPendular

    sim = dry
    if sim.contacts is None:
        sim.evaluate_forces()
    touching = sim.contacts.overlap > 0.0
    pairs = (sim.contacts.pair_i[touching], sim.contacts.pair_j[touching], None)
    try:
        bridges, clusters, _, found, steps = hold_water(sim, bridges_config, pairs, target,
                                                        settle, entry)
    except NotPendular as error:
        raise ValueError(
            f"--water-content = {100.0 * bridges_config.water_content:g} % is more than this "
            f"sample holds with --liquid clusters: its liquid is held at {error.suction:.4g} "
            f"Pa, below the {error.lowest:.4g} Pa where bridges at contact pass the pendular "
            "limit; lower --water-content") from None
    return bridges, clusters, {"wetting_steps": steps, "formation_suction_pa": found.suction,
                               "liquid_initial": target}


class ClusterUpdates:
    """Writer: every ``follow`` steps from step ``origin`` the clusters' forces follow the
    grains (LiquidClusters.follow_packing), and every ``updates_every``-th time instead
    ``clusters`` take their bridges' suction again at the packing as it stands
    (LiquidClusters.set_suction), or with a closed liquid ``volume`` [m^3] the suction that
    holds it there (LiquidClusters.hold_volume); at the step the bridges' suction changes (a
    path's suction stage) too, at most once every ``follow`` steps while it changes; and
    ``frames`` (pendular.io.vtk.PoreFrames, or None) gets a frame of the pore units with
    ``field_data(sim)`` (the loading's frame fields) and the suction at each update; the
    first frame, the state of ``sim`` the loading starts from, by ``start`` (a resumed
    loading has it already). ``updates``: how many updates ran; ``time_s``: the wall time of
    the updates and of the forces following the grains [s]."""

    def __init__(self, clusters, follow, updates_every, origin, frames=None, field_data=None,
                 volume=None):
        self.clusters, self.frames, self.field_data = clusters, frames, field_data
        self.volume = volume
        self.follow = max(1, int(follow))
        self.period, self.origin = self.follow * max(1, int(updates_every)), int(origin)
        self.updates, self.time_s = 0, 0.0
        self._updated = self.origin

    def state_dict(self):
        """``origin`` (the step the updates count from: a resumed run builds its writer at
        another step), ``updates`` (the updates so far), ``updated`` (the step of the last,
        or the origin), ``time_s`` [s] their wall time and ``frames`` the pores/ frames
        written (PoreFrames.state_dict; None without frames)."""
        return {"origin": self.origin, "updates": self.updates, "updated": self._updated,
                "time_s": self.time_s,
                "frames": None if self.frames is None else self.frames.state_dict()}

    def load_state(self, state):
        origin = check_int("origin", state["origin"], low=0)
        updates = check_int("updates", state["updates"], low=0)
        updated = check_int("updated", state["updated"], low=origin)
        time_s = check_range("time_s", state["time_s"], 0.0, unit="s")
        if (self.frames is None) != (state["frames"] is None):
            raise ValueError("frames: the checkpoint's loading and this one differ in their "
                             "pores/ frames (--vtk-frames, --vtk-every)")
        if self.frames is not None:
            self.frames.load_state(state["frames"])
        self.origin, self.updates, self._updated, self.time_s = origin, updates, updated, time_s

    def start(self, sim):
        """The first frame of pores/: the state of ``sim`` the loading starts from."""
        self._frame(sim)

    def apply(self, sim):
        taken = sim.step - self.origin
        changed = (self.volume is None and self.clusters.bridges.suction != self.clusters.suction
                   and sim.step - self._updated >= self.follow)
        if taken == 0 or (taken % self.follow and not changed):
            return
        started = time.perf_counter()
        if taken % self.period and not changed:
            self.clusters.follow_packing(sim)
            self.time_s += time.perf_counter() - started
            return
        self._updated = sim.step
        if self.volume is None:
            self.clusters.set_suction(sim, self.clusters.bridges.suction)
        else:
            self.clusters.hold_volume(sim, self.volume)
        self.updates += 1
        self.time_s += time.perf_counter() - started
        self._frame(sim)

    def _frame(self, sim):
        if self.frames is not None:
            self.frames.write(len(self.frames.frames), self.clusters.units,
                              self.clusters.found.label,
                              {**self.field_data(sim), "suction": self.clusters.suction})


def cluster_row(history, row: int, names) -> dict:
    """The clusters' figures ``names`` of ``history`` row ``row``
    (pendular.procedures.columns.cluster_columns) as plain JSON values: ``clusters`` an int,
    ``largest_cluster_percolates`` three bools, the rest floats."""
    figures = {}
    for name in names:
        value = np.asarray(history[name][row])
        figures[name] = (value.astype(bool).tolist() if name == "largest_cluster_percolates"
                         else int(value) if name == "clusters" else float(value))
    return figures


def cluster_summary(history, row: int, key: str) -> dict:
    """{``key``: the clusters' figures of ``history`` row ``row``}: CLUSTER_FIGURES,
    ``chi_with_clusters`` and the bridges' ``chi`` (each tr chi / 3), and
    ``p_effective_with_clusters`` = p + chi_with_clusters s (Eq. 3.43's form, u_a = 0; p the
    mean wall stress) [Pa]."""
    figures = cluster_row(history, row, CLUSTER_FIGURES)
    chi = float(np.trace(history["chi_with_clusters"][row]) / 3.0)
    figures.update({"chi_with_clusters": chi,
                    "chi": float(np.trace(history["chi"][row]) / 3.0),
                    "p_effective_with_clusters": float(
                        mean_stress(history["sigma_wall"][row]) + chi * figures["suction"])})
    return {key: figures}
