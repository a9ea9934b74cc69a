"""Direct tension of wet sand at fixed water content (Kim 2001; thesis §4.4.1.2, Table 4.5).

    python scenarios/direct_tension.py [--void-ratio E[,E...]] [--water-content W[,W...]]
        [--particles N] [--radius M] [--contact-angle DEG] [--surface-tension N/M]
        [--roughness H_OVER_R]
        [--confining PA] [--friction DEG] [--inertial-number I] [--max-strain X]
        [--grip-depth D] [--vtk-frames F] [--seed S] [--out DIR] [--quiet]

Without --void-ratio / --water-content it runs Kim's six cases: F-75 sand, R = 0.11 mm,
e = 0.72 at w = 0.47, 1.04, 2.11 % and e = 0.58 at w = 0.43, 1.04, 2.01 % (gravimetric,
Gs = 2.65). Each case:

1. Sample (one per void ratio, shared by its water contents): equal spheres prepared as thesis
   Ch. 5.2.2 (dem.preparation, radius growth to 5 kPa, friction set, walls servoed at
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
   dem.tension.formation_suction; contacts made while the sample settles under the bridges
   get bridges too, so the suction is corrected until w is within 1 %. Walls servoed at
   --confining until static.
3. Pull: the particles within --grip-depth diameters of each z wall (surface to wall) move
   rigidly with it (dem.tension.Grip), the two z walls move apart at a constant strain rate
   (from --inertial-number I = rate d sqrt(rho / confining)), the lateral walls stay where they
   are. The tensile stress is the mean force of the specimen on the two grips over the
   cross-section, positive in tension (the compression-positive axial stress's opposite);
   the tensile strength is its peak. The pull stops when the stress has fallen below
   --residual of the peak for 1 % more extension, or at --max-strain (the samples stretch
   nearly uniformly between the held lateral walls and soften slowly: docs/direct_tension.md).

Outputs in --out: tension.json (per case: void ratios, water content, saturation, bridges,
formation suction, tensile strength, Kim's measurement, homogenize.packing_state's prediction
psi_xx (isotropic BCC for e >= 0.65, FCP below, H/R = 0.09, as docs/chapter4.md) and relative
differences), report.md (the table), plots/ (tensile stress against axial extension per case,
strength against w beside Kim and the prediction), and per case cases/<case>/history.h5
(group ``history``: step, time, axial_strain (compression positive, so negative here),
tensile_stress [Pa], grip_pull (2) [N] (z-, z+ grips), sigma_wall (3) [Pa], coordination,
bridges, water_content, saturation, unbalanced_force) and the ParaView series
cases/<case>/vtk/*.pvd.
"""

import argparse
import copy
import math
import os
import sys
import time

import numba
import numpy as np

from capillary.coupling import CapillaryBridges, table_radius_ratios
from capillary.table import BridgeTable
from chapter4 import KIM_2001, KIM_PACKINGS, KIM_RADIUS, KIM_SEPARATION, SPECIFIC_GRAVITY
from dem.atomic import write_json, write_text
from dem.figures import pyplot, save_figure
from dem.measure import coordination, unbalanced_force
from dem.preparation import PrepareConfig, equilibrated, prepare_sample
from dem.record import HistoryRecorder, write_history
from dem.tension import (Grip, core_void_ratio, formation_suction, grip_members,
                         gravimetric_water_content, tensile_stress)
from dem.triaxial import inertial_number
from dem.validate import check_range
from dem.vtk import VtkWriter
from dem.walls import ConstantStrainRate, StressServo
from homogenize import packing_state, regular_packing

