"""Sample preparation (thesis Ch. 5.2.2, docs/physics.md 'Walls, servo and preparation').

1. A random non-overlapping cloud in a fixed frictionless box, friction ``prep_friction`` (0.5°).
2. Radii grown homogeneously until the mean wall stress reaches ``prep_stress`` (5 kPa) and the
   packing is in quasi-static equilibrium (the engine's controls pendular.dem.growth, which the
   GPU runs too).
3. The whole sample rescaled so that the mean radius is the nominal one. With linear springs
   kn = E R, forces scale as R^2 and stresses are unchanged.
4. Friction set to the test value (18°) and the rolling and twisting resistance, if any,
   switched on (pendular.dem.rolling), the six walls servoed at ``prep_stress``, then the
   target lowered slowly to the confining stress, and equilibrium again.

With ``gravity`` the particles have their weight in every phase (pendular.dem.gravity).

With ``periodic`` the box is a periodic cell (pendular.dem.cell) instead of six walls: the same
procedure, the cell's stress (the Love–Weber stress of the contacts) servoed instead of the
walls'; no wall layers.

The phases, by name (PREPARATION_PHASES): "growth" (2), "friction" (equilibrium at the test
friction, 4), "unload" (4), "equilibrate" (at the confining stress, 4). Writers passed to
``prepare_sample`` watch all of them (e.g. ParaView frames, pendular.io.vtk.VtkWriter).
"""

import math
from dataclasses import dataclass

import numpy as np

from pendular.dem import growth
from pendular.dem.cell import PeriodicCell
from pendular.dem.contact_law import MAX_FRICTION_DEG, MAX_SHEAR_RATIO, ContactForces
from pendular.dem.grading import MAX_RADIUS_SPREAD, check_grading_curve, grading, sample_radii
from pendular.dem.gravity import MAX_GRAVITY, Gravity
from pendular.dem.hertz_mindlin import CONTACT_LAWS, DampedLinearForces, HertzMindlinForces
from pendular.dem.material import POISSON_RANGE, Material
from pendular.dem.growth import RadiusGrowth
from pendular.dem.integrate import Integrator
from pendular.dem.measure import coordination, porosity, unbalanced_force
from pendular.dem.cell_list import spatial_order
from pendular.dem.cloud import MAX_SEED, random_cloud
from pendular.dem.neighbors import NeighborList
from pendular.dem.rolling import MAX_RESISTANCE, RollingResistance
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.timestep import (TIMESTEP_RULES, critical_timestep, pwave_timestep,
    rayleigh_timestep)
from pendular.utils.parameters import ParameterError, fail, parameter, spec_of, validate
from pendular.utils.progress import PhaseBar
from pendular.procedures.progress import equilibrium_bar, growth_bar
from pendular.utils.validate import check_int
from pendular.dem.wall_friction import WALL_FRICTION_RANGE, wall_law
from pendular.dem.wall_rolling import wall_resistance
from pendular.dem.walls import StressServo
from pendular.homogenize.on_the_fly import homogenized


#: Names of the phases of ``prepare_sample``, in order (module docstring).
PREPARATION_PHASES = ("growth", "friction", "unload", "equilibrate")

#: Changes when the same PrepareConfig prepares a different sample (2: particles numbered
#: along a space-filling curve; 3: a contact lost on a neighbour-list rebuild step forgets
#: its shear spring; 4: the radius growth's skin no longer follows a skin_factor above 0.3);
#: caches of prepared samples key on it.
PREPARATION_VERSION = 4


#: Largest stress / young of a sample: linear springs kn = E R hold a stress sigma with
#: overlaps of about 8 sigma / E times the radius at the most loaded contact (measured on
#: prepared samples), so 0.02 keeps every overlap below about 16 % of the radius.
MAX_STRESS_OVER_YOUNG = 0.02

#: Largest sample: about 1 kB of state per sphere and hours per 1e-3 of strain at 1e6 spheres
#: on a few cores; beyond, memory and run time are out of reach.
MAX_PARTICLES = 10_000_000
#: Largest stress a test's options may set [Pa] (confining, axial, normal, stages' stresses).
MAX_STRESS = 1e7
#: Sphere radii a run accepts [m]: grains of a micron to a metre. Outside, the strain rate of
#: an inertial number, the box and the masses leave the floating-point range a run needs.
RADIUS_RANGE = (1e-6, 1.0)


