"""Loading paths: stages of per-axis stress or strain-rate control, run one after the other.

A ``Stage`` says, for each axis x, y, z (z axial), either a stress target [Pa, compression
positive], held by the stress servo (pendular.dem.walls.StressServo: the two walls of the axis,
or the periodic cell's length), or a strain rate [1/s, compression positive; 0 holds the walls
where they are] (pendular.dem.walls.ConstantStrainRate); optionally a mixed condition on the
axes given neither (``MixedStress``): a constant mean stress p = (sigma_x + sigma_y +
sigma_z) / 3 (``mean_stress``), a constant b = (sigma_2 - sigma_3) / (sigma_1 - sigma_3) with
sigma_1 on z and sigma_3 on x (``b``), or both; and an end (``until``): ``Strain`` (the
engineering strain of an axis, from the start of the path), ``Stress`` (the stress of a
strain-driven axis reaching a value) or ``Static`` (equilibrium). With ``volume =
"constant"`` the lateral axes x and y move so that the box keeps its volume while z is driven
at its strain rate (pendular.dem.walls.ConstantVolume: an undrained shear of a saturated
sample). A stage may change the water of a wet sample (pendular.procedures.hydraulic): a new
``suction`` [Pa], stepped or ramped at ``suction_rate`` [Pa/s], or a new ``water_content``
[%]. In a periodic cell a stage
may also shear x with z at ``shear_rate`` gamma_dot (simple shear, Lees–Edwards:
pendular.dem.cell), to an end ``ShearStrain`` (the shear strain gamma imposed since the start of
the path). ``LoadingPath`` runs the stages of a static sample in turn and records one
history. Rates follow the inertial-number rule of the triaxial
(pendular.procedures.config.quasi_static_rate); a stage that ends at equilibrium moves its
servoed walls at most at ``max_strain_rate``.

The paths of the laboratory:

- ``shear_stage``: the triaxial shear of thesis Ch. 5.2.3 (lateral walls at the confining
  stress, axial walls at the rate of ShearConfig, to the final strain), in compression or
  extension, at a constant b or a constant mean stress, or undrained (at constant volume);
- ``oedometer_stages``: lateral walls fixed, axial compression to a stress, then unloading;
- ``isotropic_stages``: the six walls servoed to each stress in turn, each stage until static;
- ``simple_shear_stages`` (pendular.procedures.simple_shear): a periodic cell brought to a
  normal stress on z (x and y held), then sheared, x with z, at that stress (drained) or at
  constant volume.

Their summaries: ``oedometer_summary`` (K0, constrained modulus, compression and swelling
indices against the axial stress), ``isotropic_summary`` (e against log p at each stage's
end, compression and swelling indices). Stresses compression positive [Pa]; strains
compression positive.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pendular.dem import mixed_stress
from pendular.dem.cell import ConstantShearRate
from pendular.dem.mixed_stress import StageFailed
from pendular.dem.record import HistoryRecorder
from pendular.dem.walls import AXES, ConstantStrainRate, ConstantVolume, StressServo
from pendular.homogenize.invariants import deviator_stress, lateral_stress, mean_stress
from pendular.procedures.columns import capillary_operation, history_columns
from pendular.procedures.config import MAX_AXIAL_STRAIN, MAX_SHEAR_STRAIN, MAX_STRAIN_RATE
from pendular.procedures.guards import SampleGuard
from pendular.procedures.hydraulic import SuctionChange, WaterContentChange
from pendular.procedures.preparation import servo_speed, static
from pendular.procedures.progress import equilibrium_bar, stress_bar
from pendular.utils.validate import check_int, check_positive, check_range

#: The axes by name, in order (x, y lateral; z axial).
AXIS_NAMES = tuple(AXES)
#: A path of unknown length writes a ParaView frame every this many history rows.
VTK_RECORDS = 10
#: What a stage's ``volume`` may hold: "constant" (x and y keep the box's volume).
VOLUME_CONTROLS = ("constant",)
#: Largest suction a stage may name [Pa] (the bridge tables refuse far less), and its largest
#: rate of change [Pa/s].
MAX_SUCTION = 1e9
MAX_SUCTION_RATE = 1e12


# ---------------------------------------------------------------- ends of a stage

@dataclass
class Strain:
    """End when the engineering strain of ``axis`` (1 - L / L0, L0 at the start of the path,
    compression positive) reaches ``value`` [-]; the axis must be driven at a strain rate of
    the sign of the change. The stage then runs a fixed number of steps."""

    value: float
    axis: str = "z"

    def __post_init__(self):
        self.axis = _axis_name("until strain axis", self.axis)
        self.value = check_range("until strain", self.value, -MAX_AXIAL_STRAIN,
                                 MAX_AXIAL_STRAIN)


@dataclass
class Stress:
    """End when the stress of ``axis`` reaches ``value`` [Pa]: from below when the axis is
    compressed (strain rate > 0), from above when it is unloaded. The stage fails
    (StageFailed) if the axis's strain reaches +-``strain_limit`` [-] first."""

    value: float
    axis: str = "z"
    strain_limit: float = MAX_AXIAL_STRAIN

    def __post_init__(self):
        self.axis = _axis_name("until stress axis", self.axis)
        self.value = check_range("until stress", self.value, 0.0, unit="Pa")
        self.strain_limit = check_range("until strain_limit", self.strain_limit, 0.0,
                                        MAX_AXIAL_STRAIN, low_inclusive=False)


