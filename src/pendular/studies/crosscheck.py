"""Cross-check of pendular's drained triaxial shear against YADE's on the same packing.

``CrossCheck(crosscheck_config(...)).run(out, options)`` (options: a
pendular.procedures.run_options.RunOptions, or its fields one by one); command ``pendular
crosscheck``. Needs ``yade`` on PATH (pendular.interop.yade.runner); docs/yade_crosscheck.md
lists the differences by design.

1. The sample of ``config.sample`` is prepared by pendular (thesis Ch. 5.2.2 at the confining
   stress; cached, pendular.interop.yade.runner.cached_sample, shared with the benchmarks), servoed on its six
   walls at the confining stress and, wet (``config.bridges``), given capillary bridges at
   every contact (suction control, exact tables); it is run until static
   (pendular.procedures.equilibrium.equilibrate, at most ``config.wet_steps`` steps).
2. This static (wetted) packing is exported (DIR/packing.txt, pendular.interop.yade.formats.write_spheres:
   centres, radii, wall box). Both codes start the shear from it in the same state: velocities
   zero, contacts found afresh (no shear-spring history), every touching pair getting a bridge
   at the first step (YADE: Law2_ScGeom_CapillaryPhys_Capillarity with menisci created at
   contact from the files of pendular.interop.yade.capillary_files, pendular.interop.yade.runner.
   yade_capillary_files). The wet state is thus identical in both codes at the start of the
   shear (same contacts, bridges, Sr, stresses), and only the shear's dynamics can differ.
   ``packing=FILE`` starts from a packing exported by an earlier cross-check of the same sample
   and suction instead (no settling).
   Periodic (``crosscheck_config(periodic=True)``, dry only): the sample fills a periodic cell
   (pendular.dem.cell), exported as its box [0, L] with the centres wrapped into it.
3. Both shear it with x, y servoed at the confining stress and z compressed at the strain rate
   of ``config.shear`` (pendular.procedures.triaxial.TriaxialShear), with the same time step, local
   damping, servo gain (1 - stressDamping), memory (0.8) and wall speed cap (max_vel),
   recording every shear_steps / records steps. YADE (pendular/interop/yade/scripts/triaxial.py, 1 OpenMP
   thread by default) runs with its own TriaxialStressController choices; pendular runs those
   of ``config.shear``: its defaults, or YADE's (pendular.procedures.config.YADE_CHOICES: axial rate on the
   current height, per-axis wall speed cap, wall stiffness refreshed every 10 steps) with
   ``crosscheck_config(mimic_yade=True)``. Each code runs until the engineering axial strain
   reaches ``config.shear.max_strain``. Periodic: YADE drives the cell with PeriTriaxController
   (x, y stress goals, z at the true strain rate), its stress evaluated every step and its
   servo given pendular's gain (``cell_grow_damping``); pendular with its cell servo.
   The contact law is ``config.sample.contact``'s: the linear law against YADE's
   Ip2_FrictMat_FrictMat_FrictPhys / Law2_ScGeom_FrictPhys_CundallStrack, or (dry, six walls,
   undamped) Hertz–Mindlin against Ip2_FrictMat_FrictMat_MindlinPhys /
   Law2_ScGeom_MindlinPhys_Mindlin, YADE's wall contacts made pendular's rigid plane
   (``yade_wall_poisson``).

Writes DIR/crosscheck.json: ``pendular`` and ``yade`` summaries (peak q, p, axial and volumetric
strain, Sr, bridges / menisci and porosity at the peak of q, the same at the start of the shear,
steps, seconds_per_step and particle_steps_per_s of the shear measured in this run, recording
included, the largest relative deviation of the lateral stresses from the confining stress;
YADE's controller settings), ``peak_q_rel_diff`` and ``saturation_rel_diff`` ((pendular -
YADE) / YADE at the peak), ``volumetric_strain_at_peak_diff`` (pendular - YADE),
``start_sigma_rel_diff`` and ``start_saturation_rel_diff``, plus the settings and the
configuration; DIR/crosscheck.png (q/p, volumetric strain and, wet, Sr against axial strain,
both codes); DIR/yade_history.txt and DIR/pendular_history.h5. Stresses compression positive
[Pa], strains compression positive.
"""

from __future__ import annotations