def check_soft_contacts(name, stress, young, contact="linear", poisson=None):
    """ValueError naming ``name`` (a stress [Pa]) and ``young`` [Pa] when stress / young
    exceeds MAX_STRESS_OVER_YOUNG (overlaps too large for the linear contact model). With
    ``contact`` 'hertz-mindlin' (grains of Poisson ratio ``poisson``) the bound is the same,
    a loose one: the most loaded contact then overlaps by hertz_overlap, up to 0.46 of the
    radius at the bound, 0.18 at the 5 kPa growth of the default young (1 MPa, soft grains
    on which Hertz–Mindlin is validated against YADE); grains of a real modulus lie far
    below it, and check_feasible bounds their young from above."""
    if stress <= MAX_STRESS_OVER_YOUNG * young:
        return
    if contact == "hertz-mindlin":
        raise ValueError(
            f"{name} = {stress:g} Pa is outside the valid range [0, "
            f"{MAX_STRESS_OVER_YOUNG * young:g}] Pa for Hertz–Mindlin grains of --young "
            f"{young:g} Pa: stress / young must stay below {MAX_STRESS_OVER_YOUNG:g} (the most "
            f"loaded contact would overlap by {hertz_overlap(stress, young, poisson):.2g} of "
            f"the radius); lower {name}, or give --young in [{stress / MAX_STRESS_OVER_YOUNG:g}"
            ", inf) Pa")
    raise ValueError(
        f"{name} = {stress:g} Pa is outside the valid range [0, {MAX_STRESS_OVER_YOUNG * young:g}]"
        f" Pa for young = {young:g} Pa: stress / young must stay below "
        f"{MAX_STRESS_OVER_YOUNG:g} (overlaps of about 8 stress / young times the radius); "
        f"lower {name} or raise young to at least {stress / MAX_STRESS_OVER_YOUNG:g} Pa")


#: Force of a prepared sample's most loaded contact over stress x radius^2 [-]: the linear
#: springs' largest overlaps of about 8 stress / young times the radius (kn = E R).
PEAK_FORCE_OVER_STRESS = 8.0


def hertz_overlap(stress, young, poisson):
    """Overlap / radius [-] of the most loaded contact of equal Hertz–Mindlin spheres of
    Young's modulus ``young`` [Pa] and Poisson ratio ``poisson`` in a sample at ``stress``
    [Pa]: Hertz's delta = (3 F / (4 E* sqrt(R*)))^(2/3) (Johnson 1985, Eq. 4.23) with
    R* = R / 2, E* = E / (2 (1 - nu^2)) and F = PEAK_FORCE_OVER_STRESS stress R^2, i.e.
    delta / R = (12 sqrt(2) (1 - nu^2) stress / young)^(2/3): (15 stress / young)^(2/3) at
    nu = 0.3, far more than the linear law's 8 stress / young at small stress / young."""
    return (_hertz_load(poisson) * stress / young) ** (2.0 / 3.0)


def hertz_stress_over_young(overlap, poisson):
    """stress / young [-] at which the most loaded Hertz–Mindlin contact overlaps by
    ``overlap`` times the radius (the inverse of hertz_overlap)."""
    return overlap ** 1.5 / _hertz_load(poisson)


def _hertz_load(poisson):
    """12 sqrt(2) (1 - nu^2) = 3 F / (4 E* sqrt(R*) R^1.5) per stress / young (hertz_overlap)."""
    return PEAK_FORCE_OVER_STRESS * 1.5 * np.sqrt(2.0) * (1.0 - poisson ** 2)