@dataclass
class ShearStrain:
    """End when the shear strain gamma of x with z (pendular.dem.cell, the integral of the
    shear rate from the start of the path) reaches ``value`` [-]; the stage must shear at a
    ``shear_rate`` of the sign of the change, and then runs a fixed number of steps."""

    value: float

    def __post_init__(self):
        self.value = check_range("until shear strain", self.value, -MAX_SHEAR_STRAIN,
                                 MAX_SHEAR_STRAIN)


@dataclass
class Static:
    """End at equilibrium: the unbalanced force at most ``unbalanced`` and every servoed axis
    within ``tolerance`` (relative) of its target (pendular.procedures.preparation.static),
    checked every ``check_every`` steps of the stage; the stage fails after ``max_steps``."""

    max_steps: int = 200000
    unbalanced: float = 0.01
    tolerance: float = 0.01
    check_every: int = 200

    def __post_init__(self):
        self.max_steps = check_int("until static max_steps", self.max_steps, low=1)
        self.unbalanced = check_positive("until static unbalanced", self.unbalanced)
        self.tolerance = check_positive("until static tolerance", self.tolerance)
        self.check_every = check_int("until static check_every", self.check_every, low=1)


def _axis_name(name, axis):
    if axis not in AXIS_NAMES:
        raise ValueError(f"{name} = {axis!r} is not one of {AXIS_NAMES}")
    return axis


# ---------------------------------------------------------------- a stage