import dataclasses
import math
import os
import shutil
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from pendular.utils.atomic import write_json
from pendular.dem.cell import PeriodicCell
from pendular.dem.contact_law import normal_stiffness
from pendular.procedures.preparation import PrepareConfig, servoed_simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.walls import ConstantStrainRate, StressServo
from pendular.interop.yade.formats import read_spheres, write_spheres
from pendular.homogenize.invariants import stress_ratio

from pendular.procedures.config import (BridgeConfig, MAX_STAGE_STEPS, MIN_SAMPLE_PARTICLES,
    ShearConfig, YADE_CHOICES, config_to_dict)
from pendular.procedures.triaxial import TriaxialConfig
from pendular.procedures.options import SUCTION, sample_sizes, size_options
from pendular.procedures.run_options import RunOptions
from pendular.procedures.triaxial import axial_strain
from pendular.utils.parameters import (Option, OptionError, Parameter, default_of, option_from,
    option_of, spec_of)
from pendular.io.history import write_history
from pendular.io.outputs import OutputFolder
from pendular.io.plots import pyplot, save_figure
from pendular.procedures.equilibrium import NotStatic, equilibrate
from pendular.procedures.triaxial import TriaxialShear, summarize
from pendular.interop.yade.runner import (cached_sample, find_yade, run_yade_triaxial,
    yade_capillary_files, yade_history)

#: Files a cross-check owns in its output folder (pendular.io.outputs); DIR/packing.txt is not
#: among them: an earlier cross-check's packing may be the input of the next.
OUTPUTS = ("crosscheck.json", "crosscheck.png", "yade_history.txt", "yade_result.json",
           "pendular_history.h5")
#: Summary fields printed by the command.
SHOWN = ("peak_q_rel_diff", "saturation_rel_diff", "volumetric_strain_at_peak_diff",
         "start_sigma_rel_diff", "cost_ratio_yade_over_pendular")
#: Settings of YADE's controller copied from its result into the ``yade`` summary.
YADE_CONTROLLER = ("controller", "stress_damping", "strain_damping", "max_vel",
                   "stiffness_update_interval", "dyn_cell", "stress_mask", "goal",
                   "max_strain_rate", "grow_damping", "glob_update")
SETUP = ("pendular prepares and settles the sample at the confining stress (wetted: bridges at "
         "every contact, settled again); both codes shear the exported packing from rest with "
         "contacts and bridges formed afresh")


#: The cross-check's sample size and history rows over the shear (thesis Table 5.2 otherwise).
PARTICLES, RECORDS = 1000, 200
#: The most steps that bring the (wetted) sample to rest before the export, by default.
SETTLE_STEPS = 200000


def crosscheck_config(particles=PARTICLES, suction=0.0,
                      confining=default_of(PrepareConfig, "confining"),
                      max_strain=default_of(ShearConfig, "max_strain"), records=RECORDS,
                      mimic_yade=False, settle_steps=SETTLE_STEPS, seed=0, periodic=False,
                      contact="linear", poisson=default_of(PrepareConfig, "poisson"), **sizes):
    """The TriaxialConfig of a cross-check: the thesis-default sample (Table 5.2) of
    ``particles`` spheres at ``confining`` [Pa] from ``seed``, of the ``sizes`` given
    (PrepareConfig's radius, radius_spread, psd), in a periodic cell if ``periodic`` (YADE:
    PeriTriaxController) or six walls (TriaxialStressController); suction-controlled exact
    bridges at ``suction`` [Pa] (0: dry; surface tension capillary.SURFACE_TENSION, contact
    angle 0);
    the shear to ``max_strain`` with ``records`` rows, with YADE's wall-control choices if
    ``mimic_yade``; at most ``settle_steps`` steps (wet_steps) to bring the (wetted) sample to
    rest before the export; ``contact`` the contact law ("linear" against YADE's FrictPhys,
    "hertz-mindlin" of Poisson ratio ``poisson`` against its MindlinPhys)."""
    return TriaxialConfig(
        sample=PrepareConfig(particles=particles, confining=confining, seed=seed,
                             periodic=periodic, contact=contact, poisson=poisson, **sizes),
        shear=ShearConfig(max_strain=max_strain, records=records,
                          **(YADE_CHOICES if mimic_yade else {})),
        bridges=BridgeConfig(suction) if suction else None,
        wet_steps=settle_steps, vtk_frames=0)


#: The lateral stress of a cross-check [Pa]: the sample's confining stress, above 0.
CONFINING = dataclasses.replace(spec_of(PrepareConfig, "confining"), low_inclusive=False,
                                high=None, high_inclusive=False, help="lateral stress")