@dataclass
class PrepareConfig:
    """Sample and preparation parameters (SI, angles in degrees); defaults are thesis Table 5.2.

    Sizes (pendular.dem.grading): equal spheres of ``radius`` [m]; with ``radius_spread`` S > 0 radii
    uniform in radius (1 ± S), ``radius`` their mean; with ``psd``, a grading curve
    ((diameter [m], percent passing by mass), ...), the curve's own sizes, ``radius`` set on
    creation to their mean. Largest / smallest radius at most pendular.dem.grading.MAX_RADIUS_RATIO.
    ``periodic``: the sample fills a periodic cell (pendular.dem.cell) instead of a box of six walls.
    The time step is ``timestep_safety`` times the estimate of ``timestep_rule`` (``timestep``):
    'stiffness' (default), the critical step of the contacts (pendular.dem.timestep), 1.4-1.5 times
    the P-wave estimate on prepared samples; 'pwave', YADE's P-wave estimate of the smallest
    sphere (the thesis's, and pendular's former default; across six 2,000-sphere samples both
    give the same peaks within the scatter between samples, docs/seeds_timestep_rule.md).
    ``rolling_friction``, ``twisting_friction``: the coefficients of the rolling and twisting
    resistance (pendular.dem.rolling; 0: none), switched on with the test friction;
    ``gravity`` [m/s^2]: the weight along -z in every phase (pendular.dem.gravity; 0: none;
    walls only).
    ``skin_factor``: the neighbour list's Verlet skin / mean radius, a speed knob only (between
    walls results are bit-identical for any skin; in a periodic cell they differ at round-off,
    docs/periodic.md); 0.1 shears faster than 0.3 (fewer pairs, still rare rebuilds;
    docs/performance.md).
    """

    particles: int = parameter(10000, kind=int, low=2, high=MAX_PARTICLES, flag="--particles",
                               help="number of spheres")
    radius: float = parameter(0.024e-3, unit="m", low=RADIUS_RANGE[0], high=RADIUS_RANGE[1],
                              flag="--radius", help="sphere radius, the mean radius of a graded "
                              "sample")
    radius_spread: float = parameter(0.0, low=0.0, high=MAX_RADIUS_SPREAD, flag="--radius-spread",
                                     help="radii uniform in R(1 ± S), R = --radius")
    psd: tuple | None = parameter(None, kind=None, help="grading curve ((diameter [m], percent "
                                  "passing by mass), ...)")
    porosity: float = parameter(0.40, low=0.30, high=0.60, flag="--porosity",
                                help="porosity of the initial cloud box (not with --sample)")
    young: float = parameter(1e6, unit="Pa", low=0.0, low_inclusive=False, flag="--young",
                             help="YADE young E, kn = E R")
    shear_ratio: float = parameter(0.3, low=0.0, high=MAX_SHEAR_RATIO,
                                   help="contact stiffness ratio ks / kn")
    contact: str = parameter("linear", kind=str, choices=CONTACT_LAWS, flag="--contact",
                             help="contact law: linear springs (kn = E R, ks = 0.3 kn), or "
                                  "Hertz-Mindlin from the grains' E and --poisson, its time "
                                  "step the Rayleigh-wave rule (docs/physics.md)")
    poisson: float = parameter(0.3, low=POISSON_RANGE[0], high=POISSON_RANGE[1],
                               low_inclusive=False, high_inclusive=False, flag="--poisson",
                               help="Poisson ratio of the grains (Hertz-Mindlin)")
    restitution: float = parameter(1.0, low=0.0, high=1.0, low_inclusive=False,
                                   flag="--restitution",
                                   help="coefficient of restitution of a contact, normal and "
                                        "tangential: viscous damping, 1 none")
    friction_deg: float = parameter(18.0, unit="deg", low=0.0, high=MAX_FRICTION_DEG,
                                    high_inclusive=False, flag="--friction",
                                    help="contact friction")
    prep_friction_deg: float = parameter(
        0.5, unit="deg", low=0.0, high=MAX_FRICTION_DEG, high_inclusive=False,
        flag="--prep-friction",
        help="contact friction during the radius growth (thesis 0.5; higher gives a looser "
             "sample; not with --sample)")
    rolling_friction: float = parameter(
        0.0, low=0.0, high=MAX_RESISTANCE, flag="--rolling-friction",
        help="rolling resistance coefficient mu_r: limit moment mu_r R* Fn (pendular.dem."
             "rolling; 0: none; with the test friction, not during the radius growth)")
    twisting_friction: float = parameter(
        0.0, low=0.0, high=MAX_RESISTANCE, flag="--twisting-friction",
        help="twisting resistance coefficient mu_t: limit moment mu_t R* Fn about the normal "
             "(0: none)")
    density: float = parameter(2650.0, unit="kg/m^3", low=0.0, low_inclusive=False,
                               help="grain density")
    wall_friction: float = parameter(
        0.0, unit="deg", low=WALL_FRICTION_RANGE[0], high=WALL_FRICTION_RANGE[1],
        high_inclusive=False, flag="--wall-friction",
        help="friction angle between the spheres and the walls, in every phase (pendular.dem."
             "wall_friction; 0: frictionless walls)")
    wall_young: float | None = parameter(
        None, unit="Pa", low=0.0, high=math.inf, low_inclusive=False, high_inclusive=False,
        flag="--wall-young",
        help="Young's modulus of the walls (Hertz-Mindlin; default: rigid walls, E = inf; "
             "pendular.dem.material)")
    wall_poisson: float | None = parameter(
        None, low=POISSON_RANGE[0], high=POISSON_RANGE[1], low_inclusive=False,
        high_inclusive=False, flag="--wall-poisson",
        help="Poisson ratio of the walls, with --wall-young (default: the grains' --poisson)")
    wall_restitution: float | None = parameter(
        None, low=0.0, high=1.0, low_inclusive=False, flag="--wall-restitution",
        help="coefficient of restitution of the walls; a sphere-wall contact's is the mean of "
             "the grains' and the walls' (default: the grains' --restitution)")
    wall_rolling_friction: float = parameter(
        0.0, low=0.0, high=MAX_RESISTANCE, flag="--wall-rolling-friction",
        help="rolling resistance coefficient mu_r of the walls: limit moment mu_r R Fn on a "
             "sphere of radius R (pendular.dem.wall_rolling; 0: none; with the test friction)")
    wall_twisting_friction: float = parameter(
        0.0, low=0.0, high=MAX_RESISTANCE, flag="--wall-twisting-friction",
        help="twisting resistance coefficient mu_t of the walls: limit moment mu_t R Fn about "
             "the wall's normal (0: none)")
    gravity: float = parameter(0.0, unit="m/s^2", low=0.0, high=MAX_GRAVITY, flag="--gravity",
                               help="gravitational acceleration along -z (0: none; walls "
                                    "only, not with --periodic)")
    damping: float = parameter(0.2, low=0.0, high=1.0, high_inclusive=False, flag="--damping",
                               help="Cundall local damping")
    timestep_safety: float = parameter(0.7, low=0.0, high=1.0, low_inclusive=False,
                                       flag="--timestep-safety",
                                       help="time step as a fraction of the --timestep-rule "
                                            "estimate")
    timestep_rule: str = parameter("stiffness", kind=str, choices=TIMESTEP_RULES,
                                   flag="--timestep-rule",
                                   help="time step estimate: the critical step of the contacts "
                                        "(pendular.dem.timestep; default), or YADE's P-wave "
                                        "estimate of the smallest sphere")
    prep_stress: float = parameter(5000.0, unit="Pa", low=0.0, low_inclusive=False,
                                   help="mean wall stress that ends the radius growth")
    confining: float = parameter(750.0, unit="Pa", low=0.0, high=MAX_STRESS, flag="--confining",
                                 help="isotropic stress the loading starts from, the lateral "
                                      "stress of a triaxial")
    seed: int = parameter(0, kind=int, low=0, high=MAX_SEED, flag="--seed",
                          help="random seed of the sample")
    skin_factor: float = parameter(0.1, low=0.0, high=2.0, low_inclusive=False,
                                   flag="--skin-factor",
                                   help="Verlet skin of the neighbour list / radius")
    equilibrium_unbalanced: float = parameter(0.01, low=0.0, low_inclusive=False,
                                              recorded=False,
                                              help="unbalanced force of a static sample")
    stress_tolerance: float = parameter(0.01, low=0.0, low_inclusive=False, recorded=False,
                                        help="relative error of a servoed wall stress at "
                                             "equilibrium")
    unload_steps: int = parameter(10000, kind=int, low=20, recorded=False,
                                  help="steps lowering the stress to the confining stress")
    periodic: bool = parameter(False, kind=bool, flag="--periodic", recorded=False,
                               help="a periodic cell instead of six walls: no wall layers; the "
                                    "cell's stress (Love-Weber, contacts and bridges) servoed "
                                    "and its lengths driven at the strain rates")

    def __post_init__(self):
        validate(self)
        if self.gravity > 0.0 and self.periodic:
            raise fail(self, "gravity", f"gravity = {self.gravity:g} m/s^2 is outside the "
                       "valid range [0, 0] in a periodic cell (--periodic: no floor to carry "
                       "the weight); leave out gravity or the periodic cell")
        if self.wall_friction > 0.0 and self.periodic:
            raise fail(self, "wall_friction", f"wall_friction = {self.wall_friction:g} deg is "
                       "outside the valid range [0, 0] in a periodic cell (--periodic: no "
                       "walls); leave out the wall friction or the periodic cell")
        self._check_wall_material()
        if self.psd is not None:
            if self.radius_spread > 0.0:
                raise fail(self, "radius_spread",
                           f"radius_spread = {self.radius_spread:g} and a psd given: valid is "
                           "one of them (the grading curve sets the sizes)")
            self.psd = check_grading_curve(self.psd)
            mean = float(np.mean(self.radii()))
            radius = spec_of(self, "radius")
            try:
                self.radius = radius.check("radius", mean)
            except ParameterError:          # the curve's sizes, not a --radius given
                raise ParameterError("psd", f"psd: the grading curve's mean radius, {mean:.3g} "
                                     f"m, is outside the valid range {radius.valid_range()} m "
                                     "of a sphere's radius", "--psd") from None
        for name in ("prep_stress", "confining"):
            try:
                check_soft_contacts(name, getattr(self, name), self.young, self.contact,
                                    self.poisson)
            except ValueError as error:
                raise fail(self, name, str(error)) from None

    def _check_wall_material(self):
        """ParameterError naming a wall material field given in a periodic cell (no walls),
        --wall-young with the linear law (its wall is a sphere of the grains' springs),
        --wall-poisson without --wall-young (a rigid wall's plays no part), or walls less
        stiff in contact than two grains (their overlaps, then larger than the grains', would
        escape the bounds the sample's stresses are checked against)."""
        given = [name for name in ("wall_young", "wall_poisson", "wall_restitution")
                 if getattr(self, name) is not None]
        given += [name for name in ("wall_rolling_friction", "wall_twisting_friction")
                  if getattr(self, name) > 0.0]
        if given and self.periodic:
            raise fail(self, given[0], f"{given[0]} = {getattr(self, given[0]):g} applies to "
                       "walls; valid: none in a periodic cell (--periodic: no walls)")
        if self.wall_poisson is not None and self.wall_young is None:
            raise fail(self, "wall_poisson", f"wall_poisson = {self.wall_poisson:g} needs "
                       "wall_young: a rigid wall's Poisson ratio plays no part")
        if self.wall_young is None:
            return
        if self.contact != "hertz-mindlin":
            raise fail(self, "wall_young", f"wall_young = {self.wall_young:g} Pa applies to "
                       "Hertz-Mindlin contacts; valid: none with the linear law (its wall is a "
                       "sphere of the grains' springs, kn = E R)")
        wall = self.wall_material()
        least = self.young * (1.0 - wall.poisson ** 2) / (1.0 - self.poisson ** 2)
        if self.wall_young < least:
            raise fail(self, "wall_young", f"wall_young = {self.wall_young:g} Pa is outside "
                       f"the valid range [{least:g}, inf) Pa: walls at least as stiff in "
                       "contact as two grains (young (1 - wall_poisson^2) / (1 - poisson^2)), "
                       "whose overlaps the sample's stress bounds hold")

    def grain_material(self):
        """The grains' Material (pendular.dem.material) at the test friction."""
        return Material(self.young, self.poisson, self.density, self.friction_deg,
                        self.rolling_friction, self.restitution)

    def wall_material(self):
        """The walls' Material: rigid unless wall_young, of wall_poisson (the grains' Poisson
        ratio unless given), wall_friction, wall_restitution (the grains' unless given),
        wall_rolling_friction and wall_twisting_friction (pendular.dem.wall_rolling; 0 by
        default: no moment on the walls), driven (infinite density)."""
        return Material(math.inf if self.wall_young is None else self.wall_young,
                        self.poisson if self.wall_poisson is None else self.wall_poisson,
                        math.inf, self.wall_friction, self.wall_rolling_friction,
                        self.restitution if self.wall_restitution is None
                        else self.wall_restitution, self.wall_twisting_friction)

    @property
    def graded(self):
        """Whether the spheres have unequal radii (a spread or a grading curve)."""
        return self.radius_spread > 0.0 or self.psd is not None

    def radii(self):
        """The sample's radii [m] after preparation (its mean is ``radius``; pendular.dem.grading.
        sample_radii from ``seed``), in the order drawn: the preparation then numbers the
        particles along a space-filling curve."""
        return sample_radii(self.particles, self.radius, self.radius_spread, self.psd,
                            self.seed)


