"""Drained or undrained triaxial test (thesis Ch. 5.2.3): its configuration, shear, summary
and command.

- ``TriaxialConfig``: the sample, bridges and outputs of every laboratory test
  (pendular.procedures.config.LaboratoryConfig) and the shear (ShearConfig);
- ``shear_stage``: the path of the shear (lateral walls at the confining stress, axial walls
  at the rate of ShearConfig, to the final strain), in compression or extension, at a
  constant b or a constant mean stress, or undrained (at constant volume);
- ``TriaxialShear(sim, shear, ...)``: lateral walls servoed, axial walls at a constant strain
  rate, a history recorder; ``sim.run(shear.steps)`` shears to the final strain (one stage
  of a pendular.procedures.loading.LoadingPath, which runs any sequence of stages);
- ``summarize(history)``: peak values, ``undrained_summary``, ``path_deviations``;
- ``TriaxialTest(config).run(out)``: the whole test (pendular.procedures.laboratory
  .LaboratoryTest: sample, wetting, outputs, checkpoints, resume);
- ``COMMAND``: the ``pendular triaxial`` command (its options, pendular.procedures.options).

Stresses compression positive [Pa], q and p as pendular.homogenize.invariants; strains compression
positive, volumetric strain positive in contraction (docs/units.md).
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field

import numpy as np

from pendular.dem.walls import ConstantStrainRate
from pendular.homogenize.invariants import (deviator_stress, lateral_stress, mean_stress,
    principal_difference, shear_deviator)
from pendular.io.plots import plot_history, plot_stress_path, write_plots
from pendular.io.schema import peak_reached
from pendular.procedures.columns import friction_angle
from pendular.procedures.command import LaboratoryCommand
from pendular.procedures.compression import effective_diagonal
# BridgeConfig and PrepareConfig: the types of the inherited fields bridges and sample,
# which the documentation reads here (typing.get_type_hints of the configuration)
from pendular.procedures.config import (AXIAL_STRAIN_LIMIT, BridgeConfig, LaboratoryConfig,
    MAX_AXIAL_STRAIN, MIN_AXIAL_STRAIN, ShearConfig, registered)
from pendular.procedures.critical_state import critical_state
from pendular.procedures.guards import AxialStressGuard
from pendular.procedures.laboratory import LaboratoryTest, stress_balance
from pendular.procedures.loading import LoadingPath, Stage, Strain
from pendular.procedures.options import (laboratory_fields, laboratory_options, options_named,
    rate_options, steps_count)
from pendular.utils.parameters import (ParameterError, fail, fields_of, flat_options, option_of,
    spec_of)
from pendular.procedures.preparation import PrepareConfig


@registered
@dataclass
class TriaxialConfig(LaboratoryConfig):
    """A drained triaxial test (thesis Ch. 5.2.3): LaboratoryConfig's sample, bridges and
    outputs, and shear: ShearConfig (the confining stress is the lateral stress of the shear).
    """

    shear: ShearConfig = field(default_factory=ShearConfig)

    TEST = "a triaxial test"
    LENGTH = ("--max-strain",)
    LOADING = "the shear"

    def rate_settings(self):
        """The shear, whose ``strain_rate`` sets the rate."""
        return self.shear

    def loading_parameters(self):
        """The shear's options; a conventional run's rows stay as they were, without the
        path's options."""
        return flat_options(self.shear, () if not self.shear.conventional else
                            ("direction", "b", "constant_p", "drainage"))

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


#: Records whose sigma_1 - sigma_3 is below this fraction of the mean stress do not measure b
#: (its ratio is noise over nearly zero at the start of a true triaxial shear).
B_MEASURE_FROM = 0.1


def shear_stage(shear, confining, rate):
    """The Stage of a triaxial shear of ``shear`` (pendular.procedures.config.ShearConfig)
    from the isotropic ``confining`` stress [Pa] at the axial strain rate ``rate`` [1/s]: the
    axial walls compressed (or, in extension, pulled apart) to ``shear.max_strain``; the lateral
    walls at the confining stress, or with ``shear.b`` sigma_3 = confining on x and sigma_y =
    sigma_3 + b (sigma_z - sigma_3), or with ``shear.constant_p`` at the stresses that keep
    p = confining (and b, when given), or with ``shear.drainage`` "undrained" the lateral
    walls moved so that the volume stays that of the start (the pore water of a saturated
    sample, or the closed liquid of a wet one, cannot leave). b = 0 alone is the conventional
    compression."""
    sign = 1.0 if shear.direction == "compression" else -1.0
    until = Strain(sign * shear.max_strain)
    axial = {"z": sign * rate}
    if shear.drainage == "undrained":
        return Stage(strain_rate=axial, volume="constant", until=until)
    if shear.constant_p:
        return Stage(strain_rate=axial, mean_stress=confining, b=shear.b, until=until)
    if shear.b is not None and shear.b > 0.0:
        return Stage(stress={"x": confining}, strain_rate=axial, b=shear.b, until=until)
    return Stage(stress={"x": confining, "y": confining}, strain_rate=axial, until=until)


