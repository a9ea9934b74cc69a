"""Run configurations: typed dataclasses, validated once, saved into every output as JSON.

A configuration says everything that changes a result; how a run is watched (output folder,
progress bars, threads) is not part of it, so two runs with equal configurations give the same
results. ``config_to_dict`` / ``config_from_dict`` write and read the nested dataclasses as
plain JSON with ``CONFIG_SCHEMA_VERSION``; a file of another version is refused by name.
A campaign builds variants with ``dataclasses.replace``.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pendular.dem.sample import load_sample
from pendular.capillary import BRIDGE_MODELS, CONTROLS, LIQUID_MODELS, SURFACE_TENSION
from pendular.dem.walls import ConstantStrainRate
from pendular.procedures.preparation import (MAX_PARTICLES, PrepareConfig, check_soft_contacts,
    pwave_step)
from pendular.utils.parameters import (Parameter, ParameterError, default_of, fail, parameter,
    spec_of, validate)
from pendular.utils.validate import check_int
from pendular.homogenize import packing_state, regular_packing

from pendular.procedures.reference import (CHAPTER4_SURFACE_TENSION, KIM_2001, KIM_RADIUS,
    KIM_SEPARATION, SPECIFIC_GRAVITY, comparison_packing)

#: Most nodes (suction x distance) of a bridge table: about 1 kB of memory per node over the
#: ten radius ratios, 7 times the exact default (350 x 80); beyond, building takes hours.
MAX_TABLE_NODES = 200_000

#: Largest surface tension of a wetting liquid [N/m] (water 0.0728, mercury 0.485).
MAX_SURFACE_TENSION = 1.0

#: How the bridges of a triaxial test appear (TriaxialConfig.wetting).
WETTING_PROTOCOLS = ("isotropic", "at-shear", "constant-volume")

#: Directions of a triaxial shear (ShearConfig.direction): the axial (z) walls pushed in at a
#: constant rate, the lateral stress held (compression), or pulled apart (extension).
SHEAR_DIRECTIONS = ("compression", "extension")

#: Drainage of a triaxial shear (ShearConfig.drainage): the lateral stress held and the volume
#: free (drained), or the volume held (undrained: the pore water cannot leave).
DRAINAGES = ("drained", "undrained")

#: Version of the configuration layout saved in outputs (samples, checkpoints, histories).
CONFIG_SCHEMA_VERSION = 2

#: Largest final axial strain of a triaxial shear [-]: laboratory tests end by 20-30 %
#: (ISO 17892-9 and ASTM D7181 stop at 15-20 % or at the critical state; the thesis shears to
#: 25 %); at 50 % the sample is half its height and its servoed lateral walls span twice its
#: cross-section, no test any more (the particles crush into each other beyond).
MAX_AXIAL_STRAIN = 0.5
#: Smallest final axial strain [-]: below, the walls move less than a contact's overlap.
MIN_AXIAL_STRAIN = 1e-6
#: Why MAX_AXIAL_STRAIN (the end of the error refusing more).
AXIAL_STRAIN_LIMIT = ("a triaxial test ends by 20-30 % axial strain (the thesis's 25 %); at "
                      "half its height the sample is no test any more")
#: Most steps of a stage run to equilibrium (wetting, an isotropic or SWCC stage, a
#: consolidation): beyond, a stage that has not settled will not.
MAX_STAGE_STEPS = 100_000_000
#: Largest strain rate a loading may name [1/s] (ConstantStrainRate's bound).
MAX_STRAIN_RATE = ConstantStrainRate.MAX_RATE
#: Most history rows of a shear (each a few hundred bytes; one a step at most).
MAX_RECORDS = 10_000_000
#: Fewest spheres of a triaxial test or an SWCC: their stresses and saturation are averages
#: over the sample's contacts and bridges, and 50 spheres hold about 100-150 of them (a few
#: spheres give a "peak" of one contact); the trade-off study's quarter samples are 50.
MIN_SAMPLE_PARTICLES = 50
#: Why a sample needs MIN_SAMPLE_PARTICLES (the end of the error refusing fewer).
AVERAGES = ("its stresses and saturation are averages over the sample's contacts and bridges, "
            "which a few spheres do not give")
#: Fewest spheres of a simple shear: its periodic cell must be 3 diameters plus the neighbour
#: reach across (pendular.dem.neighbors), which 50 spheres at the default porosity miss by a
#: hair; 60 hold it with a margin.
MIN_SIMPLE_SHEAR_PARTICLES = 60
#: Why a simple shear needs MIN_SIMPLE_SHEAR_PARTICLES (the end of the error refusing fewer).
NARROW_CELL = ("its periodic cell must span 3 diameters plus the neighbour reach, which fewer "
               "spheres do not")
#: Fewest spheres of a direct tension sample: the grips hold a layer at each z wall and the
#: void ratio is the core's, the box less a diameter along each wall; at 100 spheres the box
#: is about 4.5 diameters across and the core 2.5.
MIN_TENSION_PARTICLES = 100
#: Most spheres of a direct tension sample (each void ratio is tuned over up to
#: pendular.procedures.tension.PREPARATIONS preparations of it).
MAX_TENSION_PARTICLES = 1_000_000


def inertial_number_parameter():
    """The field of a loading's target inertial number [-] (ShearConfig, PathConfig)."""
    return parameter(3e-4, low=0.0, high=1.0, low_inclusive=False, flag="--inertial-number",
                     help="target inertial number setting the strain rate")


def stage_steps_parameter(default, help):
    """The field of the most steps of a stage run to equilibrium [-] (``default``; ``help``:
    which stage)."""
    return parameter(default, kind=int, low=1, high=MAX_STAGE_STEPS, flag="--stage-steps",
                     help=help)


def strain_rate_parameter():
    """The field of a loading's strain rate [1/s], None for the inertial number's."""
    return parameter(None, unit="1/s", low=0.0, high=MAX_STRAIN_RATE, low_inclusive=False,
                     flag="--strain-rate", help="axial strain rate (overrides --inertial-number)")


