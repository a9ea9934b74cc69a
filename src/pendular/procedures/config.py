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

from pendular.capillary import (BRIDGE_MODELS, CONTROLS, LIQUID_MODELS, MAX_CONTACT_ANGLE,
    MAX_ROUGHNESS, SURFACE_TENSION)
from pendular.dem.sample import load_sample
from pendular.procedures.loading_clusters import (entry_suction_parameter, liquid_parameter,
    refuse_clusters, refuse_entry_suction)
from pendular.dem.walls import ConstantStrainRate
from pendular.procedures.preparation import (MAX_PARTICLES, PrepareConfig, check_soft_contacts,
    pwave_step)
from pendular.utils.parameters import default_of, fail, parameter, spec_of, validate
from pendular.utils.validate import check_int


#: Most nodes (suction x distance) of a bridge table: about 1 kB of memory per node over the
#: ten radius ratios, 7 times the exact default (350 x 80); beyond, building takes hours.
MAX_TABLE_NODES = 200_000
#: Fewest nodes of a bridge table along each of its axes (suction, distance).
MIN_TABLE_NODES = 4

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


def inertial_number_parameter():
    """The field of a loading's target inertial number [-] (ShearConfig, PathConfig)."""
    return parameter(3e-4, low=0.0, high=1.0, low_inclusive=False, flag="--inertial-number",
                     help="target inertial number setting the strain rate")


def stage_steps_parameter(default, help):
    """The field of the most steps of a stage run to equilibrium [-] (``default``; ``help``:
    which stage)."""
    return parameter(default, kind=int, low=1, high=MAX_STAGE_STEPS, flag="--stage-steps",
                     help=help)


