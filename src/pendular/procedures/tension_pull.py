"""One case of a direct tension (pendular.procedures.tension): its sample at a core void ratio,
its wetting to a water content, its pull.

``prepare_void_ratio``: the sample whose core void ratio is within tolerance of a target
(regula falsi on the growth friction); ``wet``: volume-controlled bridges holding a
gravimetric water content once static (pendular.procedures.water_content); ``Pull``: grips at
the z walls pulled apart at the inertial number's rate (or a periodic cell stretched along z)
until rupture; ``run_case``: the three, with the case's summary against Kim's (2001)
measurement and the regular packing's prediction (``prediction``). ``config`` is the run's
pendular.procedures.tension.TensionConfig. Stresses tension positive here [Pa].
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import replace

import numpy as np
from scipy.spatial import cKDTree

from pendular.capillary.bridges import CapillaryBridges
from pendular.capillary.liquid_clusters import LiquidClusters
from pendular.capillary.radius_ratios import sample_radius_ratios
from pendular.capillary.table import BridgeTable
from pendular.capillary.validation import NotPendular
from pendular.capillary.wetting import gravimetric_water_content
from pendular.dem.grading import grading
from pendular.dem.grips import Grip
from pendular.dem.measure import coordination, unbalanced_force
from pendular.dem.record import HistoryRecorder
from pendular.dem.simulation import Simulation
from pendular.dem.walls import ConstantStrainRate, StressServo
from pendular.homogenize.on_the_fly import homogenized
from pendular.homogenize.packing_state import packing_state
from pendular.homogenize.regular_packing import regular_packing
from pendular.io.history import write_history
from pendular.io.schema import TENSION_SUMMARY_UNITS
from pendular.procedures.columns import measured
from pendular.procedures.config import config_to_dict, inertial_number
from pendular.procedures.equilibrium import frame_period, frames_writer
from pendular.procedures.grips import core_void_ratio, grip_members, grip_reach, tensile_stress
from pendular.procedures.loading import run_stage
from pendular.procedures.preparation import PrepareConfig, equilibrated, prepare_sample, servo_speed
from pendular.procedures.progress import equilibrium_bar
from pendular.procedures.reference import (CHAPTER4_SURFACE_TENSION, KIM_2001, KIM_RADIUS,
    KIM_SEPARATION, comparison_packing)
from pendular.procedures.tension_clusters import (ClosedLiquidUpdates, cluster_columns,
    cluster_summary, update_period, wet_clusters)
from pendular.procedures.water_content import wet_to_water_volume
from pendular.utils.parameters import ParameterError


#: Surface tension [N/m] of the Chapter 4 comparison (docs/physics.md 'Errata').

def case_name(void_ratio, water_content):
    """Folder name of a tension case (void ratio [-], water content [-, a fraction]), e.g.
    'e0.72_w1.04'."""
    return f"e{void_ratio:.2f}_w{100 * water_content:.2f}"


SURFACE_TENSION = CHAPTER4_SURFACE_TENSION


#: Preparation friction range searched for the void ratio [deg].
PREP_FRICTION_RANGE = (0.0, 30.0)

#: Largest number of preparations tried per void ratio.
PREPARATIONS = 7


#: Steps allowed to reach equilibrium after wetting; steps between convergence checks.
WET_STEPS = 200000


CHECK_EVERY = 200


#: Extension past the peak over which the stress must stay below the residual to stop [-].
POST_PEAK_STRAIN = 0.01


#: History rows over --max-strain.
RECORDS = 400


def prepare_config(config, prep_friction: float) -> PrepareConfig:
    """The sample's preparation (thesis Ch. 5.2.2) with growth friction ``prep_friction`` [deg]."""
    return replace(config.sample, prep_friction_deg=prep_friction)