@dataclass
class Stage:
    """One stage of a loading path (module docstring).

    stress: {axis: target [Pa]}; strain_rate: {axis: rate [1/s]}, compression positive, 0 for
    walls held; every axis in one of them, except those a mixed condition sets:
    ``mean_stress`` [Pa] (the axes given neither share 3 p less the other stresses) and/or
    ``b`` in [0, 1] (sigma_1 on z, driven at a positive rate; with b alone, sigma_3 is x's
    stress and y is set; with both, x and y are set). until: Strain, Stress, Static or
    ShearStrain; max_strain_rate: largest strain rate of the servoed walls [1/s] (None: the
    path's servo speed), the quasi-static bound of a stage the servo drives; shear_rate:
    gamma_dot [1/s] of x with z, a simple shear of a periodic cell (pendular.dem.cell; walls
    refuse it when the path starts), ending with ``until`` ShearStrain, or any end but
    Static; volume: "constant" (VOLUME_CONTROLS), x and y given neither a stress nor a strain
    rate, moved so that the box keeps the volume it has when the stage starts while z is
    driven at a non-zero strain rate (an undrained shear). The water of a wet sample
    (pendular.procedures.hydraulic): ``suction`` [Pa] of suction-controlled bridges, imposed
    at the stage's first step or, with ``suction_rate`` [Pa/s] > 0, ramped to (a Static end
    is checked once the ramp is over), or ``water_content`` [%, of the grains' mass, as
    --water-content] of a closed amount of liquid, set at the first step.
    """

    stress: dict = field(default_factory=dict)
    strain_rate: dict = field(default_factory=dict)
    until: Strain | Stress | Static | ShearStrain = field(default_factory=Static)
    mean_stress: float | None = None
    b: float | None = None
    max_strain_rate: float | None = None
    shear_rate: float = 0.0
    volume: str | None = None
    suction: float | None = None
    suction_rate: float | None = None
    water_content: float | None = None

    def __post_init__(self):
        self.stress = {_axis_name("stress axis", axis): check_range(
            f"stress[{axis!r}]", value, 0.0, unit="Pa") for axis, value in self.stress.items()}
        self.strain_rate = {_axis_name("strain_rate axis", axis): check_range(
            f"strain_rate[{axis!r}]", value, -MAX_STRAIN_RATE, MAX_STRAIN_RATE, unit="1/s")
            for axis, value in self.strain_rate.items()}
        both = sorted(set(self.stress) & set(self.strain_rate))
        if both:
            raise ValueError(f"axis {', '.join(both)}: give a stress or a strain rate, not both")
        if not isinstance(self.until, (Strain, Stress, Static, ShearStrain)):
            raise TypeError(f"until = {self.until!r}: a Strain, Stress, Static or ShearStrain "
                            "expected")
        self.shear_rate = check_range("shear_rate", self.shear_rate, -MAX_STRAIN_RATE,
                                      MAX_STRAIN_RATE, unit="1/s")
        if self.mean_stress is not None:
            self.mean_stress = check_positive("mean_stress", self.mean_stress, "Pa")
        if self.b is not None:
            self.b = check_range("b", self.b, 0.0, 1.0)
        if self.max_strain_rate is not None:
            self.max_strain_rate = check_range("max_strain_rate", self.max_strain_rate, 0.0,
                                               MAX_STRAIN_RATE, low_inclusive=False, unit="1/s")
        self._check_water()
        self._check_mixed()
        self._check_until()

    @property
    def free(self):
        """The axes a mixed condition sets (neither a stress nor a strain rate given)."""
        return tuple(a for a in AXIS_NAMES if a not in self.stress and a not in self.strain_rate)

    @property
    def mixed(self):
        """The axes a mixed condition of stresses sets: ``free``, unless the volume does."""
        return () if self.volume is not None else self.free

    def _check_water(self):
        """The stage's volume and water keys, each in its range."""
        if self.volume is not None and self.volume not in VOLUME_CONTROLS:
            raise ValueError(f"volume = {self.volume!r}; valid: "
                             f"{', '.join(repr(v) for v in VOLUME_CONTROLS)} (or leave it out)")
        if self.suction is not None:
            self.suction = check_range("suction", self.suction, 0.0, MAX_SUCTION,
                                       low_inclusive=False, unit="Pa")
        if self.suction_rate is not None:
            if self.suction is None:
                raise ValueError(f"suction_rate = {self.suction_rate!r} needs a suction, the "
                                 "target of the ramp")
            self.suction_rate = check_range("suction_rate", self.suction_rate, 0.0,
                                            MAX_SUCTION_RATE, low_inclusive=False, unit="Pa/s")
        if self.water_content is not None:
            if self.suction is not None:
                raise ValueError("suction and water_content: give one (suction-controlled "
                                 "bridges hold a suction, a closed amount of liquid a water "
                                 "content)")
            self.water_content = check_range("water_content", self.water_content, 0.0, 100.0,
                                             low_inclusive=False, unit="%")

    def _check_mixed(self):
        free = self.free
        if self.volume is not None:
            if free != ("x", "y") or self.mean_stress is not None or self.b is not None:
                raise ValueError(f"volume = {self.volume!r} moves x and y to hold the volume: "
                                 "give them neither a stress nor a strain rate (nor a "
                                 "mean_stress or b), and z a strain rate")
            if self.strain_rate.get("z", 0.0) == 0.0 or self.shear_rate != 0.0:
                raise ValueError(f"volume = {self.volume!r} needs z driven at a non-zero strain "
                                 "rate, and no shear_rate (the lateral walls follow the axial "
                                 "ones)")
            return
        if self.mean_stress is None and self.b is None:
            if free:
                raise ValueError(f"axis {', '.join(free)} has neither a stress nor a strain "
                                 "rate: give one (or a mean_stress or b that sets it)")
            return
        if self.strain_rate.get("z", 0.0) == 0.0:
            raise ValueError("a mean_stress or b condition needs z driven at a non-zero strain "
                             "rate (the axial walls load, the lateral ones follow)")
        if self.b is not None:
            if self.strain_rate["z"] < 0.0:
                raise ValueError(f"b = {self.b:g} needs z compressed (strain rate > 0): b is "
                                 "defined with sigma_1 on z")
            if self.mean_stress is not None and free != ("x", "y"):
                raise ValueError(f"b = {self.b:g} with mean_stress sets x and y: give them "
                                 "neither a stress nor a strain rate")
            if self.mean_stress is None and (free != ("y",) or "x" not in self.stress):
                raise ValueError(f"b = {self.b:g} sets y from sigma_3 on x: give x a stress "
                                 "and y neither a stress nor a strain rate")
        elif not free or "z" in free:
            raise ValueError("mean_stress sets the lateral axes given neither a stress nor a "
                             "strain rate: leave x or y (or both) free")

    def _check_until(self):
        until = self.until
        if isinstance(until, Static):
            moving = sorted(a for a, r in self.strain_rate.items() if r != 0.0)
            if self.shear_rate != 0.0:
                moving.append("x-z (shear_rate)")
            if moving or self.mean_stress is not None or self.b is not None:
                raise ValueError("until static needs every axis servoed or held (strain rate "
                                 f"0): axis {', '.join(moving) or 'z'} keeps moving")
            return
        if isinstance(until, ShearStrain):
            if until.value * self.shear_rate <= 0.0:
                raise ValueError(f"until shear strain {until.value:g} needs a shear_rate of its "
                                 f"sign, not {self.shear_rate:g} 1/s")
            return
        rate = self.strain_rate.get(until.axis, 0.0)
        if rate == 0.0:
            kind = "strain" if isinstance(until, Strain) else "stress"
            raise ValueError(f"until {kind} on {until.axis} needs {until.axis} driven at a "
                             "non-zero strain rate")

    def describe(self):
        """The stage in words, e.g. 'x,y 750 Pa; z 2.6 1/s; until z strain 0.25'."""
        parts = [f"{axis} {value:g} Pa" for axis, value in self.stress.items()]
        parts += [f"{axis} {value:.3g} 1/s" for axis, value in self.strain_rate.items()]
        if self.mean_stress is not None:
            parts.append(f"p {self.mean_stress:g} Pa")
        if self.b is not None:
            parts.append(f"b {self.b:g}")
        if self.shear_rate != 0.0:
            parts.append(f"shear xz {self.shear_rate:.3g} 1/s")
        if self.volume is not None:
            parts.append(f"volume {self.volume}")
        if self.suction is not None:
            parts.append(f"suction {self.suction:g} Pa" + (
                "" if self.suction_rate is None else f" at {self.suction_rate:.3g} Pa/s"))
        if self.water_content is not None:
            parts.append(f"water content {self.water_content:g} %")
        until = self.until
        if isinstance(until, Strain):
            parts.append(f"until {until.axis} strain {until.value:g}")
        elif isinstance(until, Stress):
            parts.append(f"until {until.axis} stress {until.value:g} Pa")
        elif isinstance(until, ShearStrain):
            parts.append(f"until shear strain {until.value:g}")
        else:
            parts.append("until static")
        return "; ".join(parts)