#: The share of the Rayleigh-wave step a Hertz–Mindlin scene runs at (times
#: timestep_safety): the Rayleigh step is one contact's, and a packing's grains touch several
#: others, so 20-40 % of it is the usual choice (Thornton 2015); 0.3 x 0.7 = 0.21.
RAYLEIGH_SHARE = 0.3


def pwave_step(radius, config):
    """timestep_safety times the P-wave estimate (YADE's PWaveTimeStep) of the spheres of
    ``radius`` [m] with ``config``'s material [s]; with Hertz–Mindlin contacts, times
    RAYLEIGH_SHARE of their Rayleigh-wave step (pendular.dem.timestep.rayleigh_timestep),
    whatever the rule."""
    if config.contact == "hertz-mindlin":
        return config.timestep_safety * RAYLEIGH_SHARE * rayleigh_timestep(
            radius, config.young, config.poisson, config.density)
    return config.timestep_safety * pwave_timestep(radius, config.young, config.density)


def timestep(sim, config):
    """dt [s] = timestep_safety times the estimate of ``config.timestep_rule``: the P-wave
    estimate of the current radii, or the critical step of the contacts of ``sim``
    (pendular.dem.timestep.critical_timestep; the P-wave estimate while nothing touches);
    with Hertz–Mindlin contacts the Rayleigh-wave step (pwave_step)."""
    if config.timestep_rule == "stiffness" and config.contact == "linear":
        critical = critical_timestep(sim, config.young, config.shear_ratio)
        if np.isfinite(critical):
            return config.timestep_safety * critical
    return pwave_step(sim.particles.radius, config)