def measured_b(sigma, mean):
    """b = (sigma_y - sigma_x) / (sigma_z - sigma_x) of wall stresses ``sigma`` (n, 3) [Pa],
    NaN where sigma_z - sigma_x is below B_MEASURE_FROM times ``mean`` [Pa]."""
    sigma = np.asarray(sigma, dtype=np.float64)
    span = sigma[:, 2] - sigma[:, 0]
    measured = span > B_MEASURE_FROM * mean
    return np.where(measured, (sigma[:, 1] - sigma[:, 0]) / np.where(measured, span, 1.0),
                    np.nan)


def path_deviations(history, shear, confining):
    """How closely a shear of ``shear`` (ShearConfig) held its mixed condition: with
    ``constant_p``, ``mean_stress_deviation`` max over the records of |p / confining - 1|;
    with ``b``, ``b_deviation`` max of |b measured - b| over the records with sigma_z - sigma_x
    of at least B_MEASURE_FROM confining (measured_b), None with ``b_deviation_note`` without
    such records. Both [-]; {} for neither."""
    sigma = history["sigma_wall"]
    found = {}
    if shear.constant_p:
        found["mean_stress_deviation"] = float(np.max(np.abs(mean_stress(sigma) / confining
                                                             - 1.0)))
    if shear.b is not None:
        b = measured_b(sigma, confining)
        found["b_deviation"] = (float(np.nanmax(np.abs(b - shear.b)))
                                if np.isfinite(b).any() else None)
        if found["b_deviation"] is None:
            found["b_deviation_note"] = (
                f"not measured: no record has sigma_z - sigma_x of at least {B_MEASURE_FROM:g} "
                "of the confining stress, where b is more than noise")
    return found


#: Rows of the effective stress path an undrained summary lists (undrained_summary).
PATH_POINTS = 21


def excess_pore_pressure(sigma):
    """Excess pore pressure Delta u [Pa] of each record of wall stresses ``sigma`` (n, 3) [Pa]
    from the first: the pressure a saturating, incompressible pore fluid takes up in an
    undrained shear along the conventional total stress path (the cell pressure sigma_3
    held): Delta u = Delta p_total - Delta p', p_total = sigma_3 + q / 3 and p' the mean wall
    stress, the skeleton's (the effective stress of a saturated sample); = -Delta sigma'_3
    (q = sigma_z - (sigma_x + sigma_y) / 2, pendular.homogenize.invariants)."""
    sigma = np.asarray(sigma, dtype=np.float64)
    q, p = deviator_stress(sigma), mean_stress(sigma)
    return (q - q[0]) / 3.0 - (p - p[0])


def undrained_summary(history, peak):
    """Results of an undrained (constant-volume) shear's ``history`` (column
    ``excess_pore_pressure``, excess_pore_pressure), ``peak`` the row of the peak of q:
    ``excess_pore_pressure_at_peak``, ``_final``, ``_max`` [Pa]; ``p_min`` [Pa], the least
    mean effective stress, and ``axial_strain_at_p_min`` (where a contracting sample turns to
    dilating, the phase transformation); ``max_volume_change``, max |V / V0 - 1| [-], the
    volume held; ``effective_stress_path``, PATH_POINTS rows evenly spaced over the history:
    axial strain, p' and q of the wall stresses, Delta u, and wet p' of Eq. 3.43, suction and
    saturation Sr, which change at a constant water content."""
    sigma = history["sigma_wall"]
    change = history["excess_pore_pressure"]
    p = mean_stress(sigma)
    least = int(np.argmin(p))
    summary = {
        "drainage": "undrained",
        "excess_pore_pressure_at_peak": float(change[peak]),
        "excess_pore_pressure_final": float(change[-1]),
        "excess_pore_pressure_max": float(change.max()),
        "p_min": float(p[least]),
        "axial_strain_at_p_min": float(history["axial_strain"][least]),
        "max_volume_change": float(np.max(np.abs(history["volumetric_strain"]))),
    }
    rows = np.unique(np.linspace(0, len(p) - 1, PATH_POINTS).round().astype(int))
    path = {"axial_strain": history["axial_strain"][rows], "p": p[rows],
            "q": deviator_stress(sigma[rows]), "excess_pore_pressure": change[rows]}
    effective = effective_diagonal(history)
    if effective is not None:
        path["p_effective"] = mean_stress(effective[rows])
    for name in ("suction", "saturation"):
        if name in history:
            path[name] = history[name][rows]
            summary[f"{name}_final"] = float(history[name][-1])
    summary["effective_stress_path"] = {k: [float(v) for v in values]
                                        for k, values in path.items()}
    return summary