def water_controls(stage, bridges):
    """The controls that bring the water of the wet scene's ``bridges`` (its capillary
    operation, None dry) where ``stage`` says (pendular.procedures.hydraulic): [] for a stage
    that leaves it; ValueError naming the key for a dry scene or bridges of the other
    control."""
    if stage.suction is not None:
        return [SuctionChange(bridges, stage.suction, stage.suction_rate)]
    if stage.water_content is not None:
        return [WaterContentChange(bridges, stage.water_content)]
    return []


#: Stage keys whose controls run on the CPU only (pendular.gpu.simulation.check_scene refuses
#: ConstantVolume, SuctionChange and WaterContentChange).
HOST_ONLY_KEYS = ("volume", "suction", "water_content")


def check_stages_device(stages, device):
    """ValueError naming ``--device`` when ``device`` is not "cpu" and a stage of ``stages``
    has a key of HOST_ONLY_KEYS, before anything runs."""
    if device == "cpu":
        return
    for number, stage in enumerate(stages, 1):
        for key in HOST_ONLY_KEYS:
            if getattr(stage, key) is not None:
                raise ValueError(f"--device {device}: stage {number} has {key} = "
                                 f"{getattr(stage, key)!r}, whose control runs on the CPU "
                                 "only; valid: --device cpu")