#: Surface tension [N/m] of the Chapter 4 comparison (SPEC section 7).
SURFACE_TENSION = 0.074
#: Preparation friction range searched for the void ratio [deg].
PREP_FRICTION_RANGE = (0.0, 30.0)
#: Largest number of preparations tried per void ratio.
PREPARATIONS = 7
#: Relative tolerance on the water content reached, and the most wetting attempts.
WATER_TOLERANCE = 0.01
WETTINGS = 4
#: Steps allowed to reach equilibrium after wetting; steps between convergence checks.
WET_STEPS = 200000
CHECK_EVERY = 200
#: Extension past the peak over which the stress must stay below the residual to stop [-].
POST_PEAK_STRAIN = 0.01
#: History rows over --max-strain.
RECORDS = 400


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--void-ratio", default=None,
                        help="void ratio(s) of the core, comma separated (default: Kim's 0.72, "
                             "0.58)")
    parser.add_argument("--roughness", type=float, default=KIM_SEPARATION,
                        help="meniscus separation of touching grains H/R (default Kim's sand, "
                             "as in the packing_state prediction; 0: smooth spheres)")
    parser.add_argument("--water-content", default=None,
                        help="gravimetric water content(s) [%%], comma separated (default: Kim's "
                             "for his void ratios, else 0.5,1,2)")
    parser.add_argument("--particles", type=int, default=2000, help="number of spheres")
    parser.add_argument("--radius", type=float, default=KIM_RADIUS, help="sphere radius [m]")
    parser.add_argument("--contact-angle", type=float, default=0.0, help="wetting angle [deg]")
    parser.add_argument("--surface-tension", type=float, default=SURFACE_TENSION,
                        help="surface tension [N/m]")
    parser.add_argument("--specific-gravity", type=float, default=SPECIFIC_GRAVITY,
                        help="specific gravity Gs of the grains")
    parser.add_argument("--confining", type=float, default=100.0,
                        help="isotropic stress of preparation and wetting [Pa]")
    parser.add_argument("--friction", type=float, default=18.0,
                        help="contact friction during wetting and pull [deg]")
    parser.add_argument("--young", type=float, default=1e6, help="YADE young E [Pa], kn = E R")
    parser.add_argument("--inertial-number", type=float, default=1e-3,
                        help="I = strain rate x d x sqrt(rho / confining) of the pull")
    parser.add_argument("--max-strain", type=float, default=0.1,
                        help="largest axial extension of the pull")
    parser.add_argument("--residual", type=float, default=0.2,
                        help="fraction of the peak below which the pull has ruptured")
    parser.add_argument("--grip-depth", type=float, default=1.0,
                        help="grip thickness: particles whose surface is within this many "
                             "diameters of a z wall")
    parser.add_argument("--void-ratio-tolerance", type=float, default=0.01,
                        help="largest |e - target| accepted from the preparation")
    parser.add_argument("--vtk-frames", type=int, default=20,
                        help="ParaView frames per pull (0: none)")
    parser.add_argument("--seed", type=int, default=0, help="random seed of the samples")
    parser.add_argument("--out", default="runs/direct_tension", help="output folder")
    parser.add_argument("--threads", type=int, default=1, help="Numba threads")
    parser.add_argument("--quiet", action="store_true", help="no progress bars")
    args = parser.parse_args(argv)
    try:
        args.cases = cases(args)
        check_settings(args)
    except ValueError as error:
        parser.error(str(error))
    numba.set_num_threads(args.threads)
    return args


def _numbers(name, text):
    """Floats of a comma-separated option; ValueError naming it."""
    try:
        return [float(item) for item in text.split(",")]
    except ValueError:
        raise ValueError(f"{name} = {text!r} is not a comma-separated list of numbers") from None


def cases(args):
    """[(void ratio, water content as a fraction)] of the arguments, Kim's by default."""
    if args.void_ratio is None and args.water_content is None:
        return [(e, w) for e, w, _ in KIM_2001]
    void_ratios = (sorted({e for e, _, _ in KIM_2001}, reverse=True) if args.void_ratio is None
                   else _numbers("--void-ratio", args.void_ratio))
    for e in void_ratios:
        # denser than random close packing or looser than the loosest growth: never reachable
        check_range("--void-ratio", e, 0.5, 1.2)
    result = []
    for e in void_ratios:
        if args.water_content is not None:
            waters = _numbers("--water-content", args.water_content)
        else:
            kim = [w * 100.0 for ke, w, _ in KIM_2001 if ke == e]
            waters = kim or [0.5, 1.0, 2.0]
        result += [(e, w / 100.0) for w in waters]
    return result