class GrowthTimeStep(growth.GrowthTimeStep):
    """The radius growth's time step (pendular.dem.growth.GrowthTimeStep) under the
    'stiffness' rule, with ``config``'s timestep_safety, young and density: pwave_step of the
    current radii at every neighbour-list rebuild."""

    def __init__(self, config):
        super().__init__(config.timestep_safety, config.young, config.density)


def static(unbalanced=0.01, tolerance=0.01):
    """Predicate (a function of sim): the unbalanced force is at most ``unbalanced`` and every
    StressServo's walls hold their target within ``tolerance`` (relative). A device run
    holding the state measures it there (pendular.homogenize.on_the_fly.homogenized): only the
    walls come back."""

    def done(sim):
        if homogenized(sim)["unbalanced_force"] > unbalanced:
            return False
        sim.fetch("walls")
        # the servos' targets are the host's (set between runs), read without the state
        for servo in (op for op in sim.peek("controls") if isinstance(op, StressServo)):
            error = np.abs(sim.walls.stress()[list(servo.axes)] - servo.target)
            if np.any(error > tolerance * max(servo.target, 1e-12)):
                return False
        return True

    return done


def equilibrated(config):
    """``static`` with the thresholds of a PrepareConfig (equilibrium_unbalanced,
    stress_tolerance)."""
    return static(config.equilibrium_unbalanced, config.stress_tolerance)


