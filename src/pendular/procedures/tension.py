"""Direct tension of wet sand at fixed water content (Kim 2001; thesis §4.4.1.2, Table 4.5).

``TensionTest(TensionConfig(...)).run(out)`` returns the content of tension.json; command
``pendular tension`` (pendular.cli.commands.tension; options named as the TensionConfig fields
and those of its sample, a PrepareConfig, dashes for underscores; --specific-gravity sets the
grains' density). Variants: ``dataclasses.replace(config, cases=[(0.65, 0.01)])``, a sample
by ``tension_sample(particles=200)``; ``run(out, device="gpu")`` (--device) runs every phase
on the GPU; ``liquid="clusters"`` (--liquid clusters) holds the water in bridges and liquid
clusters at the suction found (pendular.procedures.tension_clusters). By default Kim's six
cases: F-75 sand, R = 0.11 mm, e = 0.72 at w = 0.47, 1.04, 2.11 % and e = 0.58 at w = 0.43,
1.04, 2.01 % (gravimetric, Gs = 2.65, the grains' density over the water's). Each case:

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

This module holds the configuration, its options and command (``COMMAND``), the run of the
cases with its checkpoints; one case's sample, wetting and pull are in
pendular.procedures.tension_pull, the report in pendular.procedures.tension_report, the
figures in pendular.io.plots.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import time
from dataclasses import dataclass, field

import h5py

from pendular.capillary import MAX_ROUGHNESS
from pendular.capillary.volume_control import rupture_distance_for_volume
from pendular.dem.checkpoint import CheckpointWriter, checkpoint_extra_state, load_checkpoint
from pendular.dem.simulation import check_device
from pendular.homogenize import packing_state, regular_packing
from pendular.io.outputs import OutputFolder
from pendular.io.plots import plot_curves, plot_strength
from pendular.procedures.command import LaboratoryCommand
from pendular.procedures.config import (MAX_SURFACE_TENSION, WATER_DENSITY, check_particles,
    check_steps_count, config_from_dict, config_to_dict, contact_angle_parameter, inertial_number,
    registered)
from pendular.procedures.loading_clusters import (entry_suction_parameter, liquid_parameter,
    refuse_entry_suction)
from pendular.procedures.feasibility import MAX_INERTIAL_NUMBER
from pendular.procedures.laboratory import Interrupted
from pendular.procedures.options import (CHECKPOINT_EVERY, CommandOptions, WATER_CONTENT,
    sample_sizes, size_options)
from pendular.procedures.preparation import PrepareConfig, pwave_step
from pendular.procedures.progress import tension_plan
from pendular.procedures.reference import (CHAPTER4_SURFACE_TENSION, KIM_2001, KIM_RADIUS,
    KIM_SEPARATION, SPECIFIC_GRAVITY, comparison_packing)
from pendular.procedures.resume import resume_files, stored_run
from pendular.procedures.run_options import RunOptions
from pendular.procedures.tension_clusters import refuse_clusters
from pendular.procedures.tension_pull import case_name, prepare_void_ratio, run_case
from pendular.procedures.tension_report import case_line, strength_predictions, write_report
from pendular.utils.atomic import write_json
from pendular.utils.integrity import config_hash
from pendular.utils.parameters import (OptionError, Parameter, ParameterError, default_of, fail,
    fields_of, option_from, option_of, parameter, spec_of, validate)
from pendular.utils.progress import whole_run
from pendular.utils.validate import check_int


#: Fewest spheres of a direct tension sample: the grips hold a layer at each z wall and the
#: void ratio is the core's, the box less a diameter along each wall; at 100 spheres the box
#: is about 4.5 diameters across and the core 2.5.
MIN_TENSION_PARTICLES = 100


#: Most spheres of a direct tension sample (each void ratio is tuned over up to
#: pendular.procedures.tension_pull.PREPARATIONS preparations of it).
MAX_TENSION_PARTICLES = 1_000_000


#: Valid specific gravities Gs of a direct tension's grains [-] (--specific-gravity).
SPECIFIC_GRAVITY_RANGE = (1.0, 10.0)

#: The direct tension's sample where it differs from PrepareConfig's defaults: Kim's (2001)
#: F-75 sand (R = 0.11 mm, Gs = 2.65), 2,000 spheres held at 100 Pa.
TENSION_SAMPLE = {"particles": 2000, "radius": KIM_RADIUS,
                  "density": SPECIFIC_GRAVITY * WATER_DENSITY, "confining": 100.0}


#: The direct tension's ranges of its sample's fields, narrower than PrepareConfig's:
#: field -> (low, high), the bounds' openness PrepareConfig's.
TENSION_RANGES = {"radius": (1e-6, 1e-2), "confining": (1.0, 1e5), "young": (0.0, 1e12)}


#: The specific gravity Gs = density / WATER_DENSITY of a direct tension's grains, as its
#: command sets it.
SPECIFIC_GRAVITY_PARAMETER = Parameter(
    "1", f"specific gravity Gs of the grains: sets their density, Gs x {WATER_DENSITY:g} "
    "kg/m^3, which gives their mass (time step, strain rate) and the water volume of a water "
    "content by mass",
    *SPECIFIC_GRAVITY_RANGE, flag="--specific-gravity")

#: The core void ratio of a direct tension's case: denser than random close packing or looser
#: than the loosest growth is unreachable.
VOID_RATIO_PARAMETER = Parameter("1", "core void ratio", 0.5, 1.2, flag="--void-ratio")


def check_tension_sample(fields):
    """ParameterError naming the field (and its option) of ``fields`` (PrepareConfig's names;
    those absent are not checked) outside the direct tension's range, narrower than
    PrepareConfig's: particles in [MIN_TENSION_PARTICLES, MAX_TENSION_PARTICLES],
    TENSION_RANGES, density [kg/m^3] as the specific gravity Gs = density / WATER_DENSITY
    (--specific-gravity), friction_deg and seed in PrepareConfig's ranges."""
    if "particles" in fields:
        check_particles(fields["particles"], MIN_TENSION_PARTICLES, MAX_TENSION_PARTICLES,
                        "direct tension", "the grips hold a layer at each z wall and the void "
                        "ratio is the core's")
    if "density" in fields:
        SPECIFIC_GRAVITY_PARAMETER.check("specific_gravity", fields["density"] / WATER_DENSITY)
    for name in ("radius", "confining", "friction_deg", "young", "seed"):
        if name in fields:
            spec = spec_of(PrepareConfig, name)
            low, high = TENSION_RANGES.get(name, (spec.low, spec.high))
            spec = dataclasses.replace(spec, low=low, high=high)
            try:
                spec.check(name, fields[name])
            except ParameterError:
                if name != "radius" or fields.get("psd") is None:
                    raise
                # the grading curve's sizes, not a --radius given
                raise ParameterError("psd", f"psd: the grading curve's mean radius, "
                                     f"{fields['radius']:.3g} m, is outside the valid range "
                                     f"{spec.valid_range()} m of a direct tension's sphere",
                                     "--psd") from None