def sample_void_ratio(sim: Simulation, radius: float) -> float:
    """Void ratio of the core: the box less one diameter along each wall (a periodic cell,
    which has no wall layers: the whole cell)."""
    if sim.walls.periodic:
        voids = sim.walls.volume() - sim.particles.solid_volume()
        return voids / sim.particles.solid_volume()
    return core_void_ratio(sim.particles, sim.walls, 2.0 * radius, radius / 8.0)


def prepare_void_ratio(config, target: float, progress: bool,
                       device: str = "cpu") -> tuple[Simulation, dict]:
    """(sim, preparation report) of the sample whose core void ratio is within tolerance of
    ``target``: regula falsi on the growth friction over PREP_FRICTION_RANGE; the closest
    preparation if none is within tolerance after PREPARATIONS tries. ValueError when the
    target lies outside the void ratios of the range's two ends. The preparations run on
    ``device`` ("cpu" or "gpu"), and so do the returned simulation's runs."""
    tried = {}

    def prepared(friction):
        sim, report = prepare_sample(prepare_config(config, friction), progress=progress,
                                     device=device)
        report["void_ratio"] = sample_void_ratio(sim, config.sample.radius)
        report["box_void_ratio"] = report["porosity"] / (1.0 - report["porosity"])
        report["prep_friction_deg"] = friction
        tried[friction] = (sim, report)
        if progress:
            print(f"  prepared: growth friction {friction:.2f} deg -> core e = "
                  f"{report['void_ratio']:.4f} (box {report['box_void_ratio']:.4f})", flush=True)
        return report["void_ratio"] - target

    low, high = PREP_FRICTION_RANGE
    error_low = prepared(low)
    if error_low > config.void_ratio_tolerance:
        raise ValueError(f"--void-ratio = {target:g} is outside the valid range of this "
                         f"sample, [{target + error_low:.3f}, ...]: the densest preparation "
                         f"(growth friction {low:g} deg) gives e = {target + error_low:.3f}")
    if abs(error_low) > config.void_ratio_tolerance:
        error_high = prepared(high)
        if error_high < -config.void_ratio_tolerance:
            # the ends of the friction range need not order the void ratios (small samples)
            ends = sorted((target + error_low, target + error_high))
            raise ValueError(f"--void-ratio = {target:g} is outside the valid range of this "
                             f"sample, [{ends[0]:.3f}, {ends[1]:.3f}]: the preparations at "
                             f"growth friction {low:g} and {high:g} deg give e = "
                             f"{target + error_low:.3f} and {target + error_high:.3f}")
    def closest():
        return min(abs(report["void_ratio"] - target) for _, report in tried.values())

    while len(tried) < PREPARATIONS and closest() > config.void_ratio_tolerance:
        guess = round(low - error_low * (high - low) / (error_high - error_low), 2)
        if guess in tried:                      # secant stalled: bisect the bracket
            guess = round(0.5 * (low + high), 2)
            if guess in tried:
                break
        error = prepared(guess)
        if error < 0.0:
            low, error_low = guess, error
        else:
            high, error_high = guess, error
    sim, report = min(tried.values(), key=lambda item: abs(item[1]["void_ratio"] - target))
    report["preparations"] = {f"{f:.3f}": r["void_ratio"] for f, (_, r) in sorted(tried.items())}
    return sim, report


def sample_sizes_given(config) -> str:
    """The size options of ``config``'s sample that differ from the direct tension's defaults,
    as typed ('--radius-spread 0.5', '--psd', '--radius 0.0002'), comma separated; '' for
    Kim's equal spheres."""
    sample = config.sample
    given = []
    if sample.psd is not None:
        given.append("--psd")
    elif sample.radius_spread > 0.0:
        given.append(f"--radius-spread {sample.radius_spread:g}")
    if sample.psd is None and sample.radius != KIM_RADIUS:
        given.append(f"--radius {sample.radius:g}")
    return ", ".join(given)


