"""Soil-water characteristic curve (SWCC) of a DEM sample: drying then wetting at constant stress.

``SwccTest(SwccConfig(...)).run(out)``:

1. a sample prepared as in thesis Ch. 5.2.2 (pendular.procedures.preparation), its walls servoed at the
   confining stress;
2. wetted at the lowest suction of the path with suction-controlled bridges that persist
   across gaps up to their rupture distance (capillary.CapillaryBridges, ``persist``): at every
   contact and, with ``form_gap`` > 0, across every gap up to form_gap mean radii where a bridge
   of that suction exists (a sample mixed with its water: the liquid is where a meniscus can
   hold it);
3. drying: the suction raised through the list, each stage run until static (unbalanced force
   and wall stresses within tolerance); a bridge whose gap exceeds the new rupture distance
   breaks;
4. wetting: back down the same list; bridges form again only where grains touch
   (CapillaryBridges.set_suction).

Hysteresis therefore comes from the bridge physics alone: on drying, bridges across gaps
survive until the suction shortens their rupture distance below the gap; on wetting, a broken
bridge does not form again until its grains touch, so the wetting branch holds less water at
the same suction (contact angle hysteresis and pore-scale ink-bottle effects are not modelled).

Outputs in ``out``: swcc.json (``drying`` and ``wetting`` lists of stage rows {suction [Pa],
saturation, bridges, porosity, volumetric_strain (contraction positive, from the dry sample),
chi (tr chi / 3, Eq. 3.44), pendular_overlaps (pairs of menisci merging on a grain: beyond the
pendular regime where many), ...}), swcc.png (Sr against log suction, both branches, with
thesis Fig. 5.5's points and the regular packings' SWCCs of Chapter 4), history.h5 (the wet
triaxial's columns, pendular.io.schema, recorded through the whole path) and sample.h5.

``run(out, device="gpu")`` runs the preparation and every stage of the path on the GPU
(docs/gpu.md: the persisting bridges and the suction changes between stages run there); the
wetting across gaps and the rows of swcc.json are computed on the host between the stages.
"""

from __future__ import annotations

import os
import time

import numpy as np

from pendular.capillary import CapillaryBridges, sample_radius_ratios
from pendular.utils.atomic import write_json
from pendular.dem.grading import GRADING_UNITS, grading
from pendular.dem.measure import coordination, porosity
from pendular.procedures.preparation import prepare_sample
from pendular.procedures.progress import swcc_plan
from pendular.dem.record import HistoryRecorder
from pendular.dem.sample import save_sample
from pendular.dem.simulation import check_device
from pendular.dem.walls import ConstantStrainRate
from pendular.utils.progress import whole_run
from pendular.homogenize import packing_state, regular_packing
from pendular.homogenize.on_the_fly import CapillaryHomogenization
from pendular.homogenize.regular_packing import KINDS

from pendular.procedures.config import SwccConfig, config_to_dict
from pendular.io.history import write_history
from pendular.io.schema import SWCC_STAGE_UNITS
from pendular.io.outputs import OutputFolder
from pendular.io.plots import pyplot, save_figure
from pendular.procedures.reference import FIG_5_5
from pendular.procedures.loading import history_columns
from pendular.procedures.triaxial import (MIN_CONFINING_OVER_YOUNG, NotStatic, equilibrate,
    equilibrium_status, watched)

#: Files a SWCC run owns in its output folder.
OUTPUTS = ("swcc.json", "swcc.png", "history.h5", "sample.h5")


def path_bridges(config: SwccConfig, radii) -> CapillaryBridges:
    """The persisting suction-controlled bridges of the path, their tables loaded for
    ``radii`` [m] and every suction of the path checked against them (ValueError naming the
    suction outside the tables or the pendular regime)."""
    bridges = CapillaryBridges(config.suctions[0], config.surface_tension,
                               config.contact_angle, persist=True)
    bridges.load_tables(float(np.min(radii)), float(np.max(radii)),
                        radius_ratios=sample_radius_ratios(radii))
    for suction in config.suctions:
        bridges._check_suction(suction, float(np.min(radii)), float(np.max(radii)))
    return bridges


