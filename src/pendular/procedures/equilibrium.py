"""The phases a laboratory test runs before its loading: equilibrium and wetting.

- ``equilibrate(sim, ...)``: run until static (unbalanced force and servoed stresses within
  tolerance), NotStatic when the step limit comes first;
- ``wet(sim, bridges, ...)``: add capillary bridges to a static sample and re-equilibrate;
- ``wet_sample(sim, config)``: wet a sample as its LaboratoryConfig says (at a suction, by
  protocol, or to a water content: pendular.procedures.water_content);
- ``watched``, ``frames_writer``, ``frame_period``: ParaView frames of these phases and of a
  loading.

Usable alone for a custom loading path (docs/tutorials/plot_3_custom_loading_path.py).
Stresses compression positive [Pa].
"""

from __future__ import annotations

import contextlib
import os
import time

import numpy as np

from pendular.dem.measure import porosity, unbalanced_force
from pendular.dem.walls import StressServo
from pendular.io.vtk import VtkWriter
from pendular.procedures.config import WATER_DENSITY
from pendular.procedures.loading import run_stage
from pendular.procedures.loading_clusters import (join_clusters, wet_clusters_at_water_content,
    wetted_clusters)
from pendular.procedures.preparation import static
from pendular.procedures.progress import equilibrium_bar
from pendular.procedures.water_content import wet_to_water_volume


class NotStatic(ValueError):
    """An equilibrium phase ended at its step limit without reaching equilibrium."""