def check_settings(args):
    """Every input against its valid range (ValueError naming it); water contents against the
    pendular limit of the comparison packing."""
    check_range("--particles", args.particles, 100, 1e6)
    check_range("--radius", args.radius, 1e-6, 1e-2, unit="m")
    check_range("--contact-angle", args.contact_angle, 0.0, 90.0, high_inclusive=False,
                unit="deg")
    check_range("--surface-tension", args.surface_tension, 0.0, 1.0, low_inclusive=False,
                unit="N/m")
    check_range("--specific-gravity", args.specific_gravity, 1.0, 10.0)
    check_range("--roughness", args.roughness, 0.0, 0.5)
    check_range("--confining", args.confining, 1.0, 1e5, unit="Pa")
    check_range("--friction", args.friction, 0.0, 90.0, high_inclusive=False, unit="deg")
    check_range("--young", args.young, 0.0, 1e12, low_inclusive=False, unit="Pa")
    check_range("--inertial-number", args.inertial_number, 0.0, 0.01, low_inclusive=False)
    check_range("--max-strain", args.max_strain, 0.0, 0.5, low_inclusive=False)
    check_range("--residual", args.residual, 0.0, 1.0, low_inclusive=False,
                high_inclusive=False)
    check_range("--grip-depth", args.grip_depth, 0.0, 3.0)
    check_range("--void-ratio-tolerance", args.void_ratio_tolerance, 0.001, 0.1)
    check_range("--vtk-frames", args.vtk_frames, 0, 1000)
    check_range("--threads", args.threads, 1, numba.config.NUMBA_NUM_THREADS)
    for e, w in args.cases:
        kind, label = comparison_packing(e)
        limit = packing_state(regular_packing(kind, separation=KIM_SEPARATION),
                              radius=args.radius, contact_angle=args.contact_angle,
                              surface_tension=args.surface_tension,
                              filling_angle=regular_packing(kind).max_filling_angle,
                              specific_gravity=args.specific_gravity).water_content
        if not 0.0 < w <= limit:
            raise ValueError(f"--water-content = {100.0 * w:g} % is outside the valid range "
                             f"(0, {100.0 * limit:.3g}] %: the pendular regime ends at the "
                             f"pendular limit of the {label} packing")


def comparison_packing(void_ratio):
    """(kind, label) of the regular packing a sample is compared with (docs/chapter4.md)."""
    return KIM_PACKINGS[0.72] if void_ratio >= 0.65 else KIM_PACKINGS[0.58]


def prepare_config(args, prep_friction):
    return PrepareConfig(particles=args.particles, radius=args.radius, young=args.young,
                         friction_deg=args.friction, prep_friction_deg=prep_friction,
                         confining=args.confining, seed=args.seed)


def sample_void_ratio(sim, radius):
    """Void ratio of the core: the box less one diameter along each wall."""
    return core_void_ratio(sim.particles, sim.walls, 2.0 * radius, radius / 8.0)


def prepare_void_ratio(args, target, progress):
    """(sim, preparation report) of the sample whose core void ratio is within tolerance of
    ``target``: regula falsi on the growth friction over PREP_FRICTION_RANGE; the closest
    preparation if none is within tolerance after PREPARATIONS tries. ValueError when the
    target lies outside the void ratios of the range's two ends."""
    tried = {}

    def prepared(friction):
        sim, report = prepare_sample(prepare_config(args, friction), progress=False)
        report["void_ratio"] = sample_void_ratio(sim, args.radius)
        report["box_void_ratio"] = report["porosity"] / (1.0 - report["porosity"])
        report["prep_friction_deg"] = friction
        tried[friction] = (sim, report)
        if progress:
            print(f"  prepared: growth friction {friction:.2f} deg -> core e = "
                  f"{report['void_ratio']:.4f} (box {report['box_void_ratio']:.4f})", flush=True)
        return report["void_ratio"] - target

    low, high = PREP_FRICTION_RANGE
    error_low = prepared(low)
    if error_low > args.void_ratio_tolerance:
        raise ValueError(f"--void-ratio = {target:g} is outside the valid range of this "
                         f"sample, [{target + error_low:.3f}, ...]: the densest preparation "
                         f"(growth friction {low:g} deg) gives e = {target + error_low:.3f}")
    if abs(error_low) > args.void_ratio_tolerance:
        error_high = prepared(high)
        if error_high < -args.void_ratio_tolerance:
            raise ValueError(f"--void-ratio = {target:g} is outside the valid range of this "
                             f"sample, [{target + error_low:.3f}, {target + error_high:.3f}] "
                             f"(growth friction {low:g} to {high:g} deg)")
    def closest():
        return min(abs(report["void_ratio"] - target) for _, report in tried.values())

    while len(tried) < PREPARATIONS and closest() > args.void_ratio_tolerance:
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