#: The options of ``pendular crosscheck`` (how it runs apart: folder, threads, concurrency):
#: the sample's and the shear's from their fields, at the cross-check's defaults (the
#: suction and confining stress checked as they are read: the ranges the cross-check takes),
#: YADE's choices, the settling and a packing to start from.
OPTIONS = (option_of(PrepareConfig, "particles", default=PARTICLES, low=MIN_SAMPLE_PARTICLES),
           option_from(dataclasses.replace(SUCTION, high_inclusive=False), 0.0, checked=True),
           option_from(CONFINING, default_of(PrepareConfig, "confining"),
                       field=(PrepareConfig, "confining"), checked=True),
           option_of(ShearConfig, "max_strain", help="final axial strain"),
           *size_options(),
           option_of(PrepareConfig, "seed"),
           option_of(PrepareConfig, "periodic",
                     help="a periodic cell instead of six walls: pendular's cell servo against "
                          "YADE's PeriTriaxController"),
           option_of(PrepareConfig, "contact",
                     help="contact law: linear springs (YADE's Ip2_FrictMat_FrictMat_FrictPhys, "
                          "Law2_ScGeom_FrictPhys_CundallStrack) or Hertz-Mindlin (YADE's "
                          "Ip2_FrictMat_FrictMat_MindlinPhys, Law2_ScGeom_MindlinPhys_Mindlin); "
                          "six walls, dry"),
           option_of(PrepareConfig, "poisson"),
           Option("mimic_yade", "pendular takes YADE's wall-control choices "
                                "(pendular.procedures.config.YADE_CHOICES)",
                  default=False, kind=bool),
           option_of(ShearConfig, "records", default=RECORDS, unset=False,
                     help="history rows over the shear"),
           # the wetted sample's equilibrium (its wet_steps): at most MAX_STAGE_STEPS
           option_from(Parameter("1", "most steps to bring the (wetted) sample to rest before "
                                      "export (0: export it as loaded)", low=0,
                                 high=MAX_STAGE_STEPS, kind=int, flag="--settle-steps"),
                       SETTLE_STEPS, checked=True),
           Option("packing", "shear this exported packing (DIR/packing.txt of an earlier "
                             "cross-check of the same sample and suction) instead of settling",
                  kind=str, metavar="FILE"))


def crosscheck_from_options(values):
    """The cross-check's TriaxialConfig (crosscheck_config) of ``values`` of OPTIONS
    (pendular.utils.parameters.option_values); ParameterError naming an option outside its
    range, OptionError naming the options of a wet periodic cross-check, which YADE cannot
    mirror."""
    axial_strain(values["max_strain"])
    suction = values["suction"]
    if values["periodic"] and suction > 0.0:
        raise OptionError(lambda name: f"{name('suction')} {suction} Pa with {name('periodic')}: "
                                       "YADE's PeriTriaxController servoes the stress of the "
                                       "contact forces alone (without the capillary forces); "
                                       f"valid: 0 with {name('periodic')}")
    contact = values["contact"]
    if contact == "hertz-mindlin" and (suction > 0.0 or values["periodic"]):
        what = "suction" if suction > 0.0 else "periodic"
        raise OptionError(lambda name: f"{name(what)} with {name('contact')} hertz-mindlin: the "
                                       "Hertz-Mindlin cross-check is dry, in six walls; valid: "
                                       f"{name('contact')} linear, or a dry walled test")
    return crosscheck_config(particles=values["particles"], suction=suction,
                             confining=values["confining"], max_strain=values["max_strain"],
                             records=values["records"], mimic_yade=values["mimic_yade"],
                             settle_steps=max(values["settle_steps"], 1), seed=values["seed"],
                             periodic=values["periodic"], contact=contact,
                             poisson=values["poisson"], **sample_sizes(values))


def mimics_yade(shear):
    """Whether the ShearConfig ``shear`` takes every one of YADE's wall-control choices."""
    return all(getattr(shear, name) == value for name, value in YADE_CHOICES.items())


