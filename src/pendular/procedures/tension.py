"""Direct tension of wet sand at fixed water content (Kim 2001; thesis §4.4.1.2, Table 4.5).

``TensionTest(TensionConfig(...)).run(out)`` returns the content of tension.json; command
``pendular tension`` (pendular.cli.commands.tension; options named as the TensionConfig fields
and those of its sample, a PrepareConfig, dashes for underscores; --specific-gravity sets the
grains' density). Variants: ``dataclasses.replace(config, cases=[(0.65, 0.01)])``, a sample
by ``tension_sample(particles=200)``; ``run(out, device="gpu")`` (--device) runs every phase
on the GPU. By default Kim's six cases: F-75 sand, R = 0.11 mm,
e = 0.72 at w = 0.47, 1.04, 2.11 % and e = 0.58 at w = 0.43, 1.04, 2.01 % (gravimetric,
Gs = 2.65, the grains' density over the water's). Each case:

1. Sample (one per void ratio, shared by its water contents): equal spheres prepared as thesis
   Ch. 5.2.2 (pendular.procedures.preparation, radius growth to 5 kPa, friction set, walls servoed at
   --confining). The void ratio is that of the core, the box less one diameter along every wall
   (the layers along flat walls are looser: with 2,000 spheres the whole box's e is about 0.09
   higher; Kim's samples are thousands of grains across). It is reached by tuning the friction
   during the radius growth (0 deg gives the densest packing, about e = 0.57), by regula falsi
   within --void-ratio-tolerance.
2. Wetting at constant water content: volume-controlled bridges (CapillaryBridges,
   control="volume") form at every contact with the volume of the suction-controlled bridge at
   their formation suction, found so that the bridges hold V_w = w Gs V_s. The grains are rough:
   the menisci of touching grains are --roughness R apart (default Kim's H/R = 0.09, the
   separation of thesis Ch. 4's prediction; 0 for smooth spheres). The suction is found by
   pendular.capillary.formation_suction; contacts made while the sample settles under the bridges
   get bridges too, so the suction is corrected until w is within 1 %. Walls servoed at
   --confining until static.
3. Pull: the particles within --grip-depth diameters of each z wall (surface to wall) move
   rigidly with it (pendular.dem.grips.Grip), the two z walls move apart at a constant strain rate
   (from --inertial-number I = rate d sqrt(rho / confining)), the lateral walls stay where they
   are. The tensile stress is the mean force of the specimen on the two grips over the
   cross-section, positive in tension (the compression-positive axial stress's opposite);
   the tensile strength is its peak. The pull stops when the stress has fallen below
   --residual of the peak for 1 % more extension, or at --max-strain (the samples stretch
   nearly uniformly between the held lateral walls and soften slowly: docs/direct_tension.md).

Outputs in --out: tension.json (per case: void ratios, water content, saturation, bridges,
formation suction, tensile strength, Kim's measurement, pendular.homogenize.packing_state's prediction
psi_xx (isotropic BCC for e >= 0.65, FCP below, H/R = 0.09, as docs/chapter4.md) and relative
differences), report.md (the table), plots/ (tensile stress against axial extension per case,
strength against w beside Kim and the prediction), and per case cases/<case>/history.h5
(group ``history``: step, time, axial_strain (compression positive, so negative here),
tensile_stress [Pa], grip_pull (2) [N] (z-, z+ grips), sigma_wall (3) [Pa], coordination,
bridges, water_content, saturation, unbalanced_force) and the ParaView series
``cases/<case>/vtk/*.pvd`` (every --vtk-every steps, or --vtk-frames frames per pull); with
``run(out, checkpoint_every=N)`` checkpoint.h5 (TensionRun), from which
``TensionTest.resume(out)`` continues an interrupted run bit for bit.
"""

from __future__ import annotations

import json
import math
import os
import time
from dataclasses import replace

import h5py
import numpy as np
from scipy.spatial import cKDTree

from pendular.capillary import (BridgeTable, CapillaryBridges, gravimetric_water_content,
    sample_radius_ratios)
from pendular.utils.atomic import write_json, write_text
from pendular.dem.grading import grading
from pendular.dem.measure import coordination, unbalanced_force
from pendular.procedures.preparation import (PrepareConfig, equilibrated, prepare_sample,
    servo_speed)
from pendular.dem.record import HistoryRecorder
from pendular.dem.simulation import Simulation, check_device
from pendular.dem.grips import Grip
from pendular.procedures.grips import core_void_ratio, grip_members, grip_reach, tensile_stress
from pendular.dem.walls import ConstantStrainRate, StressServo
from pendular.homogenize import packing_state, regular_packing