def contact_forces(config, friction_deg):
    """The contact law of ``config`` at ``friction_deg`` [deg]: the linear law
    (ContactForces), damped where its ``restitution`` is below 1 (DampedLinearForces), or
    Hertz–Mindlin (pendular.dem.hertz_mindlin)."""
    if config.contact == "hertz-mindlin":
        return HertzMindlinForces(config.young, config.poisson, config.restitution,
                                  friction_deg)
    if config.restitution < 1.0:
        return DampedLinearForces(config.young, config.shear_ratio, config.restitution,
                                  friction_deg)
    return ContactForces(config.young, config.shear_ratio, friction_deg)


def dry_simulation(particles, walls, config, dt, skin, friction_deg, controls, threads=None,
                   device="cpu", resistance=True):
    """The scene of a dry sample, time step ``dt`` [s]: neighbour list of ``skin`` [m],
    contacts of ``config``'s law at ``friction_deg`` [deg] (contact_forces), wall contacts of
    the same law with the walls' material, ``config.wall_material()``
    (pendular.dem.wall_friction.wall_law; none in a periodic cell), the weight (``config.gravity``
    > 0), the rolling and twisting resistance (``resistance`` and one of ``config``'s
    coefficients > 0: ``resisting``; on the walls, one of the walls' > 0:
    pendular.dem.wall_rolling.wall_resistance), the given wall ``controls``, leapfrog; its runs
    on ``device`` ("cpu" or "gpu"). A scene pays only for what it uses: without gravity and
    resistance it holds the contacts and the walls alone."""
    forces = [contact_forces(config, friction_deg)]
    if not walls.periodic:
        forces.append(wall_law(forces[0], config.young, config.wall_material()))
    if config.gravity > 0.0:
        forces.append(Gravity(config.gravity))
    if resistance:
        forces.extend(resisting(config, forces[0], walls))
    return Simulation(particles, walls, dt,
                      neighbors=NeighborList(skin),
                      forces=forces,
                      controls=controls,
                      integrator=Integrator(config.damping),
                      threads=threads, device=device)


def resisting(config, contact, walls):
    """The rolling and twisting resistance of ``config`` as a list of forces: one
    RollingResistance when its rolling_friction or twisting_friction is above 0, and inside
    ``walls`` (not a periodic cell) one WallRollingResistance of the contact law ``contact``
    when its wall_rolling_friction or wall_twisting_friction is above 0
    (pendular.dem.wall_rolling.wall_resistance); else none."""
    forces = []
    if config.rolling_friction > 0.0 or config.twisting_friction > 0.0:
        forces.append(RollingResistance(config.rolling_friction, config.twisting_friction))
    if not walls.periodic:
        forces.extend(wall_resistance(contact, config.wall_material()))
    return forces