def check_mirrored(config):
    """ValueError naming the setting when ``config`` asks for something the YADE side cannot
    reproduce (its capillary law has exact, suction-controlled bridges from the default
    tables, in six walls only; the sample is a prepared one)."""
    if config.sample_path is not None:
        raise ValueError(f"sample_path = {config.sample_path!r}: the cross-check prepares its "
                         "own (cached) sample; valid: None")
    CONFINING.check("confining", config.confining)
    sample = config.sample
    if sample.contact == "hertz-mindlin" and (config.bridges is not None or sample.periodic):
        raise ValueError("contact = 'hertz-mindlin' with "
                         f"{'bridges' if config.bridges is not None else 'a periodic cell'}: "
                         "the Hertz-Mindlin cross-check is dry, in six walls; valid: contact "
                         "'linear', or a dry walled test")
    if sample.contact == "hertz-mindlin" and sample.restitution != 1.0:
        raise ValueError(f"restitution = {sample.restitution:g} with contact 'hertz-mindlin': "
                         "the cross-check mirrors YADE's undamped MindlinPhys; valid: 1")
    bridges = config.bridges
    if bridges is None:
        return
    if config.sample.periodic:
        raise ValueError(f"suction = {bridges.suction:g} Pa with a periodic cell: YADE's "
                         "PeriTriaxController servoes the stress of the contact forces alone "
                         "(utils.getStress; the capillary forces are apart, utils."
                         "getCapillaryStress) while pendular's cell servo holds both; valid: "
                         "0 (dry) with a periodic cell")
    for name, value, valid in (("model", bridges.model, "exact"),
                               ("control", bridges.control, "suction"),
                               ("table_resolution", bridges.table_resolution, None)):
        if value != valid:
            raise ValueError(f"bridges {name} = {value!r}: YADE's capillary law is mirrored "
                             f"only with {name} = {valid!r}")


def check_packing(config, packing):
    """FileNotFoundError or ValueError naming ``packing`` when it is not the export of a
    cross-check (DIR/packing.txt) with the box of ``config``: a '# box_lo ... box_hi ...'
    line, its low corner at 0 for a periodic cell."""
    if not os.path.isfile(packing):
        what = "is a folder" if os.path.isdir(packing) else "no such file"
        raise FileNotFoundError(f"packing = {packing!r}: {what}; valid: DIR/packing.txt of an "
                                "earlier cross-check")
    lo = read_spheres(packing)[2]
    if lo is None:
        raise ValueError(f"packing = {packing!r}: no '# box_lo ... box_hi ...' line; valid: "
                         "DIR/packing.txt of an earlier cross-check")
    if config.sample.periodic and np.any(lo != 0.0):
        raise ValueError(f"packing = {packing!r}: box_lo = {lo.tolist()} m is not a periodic "
                         "cell's corner 0; valid: DIR/packing.txt of a periodic cross-check")


def static_packing(config, path, options, settle=True):
    """Load (or prepare, on the CPU: the cache is shared) the cached sample of ``config``,
    bring it to rest at the confining stress as the RunOptions ``options`` say (its device,
    threads and progress bars; wetted if ``config.bridges``; ``settle=False``: as loaded),
    write it to ``path`` (pendular.interop.yade.formats.write_spheres; a periodic cell's box
    is [0, L], the centres wrapped into it); return the settle report (steps, time, wall or
    cell stresses and, wet, Sr and bridges)."""
    sample, progress, threads = config.sample, options.progress, options.threads
    particles, walls, _ = cached_sample(sample, progress=progress, threads=threads)
    sim = servoed_simulation(particles, walls, sample, sample.confining, threads=threads)
    sim.device = options.device
    bridges = None
    if config.bridges is not None:
        bridges = config.bridges.build()
        sim.forces.append(bridges)
    started = time.perf_counter()
    steps = 0
    if settle:
        try:
            steps = equilibrate(sim, unbalanced=sample.equilibrium_unbalanced,
                                tolerance=sample.stress_tolerance, max_steps=config.wet_steps,
                                progress="settle" if progress else None,
                                phase="equilibrium before the export")
        except NotStatic as error:
            raise NotStatic(f"{error} (cross-check: --settle-steps)") from None
    else:
        sim.evaluate_forces()
    if sim.walls.periodic:
        sim.walls.wrap(sim.particles)   # centres in [0, L), the cell YADE is given
    write_spheres(path, sim.particles.position, sim.particles.radius, sim.walls.lo,
                  sim.walls.hi)
    report = {"settle_steps": steps, "settle_time_s": time.perf_counter() - started,
              "sigma_wall": sim.walls.stress().tolist()}
    if bridges is not None:
        report.update(saturation=bridges.saturation(sim), bridges=bridges.count(sim))
    return report