@dataclass
class ShearConfig:
    """Shear phase of a triaxial test to the axial strain ``max_strain`` [-] (at most
    MAX_AXIAL_STRAIN). ``strain_rate`` [1/s] defaults to the one giving ``inertial_number``
    I = rate * 2R * sqrt(rho / confining) (GDR MiDi 2004); ``records``: history rows (at most
    one a step).

    Wall-control options, pendular's choice by default; ``YADE_CHOICES`` holds YADE's
    (TriaxialStressController, docs/yade_crosscheck.md):

    - rate_on_current_length: the axial rate acts on the current height (true strain rate)
      instead of the initial one (engineering strain rate);
    - servo_max_velocity: speed cap of the lateral walls [m/s] (None: the preparation servo's);
    - servo_scale_max_velocity: scale the cap per axis by 3 L_a / (L_x + L_y + L_z);
    - servo_stiffness_every: refresh the walls' stiffness every this many steps (and at each of
      the first 100) instead of every step.

    The path of the shear (pendular.procedures.loading.shear_stage): ``direction``
    (SHEAR_DIRECTIONS; in extension ``max_strain`` is the magnitude of the axial extension);
    ``b``: the intermediate principal stress ratio (sigma_2 - sigma_3) / (sigma_1 - sigma_3)
    held through a compression, sigma_1 on z, sigma_3 on x (None: sigma_x = sigma_y, a
    conventional triaxial); ``constant_p``: the lateral stresses follow the axial one so that
    the mean stress stays the confining stress; ``drainage`` (DRAINAGES): "undrained" holds the
    sample's volume, the lateral walls moving with the axial ones (neither b nor constant_p:
    the volume sets the lateral walls).
    """

    max_strain: float = parameter(0.25, low=MIN_AXIAL_STRAIN, high=MAX_AXIAL_STRAIN,
                                  flag="--max-strain",
                                  help="final axial strain (in extension, the magnitude of the "
                                       "axial extension)")
    inertial_number: float = inertial_number_parameter()
    strain_rate: float | None = strain_rate_parameter()
    records: int = parameter(500, kind=int, low=2, high=MAX_RECORDS, flag="--records", unset=True,
                             help="history rows over the test (at most one a step)")
    rate_on_current_length: bool = parameter(False, kind=bool, recorded=False,
                                             help="axial rate on the current height")
    servo_max_velocity: float | None = parameter(None, unit="m/s", low=0.0, low_inclusive=False,
                                                 recorded=False,
                                                 help="speed cap of the lateral walls")
    servo_scale_max_velocity: bool = parameter(False, kind=bool, recorded=False,
                                               help="speed cap scaled per axis")
    servo_stiffness_every: int = parameter(1, kind=int, low=1, recorded=False,
                                           help="steps between wall stiffness updates")
    direction: str = parameter("compression", kind=str, choices=SHEAR_DIRECTIONS,
                               flag="--direction",
                               help="axial walls pushed in (compression) or pulled apart "
                                    "(extension), the lateral stress held")
    b: float | None = parameter(None, low=0.0, high=1.0, flag="--b",
                                help="true triaxial compression: hold b = (s2 - s3) / (s1 - s3), "
                                     "s1 axial, s3 = --confining on x, s2 on y (default: "
                                     "s2 = s3)")
    constant_p: bool = parameter(False, kind=bool, flag="--constant-p",
                                 help="hold the mean stress p at --confining while q rises (the "
                                      "lateral stresses follow the axial one)")
    drainage: str = parameter("drained", kind=str, choices=DRAINAGES, flag="--drainage",
                              help="drained: the lateral stress held, the volume free; "
                                   "undrained: the volume held (the lateral walls follow the "
                                   "axial ones), the excess pore pressure of a saturated "
                                   "sample an output; wet, the water content held too")

    def __post_init__(self):
        validate(self)
        if self.b is not None and self.direction != "compression":
            raise fail(self, "b", f"b = {self.b:g} needs --direction compression: b = "
                       "(sigma_2 - sigma_3) / (sigma_1 - sigma_3) is held with sigma_1 on the "
                       "axial walls")
        if self.drainage == "undrained" and (self.b is not None or self.constant_p):
            raise fail(self, "drainage", "drainage = 'undrained' holds the volume with the "
                       "lateral walls: --b and --constant-p, which set their stresses, do not "
                       "apply")

    def rate(self, radius, density, confining):
        """Axial strain rate [1/s]: the given one, or the one of the target inertial number at
        the confining stress [Pa] for spheres of ``radius`` [m] and ``density`` [kg/m^3]."""
        return quasi_static_rate(self.inertial_number, self.strain_rate, radius, density,
                                 confining)

    @property
    def conventional(self):
        """Whether this is the conventional triaxial compression of thesis Ch. 5 (lateral stress
        held, sigma_x = sigma_y)."""
        return (self.direction == "compression" and self.b is None and not self.constant_p
                and self.drainage == "drained")


#: ShearConfig options that reproduce YADE's TriaxialStressController (stiffnessUpdateInterval 10).
YADE_CHOICES = {"rate_on_current_length": True, "servo_scale_max_velocity": True,
                "servo_stiffness_every": 10}


def inertial_number(strain_rate, radius, density, pressure):
    """I = strain_rate * d * sqrt(rho / p), d = 2R (GDR MiDi 2004); SI units."""
    return strain_rate * 2.0 * radius * np.sqrt(density / pressure)


def quasi_static_rate(target, strain_rate, radius, density, pressure):
    """Strain rate [1/s] of a loading stage: ``strain_rate`` when given, else the one giving the
    inertial number ``target`` at ``pressure`` [Pa] (the lowest stress of the stage, where a
    rate is least quasi-static) for spheres of ``radius`` [m] and ``density`` [kg/m^3]."""
    if strain_rate is not None:
        return strain_rate
    return target / inertial_number(1.0, radius, density, pressure)