from pendular.dem.checkpoint import CheckpointWriter, checkpoint_extra_state, load_checkpoint
from pendular.procedures.config import (TensionConfig, case_name, config_from_dict,
    config_to_dict, inertial_number)
from pendular.procedures.loading import measured
from pendular.procedures.progress import equilibrium_bar, tension_plan
from pendular.utils.progress import whole_run
from pendular.homogenize.on_the_fly import homogenized
from pendular.io.history import write_history
from pendular.io.outputs import OutputFolder
from pendular.io.plots import pyplot, save_figure
from pendular.procedures.reference import (CHAPTER4_SURFACE_TENSION, KIM_2001, KIM_SEPARATION,
    comparison_packing)
from pendular.procedures.triaxial import Interrupted, frame_period, frames_writer
from pendular.io.schema import TENSION_SUMMARY_UNITS
from pendular.utils.integrity import config_hash
from pendular.utils.validate import check_int
from pendular.procedures.water_content import wet_to_water_volume

#: Surface tension [N/m] of the Chapter 4 comparison (docs/physics.md 'Errata').
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
#: Files and folders a tension run owns in its output folder.
OUTPUTS = ("tension.json", "report.md", "plots", "cases", "checkpoint.h5")


def cases_of(void_ratios: list[float] | None = None,
             water_contents: list[float] | None = None) -> list[tuple[float, float]]:
    """[(void ratio, water content as a fraction)]: Kim's six cases by default; ``void_ratios``
    and ``water_contents`` [%] (lists) otherwise, every water content at every void ratio
    (Kim's water contents at his void ratios when none are given, else 0.5, 1, 2 %).
    TensionConfig checks them."""
    if void_ratios is None and water_contents is None:
        return [(e, w) for e, w, _ in KIM_2001]
    if void_ratios is None:
        void_ratios = sorted({e for e, _, _ in KIM_2001}, reverse=True)
    result = []
    for e in void_ratios:
        if water_contents is not None:
            waters = water_contents
        else:
            kim = [w * 100.0 for ke, w, _ in KIM_2001 if ke == e]
            waters = kim or [0.5, 1.0, 2.0]
        result += [(e, w / 100.0) for w in waters]
    return result


def prepare_config(config: TensionConfig, prep_friction: float) -> PrepareConfig:
    """The sample's preparation (thesis Ch. 5.2.2) with growth friction ``prep_friction`` [deg]."""
    return replace(config.sample, prep_friction_deg=prep_friction)


def sample_void_ratio(sim: Simulation, radius: float) -> float:
    """Void ratio of the core: the box less one diameter along each wall (a periodic cell,
    which has no wall layers: the whole cell)."""
    if sim.walls.periodic:
        voids = sim.walls.volume() - sim.particles.solid_volume()
        return voids / sim.particles.solid_volume()
    return core_void_ratio(sim.particles, sim.walls, 2.0 * radius, radius / 8.0)