def pendular_shear(config, packing, threads=1, device="cpu"):
    """The shear of the exported ``packing`` by pendular on ``device``: (Simulation,
    TriaxialShear), not yet run; the same scene as a triaxial test's shear (walls or, with
    ``config.sample.periodic``, the periodic cell of the packing's box), started from the
    packing at rest."""
    sample = config.sample
    position, radius, lo, hi = read_spheres(packing)
    box = (PeriodicCell if sample.periodic else Walls).box(lo, hi)
    sim = servoed_simulation(Particles(position, radius, sample.density), box, sample,
                             sample.confining, threads=threads)
    sim.device = device
    if config.bridges is not None:
        sim.forces.append(config.bridges.build())
    shear = TriaxialShear(sim, config.shear, sample.confining, sample.radius, sample.density)
    return sim, shear


def cell_grow_damping(sim, gain, sample):
    """PeriTriaxController.growDamping [-] that gives YADE's cell servo the gain ``gain`` of
    pendular's on the scene ``sim`` (a periodic cell, forces evaluated) of ``sample`` (its
    young and shear_ratio). Per step, YADE changes the strain of axis a by (1 - growDamping)
    (sigma - target) A_a / k_a, A_a the cell's face normal to a [m^2] and k_a the mean over
    the contacts of |n_a| kn + (1 - |n_a|) ks [N/m]: a compliance whose units do not balance,
    at pendular's micrometre spheres hundreds of times below the cell's own 1 / S_a
    (pendular.dem.cell), while pendular changes it by gain (sigma - target) / S_a. Matched on the mean
    of x and y at the start of the shear (negative: YADE's term amplified)."""
    sim.walls.update_stiffness(sim)
    contacts = sim.contacts
    touching = contacts.touching()
    radius = sim.particles.radius
    kn = normal_stiffness(sample.young, radius[contacts.pair_i[touching]],
                          radius[contacts.pair_j[touching]])[:, None]
    normal = np.abs(contacts.normal[touching, :2])
    mean_stiffness = (normal * kn + (1.0 - normal) * sample.shear_ratio * kn).mean(axis=0)
    lx, ly, lz = sim.walls.lengths()
    area = np.array([ly * lz, lx * lz])
    return float(1.0 - gain * np.mean(mean_stiffness / (sim.walls.stiffness[:2] * area)))


def yade_wall_poisson(poisson):
    """The Poisson ratio [-] of YADE's wall material that gives its Hertz wall contacts
    pendular's, a sphere on a rigid plane of E* = E / (1 - nu^2), R* = R
    (pendular.dem.hertz_mindlin). Ig2_Box_Sphere_ScGeom gives the wall the sphere's radius,
    so YADE's R* is R / 2, and Ip2_FrictMat_FrictMat_MindlinPhys mixes E* = E_a E_b /
    ((1 - nu_a^2) E_b + (1 - nu_b^2) E_a): of the wall's E = E_a and this nu_b,
    E* sqrt(R / 2) = E / (1 - nu^2) sqrt(R). Above 1, no real material's: only that formula
    reads it (the walls are frictionless, so their shear stiffness never acts)."""
    return math.sqrt(1.0 + (1.0 - poisson ** 2) * (1.0 - 1.0 / math.sqrt(2.0)))


def yade_settings(config, packing, sim, shear, folder):
    """The YADE driver's configuration for the same shear (pendular/interop/yade/scripts/triaxial.py)."""
    sample = config.sample
    lateral = sim.operation(StressServo)
    # YADE imposes the rate on the current height: its own number of steps to max_strain
    yade_axial = ConstantStrainRate("z", shear.rate, shear.axial.reference_length,
                                    on_current_length=True)
    settings = {
        "spheres": packing, "young": sample.young, "poisson": sample.shear_ratio,
        "friction_deg": sample.friction_deg, "density": sample.density,
        "damping": sample.damping, "dt": sim.dt, "confining": sample.confining,
        "strain_rate": shear.rate, "steps": yade_axial.steps_to(config.shear.max_strain, sim.dt),
        "periodic": sample.periodic,
        "warmup_steps": 0, "record_every": shear.recorder.period, "record_initial": True,
        "stress_damping": 1.0 - lateral.gain, "strain_damping": 0.0,
        "max_vel": lateral.max_velocity,
        "history": os.path.join(folder, "yade_history.txt"),
        "output": os.path.join(folder, "yade_result.json"),
        "contact": sample.contact}
    if sample.contact == "hertz-mindlin":
        settings["poisson"] = sample.poisson
        settings["wall_poisson"] = yade_wall_poisson(sample.poisson)
    if sample.periodic:
        # PeriTriaxController's stress and stiffness from the contacts every step: between
        # evaluations it predicts the stress by a formula whose units do not balance, which at
        # micrometre spheres drives the lateral strain rates from cap to cap; and its gain
        # made pendular's (docs/yade_crosscheck.md, "Periodic cell")
        settings["glob_update"] = 1
        settings["stress_damping"] = cell_grow_damping(sim, lateral.gain, sample)
    bridges = config.bridges
    if bridges is not None:
        settings["capillary"] = {"suction": bridges.suction,
                                 "files": yade_capillary_files(bridges.contact_angle),
                                 "surface_tension": bridges.surface_tension,
                                 "persist": bridges.persist}
    return settings