def equilibrate(sim, *, unbalanced=0.01, tolerance=0.01, max_steps=200000, check_every=200,
                progress=None, phase="equilibrium"):
    """Run ``sim`` until static: unbalanced force below ``unbalanced`` and, if a StressServo
    controls walls, their stresses within ``tolerance`` (relative) of its target; at most
    ``max_steps`` steps; ``progress``: the label of its bar (procedures.progress
    .equilibrium_bar). Returns the steps taken; NotStatic (naming ``phase`` and what it
    reached) when the limit is hit first. A stage on the scene's own controls, run by the
    stages' loop (pendular.procedures.loading.run_stage): checked every ``check_every`` steps
    and at its limit, the first check after ``check_every`` steps (a sample static at the
    start still runs them, where a LoadingPath's Static stage ends at once)."""
    done, start = static(unbalanced, tolerance), sim.step
    steps = run_stage(sim, lambda s: s.step > start and done(s), start=start, limit=max_steps,
                      every=check_every, progress=equilibrium_bar(progress, unbalanced, tolerance),
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
        sim.fetch()                 # all of a device run's state (Simulation.fetch)
        fields = {"unbalanced": f"{unbalanced_force(sim.particles, sim.contacts):.3g}"
                                f"/{unbalanced:g}"}
        for servo in (op for op in sim.controls if isinstance(op, StressServo)):
            stress = sim.walls.stress()[list(servo.axes)]
            fields["stress"] = (f"{np.max(np.abs(stress - servo.target)):.3g}Pa off "
                                f"{servo.target:g}Pa")
        return fields

    return status


def wet(sim, bridges, *, unbalanced=0.01, tolerance=0.01, max_steps=200000, progress=None,
        cluster_entry=None):
    """Add the capillary operation ``bridges`` to the forces of a static sample and run until
    static again; returns the wetting report (steps, time, Sr, bridges, porosity). With
    ``cluster_entry``, a throat entry estimate (--entry-suction), liquid clusters join the
    bridges (pendular.procedures.loading_clusters.join_clusters: set before the
    equilibrium, then again at the packing it reaches, which is run until static once more
    where units are filled)."""
    sim.forces.append(bridges)
    started = time.perf_counter()
    joined = join_clusters(sim, bridges, cluster_entry) if cluster_entry else None
    steps = equilibrate(sim, unbalanced=unbalanced, tolerance=tolerance, max_steps=max_steps,
                        progress=progress, phase="equilibrium after wetting")
    if joined is not None:          # the units of the packing reached, in equilibrium again
        joined.set_suction(sim, bridges.suction)
    if joined is not None and joined.filled.any():
        steps += equilibrate(sim, unbalanced=unbalanced, tolerance=tolerance,
                             max_steps=max_steps, progress=progress,
                             phase="equilibrium after wetting with liquid clusters")
    return wetting_report(sim, bridges, steps, started, clusters=joined)


def wetting_report(sim, bridges, steps, started, clusters=None, **details):
    """The report of a wetting that took ``steps`` steps from ``started`` (time.perf_counter,
    [s]): steps and time, ``details`` (what the protocol adds), then the wet state: Sr, the
    bridges of the operation ``bridges`` and the porosity; with liquid ``clusters``, their
    figures (``clusters_wet``; Sr of bridges and clusters together)."""
    report = {"wetting_steps": steps, "wetting_time_s": time.perf_counter() - started,
              **details, "initial_saturation": bridges.saturation(sim),
              "initial_bridges": bridges.count(sim),
              "wet_porosity": porosity(sim.particles, sim.walls)}
    if clusters is not None:
        report["clusters_wet"] = wetted_clusters(sim, clusters)
        report["initial_saturation"] = report["clusters_wet"]["saturation"]
    return report


def wet_sample(sim, config, *, progress=None):
    """Wet the static sample ``sim`` as ``config`` (TriaxialConfig) says; returns (the wet
    simulation, its bridge operation, the wetting report). Protocols (config.wetting):

    - 'isotropic': bridges added, the servo re-equilibrates the sample (``wet``);
    - 'at-shear': bridges added, formed at the sample's contacts now and shearing starts at
      once (the servo meets them during the shear);
    - 'constant-volume': bridges added with the walls fixed, run until the unbalanced force is
      below the threshold, then the servo brings the walls to the confining stress.

    Undrained (TriaxialConfig.undrained) at a suction, the bridges are volume-controlled,
    formed at the suction from a reservoir, and the liquid is then closed
    (CapillaryBridges.close_liquid), so that the shear holds the water content.

    At a water content (config.bridges.water_content) the bridges are volume-controlled, their
    formation suction found so that they hold w Gs V_s (Gs = density / 1000 kg/m^3;
    pendular.procedures.water_content), the sample re-equilibrated; the liquid is then closed
    (CapillaryBridges.close_liquid), so the shear conserves it.

    With config.liquid 'clusters' (at a suction), liquid clusters join the persisting
    suction-controlled bridges (pendular.procedures.loading_clusters), the pore units filled
    at their filling suction before the equilibria and again at the packing they reach (then
    run until static once more); the report adds ``clusters_wet``. At a water content with
    clusters, the liquid is a closed volume held by persisting suction-controlled bridges and
    the clusters at the suction that holds it (loading_clusters.wet_clusters_at_water_content).

    The equilibria run on ``sim``'s device (Simulation.device; the wettings at a water content
    from copies of ``sim``, which keep it); the bridges of 'at-shear' form on the host."""
    sample = config.sample
    thresholds = {"unbalanced": sample.equilibrium_unbalanced,
                  "tolerance": sample.stress_tolerance, "max_steps": config.wet_steps}
    if config.bridges.water_content is not None:
        if config.liquid == "clusters":
            return _wet_clusters_at_water_content(sim, config, thresholds, progress)
        return _wet_at_water_content(sim, config, thresholds, progress)
    bridges = config.bridges.build()
    cluster_entry = config.entry_suction if config.liquid == "clusters" else None
    if config.wetting == "isotropic":
        report = wet(sim, bridges, progress=progress, cluster_entry=cluster_entry, **thresholds)
    else:
        report = _wet_by_protocol(sim, config, bridges, thresholds, progress, cluster_entry)
    if config.undrained:                # the water cannot leave during the shear
        bridges.close_liquid(sim, config.bridges.liquid)
        report["liquid_initial"] = bridges.liquid_initial
    return sim, bridges, report


def _wet_by_protocol(sim, config, bridges, thresholds, progress, cluster_entry=None):
    """The wetting report of wet_sample's 'at-shear' and 'constant-volume' protocols (with
    ``cluster_entry``, liquid clusters beside the bridges, as ``wet``)."""
    started = time.perf_counter()
    sim.forces.append(bridges)
    joined = join_clusters(sim, bridges, cluster_entry) if cluster_entry else None
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
        if joined is not None:
            joined.set_suction(sim, bridges.suction)
            if joined.filled.any():
                steps += equilibrate(sim, progress=progress, **thresholds,
                                     phase="equilibrium after wetting with liquid clusters")
    report = {"wetting": config.wetting, **wetting_report(sim, bridges, steps, started,
                                                          clusters=joined)}
    if config.wetting == "constant-volume":
        report["sigma_wall_at_constant_volume"] = fixed_stress
    return report


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
    water_content = gravimetric_water_content(bridges.liquid_initial,
                                              particles.solid_volume(), specific_gravity)
    return sim, bridges, {"wetting": "water-content", **wetting_report(
        sim, bridges, sum(t["steps"] for t in tries), started,
        formation_suction_pa=tries[-1]["formation_suction_pa"], water_content=water_content,
        wetting_attempts=tries, liquid_initial=bridges.liquid_initial)}


def _wet_clusters_at_water_content(sim, config, thresholds, progress):
    """wet_sample at config.bridges.water_content with liquid clusters
    (pendular.procedures.loading_clusters.wet_clusters_at_water_content)."""
    from pendular.capillary import gravimetric_water_content

    particles = sim.particles
    specific_gravity = particles.density / WATER_DENSITY
    target = config.bridges.water_content * specific_gravity * particles.solid_volume()
    started = time.perf_counter()
    bridges, clusters, details = wet_clusters_at_water_content(
        sim, config.bridges, target,
        lambda s: equilibrate(s, progress=progress, phase="equilibrium after wetting",
                              **thresholds), config.entry_suction)
    steps = details.pop("wetting_steps")
    water_content = gravimetric_water_content(clusters.account(sim).total,
                                              particles.solid_volume(), specific_gravity)
    return sim, bridges, {"wetting": "water-content", **wetting_report(
        sim, bridges, steps, started, clusters=clusters, water_content=water_content,
        **details)}


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


def frame_period(vtk_every, vtk_frames, steps, unknown_length_period=0):
    """Steps between the ParaView frames of a loading of ``steps`` steps (0: no frames):
    ``vtk_every`` when given, else ``vtk_frames`` frames over the loading (0: none), or, for a
    loading whose length is not known before it runs (``steps`` None), one every
    ``unknown_length_period`` steps."""
    if vtk_every is not None:
        return vtk_every
    if not vtk_frames:
        return 0
    if steps is not None:
        return max(1, int(steps // vtk_frames))
    return unknown_length_period


def frames_writer(sim, out, period, **options):
    """The VtkWriter of ``out``/vtk/, a frame every ``period`` steps (``options``: VtkWriter's),
    appended to ``sim.writers``; None when ``period`` is 0 (no frames)."""
    if period <= 0:
        return None
    writer = VtkWriter(os.path.join(out, "vtk"), period, **options)
    sim.writers.append(writer)
    return writer