def servoed_simulation(particles, walls, config, target, threads=None):
    """A static sample's simulation: dry scene at the test friction, six walls servoed at
    ``target`` [Pa]. Used to continue from a saved sample."""
    dt = pwave_step(particles.radius, config)
    servo = StressServo("xyz", target, max_velocity=servo_speed(walls, dt))
    sim = dry_simulation(particles, walls, config, dt,
                         config.skin_factor * float(np.mean(particles.radius)),
                         config.friction_deg, [servo], threads)
    sim.dt = timestep(sim, config)
    return sim


def rescale(sim, factor):
    """Scale all lengths by ``factor`` (stresses unchanged: forces scale as factor^2)."""
    p = sim.particles
    p.position *= factor
    p.radius *= factor
    p.update_mass()
    p.velocity[:] = 0.0
    p.angular_velocity[:] = 0.0
    sim.walls.position *= factor
    sim.contacts.shear_force *= factor ** 2
    sim.operation(NeighborList).rebuild(sim)


#: Verlet skin / radius of the radius growth, whatever ``skin_factor``: every sphere grows each
#: step and the list is rebuilt as the surfaces move, so a thicker skin than the test's pays
#: there (docs/performance.md). One value for every sample: GrowthTimeStep sets the step at
#: the rebuilds, so the sample depends on it.
GROWTH_SKIN_FACTOR = 0.3


def prepare_sample(config, *, progress=True, max_steps=2_000_000, threads=None, writers=(),
                   device="cpu"):
    """Run the preparation of thesis Ch. 5.2.2; return (Simulation at the confining stress, report).

    The returned simulation is the dry scene with the six walls servoed at the confining
    stress (``sim.controls``); ``report`` gives porosity, coordination and steps. ValueError
    naming the phase when one ends at ``max_steps`` without reaching its target.
    ``writers``: operations that only read the state (e.g. pendular.io.vtk.VtkWriter), appended
    to the simulation's writers for the whole preparation and removed before it returns; a
    writer with an attribute ``phase`` has it set to the running phase's name
    (PREPARATION_PHASES) when the phase starts. They change no result.
    ``device``: where the phases run, "cpu" or "gpu" (docs/gpu.md): each phase's run copies
    the state to the device and back (the rescaling and the change of controls between them
    run on the host); the returned simulation's runs go on there (set its ``device`` to move
    them).
    """
    if not isinstance(config, PrepareConfig):
        raise TypeError(f"config must be a PrepareConfig, got {type(config).__name__}")
    max_steps = check_int("max_steps", max_steps, low=1)
    label = "prepare" if progress else None
    radii = config.radii()
    if config.graded:
        solid = 4.0 / 3.0 * np.pi * float(np.sum(radii ** 3))
    else:       # the product, not the sum: equal-sphere samples stay bit-identical
        solid = config.particles * 4.0 / 3.0 * np.pi * config.radius ** 3
    edge = (solid / (1.0 - config.porosity)) ** (1.0 / 3.0)
    # cloud at 60 % of the final radii (solid fraction ~0.13): sequential insertion is easy
    cloud_radius = 0.6 * radii
    lo = np.zeros(3)
    hi = np.full(3, edge)
    position = random_cloud(config.particles, cloud_radius, lo, hi, config.seed)
    # numbered along a space-filling curve: neighbours near in memory for the whole test
    order = spatial_order(position, 2.0 * float(radii.max()))
    particles = Particles(position[order], cloud_radius[order], config.density)
    walls = (PeriodicCell if config.periodic else Walls).box(lo, hi)
    growth = [RadiusGrowth(config.prep_stress, max_rate=1e-4)]
    if config.timestep_rule == "stiffness" and config.contact == "linear":
        growth.append(GrowthTimeStep(config))
    sim = dry_simulation(particles, walls, config, pwave_step(particles.radius, config),
                         GROWTH_SKIN_FACTOR * config.radius,
                         config.prep_friction_deg, growth, threads, device, resistance=False)
    writers = list(writers)
    sim.writers.extend(writers)
    done = equilibrated(config)

    def grown(s):
        stress = float(np.mean(s.fetch("walls").walls.stress()))
        return (abs(stress - config.prep_stress) <= 0.02 * config.prep_stress and done(s))

    def status(s):
        s.fetch()
        return {"sigma": f"{np.mean(s.walls.stress()):.0f}/{config.prep_stress:g}Pa",
                "n": f"{porosity(s.particles, s.walls):.3f}",
                "unbal": f"{unbalanced_force(s.particles, s.contacts):.3f}"
                         f"/{config.equilibrium_unbalanced:g}"}

    _enter(writers, "growth")
    steps = {"growth": sim.run(max_steps, until=grown, check_every=200,
                               progress=growth_bar(label and "grow radii", config.prep_stress),
                               status=status)}
    _require(grown(sim), "radius growth", steps["growth"], status(sim), config)
    rescale(sim, config.radius / float(np.mean(sim.particles.radius)))
    sim.neighbors.skin = config.skin_factor * config.radius
    servo = StressServo("xyz", config.prep_stress, max_velocity=servo_speed(sim.walls, sim.dt))
    sim.controls = [servo]
    sim.dt = timestep(sim, config)
    sim.operation(ContactForces).friction_deg = config.friction_deg
    # with the test friction, as in a loaded sample
    sim.forces.extend(resisting(config, sim.forces[0], sim.walls))
    _enter(writers, "friction")
    steps["friction"] = sim.run(max_steps, until=done, check_every=200,
                                progress=equilibrium_bar(label and "set friction",
                                                         config.equilibrium_unbalanced,
                                                         config.stress_tolerance),
                                status=status)
    _require(done(sim), "equilibrium at the test friction", steps["friction"], status(sim),
             config)
    start = servo.target
    stages = 20
    _enter(writers, "unload")
    each = config.unload_steps // stages
    bar = PhaseBar(label and "unload", each * stages)      # one bar over the stages
    try:
        for stage in range(1, stages + 1):
            servo.target = start + (config.confining - start) * stage / stages
            bar.update(sim, sim.run(each))
    finally:
        bar.close()
    steps["unload"] = each * stages
    _enter(writers, "equilibrate")
    steps["equilibrate"] = sim.run(max_steps, until=done, check_every=200,
                                   progress=equilibrium_bar(label and "equilibrate",
                                                            config.equilibrium_unbalanced,
                                                            config.stress_tolerance),
                                   status=status)
    _require(done(sim), "equilibrium at the confining stress", steps["equilibrate"],
             status(sim), config)
    sim.writers = [op for op in sim.writers if not any(op is w for w in writers)]
    report = {
        "porosity": porosity(sim.particles, sim.walls),
        "coordination": coordination(sim.contacts, len(sim.particles)),
        "unbalanced_force": unbalanced_force(sim.particles, sim.contacts),
        "sigma_wall": sim.walls.stress().tolist(),
        "steps": steps,
        "dt": sim.dt,
        "timestep": timestep_description(config),
        "grading": grading(sim.particles.radius),
        "periodic": sim.walls.periodic,
    }
    return sim, report