def tension_sample(**fields):
    """The PrepareConfig of a direct tension's sample: TENSION_SAMPLE with ``fields``
    (PrepareConfig's names) over it, e.g. ``tension_sample(particles=200)``; the tension's ranges
    (check_tension_sample) checked before PrepareConfig's own."""
    check_tension_sample(fields)
    return PrepareConfig(**{**TENSION_SAMPLE, **fields})


@registered
@dataclass
class TensionConfig:
    """Direct tension of wet sand at fixed water content (pendular.procedures.tension; Kim 2001,
    thesis §4.4.1.2 and Table 4.5). Validated on creation (ParameterError naming the field; its
    Parameter's flag on the command line).

    sample: the grains and their preparation (pendular.procedures.preparation.PrepareConfig,
    default ``tension_sample()``): particles, sizes (radius [m], the mean radius;
    radius_spread; psd), density [kg/m^3], the one grain density (its specific gravity Gs =
    density / WATER_DENSITY turns water contents by mass into water volumes; the command's
    --specific-gravity sets it), confining: isotropic stress of preparation and wetting [Pa],
    friction_deg: contact friction of wetting and pull [deg], young: YADE young E [Pa], seed,
    periodic: a periodic cell pulled along z at zero lateral stress (no walls, no grips: a
    grip_depth other than the default is refused; the void ratio is the whole cell's). Its
    prep_friction_deg is not used: the growth friction is tuned to each void ratio. Ranges
    narrower than PrepareConfig's: check_tension_sample.

    cases: [(core void ratio [-], gravimetric water content [-, a fraction])], one sample per
    void ratio (default Kim's six), distinct by their folder names (``case_name``);
    roughness: meniscus separation of touching grains H/R [-]; form_gap: at wetting, bridges
    also form across gaps up to form_gap x radius [-] (0: at contacts only; the default 1
    reaches past the rupture distance of Kim's bridges, so they form wherever they can;
    pendular.capillary.wetting); contact_angle [deg], surface_tension [N/m];
    inertial_number: I of the pull [-]; max_strain: largest axial extension [-]; residual:
    fraction of the peak below which the pull has ruptured [-]; grip_depth: grip thickness
    [diameters] (walls only); void_ratio_tolerance [-]; vtk_frames: ParaView frames per pull
    (0: none); vtk_every: steps between frames instead (None: from vtk_frames; 0: none), both
    at most the pull's steps (``pull_steps``); liquid: "pendular" (volume-controlled bridges)
    or "clusters" (filled pore units beside suction-controlled bridges, the liquid's volume
    held at the suction found: pendular.procedures.tension_clusters).
    """

    sample: PrepareConfig = field(default_factory=tension_sample)
    cases: list[tuple[float, float]] = parameter(
        default_factory=lambda: [(e, w) for e, w, _ in KIM_2001], kind=None, recorded=False,
        help="(core void ratio, gravimetric water content as a fraction) of each case")
    roughness: float = parameter(KIM_SEPARATION, low=0.0, high=MAX_ROUGHNESS,
                                 flag="--roughness",
                                 help="meniscus separation of touching grains H/R (default "
                                      "Kim's sand, as in the regular packing prediction; 0: "
                                      "smooth spheres)")
    form_gap: float = parameter(1.0, low=0.0, high=1.0, flag="--form-gap",
                                help="at wetting, bridges also form across gaps up to this many "
                                     "radii (0: at contacts only; 1: wherever a bridge of the "
                                     "formation suction can exist, docs/direct_tension.md)")
    contact_angle: float = contact_angle_parameter()
    surface_tension: float = parameter(CHAPTER4_SURFACE_TENSION, unit="N/m", low=0.0,
                                       high=MAX_SURFACE_TENSION, low_inclusive=False,
                                       flag="--surface-tension",
                                       help="surface tension (thesis Chapter 4's, which the "
                                            "comparison with Kim and the regular packing "
                                            "prediction uses; triaxial and swcc default to "
                                            "Chapter 5's 0.073)")
    inertial_number: float = parameter(1e-3, low=0.0, high=MAX_INERTIAL_NUMBER,
                                       low_inclusive=False,
                                       flag="--inertial-number",
                                       help="I = strain rate x d x sqrt(rho / confining) of "
                                            "the pull")
    max_strain: float = parameter(0.1, low=0.0, high=0.5, low_inclusive=False,
                                  flag="--max-strain", help="largest axial extension of the pull")
    residual: float = parameter(0.2, low=0.0, high=1.0, low_inclusive=False,
                                high_inclusive=False, flag="--residual",
                                help="fraction of the peak below which the pull has ruptured")
    grip_depth: float = parameter(1.0, low=0.0, high=3.0, flag="--grip-depth", unset=True,
                                  help="grip thickness: particles whose surface is within this "
                                       "many diameters of a z wall, in diameters (not with "
                                       "--periodic, which has no grips)")
    void_ratio_tolerance: float = parameter(0.01, low=0.001, high=0.1,
                                            flag="--void-ratio-tolerance",
                                            help="largest |e - target| accepted from the "
                                                 "preparation")
    vtk_frames: int = parameter(20, kind=int, low=0, high=1000, flag="--vtk-frames",
                                help="ParaView frames per pull (0: none)")
    vtk_every: int | None = parameter(None, kind=int, low=0, flag="--vtk-every",
                                      help="steps between ParaView frames of the pull, instead "
                                           "of --vtk-frames (0: none)")
    liquid: str = liquid_parameter("at the suction that holds the water; --roughness 0")
    entry_suction: str = entry_suction_parameter()

    def __post_init__(self):
        if not isinstance(self.sample, PrepareConfig):
            raise TypeError(f"sample must be a PrepareConfig, got {type(self.sample).__name__}")
        check_tension_sample(vars(self.sample))
        validate(self)
        self.cases = [(float(e), float(w)) for e, w in self.cases]
        if not self.cases:
            raise ValueError("cases = [] is empty: give at least one (void ratio, water "
                             "content)")
        for e, _ in self.cases:
            # denser than random close packing or looser than the loosest growth: unreachable
            VOID_RATIO_PARAMETER.check("void_ratio", e)
        names = [case_name(e, w) for e, w in self.cases]
        for k, name in enumerate(names):
            if name in names[:k]:        # one folder, one sample per void ratio: run once
                (e0, w0), (e1, w1) = self.cases[names.index(name)], self.cases[k]
                raise ValueError(
                    f"cases: (e {e0:g}, w {100 * w0:g} %) and (e {e1:g}, w {100 * w1:g} %) "
                    f"share the folder {name}: give each case once, void ratios 0.01 or water "
                    "contents 0.01 % apart")
        if self.sample.periodic and self.grip_depth != default_of(TensionConfig, "grip_depth"):
            raise fail(self, "grip_depth", f"grip_depth = {self.grip_depth:g} does not apply "
                       "to --periodic: a periodic cell has no walls, so no grips")
        if refuse_clusters(self) is not None:
            raise fail(self, "liquid", refuse_clusters(self))
        refuse_entry_suction(self)
        steps = self.pull_steps()
        for name in ("vtk_frames", "vtk_every"):
            if getattr(self, name) is not None:
                try:
                    check_steps_count(name, getattr(self, name), steps,
                                      f"the pull to --max-strain {self.max_strain:g}")
                except ValueError as error:
                    raise fail(self, name, str(error)) from None
        for e, w in self.cases:
            limit = self.pendular_limit(e)
            if not 0.0 < w <= limit:
                raise ParameterError("water_content", f"water_content = {100.0 * w:g} % is "
                                     f"outside the valid range (0, {100.0 * limit:.3g}] %: the "
                                     "pendular regime ends at the pendular limit of the "
                                     f"{comparison_packing(e)[1]} packing", "--water-content")

    @property
    def specific_gravity(self):
        """Specific gravity Gs of the grains [-]: the sample's density over WATER_DENSITY."""
        return self.sample.density / WATER_DENSITY

    def options(self):
        """The run's options, flat and named as the command's (tension.json 'arguments' of a
        library run, campaign rows): the sample's as --particles, --radius, ..., its density
        as specific_gravity."""
        sample = self.sample
        return {"roughness": self.roughness, "form_gap": self.form_gap,
                "particles": sample.particles, "radius": sample.radius,
                "radius_spread": sample.radius_spread, "psd": sample.psd,
                "contact_angle": self.contact_angle, "surface_tension": self.surface_tension,
                "specific_gravity": self.specific_gravity, "confining": sample.confining,
                "friction": sample.friction_deg, "young": sample.young,
                "inertial_number": self.inertial_number, "max_strain": self.max_strain,
                "residual": self.residual, "grip_depth": self.grip_depth,
                "void_ratio_tolerance": self.void_ratio_tolerance,
                "vtk_frames": self.vtk_frames, "vtk_every": self.vtk_every,
                "seed": sample.seed, "periodic": sample.periodic, "liquid": self.liquid,
                **({"entry_suction": self.entry_suction} if self.liquid == "clusters" else {})}

    def pull_steps(self):
        """Steps of a pull to max_strain estimated before anything runs [-]: max_strain over
        the strain rate times the P-wave step of the mean radius (pendular.procedures.preparation
        .pwave_step; the pull runs at the 'stiffness' rule's step, 1.4-1.5 times longer on
        prepared samples); a pull that ruptures stops sooner."""
        sample = self.sample
        rate = self.inertial_number / inertial_number(1.0, sample.radius, sample.density,
                                                      sample.confining)
        return self.max_strain / (rate * pwave_step(sample.radius, sample))

    def pendular_limit(self, void_ratio):
        """Gravimetric water content [-] at the pendular limit of the regular packing compared
        with a sample of ``void_ratio`` (reference.comparison_packing, H/R = KIM_SEPARATION)."""
        kind, _ = comparison_packing(void_ratio)
        return packing_state(regular_packing(kind, separation=KIM_SEPARATION),
                             radius=self.sample.radius, contact_angle=self.contact_angle,
                             surface_tension=self.surface_tension,
                             filling_angle=regular_packing(kind).max_filling_angle,
                             specific_gravity=self.specific_gravity).water_content


    def least_water_content(self, void_ratio):
        """Gravimetric water content [-] below which the regular packing compared with a
        sample of ``void_ratio`` (reference.comparison_packing, H/R = KIM_SEPARATION) holds
        no bridge: its bridges' rupture distance (capillary.rupture_distance_for_volume)
        falls below the grains' separation. Bisection in ln w up to the pendular limit."""
        packing = regular_packing(comparison_packing(void_ratio)[0], separation=KIM_SEPARATION)
        pore_volume = packing.porosity * packing.cell_volume           # [R^3]

        def holds(water):
            volume_star = (water * self.specific_gravity / packing.void_ratio * pore_volume
                           / packing.bridges_per_cell)
            try:
                reach = rupture_distance_for_volume(1.0, self.contact_angle, volume_star)
            except ValueError:                   # a volume below the solver's bridges
                return False
            return reach >= KIM_SEPARATION

        low, high = 1e-9, self.pendular_limit(void_ratio)
        if holds(low):
            return 0.0
        for _ in range(40):
            middle = math.sqrt(low * high)
            low, high = (low, middle) if holds(middle) else (middle, high)
        return high


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