@dataclass
class BridgeConfig:
    """Capillary bridges of a wet test (docs/physics.md 'The bridge model';
    capillary.CapillaryBridges).

    suction [Pa] > 0 (suction control: imposed; volume control: at formation), or instead
    water_content: gravimetric water content w (a fraction) that volume-controlled bridges
    hold, their formation suction found at wetting (pendular.procedures.water_content) and the liquid
    then a closed amount (``liquid``: 'shared' or 'lost', capillary.CapillaryBridges);
    surface_tension [N/m]; contact_angle [deg] in [0, 90); model: 'exact' (Young–Laplace
    tables) or 'toroidal' (thesis Appendix A, equal spheres); control: 'suction' or 'volume';
    persist: suction-controlled bridges live to their rupture distance instead of breaking when
    contact is lost; roughness: meniscus separation at contact H/R2 (volume control);
    table_resolution: (nodes in suction, nodes in distance) of the tables, None for the model's
    default; wall_bridges: bridges between the spheres and the walls too (suction control,
    pendular.capillary.wall_bridges).
    """

    suction: float | None = parameter(None, unit="Pa", low=0.0, low_inclusive=False,
                                      flag="--suction", help="matric suction")
    surface_tension: float = parameter(SURFACE_TENSION, unit="N/m", low=0.0,
                                       high=MAX_SURFACE_TENSION, low_inclusive=False,
                                       flag="--surface-tension", unset=True,
                                       help="liquid surface tension (wet test)")
    contact_angle: float = parameter(0.0, unit="deg", low=0.0, high=90.0, high_inclusive=False,
                                     flag="--contact-angle", unset=True,
                                     help="wetting angle (wet test)")
    model: str = parameter("exact", kind=str, choices=BRIDGE_MODELS, flag="--bridges",
                           unset=True,
                           help="bridge model of the wet test: exact Young-Laplace tables "
                                "(default) or the toroidal approximation (equal spheres)")
    control: str = parameter("suction", kind=str, choices=CONTROLS,
                             help="what the bridges hold: their suction or their volume")
    persist: bool = parameter(False, kind=bool, flag="--persist-bridges",
                              help="bridges live up to their rupture distance instead of "
                                   "breaking when contact is lost")
    roughness: float = parameter(0.0, low=0.0, high=0.5,
                                 help="meniscus separation of touching spheres H / R2")
    table_resolution: tuple[int, int] | None = parameter(
        None, kind=None, flag="--table-resolution",
        help="bridge table nodes in suction and in distance")
    water_content: float | None = parameter(None, low=0.0, high=1.0, low_inclusive=False,
                                            help="gravimetric water content (a fraction)")
    wall_bridges: bool = parameter(False, kind=bool, flag="--wall-bridges",
                                   help="liquid bridges between the spheres and the walls too "
                                        "(exact sphere-plane solutions; suction control)")
    liquid: str = parameter("shared", kind=str, choices=LIQUID_MODELS[1:], flag="--liquid",
                            unset=True,
                            help="with --water-content: the liquid of a ruptured bridge goes "
                                 "to its grains' other bridges (shared, default) or is lost")

    def __post_init__(self):
        if (self.suction is None) == (self.water_content is None):
            raise ValueError("bridges: give one of suction (Pa) and water_content (a fraction)")
        validate(self)
        if self.water_content is not None and (self.control != "volume"
                                               or self.model != "exact"):
            raise fail(self, "water_content", "water_content needs volume-controlled exact "
                       "bridges (control='volume', model='exact')")
        if self.wall_bridges and (self.control != "suction" or self.model != "exact"):
            raise fail(self, "wall_bridges", "wall_bridges needs suction-controlled exact "
                       "bridges (--suction, not --water-content or an undrained test; not "
                       "--bridges toroidal): volume-controlled sphere-wall bridges are not "
                       "implemented")
        if self.table_resolution is not None:
            if len(self.table_resolution) != 2:
                raise fail(self, "table_resolution", f"table_resolution = "
                           f"{self.table_resolution!r}: two integers (nodes in suction, nodes in "
                           "distance) expected")
            try:
                self.table_resolution = tuple(
                    check_int(f"table_resolution[{k}]", value, low=4, high=MAX_TABLE_NODES // 4)
                    for k, value in enumerate(self.table_resolution))
            except ValueError as error:
                raise fail(self, "table_resolution", str(error)) from None
            nodes = self.table_resolution[0] * self.table_resolution[1]
            if nodes > MAX_TABLE_NODES:
                raise fail(self, "table_resolution", f"table_resolution = "
                           f"{self.table_resolution!r} has {nodes} nodes, outside the valid range "
                           f"[16, {MAX_TABLE_NODES}] (suction nodes x distance nodes)")

    def build(self, suction=None, closed=False):
        """The capillary operation (capillary.CapillaryBridges) of this configuration; with a
        water content, ``suction`` [Pa] is the formation suction found at wetting, and
        ``closed`` builds the bridges with the liquid model ``liquid`` of the loading (a resumed
        run, whose checkpoint holds the liquid's account) instead of the open reservoir of the
        wetting."""
        from pendular.capillary import CapillaryBridges   # a dry run never builds one

        if suction is None:
            if self.suction is None:
                raise ValueError("bridges at a water content: build(suction) needs the "
                                 "formation suction found at wetting")
            suction = self.suction
        table_options = (None if self.table_resolution is None else
                         dict(zip(("n_suction", "n_distance"), self.table_resolution)))
        liquid = self.liquid if closed and self.control == "volume" else "reservoir"
        return CapillaryBridges(suction, surface_tension=self.surface_tension,
                                contact_angle=self.contact_angle, model=self.model,
                                control=self.control, persist=self.persist,
                                roughness=self.roughness, table_options=table_options,
                                liquid=liquid, wall_bridges=self.wall_bridges)


@dataclass
class LaboratoryConfig:
    """What every laboratory test on a prepared sample shares (TriaxialConfig, OedometerConfig,
    IsotropicConfig; pendular.procedures.triaxial.LaboratoryTest): sample, optional bridges,
    outputs.

    sample: preparation and material (pendular.procedures.preparation.PrepareConfig; its
    ``confining`` [Pa] is the isotropic stress the loading path starts from; at least
    MIN_SAMPLE_PARTICLES spheres); bridges: None for a dry test;
    sample_path: start from this saved sample (pendular.dem.sample) instead of preparing one,
    whose count and sizes the test takes where ``sample`` leaves them at their defaults
    (``sized_as_sample``);
    wet_steps: most steps to equilibrate after wetting (or after loading a sample);
    vtk_frames: ParaView frames over the loading (0: none; a path whose length is not known
    before it runs writes one every VTK_RECORDS history rows); vtk_every: steps between frames
    instead (None: from vtk_frames);
    checkpoint_every: steps between checkpoints of the loading (0: none); both at most
    MAX_STAGE_STEPS;
    wetting: how the bridges appear (WETTING_PROTOCOLS; pendular.procedures.triaxial.wet_sample):
    'isotropic' (added to the static sample, re-equilibrated by the servo), 'at-shear'
    (switched on at the first loading step), 'constant-volume' (added with the walls fixed,
    equilibrated, then servoed to the confining stress).
    """

    sample: PrepareConfig = field(default_factory=PrepareConfig)
    bridges: BridgeConfig | None = None
    sample_path: str | None = parameter(None, kind=str, flag="--sample", metavar="PATH",
                                        help="start from this prepared sample (sample.h5) "
                                             "instead of preparing one")
    wet_steps: int = parameter(200000, kind=int, low=1, high=MAX_STAGE_STEPS, flag="--wet-steps",
                               help="most steps to equilibrate the wetted (or loaded) sample")
    vtk_frames: int = parameter(50, kind=int, low=0, flag="--vtk-frames",
                                help="ParaView frames over the loading")
    vtk_every: int | None = parameter(None, kind=int, low=0, high=MAX_STAGE_STEPS,
                                      flag="--vtk-every",
                                      help="steps between ParaView frames of the loading")
    checkpoint_every: int = parameter(0, kind=int, low=0, high=MAX_STAGE_STEPS,
                                      flag="--checkpoint-every", help="steps between checkpoints")
    wetting: str = parameter("isotropic", kind=str, choices=WETTING_PROTOCOLS, flag="--wetting",
                             help="when bridges appear (--suction): added to the static sample "
                                  "and re-equilibrated (isotropic), switched on at the first "
                                  "loading step (at-shear), or added with the walls fixed, then "
                                  "servoed (constant-volume)")

    #: The test in words, for errors ("a triaxial test").
    TEST = "a laboratory test"
    #: Whether the loading holds the sample's volume and water (TriaxialConfig.undrained).
    undrained = False
    #: The options that set the loading's estimated length (``estimated_steps``).
    LENGTH = ()
    #: Fewest spheres of the test, and why.
    MIN_PARTICLES, FEWEST = MIN_SAMPLE_PARTICLES, AVERAGES

    def __post_init__(self):
        if not isinstance(self.sample, PrepareConfig):
            raise TypeError(f"sample must be a PrepareConfig, got {type(self.sample).__name__}")
        if self.bridges is not None and not isinstance(self.bridges, BridgeConfig):
            raise TypeError(f"bridges must be a BridgeConfig or None, got "
                            f"{type(self.bridges).__name__}")
        check_particles(self.sample.particles, self.MIN_PARTICLES, MAX_PARTICLES, self.TEST,
                        self.FEWEST)
        if self.sample.confining <= 0.0:
            # the path's starting stress: the inertial number and the servo need it > 0
            raise fail(self.sample, "confining", f"confining = {self.sample.confining:g} Pa is "
                       f"outside the valid range (0, 1e+07] Pa for {self.TEST}")
        validate(self)
        if self.wetting != "isotropic" and (self.bridges is None
                                            or self.bridges.water_content is not None):
            raise fail(self, "wetting", f"wetting = {self.wetting!r} needs a wet test at a "
                       "suction (--suction > 0)")

    def stage_rates(self):
        """[(where, strain rate [1/s], steps or None)] of the loading's stages that name their
        own rate (a path table's, TablePathConfig); none here: the test's rate is ``rate``."""
        return []

    @property
    def confining(self):
        """Isotropic stress the path starts from [Pa] (the sample's confining stress)."""
        return self.sample.confining

    @property
    def suction(self):
        """Matric suction [Pa]; 0 for a dry test, NaN at a water content (the suction is an
        output)."""
        if self.bridges is None:
            return 0.0
        return math.nan if self.bridges.suction is None else self.bridges.suction

    def strain_per_step(self, rate):
        """Strain [-] of one step at ``rate`` [1/s]: the P-wave step of the mean radius
        (pendular.procedures.preparation.pwave_step; the 'stiffness' rule's step is 1.4-1.5
        times longer on prepared samples). ValueError when it underflows."""
        per_step = rate * pwave_step(self.sample.radius, self.sample)
        if not per_step > 0.0:          # a rate or time step that underflows
            raise ValueError(f"the strain per step, {per_step:g}, is not positive: the strain "
                             "rate (--strain-rate / --inertial-number) or the time step "
                             "(--timestep-safety) is too small to be represented")
        return per_step


#: The fields of a PrepareConfig that a prepared sample fixes: its spheres' count and sizes
#: (the seed draws a spread of radii).
SAMPLE_FIELDS = ("particles", "radius", "radius_spread", "psd", "seed")


def sized_as_sample(sample, path):
    """``sample`` (a PrepareConfig) with the count and sizes (SAMPLE_FIELDS) of the prepared
    sample at ``path`` for the fields at their defaults (not given), read from the
    configuration the sample was prepared with, else from its spheres (count and mean
    radius). A field given keeps its value, which pendular.dem.sample.load_sample then
    refuses when the sample contradicts it. ValueError naming the path for an unreadable
    sample."""
    particles, _, _, stored = load_sample(path)
    radius = particles.radius      # equal spheres: their radius exactly, not a rounded mean
    made = {"particles": len(particles),
            "radius": float(radius[0] if np.all(radius == radius[0]) else np.mean(radius))}
    if isinstance(stored.get("config"), dict):
        try:
            prepared = config_from_dict(stored["config"], f"sample = {path!r}").sample
        except (AttributeError, TypeError, ValueError):
            prepared = None            # written by another tool: its spheres say enough
        if isinstance(prepared, PrepareConfig):
            made = {name: getattr(prepared, name) for name in SAMPLE_FIELDS}
    return dataclasses.replace(sample, **{
        name: value for name, value in made.items()
        if getattr(sample, name) == default_of(PrepareConfig, name)})


@dataclass
class TriaxialConfig(LaboratoryConfig):
    """A drained triaxial test (thesis Ch. 5.2.3): LaboratoryConfig's sample, bridges and
    outputs, and shear: ShearConfig (the confining stress is the lateral stress of the shear).
    """

    shear: ShearConfig = field(default_factory=ShearConfig)

    TEST = "a triaxial test"
    LENGTH = ("--max-strain",)

    def __post_init__(self):
        if not isinstance(self.shear, ShearConfig):
            raise TypeError(f"shear must be a ShearConfig, got {type(self.shear).__name__}")
        super().__post_init__()
        bridges = self.bridges
        if self.undrained and bridges is not None and bridges.control != "volume":
            # the water cannot leave either: bridges of constant volume, formed at the suction
            if bridges.model != "exact" or bridges.persist:
                raise fail(self.shear, "drainage", "drainage = 'undrained' of a wet sample "
                           "holds its water in volume-controlled exact bridges: --bridges "
                           "toroidal and --persist-bridges do not apply")
            self.bridges = dataclasses.replace(bridges, control="volume")

    @property
    def undrained(self):
        """Whether the shear holds the volume (and, wet, the water content)."""
        return self.shear.drainage == "undrained"

    def rate(self):
        """Axial strain rate of the shear [1/s] (ShearConfig.rate at the confining stress)."""
        sample = self.sample
        return self.shear.rate(sample.radius, sample.density, sample.confining)

    def reference_pressure(self):
        """Stress at which the inertial number of the rate is taken [Pa]: the confining."""
        return self.sample.confining

    def shear_steps(self):
        """Steps of the shear estimated before anything runs [-]: max_strain over the strain
        rate times the P-wave step of the mean radius (pendular.procedures.preparation.pwave_step). An
        upper bound for equal spheres: the 'stiffness' rule's step is 1.4-1.5 times longer on
        prepared samples, so the shear takes that much fewer."""
        return self.shear.max_strain / self.strain_per_step(self.rate())

    def estimated_steps(self):
        """Steps of the loading estimated before anything runs (``shear_steps``)."""
        return self.shear_steps()


#: Smallest strain between two history rows of a path of unknown length [-].
MIN_RECORD_STRAIN = 1e-7
#: Largest strain between two history rows of a path of unknown length [-].
MAX_RECORD_STRAIN = 0.01


@dataclass
class PathConfig(LaboratoryConfig):
    """A loading path whose stages end at a stress or at equilibrium, so that its length is
    known only as it runs (OedometerConfig, IsotropicConfig): LaboratoryConfig's fields and
    the rate of its stages, ``strain_rate`` [1/s] or, when None, the one giving
    ``inertial_number`` at the lowest stress of the path (``reference_pressure``);
    ``record_strain``: strain at that rate between two history rows [-] (rows are also
    written at the end of each stage)."""

    inertial_number: float = inertial_number_parameter()
    strain_rate: float | None = strain_rate_parameter()
    record_strain: float = parameter(1e-4, low=MIN_RECORD_STRAIN, high=MAX_RECORD_STRAIN,
                                     flag="--record-strain",
                                     help="strain at the loading rate between history rows "
                                          "(rows also at each stage's end)")

    def rate(self):
        """Strain rate of the path's stages [1/s] (quasi_static_rate)."""
        sample = self.sample
        return quasi_static_rate(self.inertial_number, self.strain_rate, sample.radius,
                                 sample.density, self.reference_pressure())

    def estimated_steps(self):
        """None: the stages end at a stress or at equilibrium."""
        return None

    def record_every(self, dt):
        """Steps of ``dt`` [s] between history rows [-]: ``record_strain`` at ``rate``."""
        return max(1, int(round(self.record_strain / (self.rate() * dt))))

    def path_parameters(self):
        """The path's own options, named as the command's (pendular.procedures.triaxial
        .parameters)."""
        raise NotImplementedError


@dataclass
class OedometerConfig(PathConfig):
    """Oedometric (K0) compression (pendular.procedures.loading.oedometer_stages): the lateral
    walls fixed, the axial ones pushed in at the path's rate until the axial stress is
    ``axial_stress`` [Pa] (above the confining stress the sample starts from), then, with
    ``unload_to`` [Pa] (below ``axial_stress``, above 0), pulled back until it is that."""

    axial_stress: float = parameter(10000.0, unit="Pa", low=0.0, high=1e7,
                                    flag="--axial-stress",
                                    help="axial stress the compression ends at, above "
                                         "--confining")
    unload_to: float | None = parameter(None, unit="Pa", low=0.0, high=1e7, low_inclusive=False,
                                        flag="--unload-to",
                                        help="then unload to this axial stress, below "
                                             "--axial-stress")

    TEST = "an oedometer test"

    def __post_init__(self):
        super().__post_init__()
        confining = self.sample.confining
        if self.axial_stress <= confining:
            raise fail(self, "axial_stress", f"axial_stress = {self.axial_stress:g} Pa is "
                       f"outside the valid range ({confining:g}, 1e+07] Pa: the compression "
                       f"starts from the confining stress (--confining {confining:g} Pa)")
        check_soft(self, "axial_stress", self.axial_stress)
        if self.unload_to is not None and self.unload_to >= self.axial_stress:
            raise fail(self, "unload_to", f"unload_to = {self.unload_to:g} Pa is outside the "
                       f"valid range (0, {self.axial_stress:g}) Pa: an unloading ends below "
                       f"the load (--axial-stress {self.axial_stress:g} Pa)")

    def reference_pressure(self):
        """The lowest axial stress of the path [Pa]: the confining stress, or ``unload_to``."""
        return min(self.sample.confining, self.unload_to or math.inf)

    def path_parameters(self):
        return {"axial_stress": self.axial_stress, "unload_to": self.unload_to}


#: Fewest stresses of an isotropic path: a loading (or unloading) needs two.
MIN_ISOTROPIC_STAGES = 2


@dataclass
class IsotropicConfig(PathConfig):
    """Isotropic loading and unloading in stages (pendular.procedures.loading.isotropic_stages):
    the six walls servoed to each of ``stresses`` [Pa] (each > 0, in any order, at least
    MIN_ISOTROPIC_STAGES) in turn, each stage run until static; the walls move at most at the
    path's rate. ``stage_steps``: most steps of a stage."""

    stresses: list[float] = parameter(
        default_factory=lambda: [500.0, 1000.0, 2000.0, 5000.0, 2000.0, 500.0], many=True,
        unit="Pa", low=0.0, high=1e7, low_inclusive=False, flag="--stresses",
        metavar="P1,P2,...", help="isotropic stresses of the stages, each > 0, in any order")
    stage_steps: int = stage_steps_parameter(2_000_000,
                                             "most steps of a stage to reach equilibrium")

    TEST = "an isotropic test"

    def __post_init__(self):
        super().__post_init__()
        listed = ",".join(f"{v:g}" for v in self.stresses)
        if len(self.stresses) < MIN_ISOTROPIC_STAGES:
            raise fail(self, "stresses", f"stresses = {listed}: at least "
                       f"{MIN_ISOTROPIC_STAGES} stresses [Pa] expected (a loading or unloading "
                       "goes from one to the next)")
        for k in range(1, len(self.stresses)):
            if self.stresses[k] == self.stresses[k - 1]:
                raise fail(self, "stresses", f"stresses = {listed}: stage {k + 1} repeats the "
                           f"{self.stresses[k]:g} Pa of stage {k}; valid: each stress unlike "
                           "the one before (a stage to the stress it holds does nothing)")
        for value in self.stresses:
            check_soft(self, "stresses", value)

    def reference_pressure(self):
        """The lowest stress of the path [Pa]: the confining or the least of ``stresses``."""
        return min(self.sample.confining, *self.stresses)

    def path_parameters(self):
        return {"stresses": ",".join(f"{v:g}" for v in self.stresses),
                "stage_steps": self.stage_steps}


#: Density of water [kg/m^3]: the specific gravity of the grains is their density over it
#: (Gs = rho_s / rho_w), which turns a water content by mass into a water volume.
WATER_DENSITY = 1000.0
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
    at most the pull's steps (``pull_steps``).
    """

    sample: PrepareConfig = field(default_factory=tension_sample)
    cases: list[tuple[float, float]] = parameter(
        default_factory=lambda: [(e, w) for e, w, _ in KIM_2001], kind=None, recorded=False,
        help="(core void ratio, gravimetric water content as a fraction) of each case")
    roughness: float = parameter(KIM_SEPARATION, low=0.0, high=0.5, flag="--roughness",
                                 help="meniscus separation of touching grains H/R (default "
                                      "Kim's sand, as in the regular packing prediction; 0: "
                                      "smooth spheres)")
    form_gap: float = parameter(1.0, low=0.0, high=1.0, flag="--form-gap",
                                help="at wetting, bridges also form across gaps up to this many "
                                     "radii (0: at contacts only; 1: wherever a bridge of the "
                                     "formation suction can exist, docs/direct_tension.md)")
    contact_angle: float = parameter(0.0, unit="deg", low=0.0, high=90.0, high_inclusive=False,
                                     flag="--contact-angle", help="wetting angle")
    surface_tension: float = parameter(CHAPTER4_SURFACE_TENSION, unit="N/m", low=0.0,
                                       high=MAX_SURFACE_TENSION, low_inclusive=False,
                                       flag="--surface-tension",
                                       help="surface tension (thesis Chapter 4's, which the "
                                            "comparison with Kim and the regular packing "
                                            "prediction uses; triaxial and swcc default to "
                                            "Chapter 5's 0.073)")
    inertial_number: float = parameter(1e-3, low=0.0, high=0.01, low_inclusive=False,
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
                "seed": sample.seed, "periodic": sample.periodic}

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


@dataclass
class SwccConfig:
    """The soil-water characteristic curve of a sample (pendular.procedures.swcc): drying through
    ``suctions`` then wetting back, at the sample's confining stress.

    sample: preparation and material (pendular.procedures.preparation.PrepareConfig; its ``confining`` [Pa]
    holds during the path; at least MIN_SAMPLE_PARTICLES spheres); suctions [Pa]: the path's
    stages, ascending and distinct, at least two; surface_tension [N/m]; contact_angle [deg];
    form_gap: at wetting, bridges also form across gaps up to form_gap mean radii (0: at
    contacts only); stage_steps: most steps per stage to reach equilibrium; record_every: steps
    between history records.
    """

    sample: PrepareConfig = field(default_factory=PrepareConfig)
    suctions: list[float] = parameter(
        default_factory=lambda: [3000.0, 10000.0, 30000.0, 100000.0, 300000.0], many=True,
        unit="Pa", low=0.0, low_inclusive=False, flag="--suctions", metavar="S1,S2,...",
        help="suctions of the drying path, ascending; wetting goes back along them")
    surface_tension: float = parameter(SURFACE_TENSION, unit="N/m", low=0.0,
                                       high=MAX_SURFACE_TENSION, low_inclusive=False,
                                       flag="--surface-tension", help="liquid surface tension")
    contact_angle: float = parameter(0.0, unit="deg", low=0.0, high=90.0, high_inclusive=False,
                                     flag="--contact-angle", help="wetting angle")
    form_gap: float = parameter(1.0, low=0.0, high=1.0, flag="--form-gap",
                                help="at wetting, bridges also form across gaps up to this many "
                                     "mean radii (0: at contacts only; 1: wherever a bridge of "
                                     "the lowest suction can exist)")
    stage_steps: int = stage_steps_parameter(200000, "most steps per stage to reach equilibrium")
    record_every: int = parameter(1000, kind=int, low=1, flag="--record-every",
                                  help="steps between history records")

    def __post_init__(self):
        if not isinstance(self.sample, PrepareConfig):
            raise TypeError(f"sample must be a PrepareConfig, got {type(self.sample).__name__}")
        check_particles(self.sample.particles, MIN_SAMPLE_PARTICLES, MAX_PARTICLES, "an SWCC",
                        AVERAGES)
        validate(self)
        if len(self.suctions) < 2 or any(b <= a for a, b in zip(self.suctions,
                                                                   self.suctions[1:])):
            raise fail(self, "suctions", f"suctions = "
                       f"{','.join(f'{s:g}' for s in self.suctions)}: at least two suctions "
                       "[Pa], ascending and distinct, expected (the drying path; wetting goes "
                       "back along it)")
        if self.sample.confining <= 0.0:
            raise fail(self.sample, "confining", f"confining = {self.sample.confining:g} Pa is "
                       "outside the valid range (0, 1e+07] Pa for an SWCC at constant stress")


def check_particles(particles, low, high, test, why):
    """``particles`` as an int; ParameterError naming particles outside [low, high], the
    sample sizes of ``test`` (e.g. 'a triaxial test'), saying ``why`` (the reason for
    ``low``)."""
    count = spec_of(PrepareConfig, "particles").check("particles", particles)
    if not low <= count <= high:
        raise fail(PrepareConfig, "particles", f"particles = {count} is outside the valid range "
                   f"[{low}, {high}] for {test}: {why}")
    return count


def check_soft(config, name, stress, label=None):
    """ParameterError of field ``name`` of the LaboratoryConfig ``config`` when ``stress`` [Pa]
    (the field's value, or the stress called ``label`` made from it) is too large for its
    sample's contacts (pendular.procedures.preparation.check_soft_contacts)."""
    try:
        check_soft_contacts(label or name, stress, config.sample.young)
    except ValueError as error:
        message = str(error) if label is None else \
            f"{name} = {getattr(config, name):g} Pa: {error}"
        raise fail(config, name, message) from None


def check_steps_count(name, value, steps, phase, low=0):
    """ValueError naming ``name`` (an option counting frames or rows of a phase, or the steps
    between them, e.g. '--vtk-frames') when ``value`` exceeds ``steps``, the phase's estimated
    steps: one a step at most. ``phase``: what runs them, e.g. 'the shear'; ``low``: the
    option's own least value, for the valid range."""
    most = max(low, 1, int(steps))
    if value > most:
        raise ValueError(f"{name} = {value} is outside the valid range [{low}, {most}]: "
                         f"{phase} has about {most} steps")


def case_name(void_ratio, water_content):
    """Folder name of a tension case (void ratio [-], water content [-, a fraction]), e.g.
    'e0.72_w1.04'."""
    return f"e{void_ratio:.2f}_w{100 * water_content:.2f}"


# ---------------------------------------------------------------- cyclic triaxial

#: Most cycles of a cyclic triaxial test: liquefaction tests run tens to hundreds of cycles,
#: resilient-modulus tests about 2,000 (AASHTO T 307: up to 1,000 to condition, then 15
#: sequences of 100).
MAX_CYCLES = 10_000
#: Largest axial strain amplitude of a strain-controlled cyclic test [-]: cyclic triaxial tests
#: measure modulus and damping from about 1e-5 to a few % (Kramer 1996, Ch. 6); beyond, the
#: extension half of a cycle pulls the sample apart rather than cycling it.
MAX_CYCLIC_STRAIN = 0.05


@dataclass
class CyclicConfig(PathConfig):
    """Cyclic triaxial loading (pendular.procedures.cyclic.cyclic_stages) from the isotropic
    confining stress sigma_c, the lateral walls servoed at sigma_c, the axial walls driven at
    the path's rate: a first loading to the amplitude, then ``cycles`` cycles (at most
    MAX_CYCLES), each an unloading to minus the amplitude and a reloading back. Exactly one
    amplitude: ``amplitude_q`` [Pa] (stress control: q = sigma_axial - sigma_lateral between
    +A and -A, in (0, sigma_c): at -A the axial stress is sigma_c - A, and walls cannot pull)
    or ``amplitude_strain`` [-] (strain control: the axial strain between +X and -X from the
    start, in [MIN_AXIAL_STRAIN, MAX_CYCLIC_STRAIN]; a run whose axial stress falls to 0
    stops with pendular.procedures.loading.StageFailed)."""

    amplitude_q: float | None = parameter(None, unit="Pa", low=0.0, low_inclusive=False,
                                          flag="--amplitude-q", metavar="PA",
                                          help="stress control: q cycles between +PA and -PA, "
                                               "below --confining (one of --amplitude-q and "
                                               "--amplitude-strain is required)")
    amplitude_strain: float | None = parameter(None, low=MIN_AXIAL_STRAIN,
                                               high=MAX_CYCLIC_STRAIN,
                                               flag="--amplitude-strain", metavar="X",
                                               help="strain control: the axial strain cycles "
                                                    "between +X and -X")
    cycles: int = parameter(10, kind=int, low=1, high=MAX_CYCLES, flag="--cycles",
                            help="cycles after the first loading")

    TEST = "a cyclic triaxial test"
    LENGTH = ("--cycles", "--amplitude-strain")

    def __post_init__(self):
        super().__post_init__()
        if (self.amplitude_q is None) == (self.amplitude_strain is None):
            raise ValueError("amplitude_q, amplitude_strain: give exactly one (stress control: "
                             "q between +-A [Pa]; strain control: the axial strain between "
                             "+-X)")
        confining = self.sample.confining
        if self.amplitude_q is not None:
            if self.amplitude_q >= confining:
                raise fail(self, "amplitude_q", f"amplitude_q = {self.amplitude_q!r} Pa is "
                           f"outside the valid range (0, {confining:g}) Pa: at q = -A the axial "
                           f"stress is --confining ({confining:g} Pa) - A, and walls cannot "
                           "pull")
            check_soft(self, "amplitude_q", confining + self.amplitude_q,
                       "the largest axial stress (--confining + --amplitude-q)")

    @property
    def stress_controlled(self):
        """Whether q (not the axial strain) cycles between the amplitudes."""
        return self.amplitude_q is not None

    def reference_pressure(self):
        """The least mean stress of the path [Pa], where the inertial number is taken: sigma_c
        - A / 3 at q = -A (stress control); 2 sigma_c / 3, its bound while the axial walls
        touch, under strain control."""
        confining = self.sample.confining
        if self.stress_controlled:
            return confining - self.amplitude_q / 3.0
        return 2.0 * confining / 3.0

    def estimated_steps(self):
        """Steps of a strain-controlled path, (1 + 4 cycles) X over the strain of a step;
        None under stress control (its stages end at a stress)."""
        if self.stress_controlled:
            return None
        travel = (1 + 4 * self.cycles) * self.amplitude_strain
        return travel / self.strain_per_step(self.rate())

    def path_parameters(self):
        """The path's own options, named as the command's (pendular.procedures.triaxial
        .parameters)."""
        return {"amplitude_q": self.amplitude_q, "amplitude_strain": self.amplitude_strain,
                "cycles": self.cycles}


# ---------------------------------------------------------------- a path from a table

@dataclass
class TablePathConfig(PathConfig):
    """A loading path read from a table (pendular.procedures.path_table): PathConfig's sample,
    bridges, outputs, rate (``inertial_number`` at the lowest stress of the path, or
    ``strain_rate``: the value of the name 'quasi-static') and row spacing, and ``stages``:
    the table's [[stage]] entries as plain data (numbers, the names 'confining' and
    'quasi-static', groups repeated), built into pendular.procedures.loading.Stage objects by
    ``loading_stages``; ``source``: the table's file, named in errors; ``records``: history
    rows over a path of one stage ending at a strain, as ShearConfig.records (None: a row
    every ``record_strain``)."""

    stages: list = parameter(default_factory=list, kind=None, recorded=False,
                             help="the table's [[stage]] entries, as plain data")
    source: str = parameter("path table", kind=str, help="the table's file, named in errors")
    records: int | None = parameter(None, kind=int, low=2, high=MAX_RECORDS, flag="--records",
                                    help="history rows over a path of one stage ending at a "
                                         "strain, as pendular triaxial's --records (default: a "
                                         "row every --record-strain)")

    TEST = "a loading path"

    def __post_init__(self):
        super().__post_init__()
        stages = self.loading_stages()       # every entry checked, named by file and stage
        if self.records is not None:
            from pendular.procedures.loading import Strain

            if len(stages) != 1 or not isinstance(stages[0].until, Strain):
                raise fail(self, "records", f"records = {self.records} applies to a path of "
                           f"one stage ending at a strain (a triaxial's); {self.source} has "
                           f"{len(stages)} stage(s): leave it out (a row every "
                           "--record-strain)")

    def loading_stages(self):
        """The pendular.procedures.loading.Stage list of the table (ValueError naming the
        source, the entry and the key)."""
        from pendular.procedures.path_table import build_stages

        from pendular.procedures.path_table import wetting_of

        return build_stages(self.stages, self.source, confining=self.sample.confining,
                            rate=self.rate(), young=self.sample.young,
                            wetting=wetting_of(self.bridges))

    def stage_rates(self):
        """[(where, rate, steps)] of each stage of the table that moves an axis: 'FILE: stage
        N', its fastest |strain rate| or |shear rate| [1/s] and, when it ends at a strain
        whose start is known (the path's start, or the end of an earlier stage at a strain
        of that axis, not moved since), its steps estimated before anything runs (the strain
        to go over the strain of a step, ``strain_per_step``), else None."""
        from pendular.procedures.loading import ShearStrain, Strain
        from pendular.procedures.path_table import labelled_stages

        start = {"x": 0.0, "y": 0.0, "z": 0.0, "shear": 0.0}      # None: not known
        found = []
        for label, stage in labelled_stages(self.stages, self.source,
                                            confining=self.sample.confining, rate=self.rate()):
            rates = {**stage.strain_rate, "shear": stage.shear_rate}
            until = stage.until
            ends = isinstance(until, (Strain, ShearStrain))
            axis = "shear" if isinstance(until, ShearStrain) else getattr(until, "axis", None)
            steps = None
            if ends and start[axis] is not None:
                try:
                    steps = (abs(until.value - start[axis])
                             / self.strain_per_step(abs(rates[axis])))
                except ValueError:              # a strain per step that underflows
                    steps = math.inf
            for name in start:
                if ends and name == axis:
                    start[name] = until.value
                elif rates.get(name, 0.0) != 0.0 or name in stage.stress or name in stage.free:
                    start[name] = None
            fastest = max(abs(value) for value in rates.values())
            if fastest > 0.0:
                found.append((f"{self.source}: {label}", fastest, steps))
        return found

    def reference_pressure(self):
        """The lowest stress of the path [Pa] (path_table.lowest_stress): the confining
        stress or a lower target of a stage."""
        from pendular.procedures.path_table import lowest_stress

        return lowest_stress(self.stages, self.source, self.sample.confining)

    def path_parameters(self):
        """The path's own options, named as the command's (pendular.procedures.triaxial
        .parameters)."""
        return {"path": self.source, "records": self.records}


# ---------------------------------------------------------------- simple shear

#: Largest final shear strain of a simple shear [-]: laboratory simple shear stops by 20-30 %
#: (ASTM D6528: 20 %), a ring shear measures the residual strength over several; the
#: Lees–Edwards cell (pendular.dem.cell) has no end, but beyond 10 a run only repeats the
#: residual state.
MAX_SHEAR_STRAIN = 10.0


@dataclass
class SimpleShearConfig(PathConfig):
    """Simple shear, x with z, of a sample in a periodic cell (pendular.procedures.simple_shear;
    Lees–Edwards, pendular.dem.cell): from the isotropic confining stress, z brought to
    ``normal_stress`` [Pa] (None: the confining stress) with x and y held, then sheared to the
    shear strain ``max_strain`` [-] (in [MIN_AXIAL_STRAIN, MAX_SHEAR_STRAIN]) at that normal
    stress (drained), or with ``constant_volume`` with the cell's lengths held. The shear rate
    gamma_dot [1/s] is ``strain_rate`` or the one giving ``inertial_number`` at the lower of
    the confining and normal stresses (quasi_static_rate); ``record_strain``: shear strain
    between two history rows; ``stage_steps``: most steps of the consolidation to the normal
    stress. The sample must be periodic (walls cannot shear it)."""

    # the shear rate gamma_dot [1/s]: PathConfig's strain rate, under the command's name
    strain_rate: float | None = parameter(None, unit="1/s", low=0.0, high=MAX_STRAIN_RATE,
                                          low_inclusive=False, flag="--shear-rate",
                                          help="shear rate gamma_dot (overrides "
                                               "--inertial-number)")
    record_strain: float = parameter(4e-4, low=MIN_RECORD_STRAIN, high=MAX_RECORD_STRAIN,
                                     flag="--record-strain",
                                     help="shear strain between history rows")
    normal_stress: float | None = parameter(None, unit="Pa", low=0.0, high=1e7,
                                            low_inclusive=False, flag="--normal-stress",
                                            help="normal stress sigma_zz of the shear "
                                                 "(default: --confining)")
    constant_volume: bool = parameter(False, kind=bool, flag="--constant-volume",
                                      help="shear at constant volume (the cell's lengths held; "
                                           "the normal stress an output) instead of at "
                                           "--normal-stress")
    max_strain: float = parameter(0.2, low=MIN_AXIAL_STRAIN, high=MAX_SHEAR_STRAIN,
                                  flag="--max-strain", help="final shear strain gamma")
    stage_steps: int = stage_steps_parameter(
        2_000_000, "most steps of the consolidation to --normal-stress")

    TEST = "a simple shear test"
    LENGTH = ("--max-strain",)
    MIN_PARTICLES, FEWEST = MIN_SIMPLE_SHEAR_PARTICLES, NARROW_CELL

    def __post_init__(self):
        super().__post_init__()
        if not self.sample.periodic:
            raise fail(self.sample, "periodic", "periodic = False: a simple shear needs a "
                       "periodic cell (--periodic; Lees–Edwards images), walls cannot shear a "
                       "sample")
        if self.normal_stress is None:
            self.normal_stress = self.sample.confining
        check_soft(self, "normal_stress", self.normal_stress)

    @property
    def consolidates(self):
        """Whether z is first brought from the confining to the normal stress."""
        return self.normal_stress != self.sample.confining

    def reference_pressure(self):
        """The lower of the confining and normal stresses [Pa], where the inertial number of
        the shear rate is taken."""
        return min(self.sample.confining, self.normal_stress)

    def estimated_steps(self):
        """Steps of the shear, max_strain over the shear strain of a step (the consolidation,
        which ends at equilibrium, not counted)."""
        return self.max_strain / self.strain_per_step(self.rate())

    def path_parameters(self):
        """The path's own options, named as the command's (pendular.procedures.triaxial
        .parameters)."""
        return {"normal_stress": self.normal_stress, "constant_volume": self.constant_volume,
                "max_strain": self.max_strain, "stage_steps": self.stage_steps}


# ---------------------------------------------------------------- JSON form

#: Dataclasses a configuration may nest, by name (JSON ``type`` tags).
CONFIG_TYPES = {kind.__name__: kind for kind in
                (PrepareConfig, ShearConfig, BridgeConfig, TriaxialConfig, OedometerConfig,
                 IsotropicConfig, TensionConfig, SwccConfig, CyclicConfig,
                 TablePathConfig, SimpleShearConfig)}


def config_to_dict(config):
    """Plain-JSON form of a (nested) configuration dataclass, with its type and the schema
    version: {"type": ..., "schema_version": ..., "fields": {...}}."""
    def plain(value):
        if dataclasses.is_dataclass(value):
            return {"type": type(value).__name__,
                    "fields": {f.name: plain(getattr(value, f.name))
                               for f in dataclasses.fields(value)}}
        if isinstance(value, tuple):
            return list(value)
        if isinstance(value, np.generic):
            return value.item()
        return value

    data = plain(config)
    data["schema_version"] = CONFIG_SCHEMA_VERSION
    return data


def config_from_dict(data, source="configuration"):
    """The configuration dataclass of ``config_to_dict``'s output, validated; ValueError naming
    ``source`` (e.g. a file path) for another schema version or a malformed layout."""
    if not isinstance(data, dict) or "schema_version" not in data:
        raise ValueError(f"{source}: no pendular configuration (schema_version missing); it was "
                         "written by pendular before 0.2 — prepare the sample again")
    if data["schema_version"] != CONFIG_SCHEMA_VERSION:
        raise ValueError(f"{source}: configuration schema_version {data['schema_version']!r} "
                         f"is not this pendular's {CONFIG_SCHEMA_VERSION}")

    def build(value):
        if isinstance(value, dict) and "type" in value and "fields" in value:
            kind = CONFIG_TYPES.get(value["type"])
            if kind is None:
                raise ValueError(f"{source}: unknown configuration type {value['type']!r}")
            names = {f.name for f in dataclasses.fields(kind)}
            unknown = set(value["fields"]) - names
            if unknown:
                raise ValueError(f"{source}: {value['type']} has no field(s) {sorted(unknown)}")
            fields = {k: build(v) for k, v in value["fields"].items()}
            if "table_resolution" in fields and fields["table_resolution"] is not None:
                fields["table_resolution"] = tuple(fields["table_resolution"])
            return kind(**fields)
        return value

    return build({k: v for k, v in data.items() if k != "schema_version"})


def config_json(config):
    """The configuration as a JSON string (sorted keys: equal configurations, equal text)."""
    return json.dumps(config_to_dict(config), sort_keys=True)


def stored_config(path: str, key: str) -> dict | None:
    """The configuration dict stored under ``key`` in the config attribute of a pendular HDF5
    file (sample.h5), or None when absent or unreadable."""
    import h5py

    if not os.path.isfile(path):
        return None
    try:
        with h5py.File(path, "r") as handle:
            return json.loads(handle.attrs["config"]).get(key)
    except (OSError, KeyError, ValueError, TypeError, AttributeError, RecursionError):
        return None


def same_config(stored: dict | None, config: Any) -> bool:
    """Whether a stored configuration dict equals ``config`` (``config_json``). The stored one
    is read back through ``config_from_dict`` first, so that a run stored before a field was
    added (whose default keeps the former behaviour) equals a configuration with that default."""
    if stored is None:
        return False
    try:
        stored = config_to_dict(config_from_dict(stored))
    except (ValueError, TypeError, KeyError, AttributeError, ArithmeticError, RecursionError):
        return False
    return json.dumps(stored, sort_keys=True) == config_json(config)


def sample_made_with(path: str, sample: PrepareConfig) -> bool:
    """Whether the saved sample ``path`` was prepared with the PrepareConfig ``sample``."""
    return same_config(stored_config(path, "sample"), sample)