def timestep_description(config):
    """How ``config`` sets the time step, in words (reports)."""
    if config.contact == "hertz-mindlin":
        return (f"{config.timestep_safety} x {RAYLEIGH_SHARE} x Rayleigh-wave time step "
                "pi R_min sqrt(rho / G) / (0.1631 nu + 0.8766)")
    if config.timestep_rule == "stiffness":
        return (f"{config.timestep_safety} x the critical time step of the contacts "
                "(pendular.dem.timestep; radius growth: P-wave estimate of the current radii)")
    return f"{config.timestep_safety} x P-wave time step min R / sqrt(E / rho)"


def _enter(writers, phase):
    """Tell the ``writers`` that have a ``phase`` attribute that ``phase`` starts."""
    for writer in writers:
        if hasattr(writer, "phase"):
            writer.phase = phase


def _require(reached, phase, steps, status, config):
    """ValueError naming the step limit, what the preparation ``phase`` reached and the
    settings that set its length, when it ended at its step limit without reaching its
    target (a run never continues from a sample that is not in equilibrium)."""
    if not reached:
        raise ValueError(
            f"max_steps = {steps} is outside the valid range for this sample: preparation "
            f"{phase} not reached ({', '.join(f'{k} {v}' for k, v in status.items())}); the "
            f"time step falls as 1/sqrt(young) (young = {config.young:g} Pa, timestep_safety = "
            f"{config.timestep_safety:g}) and the servo settles slowly at low stress "
            f"(confining = {config.confining:g} Pa)")


def servo_speed(walls, dt):
    """Servo speed cap [m/s]: a wall may travel 1e-4 of the box per time step ``dt`` [s]."""
    return 1e-4 * float(np.mean(walls.lengths())) / dt