class MixedStress(mixed_stress.MixedStress):
    """The mixed condition of a Stage (module docstring): a control that sets, each step
    before the servos run, the targets of the servos of the stage's free axes from the
    stresses now (pendular.dem.mixed_stress.MixedStress, with the stage's mean_stress, b and
    given stresses); StageFailed when a target falls below zero (walls cannot pull).
    ``servos``: {axis index: the StressServo of that axis}. A class of its own here because a
    checkpoint names each operation's type (pendular.dem.checkpoint): those written with it
    load as before."""

    def __init__(self, stage, servos):
        super().__init__(servos, stage.free, mean_stress=stage.mean_stress, b=stage.b,
                         stress=stage.stress)


# ---------------------------------------------------------------- the run of a stage

def run_stage(sim, ended, *, start, limit, every, budget=math.inf, progress=None, bar=None,
              status=None):
    """Run one stage of ``sim`` until ``ended(sim)``, the stage's end, checked every ``every``
    steps counted from its first step ``start``, and at most to its step limit ``start +
    limit``, taking at most ``budget`` steps; returns the steps taken. A stage resumed from a
    checkpoint written between two checks first runs to the next one, so that its checks fall
    on the steps where an uninterrupted run checked: a resumed run is the same run, bit for
    bit. It stops at the limit without judging: what a stage that has not ended by then means
    (StageFailed, NotStatic, the end of a pull) is its caller's. ``progress``: the progress
    label, ``bar`` the bar of the checked run (None: ``progress``), ``status`` its fields
    (Simulation.run). Every procedure runs its stages so: LoadingPath.run, the equilibria
    (pendular.procedures.equilibrium.equilibrate), the SWCC's suction steps and the tension's
    pull."""
    bar = progress if bar is None else bar
    taken = 0
    while not ended(sim):
        done = sim.step - start
        if done >= limit or taken >= budget:
            break
        steps = int(min(limit - done, budget - taken))
        offset = done % every
        if offset:                  # a resumed stage: its checks fall where they fell before
            taken += sim.run(min(every - offset, steps), progress=progress, status=status)
            continue
        taken += sim.run(steps, until=ended, check_every=every, progress=bar, status=status)
    return taken


# ---------------------------------------------------------------- a path

class AxisStrain:
    """The engineering strain 1 - L / L0 of ``axis`` (0, 1, 2) from ``reference_length`` L0
    [m], compression positive."""

    def __init__(self, axis, reference_length):
        self.axis = axis
        self.reference_length = reference_length

    def strain(self, walls):
        return 1.0 - walls.lengths()[self.axis] / self.reference_length