class SwccTest:
    """The SWCC path of a ``SwccConfig`` (module docstring); ``run(out)`` returns the
    swcc.json content."""

    def __init__(self, config: SwccConfig):
        if not isinstance(config, SwccConfig):
            raise TypeError(f"config must be a SwccConfig, got {type(config).__name__}")
        self.config = config
        sample = config.sample
        lowest = MIN_CONFINING_OVER_YOUNG * sample.young
        if sample.confining < lowest:
            raise ValueError(
                f"--confining = {sample.confining:g} Pa is below its valid minimum {lowest:g} Pa "
                f"({MIN_CONFINING_OVER_YOUNG:g} young, young = {sample.young:g} Pa): the "
                "servoed walls never hold a lower confining stress (every stage would run to "
                "--stage-steps)")
        path_bridges(config, sample.radii())       # refuse a bad path before preparing

    def run(self, out, *, progress=True, threads=None, device="cpu"):
        """Run the path into ``out``; ``device``: where the preparation and the stages run,
        "cpu" or "gpu" (``check_device``, before anything is made)."""
        check_device(device)
        with OutputFolder(out, "swcc") as folder:
            for name in OUTPUTS:
                folder.claim(name)
            with whole_run(swcc_plan(self.config), enabled=progress):
                return self._run(out, progress, threads, device)

    def _run(self, out, progress, threads, device):
        config = self.config
        started = time.perf_counter()
        sim, preparation = prepare_sample(config.sample, progress=progress, threads=threads,
                                          device=device)
        save_sample(os.path.join(out, "sample.h5"), sim, preparation,
                    {"config": config_to_dict(config)}, identity={"seed": config.sample.seed})
        dry_volume = sim.walls.volume()
        bridges = path_bridges(config, sim.particles.radius)
        sim.forces.append(bridges)
        sim.evaluate_forces()                     # the neighbour list at the bridges' reach
        formed = 0
        if config.form_gap > 0.0:
            formed = bridges.form_across_gaps(sim, config.form_gap * config.sample.radius)
        axial = ConstantStrainRate("z", 0.0, sim.walls.lengths()[2])   # measures the strain
        recorder = HistoryRecorder(config.record_every,
                                   history_columns(sim, axial, dry_volume, bridges),
                                   origin=sim.step)
        homogenization = CapillaryHomogenization(bridges)
        sim.device = device
        stages = {"drying": [], "wetting": []}
        suctions = list(config.suctions)
        path = [("drying", s) for s in suctions] + [("wetting", s) for s in suctions[::-1]]
        with watched(sim, [recorder], "path"):
            for index, (branch, suction) in enumerate(path):
                if index == len(suctions):        # the turning point: drying's last state
                    stages[branch].append(dict(stages["drying"][-1], steps=0))
                    continue
                bridges.set_suction(suction)
                steps = self.stage(sim, suction, branch, progress)
                recorder.record(sim)
                stages[branch].append(self.stage_row(sim, bridges, homogenization, suction,
                                                     dry_volume, steps))
        history = recorder.arrays()
        write_history(os.path.join(out, "history.h5"), history, config_to_dict(config),
                      attributes={"test": "swcc", "dt": sim.dt})
        result = {
            "config": config_to_dict(config),
            "drying": stages["drying"],
            "wetting": stages["wetting"],
            "bridges_formed_across_gaps": formed,
            "hysteresis": hysteresis(stages),
            "preparation": {k: preparation[k] for k in ("porosity", "coordination", "steps")},
            "grading": grading(sim.particles.radius),
            "regular_packings": regular_packing_curves(config, suctions),
            "thesis_fig_5_5": {str(int(s)): v for s, v in FIG_5_5.items()},
            "wall_time_s": time.perf_counter() - started,
            "units": {**SWCC_STAGE_UNITS, "wall_time_s": "s", "grading": GRADING_UNITS},
        }
        write_json(os.path.join(out, "swcc.json"), result)
        plot_swcc(os.path.join(out, "swcc.png"), result)
        return result

    def stage(self, sim, suction, branch, progress):
        """Run one stage of the path to equilibrium; its steps. NotStatic naming --stage-steps
        when the stage ends at that limit first."""
        sample = self.config.sample
        limit = self.config.stage_steps
        try:
            return equilibrate(sim, unbalanced=sample.equilibrium_unbalanced,
                               tolerance=sample.stress_tolerance, max_steps=limit,
                               progress=(f"{branch} {suction:g} Pa" if progress else None))
        except NotStatic:
            reached = equilibrium_status(sample.equilibrium_unbalanced)(sim)
            raise NotStatic(
                f"--stage-steps = {limit}: the equilibrium at suction {suction:g} Pa ({branch}) "
                "was not reached within this many steps ("
                + ", ".join(f"{k} {v}" for k, v in reached.items())
                + "): raise --stage-steps or check the settings") from None

    @staticmethod
    def stage_row(sim, bridges, homogenization, suction, dry_volume, steps):
        """The swcc.json row of a static stage (pendular.io.schema.SWCC_STAGE_UNITS)."""
        state = bridges.state(sim)
        chi = homogenization.chi(sim)
        return {"suction": suction,
                "saturation": bridges.saturation(sim),
                "bridges": state.count(),
                "bridges_across_gaps": int(np.count_nonzero(state.state == 2)),
                "porosity": porosity(sim.particles, sim.walls),
                "volumetric_strain": 1.0 - sim.walls.volume() / dry_volume,
                "chi": float(np.trace(chi) / 3.0),
                "chi_tensor": chi.tolist(),
                "psi": homogenization.psi(sim).tolist(),
                "psi_interface": homogenization.psi_interface(sim).tolist(),
                "sigma_wall": sim.walls.stress().tolist(),
                "coordination": coordination(sim.contacts, len(sim.particles)),
                "pendular_overlaps": bridges.pendular_overlaps(sim),
                "steps": steps}