def wet(dry, args, water_content, progress):
    """(wetted sim, bridges, wetting report): volume-controlled bridges at every contact of a
    copy of ``dry`` holding water content ``water_content`` (fraction) once static, the
    formation suction corrected for the contacts the bridges add."""
    particles = dry.particles
    target = water_content * args.specific_gravity * particles.solid_volume()
    touching = dry.contacts.overlap > 0.0
    radius_i = particles.radius[dry.contacts.pair_i[touching]]
    radius_j = particles.radius[dry.contacts.pair_j[touching]]
    table = BridgeTable.cached(args.contact_angle, radius_ratios=table_radius_ratios(
        float(particles.radius.max() / particles.radius.min())))
    config = prepare_config(args, 0.0)      # for the equilibrium thresholds only
    aimed = target
    attempts = []
    for _ in range(WETTINGS):
        suction = formation_suction(table, radius_i, radius_j, aimed, args.surface_tension,
                                    args.roughness)
        sim = copy.deepcopy(dry)
        bridges = CapillaryBridges(suction, args.surface_tension, args.contact_angle,
                                   control="volume", roughness=args.roughness).insert(sim)
        steps = sim.run(WET_STEPS, until=equilibrated(config), check_every=CHECK_EVERY,
                        progress="wet" if progress else None)
        held = bridges.water_volume(sim.contacts)
        attempts.append({"formation_suction_pa": suction, "steps": steps,
                         "water_content": gravimetric_water_content(
                             held, particles.solid_volume(), args.specific_gravity)})
        if abs(held / target - 1.0) <= WATER_TOLERANCE:
            break
        aimed *= target / held
    report = {"formation_suction_pa": suction, "wetting_attempts": attempts,
              "water_content": attempts[-1]["water_content"],
              "saturation": bridges.saturation(sim), "bridges": bridges.count(sim),
              "coordination_wet": coordination(sim.contacts, len(sim.particles)),
              "void_ratio_wet": sample_void_ratio(sim, args.radius),
              "unbalanced_force_wet": unbalanced_force(sim.particles, sim.contacts)}
    return sim, bridges, report