class TensionTest:
    """The direct-tension cases of ``config`` (TensionConfig): one sample per void ratio, each
    water content wetted and pulled from a copy of it (module docstring)."""

    #: The configuration's type.
    CONFIG = TensionConfig

    def __init__(self, config: TensionConfig) -> None:
        if not isinstance(config, TensionConfig):
            raise TypeError(f"config must be a TensionConfig, got {type(config).__name__}")
        self.config = config
        for e, w in config.cases:         # each case is compared with its regular packing
            least = config.least_water_content(e)
            if w < least:
                _, label = comparison_packing(e)
                raise ParameterError("water_content", (
                    f"water_content = {100.0 * w:g} % is outside the valid range "
                    f"[{100.0 * least:.3g}, {100.0 * config.pendular_limit(e):.3g}] % of a sample "
                    f"of void ratio {e:g}: less water holds no bridge across the grains' "
                    f"separation (H/R = {KIM_SEPARATION:g}) of the {label} packing whose "
                    "prediction the case is compared with"), "--water-content")

    def run(self, out: str, options: RunOptions | None = None, **settings) -> dict:
        """Every case into ``out``; writes tension.json, report.md, plots/ and cases/; returns
        the tension.json content. Run as ``options`` say (pendular.procedures.run_options
        .RunOptions; ``settings``: its fields one by one): ``arguments``: what tension.json
        records under 'arguments' and the histories as attributes (the command: its options;
        default: the configuration's, TensionConfig.options); the configuration itself is
        under 'config'. ``device``: where the preparations, wettings and pulls run, "cpu" or
        "gpu" (``check_device``, before anything is made). ``checkpoint_every``: steps
        between checkpoints ``out``/checkpoint.h5 of the pulls (0: none), from which
        ``resume`` continues; ``stop_after``: stop after this many steps of the pulls as an
        interruption would (raises Interrupted). The pulls run on one thread, whatever
        ``threads``."""
        options = RunOptions.of(options, **settings)
        progress, device, stop_after = options.progress, options.device, options.stop_after
        checkpoint_every = check_int("checkpoint_every", options.checkpoint_every, low=0)
        check_device(device)
        arguments = (self.config.options() if options.arguments is None
                     else dict(options.arguments))
        with OutputFolder(out, "tension") as folder:
            for name in OUTPUTS:
                folder.claim(name)
            run = TensionRun(out, self.config, arguments, checkpoint_every, stop_after)
            with whole_run(tension_plan(self.config), enabled=progress):
                return self._run(out, progress, device, run)

    @classmethod
    def resume(cls, out: str, options: RunOptions | None = None, **settings) -> dict:
        """Continue the interrupted run of folder ``out`` from its checkpoint.h5, with the
        configuration and arguments stored there, run as ``options`` say (RunOptions;
        ``settings``: its fields one by one): the cases finished are kept, the sample of the
        case being pulled is prepared and wetted again (the engine is deterministic: the same
        state), and its pull goes on from the checkpoint; returns the tension.json content,
        bit for bit that of an uninterrupted run (timings aside)."""
        options = RunOptions.of(options, **settings)
        progress, device, stop_after = options.progress, options.device, options.stop_after
        path = resume_files(out)[1]
        with OutputFolder(out, "tension --resume", keep=True) as folder:
            for name in OUTPUTS:
                folder.claim(name)
            state = checkpoint_extra_state(path)
            config = stored_run(config_from_dict(state.get("config") if isinstance(state, dict)
                                                 else None, path), out, cls, "tension", device)
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
        plot_strength(summaries, config, KIM_2001, strength_predictions(summaries, config),
                      os.path.join(out, "plots", "strength_vs_water.png"))
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


