"""Simple shear of a sample in a periodic cell (Lees–Edwards images, pendular.dem.cell): x
sheared with z, z the normal (height) direction.

``simple_shear_stages(config, rate)``: from the isotropic confining stress, z brought to the
normal stress with x and y held (a K0 consolidation, skipped when the normal stress is the
confining one), then the shear at the rate gamma_dot to the final shear strain, the normal
stress held by the cell's servo (drained) or the cell's lengths held (constant volume: the
volume is conserved exactly). ``SimpleShearTest(config).run(out)`` runs it as every
laboratory test (pendular.procedures.laboratory.LaboratoryTest: sample, wetting, checkpoints,
resume) and writes history.h5 (the loading path's columns and ``shear_strain`` gamma,
``shear_stress`` tau, ``normal_stress`` sigma_zz), summary.json (``simple_shear_summary``),
simple_shear.png (tau, sigma_n and the volumetric strain against gamma), vtk/.

tau = -(sigma_xz + sigma_zx) / 2 of the cell's Love–Weber stress (compression positive), the
stress whose power tau gamma_dot per unit volume the shear puts in: positive where the sample
resists a positive shear (PeriodicCell.shear_stress). Friction angles atan(tau / sigma_n).

``run(out, device="gpu")`` prepares and shears on the GPU (pendular.gpu.cell: the sheared
cell step for step as on the CPU).
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass

import numpy as np

from pendular.io.plots import plot_simple_shear
from pendular.io.schema import peak_reached
from pendular.io.vtk import shear_strain_fields
from pendular.procedures.command import LaboratoryCommand
# BridgeConfig and PrepareConfig: the types of the inherited fields bridges and sample,
# which the documentation reads here (typing.get_type_hints of the configuration)
from pendular.procedures.config import (BridgeConfig, MAX_RECORD_STRAIN, MAX_SHEAR_STRAIN,
    MAX_STRAIN_RATE, MIN_AXIAL_STRAIN, MIN_RECORD_STRAIN, PathConfig, check_soft, registered,
    stage_steps_parameter)
from pendular.procedures.laboratory import LaboratoryTest, stress_balance
from pendular.procedures.loading import LoadingPath, ShearStrain, Stage, Static
from pendular.procedures.options import (SAMPLE, framed, laboratory_fields, laboratory_options,
    options_named)
from pendular.procedures.preparation import MAX_STRESS, PrepareConfig
from pendular.utils.parameters import fail, fields_of, option_of, parameter


#: Fewest spheres of a simple shear: its periodic cell must be 3 diameters plus the neighbour
#: reach across (pendular.dem.neighbors), which 50 spheres at the default porosity miss by a
#: hair; 60 hold it with a margin.
MIN_SIMPLE_SHEAR_PARTICLES = 60


#: Why a simple shear needs MIN_SIMPLE_SHEAR_PARTICLES (the end of the error refusing fewer).
NARROW_CELL = ("its periodic cell must span 3 diameters plus the neighbour reach, which fewer "
               "spheres do not")


@registered
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
    normal_stress: float | None = parameter(None, unit="Pa", low=0.0, high=MAX_STRESS,
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


#: Records whose normal stress is below this fraction of the shear's initial one do not
#: measure tau / sigma_n (a ratio of noise over nearly zero, e.g. a loose sample whose normal
#: stress collapses at constant volume).
MIN_NORMAL_FRACTION = 0.01
#: Final fraction of the shear strain over which the residual state is averaged.
RESIDUAL_FRACTION = 0.1
#: Span of shear strain, as a fraction of the shear's, of the differences that measure the
#: dilatancy -d(eps_v)/d(gamma) (narrower windows measure the records' scatter).
DILATANCY_WINDOW = 0.05

#: History columns of a simple shear beyond the loading path's (pendular.io.schema).
SHEAR_COLUMNS = {
    "shear_strain": lambda s: s.walls.shear_strain,
    "shear_stress": lambda s: s.walls.shear_stress(),
    "normal_stress": lambda s: s.walls.stress()[2],
}


def simple_shear_stages(config, rate):
    """The Stages of ``config`` (SimpleShearConfig) at the shear rate ``rate`` [1/s]: the
    consolidation of z to the normal stress (x, y held; until static, at most
    ``config.stage_steps``, the servo at most at ``rate``) when it differs from the confining
    stress, then the shear to ``config.max_strain``, drained (z at the normal stress) or at
    constant volume."""
    sample = config.sample
    held = {"x": 0.0, "y": 0.0}
    stages = []
    if config.consolidates:
        stages.append(Stage(stress={"z": config.normal_stress}, strain_rate=held,
                            max_strain_rate=rate,
                            until=Static(config.stage_steps, sample.equilibrium_unbalanced,
                                         sample.stress_tolerance)))
    if config.constant_volume:
        stages.append(Stage(strain_rate={**held, "z": 0.0}, shear_rate=rate,
                            until=ShearStrain(config.max_strain)))
    else:
        stages.append(Stage(stress={"z": config.normal_stress}, strain_rate=held,
                            shear_rate=rate, until=ShearStrain(config.max_strain)))
    return stages


def shear_rows(history):
    """Indices of the records of the shear stage (the last stage of the path), with the
    record it starts from."""
    stage = history.get("stage")
    if stage is None:
        return np.arange(len(history["step"]))
    rows = np.flatnonzero(stage == stage.max())
    return np.concatenate([rows[:1] - 1, rows]) if rows[0] > 0 else rows


def _friction_angle(ratio):
    """atan(tau / sigma_n) [deg], None for a ratio that is not finite."""
    return float(math.degrees(math.atan(ratio))) if np.isfinite(ratio) else None


def simple_shear_summary(history, constant_volume):
    """Results of a simple shear's history (``shear_rows``). Two peaks, each with the values
    of its own record: the largest tau, ``peak_shear_stress`` [Pa], with
    ``shear_strain_at_peak_stress`` and ``normal_stress_at_peak_stress`` and
    ``peak_shear_stress_reached`` (pendular.io.schema.peak_reached of tau); the peak of tau /
    sigma_n (records with sigma_n above MIN_NORMAL_FRACTION of its initial value),
    ``peak_stress_ratio``, with ``phi_peak_deg`` = atan(tau / sigma_n),
    ``shear_strain_at_peak``, ``normal_stress_at_peak``, ``shear_stress_at_peak`` and
    ``peak_reached`` (peak_reached of tau / sigma_n); over the last RESIDUAL_FRACTION of the shear strain
    ``residual_stress_ratio`` (mean tau / sigma_n) and ``phi_residual_deg``;
    ``normal_stress_final``. Drained: ``max_dilatancy`` = max -d(eps_v)/d(gamma) over windows
    of DILATANCY_WINDOW of the shear strain (eps_v contraction positive, so dilation is
    positive), ``dilatancy_angle_deg`` = atan of it, ``volumetric_strain_of_shear``; at
    constant volume ``max_volume_change``, max |V / V_start - 1| over the shear (round-off
    at most). Wet, the same peak and residual of the effective stress
    (``effective_friction``)."""
    rows = shear_rows(history)
    gamma = np.asarray(history["shear_strain"], dtype=float)[rows]
    tau = np.asarray(history["shear_stress"], dtype=float)[rows]
    normal = np.asarray(history["normal_stress"], dtype=float)[rows]
    measured = normal > MIN_NORMAL_FRACTION * normal[0]
    ratio = np.where(measured, tau / np.where(measured, normal, 1.0), np.nan)
    top = int(np.argmax(tau))
    summary = {"peak_shear_stress": float(tau[top]),
               "shear_strain_at_peak_stress": float(gamma[top]),
               "normal_stress_at_peak_stress": float(normal[top]),
               "peak_shear_stress_reached": peak_reached(gamma, tau)}
    if np.isfinite(ratio).any():
        peak = int(np.nanargmax(ratio))
        span = gamma[-1] - gamma[0]
        residual = ratio[(gamma >= gamma[-1] - RESIDUAL_FRACTION * span) & measured]
        residual_ratio = float(np.mean(residual)) if len(residual) else math.nan
        summary.update({
            "peak_stress_ratio": float(ratio[peak]),
            "phi_peak_deg": _friction_angle(ratio[peak]),
            "shear_strain_at_peak": float(gamma[peak]),
            "normal_stress_at_peak": float(normal[peak]),
            "shear_stress_at_peak": float(tau[peak]),
            "peak_reached": peak_reached(gamma[measured], ratio[measured]),
            "residual_stress_ratio": residual_ratio if np.isfinite(residual_ratio) else None,
            "phi_residual_deg": _friction_angle(residual_ratio)})
        if summary["residual_stress_ratio"] is None:
            summary["phi_residual_note"] = (
                f"not measured: no record in the last {100 * RESIDUAL_FRACTION:g} % of the "
                f"shear strain has sigma_n above {100 * MIN_NORMAL_FRACTION:g} % of its start")
    summary["normal_stress_final"] = float(normal[-1])
    if "psi" in history:
        summary.update(effective_friction(history, rows))
    volume = 1.0 - np.asarray(history["volumetric_strain"], dtype=float)[rows]   # V / V0
    if constant_volume:
        summary["max_volume_change"] = float(np.max(np.abs(volume / volume[0] - 1.0)))
    else:
        summary.update(dilatancy(gamma, 1.0 - volume / volume[0]))
    summary.update(stress_balance(history))
    return summary


def effective_friction(history, rows):
    """Of a wet history (the capillary stress psi, Eq. 3.43): the effective shear and normal
    stresses tau' = tau - (psi_xz + psi_zx) / 2 and sigma_n' = sigma_n + psi_zz [Pa] of the
    shear ``rows``, and at the peak of tau' / sigma_n' ``peak_stress_ratio_effective``,
    ``phi_peak_effective_deg`` = atan of it and ``shear_strain_at_peak_effective``; over the
    last RESIDUAL_FRACTION of the shear strain ``phi_residual_effective_deg``."""
    psi = np.asarray(history["psi"], dtype=float)[rows]
    gamma = np.asarray(history["shear_strain"], dtype=float)[rows]
    tau = np.asarray(history["shear_stress"], dtype=float)[rows] - 0.5 * (psi[:, 0, 2]
                                                                         + psi[:, 2, 0])
    normal = np.asarray(history["normal_stress"], dtype=float)[rows] + psi[:, 2, 2]
    measured = normal > MIN_NORMAL_FRACTION * normal[0]
    if not measured.any():
        return {}
    ratio = np.where(measured, tau / np.where(measured, normal, 1.0), np.nan)
    peak = int(np.nanargmax(ratio))
    span = gamma[-1] - gamma[0]
    residual = ratio[(gamma >= gamma[-1] - RESIDUAL_FRACTION * span) & measured]
    return {"peak_stress_ratio_effective": float(ratio[peak]),
            "phi_peak_effective_deg": _friction_angle(ratio[peak]),
            "shear_strain_at_peak_effective": float(gamma[peak]),
            "phi_residual_effective_deg": (_friction_angle(float(np.mean(residual)))
                                           if len(residual) else None)}


def dilatancy(gamma, volumetric):
    """``max_dilatancy`` = max over the shear of -d(eps_v)/d(gamma) [-], differences over
    windows of DILATANCY_WINDOW of the shear strain range (eps_v ``volumetric``, contraction
    positive, against ``gamma``, rising), ``dilatancy_angle_deg`` = atan of it and
    ``volumetric_strain_of_shear`` (the last eps_v); None without a range of shear strain,
    ``max_dilatancy_note`` saying so."""
    span = gamma[-1] - gamma[0]
    found = {"volumetric_strain_of_shear": float(volumetric[-1])}
    if not span > 0.0 or len(gamma) < 3:
        return {**found, "max_dilatancy": None, "dilatancy_angle_deg": None,
                "max_dilatancy_note": "not measured: the shear strain did not move, or fewer "
                                      "than 3 records"}
    window = DILATANCY_WINDOW * span
    start = np.linspace(gamma[0], gamma[-1] - window, 200)
    slope = -(np.interp(start + window, gamma, volumetric)
              - np.interp(start, gamma, volumetric)) / window
    most = float(np.max(slope))
    return {**found, "max_dilatancy": most, "dilatancy_angle_deg": _friction_angle(most)}


class SimpleShearTest(LaboratoryTest):
    """A simple shear test of ``config`` (pendular.procedures.simple_shear.SimpleShearConfig; module
    docstring): history with ``shear_strain``, ``shear_stress``, ``normal_stress`` (and
    ``stage`` with a consolidation), summary of ``simple_shear_summary``, figure
    simple_shear.png."""

    NAME = "simple-shear"
    CONFIG = SimpleShearConfig
    FIGURE = "simple_shear.png"
    PROGRESS = "simple shear"

    def loading(self, sim):
        config = self.config
        return LoadingPath(sim, simple_shear_stages(config, config.rate()),
                           record_every=config.record_every(sim.dt), columns=SHEAR_COLUMNS)

    def summarize(self, history):
        return simple_shear_summary(history, self.config.constant_volume)

    def frame_fields(self, path):
        """The shear strain gamma, in % on the ParaView time axis."""
        return (lambda s: shear_strain_fields(s.walls.shear_strain)), "shear_strain_percent"

    def plot(self, history, out, title):
        config = self.config
        rows = shear_rows(history)
        shear = {name: np.asarray(values)[rows] for name, values in history.items()
                 if np.ndim(values) and len(values) == len(history["step"])}
        kind = "constant volume" if config.constant_volume else "drained"
        plot_simple_shear(shear, os.path.join(out, self.FIGURE),
                          f"{kind}, σn = {config.normal_stress / 1e3:g} kPa; {title}",
                          summary=simple_shear_summary(history, config.constant_volume))


# ---------------------------------------------------------------- the command


#: A simple shear's sample: always in a periodic cell, --periodic implied.
SIMPLE_SHEAR_SAMPLE = tuple(
    dataclasses.replace(option, default=True, help="a periodic cell, with Lees–Edwards images "
                                                   "(implied: walls cannot shear a sample)")
    if option.key == "periodic" else
    option_of(PrepareConfig, "particles", low=MIN_SIMPLE_SHEAR_PARTICLES)
    if option.key == "particles" else option for option in SAMPLE)

SIMPLE_SHEAR_OWN = options_named(SimpleShearConfig, ("normal_stress", "constant_volume",
                                                "max_strain", "inertial_number", "strain_rate",
                                                "record_strain", "stage_steps"))


def simple_shear_config(values, given):
    """The SimpleShearConfig of ``values``: always in a periodic cell (walls cannot shear a
    sample)."""
    return SimpleShearConfig(**laboratory_fields({**values, "periodic": True}, given,
                                                 lambda: fields_of(values, SIMPLE_SHEAR_OWN)))


#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular simple-shear --particles 1000 --normal-stress 1000 "
           "--constant-volume --max-strain 0.2 --out runs/simple_shear",
           "a constant-volume simple shear to gamma 20 %: the peak of tau, the peak of "
           "tau/sigma_n with its friction angle, each with its own record; simple_shear.png with "
           "the tau-sigma_n stress path")

#: Summary keys printed at the end.
SHOWN = ("peak_shear_stress", "shear_strain_at_peak_stress", "normal_stress_at_peak_stress",
         "peak_stress_ratio", "phi_peak_deg", "shear_strain_at_peak", "normal_stress_at_peak",
         "shear_stress_at_peak", "peak_reached", "residual_stress_ratio", "phi_residual_deg",
         "phi_peak_effective_deg", "phi_residual_effective_deg", "normal_stress_final",
         "max_dilatancy", "dilatancy_angle_deg", "max_volume_change", "liquid_balance_error",
         "initial_porosity", "wall_time_s", "particle_steps_per_s")

#: The simple-shear command (pendular.procedures.registry).
COMMAND = LaboratoryCommand(
    name="simple-shear",
    description="simple shear (periodic cell), drained or constant volume",
    test=SimpleShearTest,
    declared=laboratory_options(
        SIMPLE_SHEAR_OWN, framed(simple_shear_config), sample=SIMPLE_SHEAR_SAMPLE),
    shown=SHOWN, example=EXAMPLE, out="runs/simple_shear")