def wetted_pairs(sim: Simulation, max_gap: float) -> tuple[np.ndarray, np.ndarray,
                                                             np.ndarray | None]:
    """(pair_i, pair_j, gap [m] or None) of the pairs that take liquid at wetting: the
    touching pairs of ``sim``'s contacts, and with ``max_gap`` [m] > 0 every pair whose gap is
    at most max_gap (found afresh over all spheres, gap 0 for touching ones)."""
    particles = sim.particles
    if max_gap <= 0.0:
        touching = sim.contacts.overlap > 0.0
        return sim.contacts.pair_i[touching], sim.contacts.pair_j[touching], None
    radius = particles.radius
    position, box = particles.position, None
    if sim.walls.periodic:           # pairs through the faces, nearest image
        box = sim.walls.lengths()
        position = np.mod(position, box)
    pairs = cKDTree(position, boxsize=box).query_pairs(2.0 * radius.max() + max_gap,
                                                       output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    branch = position[j] - position[i]
    if box is not None:
        branch -= box * np.round(branch / box)
    gap = np.linalg.norm(branch, axis=1) - radius[i] - radius[j]
    near = gap <= max_gap
    return i[near], j[near], np.maximum(gap[near], 0.0)


def settler(config, progress: bool):
    """settle(sim): run a wetted sample to equilibrium under its walls' servo (at most
    WET_STEPS steps); returns the steps taken."""

    def settle(sim):
        done, start = equilibrated(config.sample), sim.step
        return run_stage(sim, lambda s: s.step > start and done(s), start=start,
                         limit=WET_STEPS, every=CHECK_EVERY,
                         progress=equilibrium_bar("wet" if progress else None,
                                                  config.sample.equilibrium_unbalanced,
                                                  config.sample.stress_tolerance))
    return settle


def wet(dry: Simulation, config, water_content: float,
        progress: bool) -> tuple[Simulation, CapillaryBridges, dict]:
    """(wetted sim, bridges, wetting report): volume-controlled bridges at every contact of a
    copy of ``dry`` (and across every gap up to config.form_gap radii) holding water content
    ``water_content`` (fraction) once static, the formation suction corrected for the contacts
    the bridges add (the wetting law itself, formation suction at a water volume, is
    pendular.capillary.formation_suction). With liquid clusters
    (pendular.procedures.tension_clusters.wet_clusters) the bridges are the persisting
    suction-controlled ones, the sim's LiquidClusters beside them."""
    particles = dry.particles
    target = water_content * config.specific_gravity * particles.solid_volume()
    max_gap = config.form_gap * config.sample.radius
    pair_i, pair_j, gap = wetted_pairs(dry, max_gap)
    settle = settler(config, progress)
    if config.liquid == "clusters":
        sim, bridges, _, report = wet_clusters(dry, config, water_content,
                                               (pair_i, pair_j, gap), settle)
        report["void_ratio_wet"] = sample_void_ratio(sim, config.sample.radius)
        return sim, bridges, report
    table = BridgeTable.cached(config.contact_angle,
                               radius_ratios=sample_radius_ratios(particles.radius))

    def build(suction):
        return CapillaryBridges(suction, config.surface_tension, config.contact_angle,
                                control="volume", roughness=config.roughness)

    try:
        sim, bridges, tries = wet_to_water_volume(
            dry, target, table, (particles.radius[pair_i], particles.radius[pair_j], gap),
            build, settle, surface_tension=config.surface_tension,
            roughness=config.roughness, max_gap=max_gap)
    except NotPendular as error:
        sizes = sample_sizes_given(config)
        raise ParameterError("water_content", (
            f"water_content = {100.0 * water_content:g} % is more than this sample"
            f"{f' ({sizes})' if sizes else ''} holds in the pendular regime: its bridges form "
            f"at {error.suction:.4g} Pa, and below {error.lowest:.4g} Pa those at contact "
            f"between its smallest grains (R = {error.radius:.3g} m) pass the pendular limit "
            f"(filling angle {error.angle:.1f} deg, the menisci merge); lower --water-content"
            + (" or the size spread" if sizes else "")), "--water-content") from None
    suction = tries[-1]["formation_suction_pa"]
    attempts = [{"formation_suction_pa": t["formation_suction_pa"], "steps": t["steps"],
                 "water_content": gravimetric_water_content(
                     t["water_volume"], particles.solid_volume(), config.specific_gravity)}
                for t in tries]
    report = {"formation_suction_pa": suction, "wetting_attempts": attempts,
              "water_content": attempts[-1]["water_content"],
              "saturation": bridges.saturation(sim), "bridges": bridges.count(sim),
              "coordination_wet": coordination(sim.contacts, len(sim.particles)),
              "void_ratio_wet": sample_void_ratio(sim, config.sample.radius),
              "unbalanced_force_wet": unbalanced_force(sim.particles, sim.contacts)}
    return sim, bridges, report


class Pull:
    """The pull of a sample held by its six walls' servo: z walls apart at constant strain
    rate, grips, recorder (with the bridges' columns when ``bridges`` is given) and ParaView
    writer (a frame every ``config.vtk_every`` steps, or ``config.vtk_frames`` frames over
    --max-strain); ``run()`` pulls to rupture and returns (steps, history). In a periodic cell:
    the cell stretched along z at the strain rate, its x and y stress servoed at zero, no
    grips; the tensile stress is minus the cell's z stress. With LiquidClusters among the
    sim's forces (--liquid clusters), their columns too, and their closed liquid solved again
    CLUSTER_UPDATES times over --max-strain (tension_clusters.ClosedLiquidUpdates)."""

    def __init__(self, sim: Simulation, bridges: CapillaryBridges | None,
                 config, folder: str, progress: bool):
        self.sim, self.bridges, self.config, self.progress = sim, bridges, config, progress
        self.clusters = liquid_clusters(sim)
        sample = config.sample
        self.rate = config.inertial_number / inertial_number(1.0, sample.radius,
                                                           sim.particles.density, sample.confining)
        self.extension = ConstantStrainRate("z", -self.rate, sim.walls.lengths()[2])
        if sim.walls.periodic:
            self.grips = []
            lateral = StressServo("xy", 0.0, servo_speed(sim.walls, sim.dt))
            sim.controls = [self.extension, lateral]
        else:
            depth = grip_reach(sample.radius, config.grip_depth, sim.particles.radius)
            self.grips = [Grip(wall, grip_members(sim.particles.position, sim.particles.radius,
                                                  sim.walls, wall, depth)) for wall in (4, 5)]
            sim.controls = [self.extension, *self.grips]   # the x, y walls held where they are
            for op in self.grips:            # the grips' pull of the current (wetted) state
                op.apply(sim)
        self.steps = int(math.ceil(config.max_strain / (self.rate * sim.dt)))
        period = max(1, self.steps // RECORDS)
        # the homogenised columns measured where the state is held (loading.measured): on a
        # device a record then brings back the walls alone, with the grips' pulls
        columns = {
            "step": lambda s: s.step,
            "time": lambda s: s.time,
            "axial_strain": lambda s: self.extension.strain(s.walls),
            "tensile_stress": self.tensile_stress,
            "sigma_wall": lambda s: s.walls.stress(),
            "coordination": measured("coordination"),
            "unbalanced_force": measured("unbalanced_force"),
        }
        if self.grips:
            columns["grip_pull"] = self.pulls
        if bridges is not None:
            solid = sim.particles.solid_volume()
            water_volume = measured("water_volume")

            def saturation(s):
                return homogenized(s)["water_volume"] / (s.walls.volume() - solid)

            columns.update({
                "bridges": measured("bridges"),
                "water_content": lambda s: gravimetric_water_content(
                    water_volume(s), solid, config.specific_gravity),
                "saturation": saturation})
        if self.clusters is not None:
            columns.update(cluster_columns(self.clusters, sim.particles.solid_volume(),
                                           config.specific_gravity))
        self.start = sim.step
        self.recorder = HistoryRecorder(period, columns, origin=sim.step, reads=("walls",))
        self.recorder.record(sim)
        sim.writers.append(self.recorder)
        if self.clusters is not None:       # after the recorder: rows show the held suction
            sim.writers.append(ClosedLiquidUpdates(
                self.clusters, self.clusters.liquid.total, update_period(self.steps),
                sim.step))
        self.vtk = frames_writer(sim, folder, frame_period(config.vtk_every, config.vtk_frames,
                                                           self.steps))

    def pulls(self, sim: Simulation) -> list[float]:
        """The grips' pulls [N] (z-, z+) of ``sim``'s state."""
        sim.fetch("walls")  # on a device the pulls come back with the walls (dem.grips.Grip)
        return [grip.pull for grip in self.grips]

    def tensile_stress(self, sim: Simulation) -> float:
        """Tensile stress of the specimen [Pa], positive in tension: the grips' mean pull over
        the cross-section (pendular.procedures.grips.tensile_stress), or minus a periodic cell's
        z stress."""
        walls = sim.fetch("walls").walls   # on a device the pulls come back with the walls
        if walls.periodic:
            return -float(walls.stress()[2])
        return tensile_stress(self.grips, walls)

    def ruptured(self, sim: Simulation) -> bool:
        """The stress has stayed below the residual fraction of its positive peak for
        POST_PEAK_STRAIN of extension."""
        stress = self.recorder.rows["tensile_stress"]
        peak = int(np.argmax(stress))
        strain = self.recorder.rows["axial_strain"]
        return (stress[peak] > 0.0 and stress[-1] < self.config.residual * stress[peak]
                and strain[peak] - strain[-1] >= POST_PEAK_STRAIN)

    def _ended(self, sim: Simulation) -> bool:
        """Whether the pull has ended: at its last step, or ruptured at one of its checks
        (every recorder period of the pull, where an uninterrupted pull checks)."""
        taken = sim.step - self.start
        return taken >= self.steps or (taken > 0 and taken % self.recorder.period == 0
                                       and self.ruptured(sim))

    def advance(self, label: str | None, budget: float = math.inf) -> bool:
        """Pull on from where the pull stands (a resumed one too: its checks fall where they
        fell before) to rupture or --max-strain, at most ``budget`` steps; whether it ended."""
        def status(s):
            return {"ext": f"{-self.extension.strain(s.fetch('walls').walls):.4f}",
                    "tension": f"{self.recorder.last('tensile_stress'):.0f}Pa"}

        sim = self.sim
        run_stage(sim, self._ended, start=self.start, limit=self.steps,
                  every=self.recorder.period, budget=budget,
                  progress=label if self.progress else None, status=status)
        if not self._ended(sim):
            return False
        if self.vtk is not None:
            self.vtk.close(sim)
        return True

    def run(self, label: str | None) -> tuple[int, dict]:
        """Pull to rupture; (steps, history)."""
        self.advance(label)
        return self.sim.step - self.start, self.recorder.arrays()


def liquid_clusters(sim: Simulation):
    """The LiquidClusters among ``sim``'s forces, or None."""
    found = [op for op in sim.forces if isinstance(op, LiquidClusters)]
    return found[0] if found else None


def prediction(config, void_ratio: float,
               water_content: float) -> tuple[float, str, float]:
    """(psi_xx [Pa], label, void ratio of the packing) of pendular.homogenize.packing_state for the
    comparison packing at this water content (exact bridges, H/R = 0.09)."""
    kind, label = comparison_packing(void_ratio)
    packing = regular_packing(kind, separation=KIM_SEPARATION)
    state = packing_state(packing, radius=config.sample.radius,
                          contact_angle=config.contact_angle,
                          surface_tension=config.surface_tension, water_content=water_content,
                          specific_gravity=config.specific_gravity)
    return float(state.psi[0, 0]), label, packing.void_ratio


def kim_measured(void_ratio: float, water_content: float) -> float | None:
    """Kim's (2001) tensile strength [Pa] of this case, or None."""
    for e, w, strength in KIM_2001:
        if math.isclose(e, void_ratio) and math.isclose(w, water_content):
            return strength
    return None


def run_case(dry: Simulation, preparation: dict, config, void_ratio: float,
             water_content: float, out: str, progress: bool,
             arguments: dict | None = None, run=None) -> tuple[dict, dict]:
    """Wet, pull and summarise one case into ``out``/cases/<case>: history.h5 (and vtk/);
    returns (summary, history). ``arguments``: history file attributes (default the
    configuration's options, TensionConfig.options); ``run``: the TensionRun whose
    checkpoints and interruptions watch the pull (None: pulled to its end)."""
    name = case_name(void_ratio, water_content)
    folder = os.path.join(out, "cases", name)
    os.makedirs(folder, exist_ok=True)
    started = time.perf_counter()
    sim, bridges, wetting = wet(dry, config, water_content, progress)
    wetted = time.perf_counter()
    pull = Pull(sim, bridges, config, folder, progress)
    earlier = 0.0
    if run is None:
        pull.advance(f"pull {name}")
    else:
        earlier = run.pull(pull, f"pull {name}")
    steps, history = sim.step - pull.start, pull.recorder.arrays()
    stress = history["tensile_stress"]
    peak = int(np.argmax(stress))
    strength = float(stress[peak])
    predicted, packing_label, packing_e = prediction(config, void_ratio, water_content)
    measured = kim_measured(void_ratio, water_content)
    before_peak = history["unbalanced_force"][1:peak + 1]
    summary = {
        "case": name,
        "void_ratio_target": void_ratio,
        "void_ratio": preparation["void_ratio"],
        "void_ratio_box": preparation["box_void_ratio"],
        "void_ratio_wet": wetting["void_ratio_wet"],
        "prep_friction_deg": preparation["prep_friction_deg"],
        "water_content_target": water_content,
        **wetting,
        "grading": grading(sim.particles.radius),
        "grip_particles": [len(grip.members) for grip in pull.grips],
        "tensile_strength_pa": strength,
        "axial_extension_at_peak": float(-history["axial_strain"][peak]),
        "water_content_at_peak": float(history["water_content"][peak]),
        "bridges_at_peak": int(history["bridges"][peak]),
        "final_tensile_stress_pa": float(stress[-1]),
        "final_axial_extension": float(-history["axial_strain"][-1]),
        "ruptured": bool(stress[-1] < config.residual * strength),
        "kim_measured_pa": measured,
        "packing_state_pa": predicted,
        "packing_state_packing": f"{packing_label}, e = {packing_e:.3f}, H/R = {KIM_SEPARATION}",
        "relative_difference_to_kim": None if measured is None else strength / measured - 1.0,
        "relative_difference_to_packing_state": strength / predicted - 1.0,
        "strain_rate": pull.rate,
        "inertial_number": config.inertial_number,
        "mean_unbalanced_force_to_peak": float(np.mean(before_peak)) if len(before_peak) else None,
        "unbalanced_force_at_peak": float(history["unbalanced_force"][peak]),
        "pull_steps": steps,
        "dt": sim.dt,
        "wetting_time_s": wetted - started,
        "pull_time_s": earlier + time.perf_counter() - wetted,
    }
    if pull.clusters is not None:
        summary.update(cluster_summary(history, peak))
    attributes = dict(arguments if arguments is not None else config.options())
    attributes.update({key: value for key, value in summary.items()
                       if isinstance(value, (int, float, str))})
    write_history(os.path.join(folder, "history.h5"), history, config_to_dict(config),
                  attributes=attributes)
    summary["units"] = {key: unit for key, unit in TENSION_SUMMARY_UNITS.items()
                        if key in summary}
    return summary, history