def code_summary(history, particles, steps, seconds, confining):
    """Peak and start-of-shear values of one code's history, with its cost per step and the
    largest relative deviation of its lateral stresses from ``confining`` [Pa] over the
    records (how well its servo holds them)."""
    summary = summarize(history)
    lateral = history["sigma_wall"][:, :2]
    summary["lateral_stress_max_rel_error"] = float(np.abs(lateral / confining - 1.0).max())
    peak = summary.pop("peak_index")
    for name in ("volumetric_strain", "porosity", "bridges"):
        if name in history:
            summary[f"{name}_at_peak"] = float(history[name][peak])
    summary["start"] = {"sigma_wall": history["sigma_wall"][0].tolist(),
                        "porosity": float(history["porosity"][0])}
    for key in ("saturation", "bridges"):
        if key in history:
            summary["start"][key] = float(history[key][0])
    summary.update({"final_axial_strain": float(history["axial_strain"][-1]),
                    "steps": int(steps), "shear_time_s": seconds,
                    "seconds_per_step": seconds / steps,
                    "particle_steps_per_s": particles * steps / seconds})
    return summary


def relative(ours, theirs):
    """(ours - theirs) / |theirs|, None when either is missing."""
    if ours is None or theirs is None:
        return None
    return (ours - theirs) / abs(theirs)


def comparison(pendular, yade):
    """The agreement fields of crosscheck.json."""
    start_p, start_y = pendular["start"], yade["start"]
    return {
        "peak_q_rel_diff": relative(pendular["peak_q"], yade["peak_q"]),
        "saturation_rel_diff": relative(pendular.get("saturation_at_peak"),
                                        yade.get("saturation_at_peak")),
        "volumetric_strain_at_peak_diff": (pendular["volumetric_strain_at_peak"]
                                           - yade["volumetric_strain_at_peak"]),
        "axial_strain_at_peak_diff": (pendular["axial_strain_at_peak"]
                                      - yade["axial_strain_at_peak"]),
        "start_sigma_rel_diff": max(abs(relative(a, b)) for a, b in
                                    zip(start_p["sigma_wall"], start_y["sigma_wall"])),
        "start_saturation_rel_diff": relative(start_p.get("saturation"),
                                              start_y.get("saturation")),
        "cost_ratio_yade_over_pendular": yade["seconds_per_step"] / pendular["seconds_per_step"],
    }


def plot(histories, path):
    """q/p, volumetric strain and (wet) Sr against axial strain, one curve per code."""
    wet = all("saturation" in h for h in histories.values())
    figure, panels = pyplot().subplots(3 if wet else 2, 1, figsize=(6, 9 if wet else 6.5),
                                       sharex=True)
    for name, history in histories.items():
        strain = history["axial_strain"]
        panels[0].plot(strain, stress_ratio(history["sigma_wall"]), label=name)
        panels[1].plot(strain, history["volumetric_strain"], label=name)
        if wet:
            panels[2].plot(strain, history["saturation"], label=name)
    panels[0].set_ylabel("q/p")
    panels[1].set_ylabel("volumetric strain (contraction +)")
    if wet:
        panels[2].set_ylabel("degree of saturation Sr")
    panels[-1].set_xlabel("axial strain")
    panels[0].legend()
    save_figure(figure, path)