# ---------------------------------------------------------------- the command


#: A direct tension's sample: Kim's sand by default (TENSION_SAMPLE), the tension's ranges.
TENSION_SAMPLE_OPTIONS = {
    "particles": option_of(PrepareConfig, "particles", default=TENSION_SAMPLE["particles"],
                           low=MIN_TENSION_PARTICLES, high=MAX_TENSION_PARTICLES),
    "confining": option_of(PrepareConfig, "confining", default=TENSION_SAMPLE["confining"],
                           low=TENSION_RANGES["confining"][0],
                           high=TENSION_RANGES["confining"][1],
                           help="isotropic stress of preparation and wetting"),
    "friction": option_of(PrepareConfig, "friction_deg",
                          help="contact friction during wetting and pull"),
    "young": option_of(PrepareConfig, "young", high=TENSION_RANGES["young"][1]),
    "seed": option_of(PrepareConfig, "seed", help="random seed of the samples"),
    "periodic": option_of(PrepareConfig, "periodic",
                          help="a periodic cell instead of six walls: no grips, the cell pulled "
                               "along z at zero lateral stress; the void ratio is the whole "
                               "cell's"),
}


#: A direct tension's sizes: Kim's radius by default, the tension's range.
TENSION_SIZES = size_options(default=KIM_RADIUS, low=TENSION_RANGES["radius"][0],
                             high=TENSION_RANGES["radius"][1])