class TriaxialShear:
    """The shear phase of a static sample: its wall control becomes the lateral walls servoed
    at ``confining`` [Pa] and the axial (z) walls at the strain rate of ``shear``
    (pendular.procedures.config.ShearConfig), and a HistoryRecorder of ``history_columns`` records about
    ``shear.records`` rows (the first now, the last at the final strain): one stage of a
    pendular.procedures.loading.LoadingPath (``shear_path``).

    radius [m], density [kg/m^3]: set the strain rate from the inertial number. ``steps``: steps
    to the final strain; ``rate`` [1/s]; ``recorder``; ``axial``: the axial walls' control
    (pendular.dem.walls.ConstantStrainRate); ``path``: the LoadingPath.
    """

    def __init__(self, sim, shear, confining, radius, density):
        self.sim = sim
        self.rate = shear.rate(radius, density, confining)
        self.path = shear_path(sim, shear, confining, self.rate)
        self.axial = next(op for op in self.path.controls
                          if isinstance(op, ConstantStrainRate))
        self.steps = self.path.steps
        self.recorder = self.path.recorder

    def status(self, sim):
        """Progress-bar fields: strain, axial and lateral stress, q/p."""
        return self.path.status(sim)


def shear_path(sim, shear, confining, rate, columns=None):
    """The LoadingPath of a triaxial shear of ``shear`` (ShearConfig) at the axial strain rate
    ``rate`` [1/s] from the isotropic ``confining`` stress [Pa] (triaxial.shear_stage), with
    its servo options; ``columns``: history columns beyond ``history_columns``."""
    return LoadingPath(sim, [shear_stage(shear, confining, rate)], records=shear.records,
                       columns=columns, servo_max_velocity=shear.servo_max_velocity,
                       servo_scale_max_velocity=shear.servo_scale_max_velocity,
                       servo_stiffness_every=shear.servo_stiffness_every,
                       rate_on_current_length=shear.rate_on_current_length)