def hysteresis(stages):
    """Per suction, the saturation of the drying branch minus that of the wetting branch
    (positive: drying holds more water) and the difference in bridges."""
    wetting = {row["suction"]: row for row in stages["wetting"]}
    return [{"suction": row["suction"],
             "saturation_difference": row["saturation"] - wetting[row["suction"]]["saturation"],
             "bridges_difference": row["bridges"] - wetting[row["suction"]]["bridges"]}
            for row in stages["drying"]]


def regular_packing_curves(config, suctions):
    """Sr of the Chapter 4 regular packings (bridges at every contact, pendular.homogenize.packing_state)
    of spheres of the sample's mean radius at each suction of the path: {kind: [Sr or None
    beyond the pendular limit]}."""
    curves = {}
    for kind in KINDS:
        values = []
        for suction in suctions:
            try:
                values.append(packing_state(
                    regular_packing(kind), radius=config.sample.radius,
                    contact_angle=config.contact_angle, surface_tension=config.surface_tension,
                    suction=suction).saturation)
            except ValueError:
                values.append(None)
        curves[kind] = values
    return curves


def plot_swcc(path, result):
    """swcc.png: Sr [%] against suction [kPa] (log), both branches, thesis Fig. 5.5's points
    and the regular packings' curves."""
    plt = pyplot()
    figure, axes = plt.subplots(figsize=(6.5, 4.5))
    for branch, style in (("drying", "o-"), ("wetting", "s--")):
        rows = result[branch]
        axes.plot([r["suction"] / 1e3 for r in rows], [100 * r["saturation"] for r in rows],
                  style, label=f"DEM, {branch}")
    suctions = [r["suction"] for r in result["drying"]]
    for kind, values in result["regular_packings"].items():
        points = [(s / 1e3, 100 * v) for s, v in zip(suctions, values) if v is not None]
        if points:
            axes.plot(*zip(*points), ":", lw=1, label=f"{kind.upper()} packing (Ch. 4)")
    thesis = sorted((float(s), v) for s, v in result["thesis_fig_5_5"].items())
    axes.plot([s / 1e3 for s, _ in thesis], [100 * v for _, v in thesis], "k*", ms=10,
              label="thesis Fig. 5.5 (its DEM samples)")
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_xlabel("suction [kPa]")
    axes.set_ylabel("degree of saturation Sr [%]")
    sample = result["config"]["fields"]["sample"]["fields"]
    axes.set_title(f"SWCC, {sample['particles']} spheres, confining {sample['confining']:g} Pa",
                   fontsize=9)
    axes.grid(alpha=0.3, which="both")
    axes.legend(fontsize=7)
    return save_figure(figure, path)