#: The cases of a direct tension: every water content [%] at every void ratio.
TENSION_VOID_RATIO = option_from(dataclasses.replace(
    VOID_RATIO_PARAMETER, help="void ratio(s) of the core, comma separated (default: Kim's "
                               "0.72, 0.58)"), None, many=True, distinct=True)

TENSION_WATER_CONTENT = option_from(dataclasses.replace(
    WATER_CONTENT, low=None, high=None,
    help="gravimetric water content(s), comma separated, each at most the pendular limit of "
         "its void ratio's packing (default: Kim's for his void ratios, else 0.5,1,2)"),
    None, many=True, distinct=True)

#: A direct tension's own fields set by their options as they are.
TENSION_OWN = {name: option_of(TensionConfig, name) for name in (
    "roughness", "form_gap", "contact_angle", "surface_tension", "inertial_number",
    "max_strain", "residual", "grip_depth", "void_ratio_tolerance", "liquid", "entry_suction")}


TENSION_FRAMES = (dataclasses.replace(option_of(TensionConfig, "vtk_frames"), group="frames"),
                  dataclasses.replace(option_of(TensionConfig, "vtk_every"), least=0,
                                      group="frames"))

#: A direct tension's options, in the order of its help.
TENSION = ((TENSION_VOID_RATIO, TENSION_OWN["roughness"], TENSION_WATER_CONTENT,
            TENSION_SAMPLE_OPTIONS["particles"], TENSION_OWN["form_gap"])
           + TENSION_SIZES
           + (TENSION_OWN["contact_angle"], TENSION_OWN["surface_tension"],
              option_from(SPECIFIC_GRAVITY_PARAMETER, SPECIFIC_GRAVITY),
              TENSION_SAMPLE_OPTIONS["confining"], TENSION_SAMPLE_OPTIONS["friction"],
              TENSION_SAMPLE_OPTIONS["young"])
           + tuple(TENSION_OWN[name] for name in ("inertial_number", "max_strain", "residual",
                                                  "grip_depth", "void_ratio_tolerance",
                                                  "liquid", "entry_suction"))
           + TENSION_FRAMES + (CHECKPOINT_EVERY, TENSION_SAMPLE_OPTIONS["seed"],
                               TENSION_SAMPLE_OPTIONS["periodic"]))