class Pull:
    """The pull of a sample held by its six walls' servo: z walls apart at constant strain
    rate, grips, recorder (with the bridges' columns when ``bridges`` is given) and ParaView
    writer; ``run()`` pulls to rupture and returns (steps, history)."""

    def __init__(self, sim, bridges, args, folder):
        self.sim, self.bridges, self.args = sim, bridges, args
        servo = sim.operation(StressServo)
        self.rate = args.inertial_number / inertial_number(1.0, args.radius,
                                                           sim.particles.density, args.confining)
        self.extension = ConstantStrainRate("z", -self.rate, sim.walls.lengths()[2])
        depth = args.radius * (1.0 + 2.0 * args.grip_depth)
        self.grips = [Grip(wall, grip_members(sim.particles.position, sim.particles.radius,
                                              sim.walls, wall, depth)) for wall in (4, 5)]
        index = sim.operations.index(servo)
        sim.operations[index:index + 1] = [self.extension, *self.grips]   # x, y walls held
        for op in self.grips:            # the grips' pull of the current (wetted) state
            op.apply(sim)
        self.steps = int(math.ceil(args.max_strain / (self.rate * sim.dt)))
        period = max(1, self.steps // RECORDS)
        columns = {
            "step": lambda s: s.step,
            "time": lambda s: s.time,
            "axial_strain": lambda s: self.extension.strain(s.walls),
            "tensile_stress": lambda s: tensile_stress(self.grips, s.walls),
            "grip_pull": lambda s: [grip.pull for grip in self.grips],
            "sigma_wall": lambda s: s.walls.stress(),
            "coordination": lambda s: coordination(s.contacts, len(s.particles)),
            "unbalanced_force": lambda s: unbalanced_force(s.particles, s.contacts),
        }
        if bridges is not None:
            solid = sim.particles.solid_volume()
            columns.update({
                "bridges": bridges.count,
                "water_content": lambda s: gravimetric_water_content(
                    bridges.water_volume(s.contacts), solid, args.specific_gravity),
                "saturation": bridges.saturation})
        self.recorder = HistoryRecorder(period, columns)
        self.recorder.record(sim)
        sim.writers.append(self.recorder)
        self.vtk = None
        if args.vtk_frames > 0:
            self.vtk = VtkWriter(os.path.join(folder, "vtk"), max(1, self.steps // args.vtk_frames))
            sim.writers.append(self.vtk)

    def ruptured(self, sim):
        """The stress has stayed below the residual fraction of its positive peak for
        POST_PEAK_STRAIN of extension."""
        stress = self.recorder.rows["tensile_stress"]
        peak = int(np.argmax(stress))
        strain = self.recorder.rows["axial_strain"]
        return (stress[peak] > 0.0 and stress[-1] < self.args.residual * stress[peak]
                and strain[peak] - strain[-1] >= POST_PEAK_STRAIN)

    def run(self, label):
        def status(s):
            return {"ext": f"{-self.extension.strain(s.walls):.4f}",
                    "tension": f"{self.recorder.last('tensile_stress'):.0f}Pa"}

        steps = self.sim.run(self.steps, until=self.ruptured, check_every=self.recorder.period,
                             progress=None if self.args.quiet else label, status=status)
        if self.vtk is not None:
            self.vtk.close(self.sim)
        return steps, self.recorder.arrays()


def prediction(args, void_ratio, water_content):
    """(psi_xx [Pa], label, void ratio of the packing) of homogenize.packing_state for the
    comparison packing at this water content (exact bridges, H/R = 0.09)."""
    kind, label = comparison_packing(void_ratio)
    packing = regular_packing(kind, separation=KIM_SEPARATION)
    state = packing_state(packing, radius=args.radius, contact_angle=args.contact_angle,
                          surface_tension=args.surface_tension, water_content=water_content,
                          specific_gravity=args.specific_gravity)
    return float(state.psi[0, 0]), label, packing.void_ratio


def kim_measured(void_ratio, water_content):
    """Kim's (2001) tensile strength [Pa] of this case, or None."""
    for e, w, strength in KIM_2001:
        if math.isclose(e, void_ratio) and math.isclose(w, water_content):
            return strength
    return None


def case_name(void_ratio, water_content):
    return f"e{void_ratio:.2f}_w{100 * water_content:.2f}"


def run_case(dry, preparation, args, void_ratio, water_content):
    """Wet, pull and summarise one case; writes its history.h5 (and vtk/)."""
    name = case_name(void_ratio, water_content)
    folder = os.path.join(args.out, "cases", name)
    os.makedirs(folder, exist_ok=True)
    progress = not args.quiet
    started = time.perf_counter()
    sim, bridges, wetting = wet(dry, args, water_content, progress)
    wetted = time.perf_counter()
    pull = Pull(sim, bridges, args, folder)
    steps, history = pull.run(f"pull {name}")
    stress = history["tensile_stress"]
    peak = int(np.argmax(stress))
    strength = float(stress[peak])
    predicted, packing_label, packing_e = prediction(args, void_ratio, water_content)
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
        "grip_particles": [len(grip.members) for grip in pull.grips],
        "tensile_strength_pa": strength,
        "axial_extension_at_peak": float(-history["axial_strain"][peak]),
        "water_content_at_peak": float(history["water_content"][peak]),
        "bridges_at_peak": int(history["bridges"][peak]),
        "final_tensile_stress_pa": float(stress[-1]),
        "final_axial_extension": float(-history["axial_strain"][-1]),
        "ruptured": bool(stress[-1] < args.residual * strength),
        "kim_measured_pa": measured,
        "packing_state_pa": predicted,
        "packing_state_packing": f"{packing_label}, e = {packing_e:.3f}, H/R = {KIM_SEPARATION}",
        "relative_difference_to_kim": None if measured is None else strength / measured - 1.0,
        "relative_difference_to_packing_state": strength / predicted - 1.0,
        "strain_rate": pull.rate,
        "inertial_number": args.inertial_number,
        "mean_unbalanced_force_to_peak": float(np.mean(before_peak)) if len(before_peak) else None,
        "unbalanced_force_at_peak": float(history["unbalanced_force"][peak]),
        "pull_steps": steps,
        "dt": sim.dt,
        "wetting_time_s": wetted - started,
        "pull_time_s": time.perf_counter() - wetted,
    }
    attributes = {key: value for key, value in vars(args).items() if key != "cases"}
    attributes.update({key: value for key, value in summary.items()
                       if isinstance(value, (int, float, str))})
    write_history(os.path.join(folder, "history.h5"), history, attributes)
    return summary, history


def plot_curves(histories, folder):
    """Tensile stress against axial extension, one figure per case and one with all."""
    plt = pyplot()
    every, all_axes = plt.subplots(figsize=(6, 4))
    for name, history in histories.items():
        figure, axes = plt.subplots(figsize=(6, 4))
        for target in (axes, all_axes):
            target.plot(-100.0 * history["axial_strain"], history["tensile_stress"], label=name)
        axes.set(xlabel="axial extension [%]", ylabel="tensile stress [Pa]", title=name)
        save_figure(figure, os.path.join(folder, f"tension_{name}.png"))
    all_axes.set(xlabel="axial extension [%]", ylabel="tensile stress [Pa]")
    all_axes.legend(fontsize=7)
    save_figure(every, os.path.join(folder, "tension_all.png"))


def plot_strength(summaries, args, path):
    """Tensile strength against water content: DEM, Kim (2001) and packing_state's curve."""
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
        curve = [prediction(args, e, w)[0] for w in grid]
        axes.plot(100 * grid, curve, "--", color=colour,
                  label=f"packing_state, {comparison_packing(e)[1]}")
    axes.set(xlabel="gravimetric water content w [%]", ylabel="tensile strength [Pa]",
             xlim=(0, None), ylim=(0, None))
    axes.legend(fontsize=7)
    save_figure(figure, path)


def _percent(value):
    return "" if value is None else f"{100 * value:+.0f} %"


def write_report(summaries, args, path):
    """report.md: one table row per case."""
    lines = [f"# Direct tension, {args.particles} spheres, R = {args.radius * 1e3:g} mm, "
             f"theta = {args.contact_angle:g} deg, gamma = {args.surface_tension:g} N/m, "
             f"bridge roughness H/R = {args.roughness:g}",
             "",
             "Tensile strength [Pa] positive in tension. e: core void ratio (box less one "
             "diameter along each wall); packing_state: psi_xx of the comparison packing at the "
             "target w (exact bridges, H/R = 0.09).",
             "",
             "| e target | e reached (box) | w target [%] | w [%] | Sr | bridges | s_form [Pa] "
             "| DEM | Kim | packing_state | DEM/Kim | DEM/prediction |",
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
    write_text(path, "\n".join(lines) + "\n")
    return lines


def main(argv=None):
    args = parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    started = time.perf_counter()
    summaries, histories, samples = [], {}, {}
    for void_ratio in dict.fromkeys(e for e, _ in args.cases):
        if not args.quiet:
            print(f"sample e = {void_ratio}: tuning the growth friction", flush=True)
        try:
            dry, preparation = prepare_void_ratio(args, void_ratio, not args.quiet)
        except ValueError as error:
            sys.exit(f"direct_tension.py: error: {error}")
        samples[void_ratio] = preparation
        for e, water_content in args.cases:
            if e != void_ratio:
                continue
            summary, history = run_case(dry, preparation, args, e, water_content)
            summaries.append(summary)
            histories[summary["case"]] = history
            if not args.quiet:
                print(f"  {summary['case']}: tensile strength {summary['tensile_strength_pa']:.1f}"
                      f" Pa (Kim {summary['kim_measured_pa']}, packing_state "
                      f"{summary['packing_state_pa']:.1f})", flush=True)
    output = {"arguments": {k: v for k, v in vars(args).items() if k != "cases"},
              "samples": {str(e): {k: v for k, v in r.items() if k != "sigma_wall"}
                          for e, r in samples.items()},
              "cases": summaries, "wall_time_s": time.perf_counter() - started}
    write_json(os.path.join(args.out, "tension.json"), output, default=float)
    plot_curves(histories, os.path.join(args.out, "plots"))
    plot_strength(summaries, args, os.path.join(args.out, "plots", "strength_vs_water.png"))
    print("\n".join(write_report(summaries, args, os.path.join(args.out, "report.md"))))
    print(f"done in {output['wall_time_s']:.0f} s; outputs in {args.out}")
    return output


if __name__ == "__main__":
    main()