def summarize(history, direction="compression", b=None):
    """Peak values of a triaxial history (dict of arrays). q is that of the test
    (invariants.shear_deviator: sigma_z - sigma_lateral, negative in extension; the von Mises
    q at ``b`` != 0), its peak the largest q in compression, the least (most negative) in
    extension: ``peak_q``, ``p_at_peak``, ``axial_strain_at_peak`` (negative in extension),
    ``principal_difference_at_peak`` (sigma_1 - sigma_3) and, recorded, Sr and the suction
    there, all of that record; in compression ``peak_axial_stress`` (the largest axial
    stress), in extension ``min_axial_stress`` and ``axial_contact_lost``: whether the axial
    stress fell to 0 (the walls released a cohesive sample before it failed).
    ``phi_peak_deg``: the mobilised friction angle at the peak (columns.friction_angle of the
    net wall stresses), None with ``phi_peak_note`` when the axial contact was lost. A wet
    history adds ``peak_q_effective``, ``p_effective_at_peak`` and
    ``phi_peak_effective_deg``: q', p' and the friction angle of the effective stress (Eq.
    3.43) at the peak of q, and with the exact bridge model ``peak_q_effective_complete`` and
    ``p_effective_complete_at_peak``: those of the complete effective stress (psi plus the
    liquid-gas interface term, pendular.homogenize.on_the_fly). The critical state
    (pendular.procedures.critical_state): ``phi_cs_deg``, ``M_cs``, ``void_ratio_cs`` and
    ``critical_state_note``, and wet ``phi_cs_effective_deg``, ``M_cs_effective``."""
    sigma = np.asarray(history["sigma_wall"], dtype=np.float64)
    extension = direction == "extension"
    q = shear_deviator(sigma, b)
    peak = int(np.argmax(-q if extension else q))
    contact_lost = extension and bool(sigma[:, 2].min() <= 0.0)
    summary = {"min_axial_stress": float(sigma[:, 2].min()),
               # the axial walls cannot pull: at zero stress they have left the sample, whose
               # strength in extension they then no longer measure (a cohesive wet sample)
               "axial_contact_lost": contact_lost} if extension else {
        "peak_axial_stress": float(sigma[:, 2].max())}
    summary.update({
        "peak_q": float(q[peak]),
        "p_at_peak": float(mean_stress(sigma)[peak]),
        "axial_strain_at_peak": float(history["axial_strain"][peak]),
        "principal_difference_at_peak": float(principal_difference(sigma[peak])),
        "lateral_stress": float(np.mean(lateral_stress(sigma))),
        "peak_index": peak,
        "phi_peak_deg": None if contact_lost else float(friction_angle(sigma[peak])),
    })
    if contact_lost:
        summary["phi_peak_note"] = (
            "not measured: the axial stress fell to 0, the axial walls (which cannot pull) "
            "left the sample before it failed in extension; the peak values are those of the "
            "walls' release")
    if "saturation" in history:
        summary["saturation_at_peak"] = float(history["saturation"][peak])
    if "suction" in history:                      # not in a YADE history
        summary["suction_at_peak"] = float(history["suction"][peak])
    effective = None
    if "sigma_effective" in history:
        effective = np.diagonal(history["sigma_effective"], axis1=1, axis2=2)
        summary["peak_q_effective"] = float(shear_deviator(effective[peak], b))
        summary["p_effective_at_peak"] = float(effective[peak].mean())
        summary["phi_peak_effective_deg"] = (None if contact_lost else
                                             float(friction_angle(effective[peak])))
    if "sigma_effective_complete" in history:
        complete = np.diagonal(history["sigma_effective_complete"][peak])
        summary["peak_q_effective_complete"] = float(shear_deviator(complete, b))
        summary["p_effective_complete_at_peak"] = float(complete.mean())
    if "porosity" in history and "volumetric_strain" in history:
        strain, volumetric = history["axial_strain"], history["volumetric_strain"]
        summary.update(critical_state(strain, volumetric, sigma, q, history["porosity"]))
        if effective is not None:
            found = critical_state(strain, volumetric, effective, shear_deviator(effective, b),
                                   history["porosity"])
            summary.update({"phi_cs_effective_deg": found["phi_cs_deg"],
                            "M_cs_effective": found["M_cs"]})
    summary.update(stress_balance(history))
    return summary


# ---------------------------------------------------------------- the whole test


class TriaxialTest(LaboratoryTest):
    """A drained triaxial test of ``config`` (pendular.procedures.triaxial.TriaxialConfig): the
    shear of ``config.shear`` (compression, extension, at a constant b or mean stress;
    triaxial.shear_stage); figure triaxial.png (q and volumetric strain against axial strain),
    plots/ (q/p, volumetric strain, wet: saturation and capillary stresses; the stress path
    stress_path.png: q-p and, wet, q'-p' of the effective stress)."""

    CONFIG = TriaxialConfig
    ENDS_AT_CONTACT_LOSS = True

    def loading(self, sim):
        config = self.config
        path = shear_path(sim, config.shear, config.confining, config.rate())
        if config.shear.direction == "extension":
            # the axial walls cannot pull: once they leave the sample the test is over
            sim.writers.append(AxialStressGuard(
                lambda s: f"extension at axial strain {path.axial.strain(s.walls):.3g}",
                "the shear ends there (summary.json axial_contact_lost)"))
        return path

    def stages(self):
        config = self.config
        return [shear_stage(config.shear, config.confining, config.rate())]

    def summarize(self, history):
        shear = self.config.shear
        summary = summarize(history, shear.direction, shear.b)
        q = shear_deviator(history["sigma_wall"], shear.b)
        summary["peak_reached"] = (not summary.get("axial_contact_lost", False)
                                   and peak_reached(history["axial_strain"],
                                                    -q if shear.direction == "extension"
                                                    else q))
        summary.update(path_deviations(history, shear, self.config.confining))
        if self.config.undrained:
            summary.update(undrained_summary(history, summary["peak_index"]))
        return summary

    def derived(self, history):
        """Undrained, the history with ``excess_pore_pressure`` (excess_pore_pressure
        of the wall stresses)."""
        if self.config.undrained:
            history["excess_pore_pressure"] = excess_pore_pressure(history["sigma_wall"])
        return history

    def plot(self, history, out, title):
        shear = self.config.shear
        plot_history(history, os.path.join(out, self.FIGURE), title, shear.direction, shear.b)
        drainage = "undrained" if self.config.undrained else "drained"
        named = f"{drainage} triaxial {shear.direction}; {title}"    # the plots/ name the test
        write_plots(history, os.path.join(out, "plots"), named, shear.direction, shear.b)
        plot_stress_path(history, os.path.join(out, "plots", "stress_path.png"), named,
                         shear.direction, shear.b)