class CrossCheck:
    """The cross-check of ``config`` (a TriaxialConfig, e.g. ``crosscheck_config``), checked
    when it is made (check_mirrored, check_packing); ``settle``: bring the (wetted) sample to
    rest before the export (False: export it as loaded); ``packing``: shear this exported
    packing instead of settling one. Run as every command runs: ``run(out, options) ->
    summary``."""

    def __init__(self, config, *, settle=True, packing=None):
        if not isinstance(config, TriaxialConfig):
            raise TypeError(f"config must be a TriaxialConfig, got {type(config).__name__}")
        check_mirrored(config)
        if packing is not None:
            packing = os.fspath(packing)
            check_packing(config, packing)
        self.config, self.settle, self.packing = config, settle, packing

    def run(self, out, options=None, **settings):
        """The cross-check into the folder ``out`` (module docstring), run as ``options`` say
        (RunOptions; ``settings``: its fields one by one): ``threads`` Numba threads of
        pendular and OpenMP threads of YADE (None: 1), ``device`` where pendular settles and
        shears ("cpu" or "gpu"), ``progress`` its bars, ``concurrent``: run YADE while
        pendular shears (halves the wall time; each code's timing then shares the machine
        with the other). Returns the crosscheck.json content; RuntimeError when YADE is
        missing or fails."""
        options = RunOptions.of(options, **settings)
        if options.threads is None:
            options = RunOptions.of(options, threads=1)
        config, packing = self.config, self.packing
        out = os.path.abspath(out)
        find_yade()
        with OutputFolder(out, "crosscheck") as folder:
            for name in OUTPUTS:
                folder.claim(name)
            exported = os.path.join(out, "packing.txt")
            if packing is None:
                settled = static_packing(config, exported, options, self.settle)
            else:
                if os.path.abspath(packing) != exported:
                    shutil.copyfile(packing, exported)
                settled = {"from": packing}
            return _shear_both(config, out, exported, settled, options)


def _shear_both(config, out, packing, settled, options):
    """Shear ``packing`` with both codes (pendular on the device of ``options``), compare,
    write the outputs."""
    concurrent, threads, device = options.concurrent, options.threads, options.device
    sim, shear = pendular_shear(config, packing, threads, device)
    settings = yade_settings(config, packing, sim, shear, out)
    box_volume = sim.walls.volume()
    with ThreadPoolExecutor(max_workers=1) as pool:
        def run_yade():
            return run_yade_triaxial(settings, threads=threads,
                                     env={"OMP_WAIT_POLICY": "PASSIVE"})
        yade_run = pool.submit(run_yade) if concurrent else None
        started = time.perf_counter()
        sim.run(shear.steps, progress="pendular shear" if options.progress else None,
                status=shear.status)
        pendular_seconds = time.perf_counter() - started
        yade_result = (yade_run or pool.submit(run_yade)).result()
    ours = shear.recorder.arrays()
    mimic = mimics_yade(config.shear)
    write_history(os.path.join(out, "pendular_history.h5"), ours, config_to_dict(config),
                  attributes={"mimic_yade": mimic, "dt": sim.dt, "strain_rate": shear.rate})
    theirs = yade_history(settings["history"], box_volume)
    count = len(sim.particles)
    confining = config.confining
    pendular = code_summary(ours, count, shear.steps, pendular_seconds, confining)
    yade = code_summary(theirs, count, yade_result["steps"], yade_result["wall_time_s"],
                        confining)
    yade["version"] = yade_result["yade_version"]
    yade["controller"] = {key: value for key, value in yade_result.items()
                          if key in YADE_CONTROLLER}
    servo = sim.operation(StressServo)
    result = {
        "particles": count, "suction": config.suction, "confining": confining,
        "periodic": config.sample.periodic, "max_strain": config.shear.max_strain,
        "mimic_yade": mimic,
        "threads": threads, "concurrent": concurrent, "device": device,
        "dt": sim.dt, "strain_rate": shear.rate, "damping": config.sample.damping,
        "servo": {"gain": servo.gain, "memory": servo.memory,
                  "max_velocity": servo.max_velocity},
        "shear_config": dataclasses.asdict(config.shear),
        "config": config_to_dict(config),
        "setup": SETUP, "settle": settled, "packing": packing,
        **comparison(pendular, yade),
        "pendular": pendular, "yade": yade,
    }
    write_json(os.path.join(out, "crosscheck.json"), result)
    plot({"pendular": ours, "YADE": theirs}, os.path.join(out, "crosscheck.png"))
    return result