class LoadingPath:
    """Run ``stages`` (Stage) of the static sample ``sim`` one after the other, recording one
    history: ``history_columns`` plus ``columns`` (name -> function of sim) and, for more than
    one stage, ``stage`` (the index of the stage running).

    Attaching it replaces ``sim.controls`` by the first stage's and records the first row.
    Rows every ``records``-th of the path's steps when its length is known (one stage ending
    at a strain: ``steps``), else every ``record_every`` steps, and at each stage's end.
    Servo settings as pendular.procedures.config.ShearConfig (``servo_max_velocity`` None:
    that of the scene's StressServo, or pendular.procedures.preparation.servo_speed);
    ``rate_on_current_length``: the strain rates act on the current lengths. A SampleGuard
    watches the sample at the rows' period (``guard`` False: none, e.g. for the densest
    packing, whose porosity is the guard's bound).

    ``run(sim)`` runs the stages to the end (or ``max_steps`` steps); ``state()`` and
    ``resume(sim, state)`` carry the stage reached across a checkpoint. ``axial``: the
    axial strain's measure; ``controls``: the running stage's controls.
    """

    def __init__(self, sim, stages, *, records=None, record_every=None, columns=None,
                 servo_max_velocity=None, servo_scale_max_velocity=False,
                 servo_stiffness_every=1, rate_on_current_length=False, guard=True):
        self.stages = list(stages)
        if not self.stages or not all(isinstance(s, Stage) for s in self.stages):
            raise ValueError("stages: a non-empty list of Stage expected")
        self.reference_length = sim.walls.lengths().copy()
        self.axial = AxisStrain(2, self.reference_length[2])
        shearing = [s for s in self.stages if s.shear_rate != 0.0]
        if shearing and not sim.walls.periodic:
            raise ValueError(f"shear_rate = {shearing[0].shear_rate:g} 1/s needs a periodic "
                             "cell (--periodic): walls cannot shear a sample")
        self.reference_shear = getattr(sim.walls, "shear_strain", 0.0)
        # every stage of a path that shears holds a shear control (rate 0 where it does not
        # shear): a checkpoint loads into a pipeline of the same operation types
        self._shears = bool(shearing)
        servo = next((op for op in sim.controls if isinstance(op, StressServo)), None)
        if servo_max_velocity is None:
            servo_max_velocity = (servo.max_velocity if servo is not None
                                  else servo_speed(sim.walls, sim.dt))
        self.servo_max_velocity = servo_max_velocity
        self.servo_scale_max_velocity = servo_scale_max_velocity
        self.servo_stiffness_every = servo_stiffness_every
        self.rate_on_current_length = rate_on_current_length
        bridges = capillary_operation(sim)
        for number, stage in enumerate(self.stages, 1):   # refused before anything runs
            try:
                water_controls(stage, bridges)
            except ValueError as error:
                raise ValueError(f"stage {number}: {error}") from None
        self.stage, self.stage_start = 0, sim.step
        self.controls = self._controls(sim, self.stages[0], ())
        if sim.contacts is None:
            sim.evaluate_forces()     # a sample just loaded: the first record sees its contacts
        sim.controls = list(self.controls)
        self.stage_steps = self._stage_steps(sim)
        self.steps = self.stage_steps if (len(self.stages) == 1 and isinstance(
            self.stages[0].until, (Strain, ShearStrain))) else None
        if self.steps is not None and records is not None:
            period, end = max(1, self.steps // records), sim.step + self.steps
        elif record_every is not None:
            period, end = check_int("record_every", record_every, low=1), None
        else:
            raise ValueError("record_every is needed: the path's length is not known before "
                             "it runs (records applies to one stage ending at a strain)")
        quantities = history_columns(sim, self.axial, sim.walls.volume(),
                                     capillary_operation(sim))
        quantities.update(columns or {})
        if len(self.stages) > 1:
            quantities["stage"] = lambda s: self.stage
        self.recorder = HistoryRecorder(period, quantities, origin=sim.step, end=end,
                                        reads=("walls",))
        self.recorder.record(sim)
        sim.writers.append(self.recorder)
        if guard:
            sim.writers.append(SampleGuard(self.recorder.period, describe=lambda s: (
                f"axial strain {self.axial.strain(s.walls):.3g}")))

    # ------------------------------------------------------------ controls of a stage
    def _controls(self, sim, stage, previous):
        """The controls of ``stage`` in order (MixedStress, servos, strain rates, and in a path
        that shears the shear rate); the servos of ``previous`` (the controls of the stage
        before) on the same axes carry on."""
        carried = {op.axes: op for op in previous if isinstance(op, StressServo)}
        max_velocity = self.servo_max_velocity
        if stage.max_strain_rate is not None:
            max_velocity = StressServo.max_velocity_for(stage.max_strain_rate,
                                                        float(np.mean(sim.walls.lengths())))
        groups = {}                          # axes -> target
        for axis, target in stage.stress.items():
            same = next((axes for axes, value in groups.items() if value == target
                         and stage.b is None), None)
            if same is None:
                groups[axis] = target
            else:
                groups[same + axis] = groups.pop(same)
        free = stage.mixed
        if free:
            start = stage.mean_stress if stage.mean_stress is not None else stage.stress["x"]
            if stage.b is None:
                groups["".join(free)] = start
            else:
                groups.update({axis: start for axis in free})
        servos = []
        for axes in sorted(groups, key=lambda a: AXIS_NAMES.index(a[0])):
            key = tuple(AXES[a] for a in axes)
            servo = carried.get(key)
            if servo is None:
                servo = StressServo(axes, groups[axes], max_velocity,
                                    scale_max_velocity=self.servo_scale_max_velocity,
                                    stiffness_every=self.servo_stiffness_every)
            else:
                servo.target, servo.max_velocity = groups[axes], max_velocity
            servos.append(servo)
        controls = []
        if free:
            by_axis = {axis: servo for servo in servos for axis in servo.axes}
            controls.append(MixedStress(stage, by_axis))
        controls += servos
        for axis in AXIS_NAMES:
            rate = stage.strain_rate.get(axis, 0.0)
            if rate != 0.0:                 # a rate of 0: the walls stay where they are
                controls.append(ConstantStrainRate(
                    axis, rate, self.reference_length[AXES[axis]],
                    on_current_length=self.rate_on_current_length))
        if stage.volume == "constant":      # after z's drive: x and y undo its volume change
            controls.append(ConstantVolume(sim.walls.volume()))
        if self._shears:
            controls.append(ConstantShearRate(stage.shear_rate))
        return controls + water_controls(stage, capillary_operation(sim))

    def _driver(self, axis):
        """The ConstantStrainRate of ``axis`` in the running stage's controls."""
        return next(op for op in self.controls
                    if isinstance(op, ConstantStrainRate) and op.axis == AXES[axis])

    def strain(self, sim, axis):
        """Engineering strain of ``axis`` from the start of the path [-]."""
        index = AXES[axis]
        return 1.0 - sim.walls.lengths()[index] / self.reference_length[index]

    def shear_strain(self, sim):
        """Shear strain gamma of x with z imposed since the start of the path [-] (0 inside
        walls)."""
        return getattr(sim.walls, "shear_strain", 0.0) - self.reference_shear

    def _stage_steps(self, sim):
        """Steps of the running stage: its length (Strain, ShearStrain), its most (Stress: to
        its strain limit; Static: max_steps)."""
        until = self.stages[self.stage].until
        if isinstance(until, Static):
            return until.max_steps
        if isinstance(until, ShearStrain):
            shear = next(op for op in self.controls if isinstance(op, ConstantShearRate))
            return shear.steps_to(until.value, sim.dt, self.shear_strain(sim))
        driver = self._driver(until.axis)
        start = self.strain(sim, until.axis) if self.stage else 0.0
        if isinstance(until, Strain):
            return driver.steps_to(until.value, sim.dt, start)
        limit = math.copysign(until.strain_limit, driver.rate)
        if (limit - start) * driver.rate <= 0.0:
            raise StageFailed(f"stage {self.stage + 1}: the strain of {until.axis} is already "
                              f"{start:.3g}, beyond its limit {limit:g}")
        return driver.steps_to(limit, sim.dt, start)

    # ------------------------------------------------------------ running
    def state(self):
        """What a checkpoint must carry to resume the path: the stage, its first step and its
        steps (its length or limit)."""
        return {"stage": self.stage, "stage_start": self.stage_start,
                "stage_steps": self.stage_steps}

    def enter_stage(self, sim, stage):
        """Make the controls of stage number ``stage`` (from 0) ``sim``'s, built as a run
        reaches them (each stage's from the one before, its servos carried): the pipeline
        that a checkpoint taken in that stage loads into, whose ``load_state`` then sets them
        as they were (``resume``)."""
        stage = check_int("stage", stage, high=len(self.stages) - 1)
        controls = self._controls(sim, self.stages[0], ())
        for number in range(1, stage + 1):
            controls = self._controls(sim, self.stages[number], controls)
        self.controls = controls
        sim.controls = list(controls)

    def resume(self, sim, state):
        """Take the stage of ``state`` (``state()`` of the run a checkpoint was written by),
        once that checkpoint is loaded into ``sim`` (its controls those of ``enter_stage``):
        the path's controls are then the loaded ones."""
        try:
            self.stage = check_int("stage", state["stage"], high=len(self.stages) - 1)
            self.stage_start = check_int("stage_start", state["stage_start"], high=sim.step)
            self.stage_steps = check_int("stage_steps", state["stage_steps"])
        except (KeyError, TypeError):
            raise ValueError(f"a checkpoint's path state {state!r} lacks the stage, its start "
                             "or its steps") from None
        self.controls = list(sim.controls)

    @property
    def done(self):
        return self.stage >= len(self.stages)

    def _reached(self, sim):
        """Whether the running stage's end is reached now."""
        stage = self.stages[self.stage]
        until = stage.until
        if isinstance(until, (Strain, ShearStrain)):
            return sim.step - self.stage_start >= self.stage_steps
        if isinstance(until, Stress):
            sigma = sim.fetch("walls").walls.stress()[AXES[until.axis]]
            return (sigma - until.value) * stage.strain_rate[until.axis] >= 0.0
        return ((sim.step - self.stage_start) % until.check_every == 0
                and all(op.done for op in self.controls if hasattr(op, "done"))
                and static(until.unbalanced, until.tolerance)(sim))

    def run(self, sim, *, max_steps=None, progress=None, status=None):
        """Run the stages from where the path is to its end, or ``max_steps`` steps; returns
        the steps taken. ``progress``: a progress bar label (None: no bar); ``status``: the
        bar's fields (default ``self.status``). StageFailed when a stage cannot reach its
        end within its limit."""
        budget = math.inf if max_steps is None else check_int("max_steps", max_steps)
        status = status or self.status
        taken = 0
        while not self.done:
            if self._reached(sim):
                self._next(sim)
                continue
            if taken >= budget:
                break
            until = self.stages[self.stage].until
            label = progress if progress is None or len(self.stages) == 1 else (
                f"{progress} {self.stage + 1}/{len(self.stages)}")
            if isinstance(until, (Strain, ShearStrain)):
                taken += sim.run(int(min(self.steps_left(sim), budget - taken)),
                                 progress=label, status=status)
                continue
            taken += run_stage(sim, self._reached, start=self.stage_start,
                               limit=self.stage_steps,
                               every=1 if isinstance(until, Stress) else until.check_every,
                               budget=budget - taken, progress=label,
                               bar=self._bar(label, until), status=status)
            if not self._reached(sim) and sim.step >= self.stage_start + self.stage_steps:
                raise StageFailed(self._failure(sim))
        return taken

    @staticmethod
    def _bar(label, until):
        """The bar of an open-ended stage: a Stress stage counts its wall's stress toward the
        target, a Static one the decades of its distance to equilibrium
        (pendular.procedures.progress)."""
        if isinstance(until, Stress):
            return stress_bar(label, AXES[until.axis], until.value)
        return equilibrium_bar(label, until.unbalanced, until.tolerance)

    def steps_left(self, sim):
        """Steps left to the running stage's end (Strain, ShearStrain) or limit (Stress,
        Static) [-]."""
        return self.stage_start + self.stage_steps - sim.step

    def _failure(self, sim):
        stage, until = self.stages[self.stage], self.stages[self.stage].until
        where = f"stage {self.stage + 1} ({stage.describe()})"
        if isinstance(until, Stress):
            sigma = sim.walls.stress()[AXES[until.axis]]
            return (f"{where}: the {until.axis} stress is {sigma:.4g} Pa after a strain of "
                    f"{self.strain(sim, until.axis):.3g}, its limit: the target "
                    f"{until.value:g} Pa is out of this sample's reach")
        fields = ", ".join(f"{k} {v}" for k, v in self.status(sim).items())
        return (f"{where}: not static after {self.stage_steps} steps ({fields}); raise the "
                "stage's step limit (--stage-steps)")

    def _next(self, sim):
        """End the running stage: its last row (unless just recorded) and the next stage's
        controls."""
        if self.recorder.rows["step"][-1] != sim.step:
            self.recorder.record(sim)
        self.stage += 1
        if self.done:
            return
        self.stage_start = sim.step
        self.controls = self._controls(sim, self.stages[self.stage], self.controls)
        sim.controls = list(self.controls)
        self.stage_steps = self._stage_steps(sim)

    def status(self, sim):
        """Progress-bar fields: strain, axial and lateral stress, q/p; in a sheared cell the
        shear strain, tau and tau / sigma_z instead of the last two."""
        sigma = sim.fetch("walls").walls.stress()
        fields = {"strain": f"{self.axial.strain(sim.walls):.3f}", "sz": f"{sigma[2]:.0f}Pa"}
        if getattr(sim.walls, "sheared", False):
            tau = sim.walls.shear_stress()
            fields.update({"gamma": f"{self.shear_strain(sim):.3f}", "tau": f"{tau:.0f}Pa",
                           "tau/sz": f"{tau / sigma[2]:.2f}" if sigma[2] else "-"})
            return fields
        fields.update({"sr": f"{lateral_stress(sigma):.0f}Pa",
                       "q/p": f"{deviator_stress(sigma) / mean_stress(sigma):.2f}"})
        return fields


# ---------------------------------------------------------------- the laboratory's paths


# ---------------------------------------------------------------- results


