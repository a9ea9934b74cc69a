"""Drained triaxial test (thesis Ch. 5.2.3): prepare, wet, shear, record, resume.

Building blocks, usable alone for a custom loading path (README "Using it"):

- ``equilibrate(sim, ...)``: run until static (unbalanced force and servoed stresses within
  tolerance);
- ``wet(sim, bridges, ...)``: add capillary bridges to a static sample and re-equilibrate;
- ``TriaxialShear(sim, shear, ...)``: lateral walls servoed, axial walls at a constant strain
  rate, a history recorder; ``sim.run(shear.steps)`` shears to the final strain;
- ``summarize(history)``: peak values.

``TriaxialTest(config).run(out)`` chains them as the thesis does and writes the outputs
(history.h5, summary.json, triaxial.png, plots/, vtk/, sample.h5, checkpoint.h5; with
``vtk_prep``, vtk_prep/: ParaView frames of the preparation and wetting);
``TriaxialTest.resume(out)`` continues an interrupted run from its checkpoint bit-identically.

Stresses compression positive [Pa], q and p as pendular.homogenize.invariants; strains compression
positive, volumetric strain positive in contraction (SPEC §1).
"""

from __future__ import annotations

import contextlib
import json
import os
import sys
import time

import numba
import numpy as np

from pendular.utils.atomic import write_json
from pendular.dem.checkpoint import CheckpointWriter, load_checkpoint
from pendular.dem.grading import grading
from pendular.utils.integrity import checksum, config_hash
from pendular.utils.interrupt import deferred_interrupts, pause_point, pausing_at
from pendular.dem.measure import coordination, porosity, unbalanced_force
from pendular.procedures.preparation import (PREPARATION_PHASES, prepare_sample, pwave_step,
    servoed_simulation, static, timestep, timestep_description)
from pendular.dem.record import HistoryRecorder
from pendular.dem.sample import load_sample, save_sample
from pendular.utils.validate import check_int
from pendular.dem.walls import ConstantStrainRate, StressServo
from pendular.homogenize import contact_stress, fabric_tensor, principal_anisotropy
from pendular.homogenize.invariants import deviator_stress, lateral_stress, mean_stress

from pendular.procedures.guards import SampleCrushed, SampleGuard
from pendular.procedures.config import (TriaxialConfig, config_from_dict, config_to_dict,
    inertial_number)
from pendular.io.history import write_history
from pendular.io.outputs import OutputFolder
from pendular.io.schema import SUMMARY_UNITS, peak_reached
from pendular.io.plots import plot_history, run_label, write_plots
from pendular.io.vtk import VtkWriter
from pendular.procedures.water_content import wet_to_water_volume

#: Largest inertial number of a quasi-static shear (GDR MiDi 2004: I < 1e-3 quasi-static,
#: dense flow beyond; at 1e-2 the wall and Love–Weber stresses already differ by a few %).
MAX_INERTIAL_NUMBER = 1e-2
#: Most shear steps a run may ask for without --force (about 1 h at 1,000 spheres here).
MAX_SHEAR_STEPS = 20_000_000
#: Smallest prep_stress / young of a preparation: the radius growth (1e-4 R per step) settles
#: only when the overlaps at the target stress (about 8 prep_stress / young R) are well above
#: its step (60 spheres: 1.7e-4 settles in 7,400 steps, 5e-5 not in 2,000,000).
MIN_PREP_STRESS_OVER_YOUNG = 1e-4
#: Smallest confining / young: below, the six servoed walls do not hold the confining stress
#: within the 1 % tolerance (60 spheres, young 1e6 Pa: 5 Pa is static after 8,600 steps,
#: 3 Pa not after 250,000; the walls hover at 10-30 Pa).
MIN_CONFINING_OVER_YOUNG = 5e-6
#: Largest difference between the wall stress and the Love–Weber stress of contacts and bridges
#: (any axis, over the mean wall stress p) of a record in equilibrium: quasi-static runs stay
#: below 2-4 % (60-1,000 spheres, max over 500 records), I = 0.05 reaches 100 %.
STRESS_BALANCE_BOUND = 0.05
#: Particle-steps per second assumed for run-time estimates (one core of the 2-core machine).
ESTIMATE_RATE = 4e6
#: Density of water [kg/m^3]: the specific gravity of the grains is their density over it.
WATER_DENSITY = 1000.0


#: Files and folders a triaxial run owns in its output folder (pendular.io.outputs).
OUTPUTS = ("history.h5", "summary.json", "triaxial.png", "plots", "vtk", "sample.h5",
           "checkpoint.h5", "vtk_prep")

#: Phases of the vtk_prep/ series, by the code in each frame's field data ``phase``: those of
#: pendular.procedures.preparation.prepare_sample, then "sample" (a loaded sample equilibrated at the confining
#: stress) and "wetting" (bridges added, equilibrated again).
PREP_PHASES = (*PREPARATION_PHASES, "sample", "wetting")


class NotStatic(ValueError):
    """An equilibrium phase ended at its step limit without reaching equilibrium."""