def tension_config(values, given):
    """The TensionConfig of ``values``: its cases every water content [%] at every void ratio
    (pendular.procedures.tension.cases_of), the sample's density from the specific gravity."""

    cases = cases_of(values["void_ratio"], values["water_content"])
    depth = values["grip_depth"]
    if values["periodic"] and depth is not None:
        raise OptionError(lambda name: f"{name('grip_depth')} = {depth:g} does not apply to "
                                       f"{name('periodic')}: a periodic cell has no walls, so "
                                       "no grips")
    sample = tension_sample(**fields_of(values, TENSION_SAMPLE_OPTIONS.values()),
                            **sample_sizes(values),
                            density=values["specific_gravity"] * WATER_DENSITY)
    return TensionConfig(sample=sample, cases=cases,
                         **fields_of(values, (*TENSION_OWN.values(), *TENSION_FRAMES)))


#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular tension --void-ratio 0.65 --water-content 1 --out runs/tension",
           "the direct tensile strength of one of Kim's (2001) cases against his measurement and "
           "the packing-state prediction; tension.json, report.md")

#: Summary keys printed at the end, tables of COLUMNS.
SHOWN = ("cases",)
#: Columns of those tables.
COLUMNS = ("case", "void_ratio", "water_content", "saturation", "bridges",
                 "tensile_strength_pa", "kim_measured_pa", "packing_state_pa")

#: The tension command (pendular.procedures.registry).
COMMAND = LaboratoryCommand(
    name="tension",
    description="direct tension of wet sand at fixed water content (Kim 2001)",
    test=TensionTest,
    declared=CommandOptions(TENSION, tension_config),
    shown=SHOWN, example=EXAMPLE, out="runs/direct_tension", columns=COLUMNS)
