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
triaxial's columns, pendular.io.schema, recorded through the whole path) and sample.h5; with
``run(out, checkpoint_every=N)`` checkpoint.h5 (SwccPath), from which ``SwccTest.resume(out)``
continues an interrupted path bit for bit.

With ``liquid = "clusters"`` (docs/liquid_clusters.md) the pore space starts saturated and
liquid clusters of filled pore units join the bridges (pendular.capillary.liquid_clusters):
drying empties units by Haines jumps from the hull, wetting fills them at their filling
suction, so that the path gives the main drying and wetting curves; each row adds the
clusters' figures, and pores/ holds the pore units coloured by cluster, one ParaView frame per
stage (on either device; a checkpoint holds the clusters' state and the frames written).

``run(out, device="gpu")`` runs the preparation and every stage of the path on the GPU
(docs/gpu.md: the persisting bridges and the suction changes between stages run there); the
wetting across gaps and the rows of swcc.json are computed on the host between the stages.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field

import numpy as np

from pendular.capillary import CapillaryBridges, SURFACE_TENSION, sample_radius_ratios
from pendular.capillary.liquid_clusters import LiquidClusters
from pendular.dem.checkpoint import CheckpointWriter, load_checkpoint
from pendular.dem.grading import GRADING_UNITS, grading
from pendular.dem.measure import coordination, porosity
from pendular.dem.record import HistoryRecorder
from pendular.dem.sample import load_sample, save_sample
from pendular.dem.simulation import check_device
from pendular.dem.walls import ConstantStrainRate
from pendular.homogenize import packing_state, regular_packing
from pendular.homogenize.clusters import chi_with_clusters
from pendular.homogenize.on_the_fly import CapillaryHomogenization
from pendular.homogenize.regular_packing import KINDS
from pendular.io.history import write_history
from pendular.io.vtk import PoreFrames
from pendular.io.outputs import OutputFolder
from pendular.io.plots import plot_swcc
from pendular.io.schema import SWCC_STAGE_UNITS
from pendular.procedures.columns import history_columns
from pendular.procedures.command import LaboratoryCommand
from pendular.procedures.config import (AVERAGES, MAX_SURFACE_TENSION, MIN_SAMPLE_PARTICLES,
    check_loaded_confining, check_particles, config_from_dict, config_to_dict,
    contact_angle_parameter, registered, stage_steps_parameter)
from pendular.procedures.equilibrium import NotStatic, equilibrium_status
from pendular.procedures.feasibility import MIN_CONFINING_OVER_YOUNG, check_hertz_equilibria
from pendular.procedures.laboratory import Interrupted, plain, run_identity
from pendular.procedures.loading import run_stage
from pendular.procedures.loading_clusters import (entry_suction_parameter, liquid_parameter,
    refuse_clusters_device, refuse_entry_suction)
from pendular.procedures.options import (CHECKPOINT_EVERY, CommandOptions, options_named,
    sample_sizes, size_options)
from pendular.procedures.preparation import (MAX_PARTICLES, PrepareConfig, prepare_sample,
    servoed_simulation, static)
from pendular.procedures.progress import swcc_plan
from pendular.procedures.reference import FIG_5_5
from pendular.procedures.resume import resume_files, stored_run
from pendular.procedures.run_options import RunOptions
from pendular.utils.atomic import write_json
from pendular.utils.parameters import fail, fields_of, option_of, parameter, validate
from pendular.utils.progress import whole_run
from pendular.utils.validate import check_int


@registered
@dataclass
class SwccConfig:
    """The soil-water characteristic curve of a sample (pendular.procedures.swcc): drying through
    ``suctions`` then wetting back, at the sample's confining stress.

    sample: preparation and material (pendular.procedures.preparation.PrepareConfig; its ``confining`` [Pa]
    holds during the path; at least MIN_SAMPLE_PARTICLES spheres); suctions [Pa]: the path's
    stages, ascending and distinct, at least two; surface_tension [N/m]; contact_angle [deg];
    form_gap: at wetting, bridges also form across gaps up to form_gap mean radii (0: at
    contacts only); stage_steps: most steps per stage to reach equilibrium; record_every: steps
    between history records; liquid: the liquid regime, "pendular" (bridges alone) or
    "clusters" (filled pore units beside them: pendular.capillary.liquid_clusters);
    entry_suction: the clusters' throat entry estimate, "inscribed" or "mayer-stowe-princen"
    (pendular.capillary.throats.ENTRY_ESTIMATES).
    """

    sample: PrepareConfig = field(default_factory=PrepareConfig)
    suctions: list[float] = parameter(
        default_factory=lambda: [3000.0, 10000.0, 30000.0, 100000.0, 300000.0], many=True,
        unit="Pa", low=0.0, low_inclusive=False, flag="--suctions", metavar="S1,S2,...",
        help="suctions of the drying path, ascending; wetting goes back along them")
    surface_tension: float = parameter(SURFACE_TENSION, unit="N/m", low=0.0,
                                       high=MAX_SURFACE_TENSION, low_inclusive=False,
                                       flag="--surface-tension", help="liquid surface tension")
    contact_angle: float = contact_angle_parameter()
    form_gap: float = parameter(1.0, low=0.0, high=1.0, flag="--form-gap",
                                help="at wetting, bridges also form across gaps up to this many "
                                     "mean radii (0: at contacts only; 1: wherever a bridge of "
                                     "the lowest suction can exist)")
    stage_steps: int = stage_steps_parameter(200000, "most steps per stage to reach equilibrium")
    record_every: int = parameter(1000, kind=int, low=1, flag="--record-every",
                                  help="steps between history records")
    liquid: str = liquid_parameter("drying from saturation")
    entry_suction: str = entry_suction_parameter()

    def __post_init__(self):
        if not isinstance(self.sample, PrepareConfig):
            raise TypeError(f"sample must be a PrepareConfig, got {type(self.sample).__name__}")
        check_particles(self.sample.particles, MIN_SAMPLE_PARTICLES, MAX_PARTICLES, "an SWCC",
                        AVERAGES)
        validate(self)
        refuse_entry_suction(self)
        if len(self.suctions) < 2 or any(b <= a for a, b in zip(self.suctions,
                                                                   self.suctions[1:])):
            raise fail(self, "suctions", f"suctions = "
                       f"{','.join(f'{s:g}' for s in self.suctions)}: at least two suctions "
                       "[Pa], ascending and distinct, expected (the drying path; wetting goes "
                       "back along it)")
        check_loaded_confining(self.sample, "an SWCC at constant stress")


#: Files a SWCC run owns in its output folder.
OUTPUTS = ("swcc.json", "swcc.png", "history.h5", "sample.h5", "checkpoint.h5")


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

    #: The configuration's type.
    CONFIG = SwccConfig

    def __init__(self, config: SwccConfig):
        if not isinstance(config, SwccConfig):
            raise TypeError(f"config must be a SwccConfig, got {type(config).__name__}")
        self.config = config
        sample = config.sample
        lowest = MIN_CONFINING_OVER_YOUNG * sample.young
        if sample.contact == "hertz-mindlin":       # Hertz's overlaps, not a spring's
            check_hertz_equilibria(config, sample.confining)
        elif sample.confining < lowest:
            raise ValueError(
                f"--confining = {sample.confining:g} Pa is below its valid minimum {lowest:g} Pa "
                f"({MIN_CONFINING_OVER_YOUNG:g} young, young = {sample.young:g} Pa): the "
                "servoed walls never hold a lower confining stress (every stage would run to "
                "--stage-steps)")
        path_bridges(config, sample.radii())       # refuse a bad path before preparing
        if config.liquid == "clusters" and sample.periodic:
            raise ValueError("liquid = 'clusters' runs the SWCC between walls, not in a periodic "
                             "cell (its drying starts at the hull of the centres, where the gas "
                             "enters)")

    def run(self, out, options=None, **settings):
        """Run the path into ``out`` as ``options`` say (pendular.procedures.run_options
        .RunOptions; ``settings``: its fields one by one): ``device``: where the preparation
        and the stages run, "cpu" or "gpu" (``check_device``, before anything is made);
        ``checkpoint_every``: steps between checkpoints ``out``/checkpoint.h5 of the path (0:
        none), from which ``resume`` continues; ``stop_after``: stop the path after this many
        steps as an interruption would (raises Interrupted)."""
        options = RunOptions.of(options, **settings)
        progress, threads, device = options.progress, options.threads, options.device
        check_device(device)
        checkpoint_every = check_int("checkpoint_every", options.checkpoint_every, low=0)
        stop_after = options.stop_after
        refuse_clusters_device(self.config, device)
        with OutputFolder(out, "swcc") as folder:
            for name in OUTPUTS:
                folder.claim(name)
            if self.config.liquid == "clusters":
                folder.claim("pores")
            with whole_run(swcc_plan(self.config), enabled=progress):
                return self._run(out, progress, threads, device, checkpoint_every, stop_after)

    def _run(self, out, progress, threads, device, checkpoint_every, stop_after):
        config = self.config
        started = time.perf_counter()
        sim, preparation = prepare_sample(config.sample, progress=progress, threads=threads,
                                          device=device)
        sample_file = os.path.join(out, "sample.h5")
        save_sample(sample_file, sim, preparation,
                    {"config": config_to_dict(config)}, identity={"seed": config.sample.seed})
        bridges = path_bridges(config, sim.particles.radius)
        path = SwccPath(self, sim, bridges, out, preparation, checkpoint_every,
                        run_identity(config, sample_file), time.perf_counter() - started)
        sim.evaluate_forces()                     # the neighbour list at the bridges' reach
        if config.form_gap > 0.0:
            path.formed = bridges.form_across_gaps(sim, config.form_gap * config.sample.radius)
        sim.device = device
        return path.finish(progress, stop_after)

    @classmethod
    def resume(cls, out, options=None, **settings):
        """Continue the interrupted run of folder ``out`` from its checkpoint.h5, with the
        configuration stored in its sample.h5, run as ``options`` say (RunOptions;
        ``settings``: its fields one by one), its path on their device; returns the swcc.json
        content."""
        options = RunOptions.of(options, **settings)
        progress, threads, device = options.progress, options.threads, options.device
        stop_after = options.stop_after
        sample_file, checkpoint = resume_files(out, "in the preparation")
        with OutputFolder(out, "swcc --resume", keep=True) as folder:
            for name in OUTPUTS:
                folder.claim(name)
            particles, walls, preparation, stored = load_sample(sample_file)
            config = stored_run(config_from_dict(stored.get("config"), sample_file), out, cls,
                                "swcc", device)
            refuse_clusters_device(config, device)
            sim = servoed_simulation(particles, walls, config.sample, config.sample.confining,
                                     threads=threads)
            test = cls.__new__(cls)          # the stored run, checked when it started
            test.config = config
            identity = run_identity(config, sample_file)
            path = SwccPath(test, sim, path_bridges(config, particles.radius), out,
                            preparation, 1, identity, 0.0)
            state = path.load(checkpoint)
            path.resumed(state, checkpoint)
            sim.device = device
            return path.finish(progress, stop_after)

    def stage_failed(self, sim, suction, branch):
        """NotStatic naming --stage-steps: the stage at ``suction`` [Pa] of ``branch`` ended
        at that limit before its equilibrium."""
        sample = self.config.sample
        reached = equilibrium_status(sample.equilibrium_unbalanced)(sim)
        return NotStatic(
            f"--stage-steps = {self.config.stage_steps}: the equilibrium at suction "
            f"{suction:g} Pa ({branch}) was not reached within this many steps ("
            + ", ".join(f"{k} {v}" for k, v in reached.items())
            + "): raise --stage-steps or check the settings")

    @staticmethod
    def stage_row(sim, bridges, homogenization, suction, dry_volume, steps, clusters=None):
        """The swcc.json row of a static stage (pendular.io.schema.SWCC_STAGE_UNITS); with
        liquid ``clusters`` (LiquidClusters), their figures, and the saturation of bridges and
        clusters together (chi, psi: the bridges' whole, their shares in filled units
        included; the clusters' share of the complete stress is psi_clusters)."""
        state = bridges.state(sim)
        chi = homogenization.chi(sim)
        row = {"suction": suction,
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
        if clusters is not None:
            row.update(clusters.statistics(sim))
            row["chi_with_clusters"] = float(np.trace(chi_with_clusters(sim, clusters)) / 3.0)
        return row


class SwccPath:
    """The drying and wetting path of a SwccTest's prepared sample ``sim`` with its persisting
    ``bridges`` (appended to its forces): the stages run to equilibrium in turn, the history
    recorded, and with ``checkpoint_every`` > 0 a checkpoint (pendular.dem.checkpoint) every
    that many steps holding where the path stands (stage, its first step, the rows so far),
    so that ``resume`` continues it bit for bit. ``finish`` runs the rest of the path and
    writes the outputs."""

    #: Steps between the equilibrium checks of a stage.
    CHECK_EVERY = 200

    def __init__(self, test, sim, bridges, out, preparation, checkpoint_every, identity,
                 preparation_time):
        config = test.config
        self.test, self.sim, self.bridges, self.out = test, sim, bridges, out
        self.preparation, self.preparation_time = preparation, preparation_time
        self.dry_volume = sim.walls.volume()
        sim.forces.append(bridges)
        self.clusters = None
        if config.liquid == "clusters":          # the pore space starts full: main drying
            self.clusters = LiquidClusters(bridges, saturated=True, entry=config.entry_suction)
            sim.forces.append(self.clusters)
        axial = ConstantStrainRate("z", 0.0, sim.walls.lengths()[2])   # measures the strain
        columns = history_columns(sim, axial, self.dry_volume, bridges)   # clusters' too
        self.recorder = HistoryRecorder(config.record_every, columns, origin=sim.step)
        self.homogenization = CapillaryHomogenization(bridges)
        suctions = list(config.suctions)
        self.path = [("drying", s) for s in suctions] + [("wetting", s) for s in suctions[::-1]]
        self.index, self.stage_start = 0, None
        self.stages = {"drying": [], "wetting": []}
        self.formed = 0
        self.pore_frames = PoreFrames(os.path.join(out, "pores"), "stage")
        self.path_time = 0.0         # seconds spent on the path by earlier (interrupted) runs
        self._static = static(config.sample.equilibrium_unbalanced,
                              config.sample.stress_tolerance)
        sim.writers.append(self.recorder)
        self.checkpoint = None
        if checkpoint_every > 0:
            self.checkpoint = CheckpointWriter(os.path.join(out, "checkpoint.h5"),
                                               checkpoint_every, self.extra_state, identity)
            sim.writers.append(self.checkpoint)
        self._clock = time.perf_counter()

    def extra_state(self, sim):
        """What a resumed run needs besides the simulation (CheckpointWriter extra_state)."""
        state = {"phase": "path", "stage": self.index, "stage_start": self.stage_start,
                 "stages": plain(self.stages), "formed": self.formed,
                 "checkpoint_every": self.checkpoint.period,
                 "preparation_time_s": self.preparation_time,
                 "path_time_s": self.path_time + time.perf_counter() - self._clock}
        if self.clusters is not None:        # the pores/ frames so far
            state["pore_frames"] = {key: value.tolist()
                                    for key, value in self.pore_frames.state_dict().items()}
        return state

    def load(self, path):
        """Load the checkpoint ``path`` into the simulation; its extra state (ValueError naming
        the file for one that does not belong to this run)."""
        return load_checkpoint(path, self.sim, expected_identity=self.checkpoint.identity)

    def resumed(self, state, path):
        """Take the progress of the checkpoint ``path`` loaded into the simulation (its extra
        ``state``); ValueError naming the file when it does not say where the path stood."""
        try:
            if state["phase"] != "path":
                raise ValueError
            index = check_int("stage", state["stage"], low=0, high=len(self.path) - 1)
            start = check_int("stage_start", state["stage_start"], high=self.sim.step)
            stages = {branch: list(state["stages"][branch]) for branch in self.stages}
            done = len(stages["drying"]) + len(stages["wetting"])
            self.checkpoint.period = check_int("checkpoint_every", state["checkpoint_every"],
                                               low=1)
            self.formed = check_int("formed", state["formed"], low=0)
            times = (float(state["preparation_time_s"]), float(state["path_time_s"]))
            if self.clusters is not None:
                frames = state["pore_frames"]
                self.pore_frames.load_state({"numbers": np.array(frames["numbers"], np.int64),
                                             "values": np.array(frames["values"], np.float64)})
        except (KeyError, TypeError, ValueError):
            raise ValueError(f"{path} does not belong to this run's suction path") from None
        if done != index or not all(isinstance(row, dict) for rows in stages.values()
                                    for row in rows):
            raise ValueError(f"{path}: its {done} stage rows do not match its stage = {index} "
                             "(an edited checkpoint)")
        self.index, self.stage_start, self.stages = index, start, stages
        self.preparation_time, self.path_time = times
        self._clock = time.perf_counter()

    def finish(self, progress, stop_after):
        """Run the rest of the path (raising Interrupted at ``stop_after`` steps or on Ctrl-C,
        the checkpoint kept) and write the outputs; returns the swcc.json content."""
        sim, bridges = self.sim, self.bridges
        budget = math.inf if stop_after is None else check_int("stop_after", stop_after, low=1)
        turning = len(self.path) // 2
        self._clock = time.perf_counter()
        try:
            while self.index < len(self.path):
                branch, suction = self.path[self.index]
                if self.index == turning:         # the turning point: drying's last state
                    self.stages[branch].append(dict(self.stages["drying"][-1], steps=0))
                    self.index += 1
                    continue
                if self.stage_start is None:
                    bridges.set_suction(suction)
                    if self.clusters is not None:
                        self.clusters.set_suction(sim, suction)
                    self.stage_start = sim.step
                budget -= self.run_stage(budget, f"{branch} {suction:g} Pa" if progress
                                         else None)
                if not self._ended(sim):
                    break
                self.recorder.record(sim)
                self.stages[branch].append(self.test.stage_row(
                    sim, bridges, self.homogenization, suction, self.dry_volume,
                    sim.step - self.stage_start, self.clusters))
                if self.clusters is not None:
                    self.write_pores(suction)
                self.index, self.stage_start = self.index + 1, None
        except KeyboardInterrupt:
            pass
        self.path_time += time.perf_counter() - self._clock
        if self.index < len(self.path):
            raise Interrupted(f"interrupted at step {sim.step}"
                              + (f"; continue with --resume {self.out}"
                                 if self.checkpoint is not None else ""))
        return self.write_outputs()

    def _ended(self, sim):
        """Whether the running stage is static at one of its checks (every CHECK_EVERY steps
        of the stage and at its step limit), where an uninterrupted run checks it."""
        taken = sim.step - self.stage_start
        return (taken > 0 and (taken % self.CHECK_EVERY == 0
                               or taken == self.test.config.stage_steps)
                and self._static(sim))

    def run_stage(self, budget, label):
        """Run the stage in progress until static, at most ``budget`` steps; the steps taken.
        NotStatic (SwccTest.stage_failed) at its --stage-steps limit."""
        sim, limit = self.sim, self.test.config.stage_steps
        taken = run_stage(sim, self._ended, start=self.stage_start, limit=limit,
                          every=self.CHECK_EVERY, budget=budget, progress=label,
                          status=equilibrium_status(self.test.config.sample
                                                    .equilibrium_unbalanced))
        if not self._ended(sim) and sim.step - self.stage_start >= limit:
            branch, suction = self.path[self.index]
            raise self.test.stage_failed(sim, suction, branch)
        return taken

    def write_pores(self, suction):
        """pores/pores_NNNN.vtu of the stage just ended (its index NNNN) and pores/pores.pvd
        of the stages so far (pendular.io.vtk.PoreFrames)."""
        self.pore_frames.write(self.index, self.clusters.units, self.clusters.found.label,
                               {"stage": self.index, "suction": suction})

    def write_outputs(self):
        """history.h5, swcc.json and swcc.png; returns the swcc.json content."""
        sim, config, out = self.sim, self.test.config, self.out
        write_history(os.path.join(out, "history.h5"), self.recorder.arrays(),
                      config_to_dict(config), attributes={"test": "swcc", "dt": sim.dt})
        result = {
            "config": config_to_dict(config),
            "drying": self.stages["drying"],
            "wetting": self.stages["wetting"],
            "bridges_formed_across_gaps": self.formed,
            "hysteresis": hysteresis(self.stages),
            "preparation": {k: self.preparation[k]
                            for k in ("porosity", "coordination", "steps")},
            "grading": grading(sim.particles.radius),
            "regular_packings": regular_packing_curves(config, list(config.suctions)),
            "thesis_fig_5_5": {str(int(s)): v for s, v in FIG_5_5.items()},
            "wall_time_s": self.preparation_time + self.path_time,
            "units": {**SWCC_STAGE_UNITS, "wall_time_s": "s", "grading": GRADING_UNITS},
        }
        write_json(os.path.join(out, "swcc.json"), result)
        plot_swcc(os.path.join(out, "swcc.png"), result)
        return result


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


# ---------------------------------------------------------------- the command


#: An SWCC's sample (1,000 spheres by default), own fields and material.
SWCC_SAMPLE = (option_of(PrepareConfig, "particles", default=1000, low=MIN_SAMPLE_PARTICLES),
               option_of(PrepareConfig, "confining"))

SWCC_OWN = options_named(SwccConfig, ("suctions", "contact_angle", "surface_tension",
                                       "form_gap", "stage_steps", "record_every", "liquid",
                                       "entry_suction"))

SWCC_MATERIAL = options_named(PrepareConfig, ("friction_deg", "prep_friction_deg", "seed"))


def swcc_config(values, given):
    """The SwccConfig of ``values``."""
    sample = PrepareConfig(**fields_of(values, SWCC_SAMPLE + SWCC_MATERIAL),
                           **sample_sizes(values))
    return SwccConfig(sample=sample, **fields_of(values, SWCC_OWN))


#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular swcc --particles 1000 --suctions 3000,10000,30000,100000 --out runs/swcc",
           "Sr and chi along drying then wetting at these suctions, with the hysteresis; "
           "swcc.json, swcc.png")

#: Summary keys printed at the end, tables of COLUMNS.
SHOWN = ("drying", "wetting")
#: Columns of those tables.
COLUMNS = ("suction", "saturation", "bridges", "porosity", "volumetric_strain", "chi")

#: The swcc command (pendular.procedures.registry).
COMMAND = LaboratoryCommand(
    name="swcc",
    description="soil-water characteristic curve of a sample: drying then wetting",
    test=SwccTest,
    declared=CommandOptions(SWCC_SAMPLE + SWCC_OWN + size_options() + SWCC_MATERIAL
                            + (CHECKPOINT_EVERY,), swcc_config),
    shown=SHOWN, example=EXAMPLE, out="runs/swcc", columns=COLUMNS)