class Interrupted(Exception):
    """A run stopped before its end (Ctrl-C, or ``stop_after``); the checkpoint, if any, is
    where ``TriaxialTest.resume`` starts."""


# ---------------------------------------------------------------- building blocks

def equilibrate(sim, *, unbalanced=0.01, tolerance=0.01, max_steps=200000, check_every=200,
                progress=None, phase="equilibrium"):
    """Run ``sim`` until static: unbalanced force below ``unbalanced`` and, if a StressServo
    controls walls, their stresses within ``tolerance`` (relative) of its target; at most
    ``max_steps`` steps. Returns the steps taken; NotStatic (naming ``phase`` and what it
    reached) when the limit is hit first."""
    done = static(unbalanced, tolerance)
    steps = sim.run(max_steps, until=done, check_every=check_every, progress=progress,
                    status=equilibrium_status(unbalanced))
    if not done(sim):
        reached = equilibrium_status(unbalanced)(sim)
        raise NotStatic(f"{phase} not reached in {steps} steps (the step limit): "
                        + ", ".join(f"{k} {v}" for k, v in reached.items())
                        + "; raise the step limit (e.g. --wet-steps) or check the settings")
    return steps


def equilibrium_status(unbalanced):
    """Progress fields of an equilibrium phase: the unbalanced force against its target and
    each servo's stress against its target."""

    def status(sim):
        fields = {"unbalanced": f"{unbalanced_force(sim.particles, sim.contacts):.3g}"
                                f"/{unbalanced:g}"}
        for servo in (op for op in sim.controls if isinstance(op, StressServo)):
            stress = sim.walls.stress()[list(servo.axes)]
            fields["stress"] = (f"{np.max(np.abs(stress - servo.target)):.3g}Pa off "
                                f"{servo.target:g}Pa")
        return fields

    return status


def wet(sim, bridges, *, unbalanced=0.01, tolerance=0.01, max_steps=200000, progress=None):
    """Add the capillary operation ``bridges`` to the forces of a static sample and run until
    static again; returns the wetting report (steps, time, Sr, bridges, porosity)."""
    sim.forces.append(bridges)
    started = time.perf_counter()
    steps = equilibrate(sim, unbalanced=unbalanced, tolerance=tolerance, max_steps=max_steps,
                        progress=progress, phase="equilibrium after wetting")
    return {"wetting_steps": steps, "wetting_time_s": time.perf_counter() - started,
            "initial_saturation": bridges.saturation(sim), "initial_bridges": bridges.count(sim),
            "wet_porosity": porosity(sim.particles, sim.walls)}


def wet_sample(sim, config, *, progress=None):
    """Wet the static sample ``sim`` as ``config`` (TriaxialConfig) says; returns (the wet
    simulation, its bridge operation, the wetting report). Protocols (config.wetting):

    - 'isotropic': bridges added, the servo re-equilibrates the sample (``wet``);
    - 'at-shear': bridges added, formed at the sample's contacts now and shearing starts at
      once (the servo meets them during the shear);
    - 'constant-volume': bridges added with the walls fixed, run until the unbalanced force is
      below the threshold, then the servo brings the walls to the confining stress.

    At a water content (config.bridges.water_content) the bridges are volume-controlled, their
    formation suction found so that they hold w Gs V_s (Gs = density / 1000 kg/m^3;
    pendular.procedures.water_content), the sample re-equilibrated; the liquid is then closed
    (CapillaryBridges.close_liquid), so the shear conserves it."""
    sample = config.sample
    thresholds = {"unbalanced": sample.equilibrium_unbalanced,
                  "tolerance": sample.stress_tolerance, "max_steps": config.wet_steps}
    if config.bridges.water_content is not None:
        return _wet_at_water_content(sim, config, thresholds, progress)
    bridges = config.bridges.build()
    if config.wetting == "isotropic":
        return sim, bridges, wet(sim, bridges, progress=progress, **thresholds)
    started = time.perf_counter()
    sim.forces.append(bridges)
    steps = 0
    if config.wetting == "at-shear":
        sim.evaluate_forces()               # the bridges form at the sample's contacts
    else:
        servo = sim.controls
        sim.controls = []                   # walls fixed
        steps = equilibrate(sim, phase="equilibrium of the wetted sample at constant volume",
                            progress=progress, **thresholds)
        fixed_stress = sim.walls.stress().tolist()
        sim.controls = servo
        steps += equilibrate(sim, phase="equilibrium after wetting at constant volume",
                             progress=progress, **thresholds)
    report = {"wetting": config.wetting, "wetting_steps": steps,
              "wetting_time_s": time.perf_counter() - started,
              "initial_saturation": bridges.saturation(sim),
              "initial_bridges": bridges.count(sim),
              "wet_porosity": porosity(sim.particles, sim.walls)}
    if config.wetting == "constant-volume":
        report["sigma_wall_at_constant_volume"] = fixed_stress
    return sim, bridges, report