def contact_angle_parameter(help="wetting angle", **changes):
    """The field of a wet test's wetting angle [deg], in [0, MAX_CONTACT_ANGLE) (``help``;
    ``changes``: e.g. ``unset``)."""
    return parameter(0.0, unit="deg", low=0.0, high=MAX_CONTACT_ANGLE, high_inclusive=False,
                     flag="--contact-angle", help=help, **changes)


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

    The path of the shear (pendular.procedures.triaxial.shear_stage): ``direction``
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
    contact_angle: float = contact_angle_parameter("wetting angle (wet test)", unset=True)
    model: str = parameter("exact", kind=str, choices=BRIDGE_MODELS, flag="--bridges",
                           unset=True,
                           help="bridge model of the wet test: exact Young-Laplace tables "
                                "(default) or the toroidal approximation (equal spheres)")
    control: str = parameter("suction", kind=str, choices=CONTROLS,
                             help="what the bridges hold: their suction or their volume")
    persist: bool = parameter(False, kind=bool, flag="--persist-bridges",
                              help="bridges live up to their rupture distance instead of "
                                   "breaking when contact is lost")
    roughness: float = parameter(0.0, low=0.0, high=MAX_ROUGHNESS,
                                 help="meniscus separation of touching spheres H / R2")
    table_resolution: tuple[int, int] | None = parameter(
        None, kind=None, flag="--table-resolution",
        help="bridge table nodes in suction and in distance")
    water_content: float | None = parameter(None, low=0.0, high=1.0, low_inclusive=False,
                                            help="gravimetric water content (a fraction)")
    wall_bridges: bool = parameter(False, kind=bool, flag="--wall-bridges",
                                   help="liquid bridges between the spheres and the walls too "
                                        "(exact sphere-plane solutions; suction control)")
    liquid: str = parameter("shared", kind=str, choices=LIQUID_MODELS[1:],
                            flag="--rupture-liquid",
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
                    check_int(f"table_resolution[{k}]", value, low=MIN_TABLE_NODES,
                              high=MAX_TABLE_NODES // MIN_TABLE_NODES)
                    for k, value in enumerate(self.table_resolution))
            except ValueError as error:
                raise fail(self, "table_resolution", str(error)) from None
            nodes = self.table_resolution[0] * self.table_resolution[1]
            if nodes > MAX_TABLE_NODES:
                raise fail(self, "table_resolution", f"table_resolution = "
                           f"{self.table_resolution!r} has {nodes} nodes, outside the valid range "
                           f"[{MIN_TABLE_NODES ** 2}, {MAX_TABLE_NODES}] (suction nodes x "
                           "distance nodes)")

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
    IsotropicConfig; pendular.procedures.laboratory.LaboratoryTest): sample, optional bridges,
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
    wetting: how the bridges appear (WETTING_PROTOCOLS; pendular.procedures.equilibrium.wet_sample):
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
    liquid: str = liquid_parameter("the sample wetted from dry at --suction or "
                                   "--water-content, the pore units updated as the packing "
                                   "deforms")
    entry_suction: str = entry_suction_parameter()

    #: The test in words, for errors ("a triaxial test").
    TEST = "a laboratory test"
    #: Whether the loading holds the sample's volume and water (TriaxialConfig.undrained).
    undrained = False
    #: The options that set the loading's estimated length (``estimated_steps``).
    LENGTH = ()
    #: Fewest spheres of the test, and why.
    MIN_PARTICLES, FEWEST = MIN_SAMPLE_PARTICLES, AVERAGES
    #: The loading in words, for errors ("the shear").
    LOADING = "the loading"

    def rate_settings(self):
        """The dataclass whose ``strain_rate`` field sets the loading's rate (its option's
        flag names it in errors): the configuration itself, a triaxial's shear."""
        return self

    def loading_parameters(self):
        """The loading's own options, named as the command's (pendular.procedures.laboratory
        .parameters)."""
        raise NotImplementedError

    def __post_init__(self):
        if not isinstance(self.sample, PrepareConfig):
            raise TypeError(f"sample must be a PrepareConfig, got {type(self.sample).__name__}")
        if self.bridges is not None and not isinstance(self.bridges, BridgeConfig):
            raise TypeError(f"bridges must be a BridgeConfig or None, got "
                            f"{type(self.bridges).__name__}")
        check_particles(self.sample.particles, self.MIN_PARTICLES, MAX_PARTICLES, self.TEST,
                        self.FEWEST)
        check_loaded_confining(self.sample, self.TEST)
        validate(self)
        if self.wetting != "isotropic" and (self.bridges is None
                                            or self.bridges.water_content is not None):
            raise fail(self, "wetting", f"wetting = {self.wetting!r} needs a wet test at a "
                       "suction (--suction > 0)")
        refuse_entry_suction(self)
        if self.liquid == "clusters":
            refused = refuse_clusters(self)
            if refused is not None:
                raise fail(self, "liquid", refused)
            if not self.bridges.persist and self.bridges.water_content is None:
                self.bridges = dataclasses.replace(self.bridges, persist=True)

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
    configuration the sample was prepared with (a test's ``config``, or the ``sample`` a
    campaign stores with its samples), else from its spheres (count and mean radius). The
    spheres alone may be an ulp off the radius asked (the preparation rescales them to it), so
    a stored configuration comes first. A field given keeps its value, which
    pendular.dem.sample.load_sample then refuses when the sample contradicts it. ValueError
    naming the path for an unreadable sample."""
    particles, _, _, stored = load_sample(path)
    radius = particles.radius      # equal spheres: their radius exactly, not a rounded mean
    made = {"particles": len(particles),
            "radius": float(radius[0] if np.all(radius == radius[0]) else np.mean(radius))}
    for key in ("config", "sample"):
        if not isinstance(stored.get(key), dict):
            continue
        try:
            prepared = config_from_dict(stored[key], f"sample = {path!r}")
            prepared = prepared.sample if key == "config" else prepared
        except (AttributeError, TypeError, ValueError):
            prepared = None            # written by another tool: its spheres say enough
        if isinstance(prepared, PrepareConfig):
            made = {name: getattr(prepared, name) for name in SAMPLE_FIELDS}
            break
    return dataclasses.replace(sample, **{
        name: value for name, value in made.items()
        if getattr(sample, name) == default_of(PrepareConfig, name)})


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
        """The path's own options, named as the command's."""
        raise NotImplementedError

    def loading_parameters(self):
        """The path's own options (``path_parameters``) and its rate's."""
        return {**self.path_parameters(), "inertial_number": self.inertial_number,
                "strain_rate": self.strain_rate, "record_strain": self.record_strain}


#: Density of water [kg/m^3]: the specific gravity of the grains is their density over it
#: (Gs = rho_s / rho_w), which turns a water content by mass into a water volume.
WATER_DENSITY = 1000.0


#: The confining stress of a test that runs at it or loads from it: PrepareConfig's, 0 left out
#: (the servo and the inertial number of the rate need a stress).
LOADED_CONFINING = dataclasses.replace(spec_of(PrepareConfig, "confining"), low_inclusive=False)


def check_loaded_confining(sample, test):
    """ParameterError naming the confining stress of the PrepareConfig ``sample`` outside
    LOADED_CONFINING's range, for ``test`` (e.g. 'a triaxial test')."""
    if not sample.confining > LOADED_CONFINING.low:
        raise fail(sample, "confining", f"confining = {sample.confining:g} Pa is outside the "
                   f"valid range {LOADED_CONFINING.valid_range()} Pa for {test}")


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
        sample = config.sample
        check_soft_contacts(label or name, stress, sample.young, sample.contact, sample.poisson)
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


# ---------------------------------------------------------------- cyclic triaxial


# ---------------------------------------------------------------- a path from a table


# ---------------------------------------------------------------- simple shear

#: Largest final shear strain of a simple shear [-]: laboratory simple shear stops by 20-30 %
#: (ASTM D6528: 20 %), a ring shear measures the residual strength over several; the
#: Lees–Edwards cell (pendular.dem.cell) has no end, but beyond 10 a run only repeats the
#: residual state.
MAX_SHEAR_STRAIN = 10.0


# ---------------------------------------------------------------- JSON form

#: Dataclasses a configuration may nest, by name (JSON ``type`` tags): the shared ones, and each
#: test's configuration as its module registers it (``registered``).
CONFIG_TYPES = {kind.__name__: kind for kind in (PrepareConfig, ShearConfig, BridgeConfig)}


def registered(kind):
    """Class decorator of a test's configuration dataclass: stored and read back by its name
    (config_to_dict, config_from_dict)."""
    CONFIG_TYPES[kind.__name__] = kind
    return kind


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