# ---------------------------------------------------------------- the command


#: A triaxial shear's own options.
SHEAR = (options_named(ShearConfig, ("max_strain", "direction", "b", "constant_p", "drainage"))
         + rate_options(ShearConfig) + (option_of(ShearConfig, "records"),))


def axial_strain(strain):
    """The final axial strain ``strain`` of a triaxial shear (--max-strain); ParameterError
    outside [MIN_AXIAL_STRAIN, MAX_AXIAL_STRAIN], saying why (AXIAL_STRAIN_LIMIT)."""
    if not MIN_AXIAL_STRAIN <= strain <= MAX_AXIAL_STRAIN:              # NaN included
        raise ParameterError("max_strain", f"max_strain = {strain:g} is outside the valid "
                             f"range [{MIN_AXIAL_STRAIN:g}, {MAX_AXIAL_STRAIN:g}]: "
                             f"{AXIAL_STRAIN_LIMIT}", "--max-strain")
    return strain


def triaxial_config(values, given):
    """The TriaxialConfig of ``values`` (its shear's steps bounding --vtk-frames and
    --records)."""
    axial_strain(values["max_strain"])
    if values["records"] is not None:
        spec_of(ShearConfig, "records").check("records", values["records"])
    fields = laboratory_fields(values, given, lambda: ShearConfig(**fields_of(values, SHEAR)))
    frames = values["vtk_frames"]
    config = TriaxialConfig(**fields, **({} if frames is None else {"vtk_frames": frames}))
    # counts given beyond the shear's steps would silently give one a step (the defaults may)
    steps = config.shear_steps()
    phase = f"the shear to --max-strain {config.shear.max_strain:g}"
    if frames is not None:
        steps_count("vtk_frames", frames, steps, phase)
    if values["records"] is not None:
        steps_count("records", values["records"], steps, phase, low=2)
    return config


#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular triaxial --particles 1000 --suction 30000 --confining 750 --out runs/wet",
           "a wet drained triaxial compression at 30 kPa suction and 750 Pa confining stress: "
           "the peak of q and its friction angles (net and effective), the critical state when "
           "reached, in summary.json; q and the volumetric strain in triaxial.png")

#: Summary keys printed at the end.
SHOWN = ("peak_axial_stress", "min_axial_stress", "peak_q", "p_at_peak", "axial_strain_at_peak",
         "principal_difference_at_peak", "phi_peak_deg", "peak_q_effective",
         "p_effective_at_peak", "phi_peak_effective_deg", "peak_q_effective_complete",
         "p_effective_complete_at_peak", "phi_cs_deg", "M_cs", "void_ratio_cs",
         "critical_state_note", "phi_peak_note",
         "mean_stress_deviation", "b_deviation", "axial_contact_lost", "initial_porosity",
         "porosity_after_wetting", "saturation_at_peak", "suction_at_peak",
         "excess_pore_pressure_at_peak", "excess_pore_pressure_final", "p_min",
         "max_volume_change", "suction_final", "saturation_final",
         "liquid_balance_error", "liquid_lost_fraction", "wall_time_s", "particle_steps_per_s")

#: The triaxial command (pendular.procedures.registry).
COMMAND = LaboratoryCommand(
    name="triaxial",
    description="triaxial test (thesis Ch. 5), dry or wet, drained or undrained",
    test=TriaxialTest,
    declared=laboratory_options(SHEAR, triaxial_config, frames=True),
    shown=SHOWN, example=EXAMPLE, out="runs/triaxial")