def _wet_at_water_content(dry, config, thresholds, progress):
    """wet_sample at config.bridges.water_content (volume-controlled bridges at contacts)."""
    from pendular.capillary import BridgeTable, gravimetric_water_content, sample_radius_ratios

    bridges_config = config.bridges
    particles = dry.particles
    specific_gravity = particles.density / WATER_DENSITY
    target = bridges_config.water_content * specific_gravity * particles.solid_volume()
    if dry.contacts is None:
        dry.evaluate_forces()
    touching = dry.contacts.overlap > 0.0
    pairs = (particles.radius[dry.contacts.pair_i[touching]],
             particles.radius[dry.contacts.pair_j[touching]], None)
    table = BridgeTable.cached(bridges_config.contact_angle,
                               radius_ratios=sample_radius_ratios(particles.radius))
    started = time.perf_counter()
    try:
        sim, bridges, tries = wet_to_water_volume(
            dry, target, table, pairs, bridges_config.build,
            lambda s: equilibrate(s, progress=progress, phase="equilibrium after wetting",
                                  **thresholds),
            surface_tension=bridges_config.surface_tension,
            roughness=bridges_config.roughness)
    except ValueError as error:
        raise ValueError(f"--water-content = {100 * bridges_config.water_content:g} %: {error}") \
            from None
    bridges.close_liquid(sim, bridges_config.liquid)
    solid = particles.solid_volume()
    return sim, bridges, {
        "wetting": "water-content", "wetting_steps": sum(t["steps"] for t in tries),
        "wetting_time_s": time.perf_counter() - started,
        "formation_suction_pa": tries[-1]["formation_suction_pa"],
        "water_content": gravimetric_water_content(bridges.liquid_initial, solid,
                                                   specific_gravity),
        "wetting_attempts": tries, "liquid_initial": bridges.liquid_initial,
        "initial_saturation": bridges.saturation(sim), "initial_bridges": bridges.count(sim),
        "wet_porosity": porosity(sim.particles, sim.walls)}


@contextlib.contextmanager
def watched(sim, writers, phase):
    """Within the block, ``writers`` (read-only operations, e.g. the vtk_prep VtkWriter) are
    appended to ``sim.writers`` and those with a ``phase`` attribute have it set to ``phase``;
    they are removed at its end."""
    writers = list(writers)
    for writer in writers:
        if hasattr(writer, "phase"):
            writer.phase = phase
    sim.writers.extend(writers)
    try:
        yield
    finally:
        sim.writers = [op for op in sim.writers if not any(op is w for w in writers)]