def prepare_void_ratio(config: TensionConfig, target: float, progress: bool,
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


def wet(dry: Simulation, config: TensionConfig, water_content: float,
        progress: bool) -> tuple[Simulation, CapillaryBridges, dict]:
    """(wetted sim, bridges, wetting report): volume-controlled bridges at every contact of a
    copy of ``dry`` (and across every gap up to config.form_gap radii) holding water content
    ``water_content`` (fraction) once static, the formation suction corrected for the contacts
    the bridges add (the wetting law itself, formation suction at a water volume, is
    pendular.capillary.formation_suction)."""
    particles = dry.particles
    target = water_content * config.specific_gravity * particles.solid_volume()
    max_gap = config.form_gap * config.sample.radius
    pair_i, pair_j, gap = wetted_pairs(dry, max_gap)
    table = BridgeTable.cached(config.contact_angle,
                               radius_ratios=sample_radius_ratios(particles.radius))

    def build(suction):
        return CapillaryBridges(suction, config.surface_tension, config.contact_angle,
                                control="volume", roughness=config.roughness)

    def settle(sim):
        return sim.run(WET_STEPS, until=equilibrated(config.sample), check_every=CHECK_EVERY,
                       progress=equilibrium_bar("wet" if progress else None,
                                                config.sample.equilibrium_unbalanced,
                                                config.sample.stress_tolerance))

    sim, bridges, tries = wet_to_water_volume(
        dry, target, table, (particles.radius[pair_i], particles.radius[pair_j], gap), build,
        settle, surface_tension=config.surface_tension, roughness=config.roughness,
        max_gap=max_gap)
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
    grips; the tensile stress is minus the cell's z stress."""

    def __init__(self, sim: Simulation, bridges: CapillaryBridges | None,
                 config: TensionConfig, folder: str, progress: bool):
        self.sim, self.bridges, self.config, self.progress = sim, bridges, config, progress
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
        self.start = sim.step
        self.recorder = HistoryRecorder(period, columns, origin=sim.step, reads=("walls",))
        self.recorder.record(sim)
        sim.writers.append(self.recorder)
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

        sim, period = self.sim, self.recorder.period
        label = label if self.progress else None
        taken = 0
        while not self._ended(sim):
            if taken >= budget:
                return False
            done = sim.step - self.start
            steps = int(min(self.steps - done, budget - taken))
            offset = done % period
            if offset:
                taken += sim.run(min(period - offset, steps), progress=label, status=status)
                continue
            taken += sim.run(steps, until=self._ended, check_every=period, progress=label,
                             status=status)
        if self.vtk is not None:
            self.vtk.close(sim)
        return True

    def run(self, label: str | None) -> tuple[int, dict]:
        """Pull to rupture; (steps, history)."""
        self.advance(label)
        return self.sim.step - self.start, self.recorder.arrays()


def prediction(config: TensionConfig, void_ratio: float,
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


def run_case(dry: Simulation, preparation: dict, config: TensionConfig, void_ratio: float,
             water_content: float, out: str, progress: bool,
             arguments: dict | None = None, run: TensionRun | None = None) -> tuple[dict, dict]:
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
    attributes = dict(arguments if arguments is not None else config.options())
    attributes.update({key: value for key, value in summary.items()
                       if isinstance(value, (int, float, str))})
    write_history(os.path.join(folder, "history.h5"), history, config_to_dict(config),
                  attributes=attributes)
    summary["units"] = {key: unit for key, unit in TENSION_SUMMARY_UNITS.items()
                        if key in summary}
    return summary, history


def plot_label(config: TensionConfig) -> str:
    """One line of the run's parameters for the figures' titles."""
    sample = config.sample
    return (f"N = {sample.particles}, R = {sample.radius * 1e3:g} mm, contact angle "
            f"θ = {config.contact_angle:g}°, γ = {config.surface_tension:g} N/m")


def case_label(summary: dict) -> str:
    """A case in words: its target void ratio and water content."""
    return (f"e = {summary['void_ratio_target']:g}, "
            f"w = {100 * summary['water_content_target']:g} %")


def plot_curves(summaries: list[dict], histories: dict, folder: str,
                config: TensionConfig) -> None:
    """Tensile stress against axial extension, one figure per case (tension_<case>.png) and
    one with all (tension_all.png)."""
    plt = pyplot()
    every, all_axes = plt.subplots(figsize=(6, 4))
    for summary in summaries:
        history = histories[summary["case"]]
        figure, axes = plt.subplots(figsize=(6, 4))
        for target in (axes, all_axes):
            target.plot(-100.0 * history["axial_strain"], history["tensile_stress"],
                        label=case_label(summary))
        axes.set(xlabel="axial extension [%]", ylabel="tensile stress [Pa]",
                 title=f"Direct tension, {case_label(summary)}\n{plot_label(config)}")
        axes.title.set_fontsize(9)
        axes.grid(alpha=0.3)
        save_figure(figure, os.path.join(folder, f"tension_{summary['case']}.png"))
    all_axes.set(xlabel="axial extension [%]", ylabel="tensile stress [Pa]",
                 title=f"Direct tension, every case\n{plot_label(config)}")
    all_axes.title.set_fontsize(9)
    all_axes.grid(alpha=0.3)
    all_axes.legend(fontsize=7)
    save_figure(every, os.path.join(folder, "tension_all.png"))


def plot_strength(summaries: list[dict], config: TensionConfig, path: str) -> None:
    """Tensile strength against water content: DEM, Kim (2001) and the prediction of the
    regular packing of the same void ratio (pendular.homogenize.packing_state, thesis Ch. 4)."""
    figure, axes = pyplot().subplots(figsize=(6, 4.5))
    void_ratios = sorted({s["void_ratio_target"] for s in summaries}, reverse=True)
    for colour, e in zip(("C0", "C3", "C2", "C1"), void_ratios):
        mine = [s for s in summaries if s["void_ratio_target"] == e]
        waters = [100 * s["water_content"] for s in mine]
        axes.plot(waters, [s["tensile_strength_pa"] for s in mine], "o-", color=colour,
                  label=f"DEM, e = {mine[0]['void_ratio']:.3f}")
        kim = [(100 * w, t) for ke, w, t in KIM_2001 if math.isclose(ke, e)]
        if kim:
            axes.plot(*zip(*kim), "s", mfc="none", color=colour, label=f"Kim (2001), e = {e}")
        grid = np.linspace(0.002, max(s["water_content_target"] for s in mine) * 1.15, 25)
        curve = [prediction(config, e, w)[0] for w in grid]
        axes.plot(100 * grid, curve, "--", color=colour,
                  label=f"regular packing prediction (Ch. 4), {comparison_packing(e)[1]}")
    axes.set(xlabel="gravimetric water content w [%]", ylabel="tensile strength [Pa]",
             xlim=(0, None), ylim=(0, None),
             title=f"Tensile strength against water content\n{plot_label(config)}")
    axes.title.set_fontsize(9)
    axes.grid(alpha=0.3)
    axes.legend(fontsize=7)
    save_figure(figure, path)


def case_line(summary: dict) -> str:
    """The progress line of a finished case (``run_case``'s summary): its strength beside
    Kim's measurement, when he made one, and the regular packing's prediction."""
    kim = summary["kim_measured_pa"]
    measured = "no Kim measurement" if kim is None else f"Kim {kim:.1f} Pa"
    return (f"  {summary['case']}: tensile strength {summary['tensile_strength_pa']:.1f} Pa "
            f"({measured}, regular packing prediction {summary['packing_state_pa']:.1f} Pa)")


def _percent(value):
    return "" if value is None else f"{100 * value:+.0f} %"


def report_lines(summaries: list[dict], config: TensionConfig) -> list[str]:
    """The lines of report.md: one table row per case."""
    sample = config.sample
    lines = [f"# Direct tension, {sample.particles} spheres, R = {sample.radius * 1e3:g} mm, "
             f"contact angle θ = {config.contact_angle:g}°, surface tension "
             f"γ = {config.surface_tension:g} N/m, bridge roughness H/R = {config.roughness:g}",
             "",
             "Tensile strength [Pa] positive in tension. e: core void ratio (box less one "
             "diameter along each wall); w: gravimetric water content (water mass over grain "
             f"mass, Gs = {config.specific_gravity:g}); Sr: degree of saturation; prediction: "
             "tensile strength psi_xx of the regular packing compared with this void ratio at "
             f"the target w (thesis Ch. 4, exact bridges, H/R = {KIM_SEPARATION:g}).",
             "",
             "| e target | e reached (box) | w target [%] | w [%] | Sr | bridges | s_form [Pa] "
             "| DEM | Kim | prediction | DEM/Kim | DEM/prediction |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for s in summaries:
        kim = "" if s["kim_measured_pa"] is None else f"{s['kim_measured_pa']:.1f}"
        lines.append(
            f"| {s['void_ratio_target']:.2f} | {s['void_ratio']:.3f} ({s['void_ratio_box']:.3f}) "
            f"| {100 * s['water_content_target']:.2f} | {100 * s['water_content']:.3f} "
            f"| {s['saturation']:.3f} | {s['bridges']} | {s['formation_suction_pa']:.0f} "
            f"| {s['tensile_strength_pa']:.1f} | {kim} | {s['packing_state_pa']:.1f} "
            f"| {_percent(s['relative_difference_to_kim'])} "
            f"| {_percent(s['relative_difference_to_packing_state'])} |")
    return lines


def write_report(summaries: list[dict], config: TensionConfig, path: str) -> list[str]:
    """report.md at ``path``; returns its lines."""
    lines = report_lines(summaries, config)
    write_text(path, "\n".join(lines) + "\n")
    return lines


class TensionTest:
    """The direct-tension cases of ``config`` (TensionConfig): one sample per void ratio, each
    water content wetted and pulled from a copy of it (module docstring)."""

    def __init__(self, config: TensionConfig) -> None:
        if not isinstance(config, TensionConfig):
            raise TypeError(f"config must be a TensionConfig, got {type(config).__name__}")
        self.config = config

    def run(self, out: str, *, progress: bool = True, arguments: dict | None = None,
            device: str = "cpu", checkpoint_every: int = 0, stop_after: int | None = None
            ) -> dict:
        """Every case into ``out``; writes tension.json, report.md, plots/ and cases/; returns
        the tension.json content. ``arguments``: what tension.json records under 'arguments'
        and the histories as attributes (the command: its options; default: the
        configuration's, TensionConfig.options); the configuration itself is under 'config'.
        ``device``: where the preparations, wettings and pulls run, "cpu" or "gpu"
        (``check_device``, before anything is made); a run option, not part of the
        configuration. ``checkpoint_every``: steps between checkpoints ``out``/checkpoint.h5
        of the pulls (0: none), from which ``resume`` continues; ``stop_after``: stop after
        this many steps of the pulls as an interruption would (raises Interrupted)."""
        check_device(device)
        checkpoint_every = check_int("checkpoint_every", checkpoint_every, low=0)
        arguments = self.config.options() if arguments is None else dict(arguments)
        with OutputFolder(out, "tension") as folder:
            for name in OUTPUTS:
                folder.claim(name)
            run = TensionRun(out, self.config, arguments, checkpoint_every, stop_after)
            with whole_run(tension_plan(self.config), enabled=progress):
                return self._run(out, progress, device, run)

    @classmethod
    def resume(cls, out: str, *, progress: bool = True, stop_after: int | None = None,
               device: str = "cpu") -> dict:
        """Continue the interrupted run of folder ``out`` from its checkpoint.h5, with the
        configuration and arguments stored there: the cases finished are kept, the sample
        of the case being pulled is prepared and wetted again (the engine is deterministic:
        the same state), and its pull goes on from the checkpoint; returns the tension.json
        content, bit for bit that of an uninterrupted run (timings aside)."""
        path = os.path.join(out, "checkpoint.h5")
        if not os.path.exists(path):
            raise ValueError(f"resume = {out!r}: {path} is missing: the run stopped before "
                             "its first checkpoint, or was started with --checkpoint-every 0, "
                             "which writes none; run it again")
        with OutputFolder(out, "tension --resume", keep=True) as folder:
            for name in OUTPUTS:
                folder.claim(name)
            state = checkpoint_extra_state(path)
            config = config_from_dict(state.get("config") if isinstance(state, dict)
                                      else None, path)
            if not isinstance(config, TensionConfig):
                raise ValueError(f"resume = {out!r} holds a run of another test "
                                 f"({type(config).__name__}), not of pendular tension")
            check_device(device)
            run = TensionRun(out, config, state.get("arguments"), 1, stop_after, state)
            return cls(config)._run(out, progress, device, run)

    def _run(self, out, progress, device, run):
        config, arguments = self.config, run.arguments
        started = time.perf_counter()
        summaries, histories, samples = run.summaries, {}, run.samples
        index = 0
        for void_ratio in dict.fromkeys(e for e, _ in config.cases):
            waters = [w for e, w in config.cases if e == void_ratio]
            if index + len(waters) <= len(summaries):          # finished before a resume
                for summary in summaries[index:index + len(waters)]:
                    histories[summary["case"]] = case_history(out, summary["case"])
                index += len(waters)
                continue
            if progress:
                print(f"sample e = {void_ratio}: tuning the growth friction", flush=True)
            dry, preparation = prepare_void_ratio(config, void_ratio, progress, device)
            samples[str(void_ratio)] = preparation
            for water_content in waters:
                if index < len(summaries):
                    name = summaries[index]["case"]
                    histories[name] = case_history(out, name)
                    index += 1
                    continue
                summary, history = run_case(dry, preparation, config, void_ratio,
                                            water_content, out, progress, arguments, run)
                summaries.append(summary)
                histories[summary["case"]] = history
                index += 1
                if progress:
                    print(case_line(summary), flush=True)
        output = {"arguments": arguments,
                  "cases_requested": [list(case) for case in config.cases],
                  "config": config_to_dict(config),
                  "samples": {e: {k: v for k, v in r.items() if k != "sigma_wall"}
                              for e, r in samples.items()},
                  "cases": summaries,
                  "wall_time_s": run.earlier_time + time.perf_counter() - started}
        write_json(os.path.join(out, "tension.json"), output, default=float)
        plot_curves(summaries, histories, os.path.join(out, "plots"), config)
        plot_strength(summaries, config, os.path.join(out, "plots", "strength_vs_water.png"))
        write_report(summaries, config, os.path.join(out, "report.md"))
        return output


def case_history(out: str, name: str) -> dict:
    """The history of the finished case ``name`` of run folder ``out`` (its history.h5), as
    Pull.run returns it: {column: array}."""
    with h5py.File(os.path.join(out, "cases", name, "history.h5"), "r") as handle:
        return {key: value[()] for key, value in handle["history"].items()
                if isinstance(value, h5py.Dataset)}


def _as_written(data):
    """``data`` as tension.json holds it (NumPy numbers as JSON numbers, write_json's
    default=float): what a checkpoint keeps of the cases finished."""
    return json.loads(json.dumps(data, default=float))


class TensionRun:
    """The checkpoints and interruptions of a TensionTest run into ``out``: with
    ``checkpoint_every`` > 0 a checkpoint (pendular.dem.checkpoint) every that many steps of a
    pull holding where the run stands (the case pulled, the step its pull started at, the
    cases finished, their samples, the configuration and ``arguments``); ``stop_after``: the
    steps of the pulls after which the run stops as an interruption would; ``state``: the
    extra state of the checkpoint a resumed run continues from."""

    def __init__(self, out, config, arguments, checkpoint_every, stop_after, state=None):
        self.out, self.config = out, config
        self.path = os.path.join(out, "checkpoint.h5")
        self.every = checkpoint_every
        self.budget = math.inf if stop_after is None else check_int("stop_after", stop_after,
                                                                     low=1)
        self.identity = {"config_hash": config_hash(config_to_dict(config)),
                         "seed": config.sample.seed}
        self.state, self.summaries, self.samples = state, [], {}
        self.arguments, self.earlier_time = arguments, 0.0
        self._pull, self._clock = None, time.perf_counter()
        if state is not None:
            try:
                if state["phase"] != "pull" or not isinstance(state["arguments"], dict):
                    raise ValueError
                self.every = check_int("checkpoint_every", state["checkpoint_every"], low=1)
                self.summaries = list(state["summaries"])
                self.samples = dict(state["samples"])
                self.earlier_time = float(state["wall_time_s"])
                check_int("case", state["case"], low=0, high=len(config.cases) - 1)
                check_int("pull_start", state["pull_start"], low=0)
                float(state["pull_time_s"])
            except (KeyError, TypeError, ValueError):
                raise ValueError(f"{self.path} does not belong to this run's pulls") from None
            if (state["case"] != len(self.summaries)
                    or not all(isinstance(s, dict) for s in self.summaries)):
                raise ValueError(f"{self.path}: its {len(self.summaries)} finished cases do not "
                                 f"match its case = {state['case']} (an edited checkpoint)")

    def extra_state(self, sim):
        """What a resumed run needs besides the simulation (CheckpointWriter extra_state)."""
        return {"phase": "pull", "config": config_to_dict(self.config),
                "arguments": _as_written(self.arguments), "checkpoint_every": self.every,
                "summaries": _as_written(self.summaries), "samples": _as_written(self.samples),
                "case": len(self.summaries), "pull_start": self._pull.start,
                "pull_time_s": self._pull_time + time.perf_counter() - self._pull_clock,
                "wall_time_s": self.earlier_time + time.perf_counter() - self._clock}

    def pull(self, pull, label):
        """Run ``pull`` (Pull) to its end under the run's checkpoints, from the checkpoint
        when the run resumes; Interrupted (the checkpoint kept) at ``stop_after`` steps or
        on Ctrl-C. Returns the seconds its earlier (interrupted) runs spent pulling."""
        sim = pull.sim
        self._pull, self._pull_time, self._pull_clock = pull, 0.0, time.perf_counter()
        writer = None
        if self.every > 0:
            writer = CheckpointWriter(self.path, self.every, self.extra_state, self.identity)
            sim.writers.append(writer)
        if self.state is not None:               # the case the checkpoint was written in
            state, self.state = self.state, None
            if state["pull_start"] != pull.start:
                raise ValueError(f"{self.path}: pull_start = {state['pull_start']} is not the "
                                 f"step {pull.start} its case's pull starts at (an edited "
                                 "checkpoint)")
            load_checkpoint(self.path, sim, expected_identity=self.identity)
            self._pull_time = float(state["pull_time_s"])
        before = sim.step
        try:
            ended = pull.advance(label, self.budget)
        except KeyboardInterrupt:
            ended = False
        self.budget -= sim.step - before
        if not ended:
            raise Interrupted(f"interrupted at step {sim.step}"
                              + (f"; continue with --resume {self.out}"
                                 if writer is not None else ""))
        return self._pull_time
