"""The direct tension with liquid clusters (``pendular tension --liquid clusters``;
docs/liquid_clusters.md 'Kim's direct tension').

The water content is a closed liquid volume V = w Gs V_s held by persisting suction-controlled
bridges and filled pore units (pendular.capillary.liquid_clusters) at the one suction at which
they hold it (pendular.capillary.closed_liquid). Wetting: from the dry sample, the branch of a
liquid added to dry grains (the units fill at their filling suctions as the suction falls):
the suction found with bridges at every contact and across every gap up to --form-gap radii,
the sample settled under the bridges' and clusters' forces, the suction found again at the
settled packing. Pull: as pendular.procedures.tension_pull.Pull, the suction found again at
the packing as it stands CLUSTER_UPDATES times over --max-strain (``ClosedLiquidUpdates``), the
filled units carried over, so the liquid is V at every update; between updates the suction
is held, the bridges following their gaps at it.

Between walls, smooth spheres (suction-controlled bridges have no roughness), on either
device: ``refuse_clusters`` names the options otherwise. A checkpoint holds the clusters'
state (LiquidClusters.state_dict), so a pull resumes bit for bit.
"""

from __future__ import annotations

import copy
import math

from pendular.capillary.validation import NotPendular
from pendular.capillary.wetting import gravimetric_water_content
from pendular.dem.measure import coordination, unbalanced_force
from pendular.procedures.columns import cluster_columns as cluster_figures
from pendular.procedures.loading_clusters import (CLUSTER_FIGURES as LABORATORY_FIGURES,
    cluster_row, hold_water)
from pendular.utils.parameters import ParameterError

#: Closed-liquid solutions of a pull (LiquidClusters.hold_volume) over --max-strain.
CLUSTER_UPDATES = 40

#: The clusters' figures of a history row, kept in a case's summary (wetted and at the peak):
#: a laboratory test's, less the saturation, which the case reports itself.
CLUSTER_FIGURES = tuple(name for name in LABORATORY_FIGURES if name != "saturation")


def refuse_clusters(config) -> str | None:
    """Why ``config`` (TensionConfig) cannot run with liquid clusters (the options named), or
    None."""
    if config.liquid != "clusters":
        return None
    if config.sample.periodic:
        return ("--liquid clusters runs the direct tension between walls, not with --periodic "
                "(its closed liquid is held in the walled sample's pore units)")
    if config.roughness > 0.0:
        return (f"--liquid clusters needs --roughness 0, got {config.roughness:g}: its "
                "suction-controlled bridges are between smooth spheres (roughness is modelled "
                "for volume-controlled bridges only)")
    return None




def wet_clusters(dry, config, water_content: float, pairs, settle):
    """(wetted sim, bridges, clusters, wetting report): a copy of ``dry`` holding the water
    content ``water_content`` (fraction) in bridges and clusters (module docstring);
    ``pairs``: (pair_i, pair_j, gap or None) of the pairs wetted
    (tension_pull.wetted_pairs); ``settle(sim)``: runs it to equilibrium, returns the steps.
    The report is tension_pull.wet's, its void ratio aside, and ``clusters_wet``."""
    particles = dry.particles
    target = water_content * config.specific_gravity * particles.solid_volume()
    sim = copy.deepcopy(dry)
    try:
        bridges, clusters, first, liquid, steps = hold_water(
            sim, config, pairs, target, settle, config.entry_suction,
            max_gap=config.form_gap * config.sample.radius, settle_filled=False)
    except NotPendular as error:
        raise ParameterError("water_content", (
            f"water_content = {100.0 * water_content:g} % is more than this sample holds with "
            f"--liquid clusters: its liquid is held at {error.suction:.4g} Pa, below the "
            f"{error.lowest:.4g} Pa where bridges at contact (R = {error.radius:.3g} m) pass "
            f"the pendular limit (filling angle {error.angle:.1f} deg); lower "
            "--water-content"), "--water-content") from None
    sim.evaluate_forces()                     # the bridges at the suction found
    solid = particles.solid_volume()
    attempts = [{"formation_suction_pa": first.suction, "steps": steps,
                 "water_content": gravimetric_water_content(first.total, solid,
                                                            config.specific_gravity)}]
    statistics = clusters.statistics(sim)
    report = {"formation_suction_pa": liquid.suction, "wetting_attempts": attempts,
              "water_content": gravimetric_water_content(clusters.account(sim).total, solid,
                                                         config.specific_gravity),
              "saturation": statistics["saturation"], "bridges": bridges.count(sim),
              "coordination_wet": coordination(sim.contacts, len(sim.particles)),
              "unbalanced_force_wet": unbalanced_force(sim.particles, sim.contacts),
              "clusters_wet": {"suction": liquid.suction,
                               **{name: statistics[name] for name in CLUSTER_FIGURES[1:]}}}
    return sim, bridges, clusters, report


class ClosedLiquidUpdates:
    """Writer: every ``period`` steps from step ``origin``, ``clusters`` hold ``volume`` [m^3]
    again at the packing as it stands (LiquidClusters.hold_volume). Its volume, period and
    origin are the pull's (a resumed pull builds it the same way)."""

    stateless = True

    def __init__(self, clusters, volume, period, origin):
        self.clusters, self.volume = clusters, float(volume)
        self.period, self.origin = max(1, int(period)), int(origin)

    def apply(self, sim):
        if (sim.step - self.origin) % self.period == 0:
            self.clusters.hold_volume(sim, self.volume)


def cluster_columns(clusters, solid_volume, specific_gravity):
    """The pull's history columns of the clusters: the SWCC's
    (pendular.procedures.columns.cluster_columns: their number, the liquid's fractions,
    percolation, the saturations of bridges and clusters together), the suction, and the
    water content of the liquid held, bridges and clusters together (``solid_volume``
    [m^3], ``specific_gravity`` Gs)."""
    columns = cluster_figures(clusters)
    columns["suction"] = lambda sim: clusters.suction
    columns["water_content"] = lambda sim: gravimetric_water_content(
        clusters.account(sim).total, solid_volume, specific_gravity)
    return columns


def cluster_summary(history, peak: int) -> dict:
    """The clusters' figures of the pull's ``history`` row ``peak`` (CLUSTER_FIGURES)."""
    return {"clusters_at_peak": cluster_row(history, peak, CLUSTER_FIGURES)}


def update_period(pull_steps: int) -> int:
    """Steps between the closed-liquid solutions of a pull of ``pull_steps`` steps."""
    return max(1, math.ceil(pull_steps / CLUSTER_UPDATES))