def prep_vtk_period(sample):
    """Default steps between the frames of vtk_prep/: one per unload stage of the preparation
    (``unload_steps`` / 20, 500 steps by default), so that a preparation (a radius growth of at
    least 5,000 steps, the unload, the equilibria) gives a few tens of frames."""
    return max(1, sample.unload_steps // 20)


def capillary_operation(sim):
    """The scene's capillary bridge operation, or None for a dry scene."""
    found = [op for op in sim.forces if hasattr(op, "water_volume")]
    return found[0] if found else None


def history_columns(sim, axial, reference_volume, bridges=None):
    """Recorded columns of a triaxial history (name -> function of sim); pendular.io.schema
    declares their units. A wet scene adds the capillary and homogenised columns of
    pendular.homogenize.on_the_fly.CapillaryHomogenization (Eqs. 3.43-3.46, 3.53-3.54, 4.5)."""

    def contact_fabric(s):
        return fabric_tensor(s.contacts.normal, s.contacts.overlap > 0.0)   # Eq. 4.1

    columns = {
        "step": lambda s: s.step,
        "time": lambda s: s.time,
        "axial_strain": lambda s: axial.strain(s.walls),
        "volumetric_strain": lambda s: 1.0 - s.walls.volume() / reference_volume,
        "sigma_wall": lambda s: s.walls.stress(),
        "sigma_contact": lambda s: contact_stress(s.particles, s.contacts, s.walls),
        "porosity": lambda s: porosity(s.particles, s.walls),
        "coordination": lambda s: coordination(s.contacts, len(s.particles)),
        "fabric": contact_fabric,
        "anisotropy": lambda s: principal_anisotropy(contact_fabric(s)),      # Eq. 3.51
        "unbalanced_force": lambda s: unbalanced_force(s.particles, s.contacts),
    }
    if bridges is not None:
        from pendular.homogenize.on_the_fly import CapillaryHomogenization

        columns.update(CapillaryHomogenization(bridges).quantities())
        if bridges.liquid != "reservoir":             # a closed amount of liquid
            columns.update({"liquid_bridges": lambda s: bridges.liquid_balance(s)[0],
                            "liquid_film": lambda s: bridges.liquid_balance(s)[1],
                            "liquid_lost": lambda s: bridges.liquid_balance(s)[2]})
    return columns


class TriaxialShear:
    """The shear phase of a static sample: its wall control becomes the lateral walls servoed
    at ``confining`` [Pa] and the axial (z) walls at the strain rate of ``shear``
    (pendular.procedures.config.ShearConfig), and a HistoryRecorder of ``history_columns`` records about
    ``shear.records`` rows (the first now, the last at the final strain).

    radius [m], density [kg/m^3]: set the strain rate from the inertial number. ``steps``: steps
    to the final strain; ``rate`` [1/s]; ``recorder``.
    """

    def __init__(self, sim, shear, confining, radius, density):
        self.sim = sim
        servo = next(op for op in sim.controls if isinstance(op, StressServo))
        self.rate = shear.rate(radius, density, confining)
        self.axial = ConstantStrainRate("z", self.rate, sim.walls.lengths()[2],
                                        on_current_length=shear.rate_on_current_length)
        max_velocity = (servo.max_velocity if shear.servo_max_velocity is None
                        else shear.servo_max_velocity)
        lateral = StressServo("xy", confining, max_velocity,
                              scale_max_velocity=shear.servo_scale_max_velocity,
                              stiffness_every=shear.servo_stiffness_every)
        if sim.contacts is None:
            sim.evaluate_forces()     # a sample just loaded: the first record sees its contacts
        sim.controls = [lateral, self.axial]
        self.steps = self.axial.steps_to(shear.max_strain, sim.dt)
        self.recorder = HistoryRecorder(
            max(1, self.steps // shear.records),
            history_columns(sim, self.axial, sim.walls.volume(), capillary_operation(sim)),
            origin=sim.step, end=sim.step + self.steps)
        self.recorder.record(sim)
        sim.writers.append(self.recorder)
        sim.writers.append(SampleGuard(self.recorder.period, describe=lambda s: (
            f"axial strain {self.axial.strain(s.walls):.3g}")))

    def status(self, sim):
        """Progress-bar fields: strain, axial and lateral stress, q/p."""
        sigma = sim.walls.stress()
        return {"strain": f"{self.recorder.last('axial_strain'):.3f}",
                "sz": f"{sigma[2]:.0f}Pa", "sr": f"{lateral_stress(sigma):.0f}Pa",
                "q/p": f"{deviator_stress(sigma) / mean_stress(sigma):.2f}"}


def summarize(history):
    """Peak values of a triaxial history (dict of arrays): axial stress, q, p, strain at the
    peak of q (and Sr there when recorded). A wet history adds ``peak_q_effective`` and
    ``p_effective_at_peak``: q' and p' of the effective stress (Eq. 3.43) at the peak of q,
    and with the exact bridge model ``peak_q_effective_complete`` and
    ``p_effective_complete_at_peak``: those of the complete effective stress (psi plus the
    liquid-gas interface term, pendular.homogenize.on_the_fly)."""
    sigma = history["sigma_wall"]
    q = deviator_stress(sigma)
    peak = int(np.argmax(q))
    summary = {
        "peak_axial_stress": float(sigma[:, 2].max()),
        "peak_q": float(q[peak]),
        "p_at_peak": float(mean_stress(sigma)[peak]),
        "axial_strain_at_peak": float(history["axial_strain"][peak]),
        "lateral_stress": float(np.mean(lateral_stress(sigma))),
        "peak_index": peak,
    }
    if "saturation" in history:
        summary["saturation_at_peak"] = float(history["saturation"][peak])
    if "suction" in history:                      # not in a YADE history
        summary["suction_at_peak"] = float(history["suction"][peak])
    if "sigma_effective" in history:
        effective = np.diagonal(history["sigma_effective"][peak])
        summary["peak_q_effective"] = float(deviator_stress(effective))
        summary["p_effective_at_peak"] = float(effective.mean())
    if "sigma_effective_complete" in history:
        complete = np.diagonal(history["sigma_effective_complete"][peak])
        summary["peak_q_effective_complete"] = float(deviator_stress(complete))
        summary["p_effective_complete_at_peak"] = float(complete.mean())
    if "sigma_contact" in history:                # not in a YADE history
        error = stress_balance_error(history)
        summary.update({
            "stress_balance_error": float(np.max(error)),
            "stress_balance_bound": STRESS_BALANCE_BOUND,
            "stress_balance_flagged": np.flatnonzero(error > STRESS_BALANCE_BOUND).tolist(),
        })
    return summary


def stress_balance_error(history):
    """Per record, max over the axes of |sigma_wall - diag(sigma_contact + sigma_capillary)| / p
    (p the mean wall stress): how far the wall stress and the Love–Weber stress (Eq. 3.41) of
    the contacts and bridges inside are from the balance that holds in equilibrium."""
    inside = history["sigma_contact"]
    if "sigma_capillary" in history:
        inside = inside + history["sigma_capillary"]
    wall = history["sigma_wall"]
    return (np.abs(np.diagonal(inside, axis1=1, axis2=2) - wall).max(axis=1)
            / np.abs(mean_stress(wall)))


# ---------------------------------------------------------------- the whole test

def check_feasible(config, force=False):
    """Refuse, before anything runs, a test that cannot be quasi-static (inertial number above
    MAX_INERTIAL_NUMBER) or would not finish in reasonable time (more than MAX_SHEAR_STEPS shear
    steps), with the estimate, or whose equilibrium phases cannot settle (confining below
    MIN_CONFINING_OVER_YOUNG young; a preparation with prep_stress below
    MIN_PREP_STRESS_OVER_YOUNG young); ``force`` lets an expert run it anyway. Output periods
    must fit the shear. ValueError naming the setting."""
    sample, shear = config.sample, config.shear
    rate = shear.rate(sample.radius, sample.density, sample.confining)
    number = inertial_number(rate, sample.radius, sample.density, sample.confining)
    dt = pwave_step(sample.radius, sample)    # the stiffness rule's step is larger
    steps = config.shear_steps()
    if not force and number > MAX_INERTIAL_NUMBER:
        raise ValueError(
            f"strain rate {rate:.3g} 1/s gives the inertial number I = {number:.3g}, outside "
            f"the quasi-static range (0, {MAX_INERTIAL_NUMBER:g}] at confining = "
            f"{sample.confining:g} Pa: lower --strain-rate / --inertial-number (or --force)")
    if not force and steps > MAX_SHEAR_STEPS:
        hours = sample.particles * steps / ESTIMATE_RATE / 3600.0
        raise ValueError(
            f"the shear would take {steps:.3g} steps (dt = {dt:.3g} s, strain rate {rate:.3g} "
            f"1/s; about {hours:.3g} h here), outside the valid range [1, {MAX_SHEAR_STEPS:g}]:"
            " raise the strain rate or lower young / the time step's cost (or --force)")
    if (not force and config.sample_path is None
            and sample.prep_stress < MIN_PREP_STRESS_OVER_YOUNG * sample.young):
        raise ValueError(
            f"young = {sample.young:g} Pa is outside the valid range (0, "
            f"{sample.prep_stress / MIN_PREP_STRESS_OVER_YOUNG:g}] Pa for the preparation at "
            f"prep_stress = {sample.prep_stress:g} Pa: the radius growth cannot settle at "
            f"overlaps below {MIN_PREP_STRESS_OVER_YOUNG:g} of the radius (it would run "
            "2,000,000 steps and stop); lower young (or --force)")
    if not force and sample.confining < MIN_CONFINING_OVER_YOUNG * sample.young:
        raise ValueError(
            f"confining = {sample.confining:g} Pa is outside the valid range "
            f"[{MIN_CONFINING_OVER_YOUNG * sample.young:g}, 1e+07] Pa for young = "
            f"{sample.young:g} Pa: below {MIN_CONFINING_OVER_YOUNG:g} young the servoed walls "
            "never hold the confining stress (the equilibrium would run to its step limit); "
            "raise confining or lower young (or --force)")
    for name in ("vtk_every", "checkpoint_every"):
        value = getattr(config, name)
        if value is not None and value > max(steps, 1.0) + 1:
            raise ValueError(f"{name} = {value} is outside the valid range [0, {int(steps) + 1}]"
                             f": the shear has about {int(steps)} steps")


def parameters(config):
    """Flat name -> value of a configuration, named as the command's options (history file
    attributes, campaign tables)."""
    sample, shear, bridges = config.sample, config.shear, config.bridges
    flat = {"particles": sample.particles, "radius": sample.radius,
            "radius_spread": sample.radius_spread, "psd": sample.psd,
            "porosity": sample.porosity,
            "young": sample.young, "shear_ratio": sample.shear_ratio,
            "friction": sample.friction_deg, "prep_friction": sample.prep_friction_deg,
            "density": sample.density, "damping": sample.damping,
            "timestep_safety": sample.timestep_safety, "timestep_rule": sample.timestep_rule,
            "prep_stress": sample.prep_stress,
            "confining": sample.confining, "seed": sample.seed, "skin_factor": sample.skin_factor,
            "max_strain": shear.max_strain, "inertial_number": shear.inertial_number,
            "strain_rate": shear.strain_rate, "records": shear.records,
            "suction": config.suction, "wet_steps": config.wet_steps,
            "wetting": config.wetting,
            "vtk_every": config.vtk_every, "checkpoint_every": config.checkpoint_every,
            "sample": config.sample_path}
    if bridges is not None:
        flat.update({"contact_angle": bridges.contact_angle, "bridges": bridges.model,
                     "surface_tension": bridges.surface_tension,
                     "persist_bridges": bridges.persist, "control": bridges.control,
                     "water_content_percent": (None if bridges.water_content is None
                                               else 100.0 * bridges.water_content),
                     "liquid": None if bridges.water_content is None else bridges.liquid,
                     "table_resolution": (None if bridges.table_resolution is None else
                                          ",".join(map(str, bridges.table_resolution)))})
    return flat


class TriaxialTest:
    """A drained triaxial test of ``config`` (pendular.procedures.config.TriaxialConfig).

    ``run(out)`` prepares the sample (or loads ``config.sample_path``), wets it at the confining
    stress (bridges at every contact, six walls servoed until static), shears it and writes
    into ``out``: history.h5, summary.json, triaxial.png, plots/, vtk/ (ParaView), sample.h5
    (the sample the shear starts from, with the configuration), with checkpoint_every
    checkpoint.h5 and, with ``vtk_prep``, vtk_prep/ (ParaView frames of the preparation and
    wetting). Returns the summary (dict). A run stopped before its end (pendular.io.outputs)
    names in summary.json the phase it reached: "prepare", "wet", "shear" or "write".
    """

    def __init__(self, config: TriaxialConfig, *, force=False):
        if not isinstance(config, TriaxialConfig):
            raise TypeError(f"config must be a TriaxialConfig, got {type(config).__name__}")
        self.config = config
        check_feasible(config, force=force)
        if config.bridges is not None and config.bridges.suction is not None:
            # check the bridges against the sample's radii before any preparation
            from pendular.capillary import sample_radius_ratios

            radii = config.sample.radii()
            config.bridges.build().load_tables(float(radii.min()), float(radii.max()),
                                               radius_ratios=sample_radius_ratios(radii))

    # ------------------------------------------------------------ phases
    def start(self, progress=True, threads=None, writers=()):
        """(static sample at the confining stress, preparation report); ``writers`` watch the
        preparation or the equilibrium of a loaded sample (e.g. the vtk_prep VtkWriter)."""
        config = self.config
        if config.sample_path is None:
            return prepare_sample(config.sample, progress=progress, threads=threads,
                                  writers=writers)
        return self.load_sample(config.sample_path, progress, threads, writers)

    def load_sample(self, path, progress=True, threads=None, writers=()):
        """(sample saved at ``path`` servoed at the confining stress and run until static,
        its report); ``writers`` watch the equilibrium (phase "sample")."""
        sample = self.config.sample
        particles, walls, report, _ = load_sample(path, expected=sample)
        sim = servoed_simulation(particles, walls, sample, sample.confining, threads=threads)
        started = time.perf_counter()
        with watched(sim, writers, "sample"):
            steps = equilibrate(sim, unbalanced=sample.equilibrium_unbalanced,
                                tolerance=sample.stress_tolerance,
                                max_steps=self.config.wet_steps,
                                progress="equilibrate sample" if progress else None,
                                phase=f"equilibrium of sample {path!r} at the confining stress")
        report = dict(report)
        report.update({"sample": os.path.abspath(path), "sample_equilibration_steps": steps,
                       "sample_equilibration_time_s": time.perf_counter() - started,
                       "porosity": porosity(sim.particles, sim.walls),
                       "coordination": coordination(sim.contacts, len(sim.particles)),
                       "sigma_wall": sim.walls.stress().tolist()})
        report.setdefault("steps", steps)
        report.setdefault("timestep", timestep_description(sample))
        return sim, report

    def run(self, out, *, progress=True, threads=None, stop_after=None, vtk_prep=False,
            plots=True):
        """The whole test into the folder ``out`` (class docstring); ``stop_after``: stop the
        shear after this many steps as an interruption would (raises Interrupted); ``plots``:
        False leaves out triaxial.png and plots/ (a run timed for its physics, as the
        trade-off study's: the figures cost about 2 s a run).
        ``vtk_prep``: ParaView frames of the preparation and wetting into ``out``/vtk_prep/
        (``prep_writer``): True every ``prep_vtk_period`` steps, a positive integer every that
        many steps, False (default) or 0 none. Output only: the results are the same."""
        if vtk_prep is not True and vtk_prep is not False:
            vtk_prep = check_int("vtk_prep", vtk_prep, low=0)
        if self.config.sample_path is not None:       # checked before the folder is touched
            load_sample(self.config.sample_path, expected=self.config.sample)
        with OutputFolder(out, "triaxial") as folder:
            for name in OUTPUTS:
                folder.claim(name)
            return self._run(folder, progress, threads, stop_after, vtk_prep, plots)

    def prep_writer(self, out, vtk_prep):
        """The VtkWriter of ``out``/vtk_prep/ (None when ``vtk_prep`` is False or 0): the four
        series of pendular.io.vtk, ParaView's time axis the simulated time [s], field data
        ``phase`` (index in PREP_PHASES: 0 growth, 1 friction, 2 unload, 3 equilibrate, 4
        sample, 5 wetting) and ``mean_wall_stress`` [Pa]; a frame every period steps and at
        the first step of each phase."""
        if vtk_prep is False or vtk_prep == 0:
            return None
        period = prep_vtk_period(self.config.sample) if vtk_prep is True else vtk_prep
        return VtkWriter(os.path.join(out, "vtk_prep"), period, phases=PREP_PHASES,
                         field_data=lambda s: {"mean_wall_stress":
                                               float(np.mean(s.walls.stress()))})

    def _run(self, folder, progress, threads, stop_after, vtk_prep, plots):
        config, out = self.config, folder.path
        started = time.perf_counter()
        frames = self.prep_writer(out, vtk_prep)
        writers = () if frames is None else (frames,)
        folder.phase = "prepare"
        pause_point(folder.phase)
        sim, preparation = self.start(progress, threads, writers)
        prepared = time.perf_counter()
        wetting = {}
        if config.bridges is not None:
            folder.phase = "wet"
            pause_point(folder.phase)
            # the water-content wetting restarts from copies of the dry sample: no frames
            with watched(sim, writers if config.bridges.suction is not None else (), "wetting"):
                sim, _, wetting = wet_sample(sim, config, progress="wet" if progress else None)
        if frames is not None:
            frames.close(sim)           # the state the shear starts from
        folder.phase = "shear"
        before_shear = _plain({"config": config_to_dict(config), "preparation": preparation,
                               "wetting": wetting, "preparation_time_s": prepared - started,
                               "pre_shear_time_s": time.perf_counter() - started})
        sample_file = os.path.join(out, "sample.h5")
        save_sample(sample_file, sim, preparation, before_shear,
                    identity={"seed": config.sample.seed})
        run = _ShearRun(sim, config, folder, before_shear, run_identity(config, sample_file))
        if run.checkpoint is not None:
            run.checkpoint.write(sim)
        return run.finish(progress, stop_after, plots)

    @classmethod
    def resume(cls, out, *, progress=True, threads=None, stop_after=None):
        """Continue the interrupted run of folder ``out`` from its checkpoint.h5, with the
        configuration stored in its sample.h5; returns the summary."""
        sample_file = os.path.join(out, "sample.h5")
        checkpoint = os.path.join(out, "checkpoint.h5")
        for path in (sample_file, checkpoint):
            if not os.path.exists(path):
                raise ValueError(f"resume = {out!r}: {path} is missing (was the run started "
                                 "with checkpoint_every > 0?)")
        with OutputFolder(out, "triaxial --resume", keep=True) as folder:
            particles, walls, _, before_shear = load_sample(sample_file)
            config = config_from_dict(before_shear.get("config"), sample_file)
            sim = servoed_simulation(particles, walls, config.sample, config.confining,
                                     threads=threads)
            if config.bridges is not None:   # its state (liquid, films) comes from the checkpoint
                sim.forces.append(config.bridges.build(
                    before_shear["wetting"].get("formation_suction_pa")))
            identity = run_identity(config, sample_file)
            run = _ShearRun(sim, config, folder, before_shear, identity)
            state = load_checkpoint(checkpoint, sim, expected_identity=identity)
            if (not isinstance(state, dict) or state.get("phase") != "shear"
                    or state.get("steps") != run.steps
                    or not isinstance(state.get("start_step"), int)
                    or not isinstance(state.get("shear_time_s"), (int, float))):
                raise ValueError(f"{checkpoint} does not belong to this run's shear")
            start, end = state["start_step"], state["start_step"] + run.steps
            if not start <= sim.step <= end:
                # a checksum can be forged: the step must lie in this shear
                raise ValueError(f"{checkpoint}: step = {sim.step} is outside the valid range "
                                 f"[{start}, {end}] of this run's shear (an edited checkpoint)")
            run.resumed(state)
            return run.finish(progress, stop_after)


def run_identity(config, sample_file):
    """What a checkpoint of this run must carry (pendular.utils.integrity): the configuration's hash, the
    seed and the checksum of the sample the shear started from."""
    return {"config_hash": config_hash(config_to_dict(config)), "seed": config.sample.seed,
            "sample_checksum": checksum(sample_file)}


class _ShearRun:
    """The shear of a TriaxialTest with its writers in a fixed order (recorder, ParaView,
    checkpoint), so that a resumed run builds the same simulation; ``finish`` runs the
    remaining steps and writes the outputs."""

    def __init__(self, sim, config, folder, before_shear, identity):
        self.sim, self.config, self.before_shear = sim, config, before_shear
        self.folder, self.out = folder, folder.path
        out = folder.path
        sample = config.sample
        sim.dt = timestep(sim, sample)    # from the state the shear starts from (and resumes)
        self.shear = TriaxialShear(sim, config.shear, sample.confining, sample.radius,
                                   sample.density)
        self.steps = self.shear.steps
        self.start_step = sim.step
        self.shear_time = 0.0        # seconds spent shearing by earlier (interrupted) runs
        self.vtk_period = config.vtk_every
        if self.vtk_period is None:
            self.vtk_period = max(1, self.steps // config.vtk_frames) if config.vtk_frames else 0
        self.vtk = None
        if self.vtk_period > 0:
            axial = self.shear.axial
            self.vtk = VtkWriter(os.path.join(out, "vtk"), self.vtk_period,
                                 field_data=lambda s: {"axial_strain": axial.strain(s.walls)},
                                 time_axis=lambda s: 100.0 * axial.strain(s.walls))
            sim.writers.append(self.vtk)
        self.checkpoint = None
        if config.checkpoint_every > 0:
            self.checkpoint = CheckpointWriter(os.path.join(out, "checkpoint.h5"),
                                               config.checkpoint_every, self.extra_state,
                                               identity)
            sim.writers.append(self.checkpoint)
        self._clock = time.perf_counter()

    def extra_state(self, sim):
        """What a resumed run needs besides the simulation (CheckpointWriter extra_state)."""
        return {"phase": "shear", "steps": self.steps, "start_step": self.start_step,
                "shear_time_s": self.shear_time + time.perf_counter() - self._clock,
                "config": self.before_shear["config"]}

    def resumed(self, state):
        """Take the progress of the checkpoint loaded into the simulation."""
        self.start_step = state["start_step"]
        self.shear_time = state["shear_time_s"]
        self._clock = time.perf_counter()

    def finish(self, progress, stop_after, plots=True):
        """Run the rest of the shear (raising Interrupted at ``stop_after`` steps or on Ctrl-C)
        and write the outputs (the figures if ``plots``); returns the summary. Interrupted, it
        keeps the history so far (summary ``completed`` false), unless the folder holds the
        finished results of an earlier run, which are then kept instead."""
        sim = self.sim
        remaining = self.steps - (sim.step - self.start_step)
        stop = stop_after is not None and stop_after < remaining
        steps = stop_after if stop else remaining
        self._clock = time.perf_counter()
        try:
            if pausing_at("shear"):          # tests: Ctrl-C halfway through the shear
                sim.run(steps // 2, progress=None)
                steps -= steps // 2
                pause_point("shear")
            sim.run(steps, progress="shear" if progress else None, status=self.shear.status)
        except KeyboardInterrupt:
            stop = True
        except SampleCrushed as error:
            self.shear_time += time.perf_counter() - self._clock
            if not self.folder.earlier_results:
                self.write_outputs(completed=False, error=str(error))
            raise
        self.shear_time += time.perf_counter() - self._clock
        if stop:
            if self.folder.earlier_results:
                raise Interrupted(f"interrupted at step {sim.step}; the earlier results in "
                                  f"{self.out} are kept")
            self.write_outputs(completed=False)
            raise Interrupted(f"interrupted at step {sim.step}; history so far in {self.out}"
                              + (f"; continue with --resume {self.out}"
                                 if self.checkpoint is not None else ""))
        if self.vtk is not None:
            self.vtk.close(sim)
        return self.write_outputs(plots=plots)

    def write_outputs(self, completed=True, plots=True, error=None):
        """history.h5, summary.json (``completed``: whether the shear reached its final strain;
        ``error``: what stopped it, if not an interruption) and, for a completed run, the plots
        unless ``plots`` is False."""
        sim, config, out = self.sim, self.config, self.out
        sample = config.sample
        preparation = self.before_shear["preparation"]
        history = self.shear.recorder.arrays()
        summary = summarize(history)
        rate = self.shear.rate
        sheared = sim.step - self.start_step
        summary.update({
            "completed": completed,
            "peak_reached": peak_reached(history["axial_strain"], summary["peak_index"]),
            "initial_porosity": preparation["porosity"],
            "initial_coordination": preparation["coordination"],
            "wall_time_s": self.before_shear["pre_shear_time_s"] + self.shear_time,
            "preparation_time_s": self.before_shear["preparation_time_s"],
            "shear_time_s": self.shear_time,
            "steps": self.steps,
            "preparation_steps": preparation["steps"],
            "particle_steps_per_s": (len(sim.particles) * sheared / self.shear_time
                                     if self.shear_time > 0.0 else None),
            "dt": sim.dt,
            "strain_rate": rate,
            "inertial_number": inertial_number(rate, sample.radius, sample.density,
                                               sample.confining),
            "max_unbalanced_force": float(np.max(history["unbalanced_force"][1:])),
            "mean_unbalanced_force": float(np.mean(history["unbalanced_force"][1:])),
            "threads": numba.get_num_threads(),
            "grading": grading(sim.particles.radius),
            **self.before_shear["wetting"],
        })
        if "liquid_bridges" in history:
            initial = self.before_shear["wetting"]["liquid_initial"]
            total = history["liquid_bridges"] + history["liquid_film"] + history["liquid_lost"]
            summary.update({
                "liquid_balance_error": float(np.max(np.abs(total - initial)) / initial),
                "liquid_lost_fraction": float(history["liquid_lost"][-1] / initial)})
        summary["units"] = {k: v for k, v in SUMMARY_UNITS.items() if k in summary}
        attributes = {k: v for k, v in parameters(config).items() if v is not None}
        attributes.update({"timestep": preparation["timestep"], "dt": sim.dt,
                           "strain_rate": rate, "vtk_every": self.vtk_period})
        if not completed:
            summary["phase"] = "shear"
        if error is not None:
            summary["error"] = error
        self.folder.phase = "write"
        with deferred_interrupts():       # history and summary are written whole, or not at all
            write_history(os.path.join(out, "history.h5"), history,
                          self.before_shear["config"], attributes=attributes)
            pause_point("write")
            write_json(os.path.join(out, "summary.json"), summary)
            if completed:
                self.folder.commit()
        if not completed:
            return summary
        flagged = summary["stress_balance_flagged"]
        if flagged:
            print(f"warning: {len(flagged)} of {len(history['step'])} records have wall and "
                  f"Love-Weber stresses apart by more than {STRESS_BALANCE_BOUND:.0%} of p (up "
                  f"to {summary['stress_balance_error']:.1%}): the shear is not quasi-static "
                  "there (summary.json stress_balance_flagged)", file=sys.stderr)
        if not plots:
            return summary
        title = run_label(parameters(config), preparation["porosity"])
        plot_history(history, os.path.join(out, "triaxial.png"), title)
        write_plots(history, os.path.join(out, "plots"), title)
        return summary


def _plain(data):
    """``data`` with NumPy scalars and arrays as JSON values."""
    return json.loads(json.dumps(data, default=lambda v: v.tolist() if hasattr(v, "tolist")
                                 else str(v)))

