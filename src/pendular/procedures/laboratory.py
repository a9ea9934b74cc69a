"""What every laboratory test on a prepared sample shares: ``LaboratoryTest``.

``LaboratoryTest(config).run(out)`` prepares the sample (or loads one), wets it
(pendular.procedures.equilibrium), loads it along the path its subclass declares
(``loading``: a pendular.procedures.loading.LoadingPath; ``summarize``; ``plot``) and writes
the outputs (history.h5, summary.json, the test's figure, plots/, vtk/, sample.h5,
checkpoint.h5; pendular.io.outputs: a locked folder, written transactionally);
``resume(out)`` continues an interrupted run from its checkpoint bit-identically. Each test
(pendular.procedures.triaxial, oedometer, isotropic, cyclic, simple_shear, path) is such a
subclass in its own module. ``check_feasible`` refuses, before anything runs, a test that
cannot be quasi-static or would not end in reasonable time; ``parameters`` flattens a
configuration into the command's options (history attributes, campaign tables).

Stresses compression positive [Pa], q and p as pendular.homogenize.invariants; strains
compression positive, volumetric strain positive in contraction (docs/units.md).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import sys
import time

import numba
import numpy as np

from pendular.dem.checkpoint import CheckpointWriter, load_checkpoint
from pendular.dem.grading import grading
from pendular.dem.measure import coordination, porosity
from pendular.dem.mixed_stress import StageFailed
from pendular.dem.sample import load_sample, save_sample
from pendular.dem.simulation import check_device
from pendular.homogenize.invariants import mean_stress
from pendular.io.history import write_history
from pendular.io.outputs import OutputFolder
from pendular.io.plots import run_label
from pendular.io.schema import SUMMARY_UNITS
from pendular.io.vtk import PoreFrames, VtkWriter, axial_strain_fields
from pendular.procedures.config import (LaboratoryConfig, config_from_dict, config_to_dict,
    inertial_number, sized_as_sample)
from pendular.procedures.equilibrium import (equilibrate, frame_period, frames_writer,
    prep_vtk_period, watched, wet_sample)
from pendular.procedures.columns import cluster_operation
from pendular.procedures.guards import AxialContactLost, SampleCrushed
from pendular.procedures.loading import VTK_RECORDS, check_stages_device
from pendular.procedures.loading_clusters import CLUSTER_RECORDS, ClusterUpdates, cluster_summary
from pendular.procedures.feasibility import check_feasible
from pendular.procedures.preparation import (PREPARATION_PHASES, prepare_sample,
    servoed_simulation, timestep, timestep_description)
from pendular.procedures.progress import laboratory_plan
from pendular.procedures.resume import resume_files, stored_run
from pendular.procedures.run_options import RunOptions
from pendular.utils.atomic import write_json
from pendular.utils.integrity import checksum, config_hash
from pendular.utils.interrupt import deferred_interrupts, pause_point, pausing_at
from pendular.utils.parameters import flat_options
from pendular.utils.progress import whole_run
from pendular.utils.validate import check_int


#: Largest difference between the wall stress and the Love–Weber stress of contacts and bridges
#: (any axis, over the mean wall stress p) of a record in equilibrium: quasi-static runs stay
#: below 2-4 % (60-1,000 spheres, max over 500 records), I = 0.05 reaches 100 %.
STRESS_BALANCE_BOUND = 0.05



#: Phases of the vtk_prep/ series, by the code in each frame's field data ``phase``: those of
#: pendular.procedures.preparation.prepare_sample, then "sample" (a loaded sample equilibrated at the confining
#: stress) and "wetting" (bridges added, equilibrated again).
PREP_PHASES = (*PREPARATION_PHASES, "sample", "wetting")


class Interrupted(Exception):
    """A run stopped before its end (Ctrl-C, or ``stop_after``); the checkpoint, if any, is
    where ``TriaxialTest.resume`` starts."""


def stress_balance(history):
    """The balance of wall and Love–Weber stresses over a history with ``sigma_contact`` (else
    {}): the largest ``stress_balance_error``, the bound and the records beyond it."""
    if "sigma_contact" not in history:            # not in a YADE history
        return {}
    error = stress_balance_error(history)
    return {"stress_balance_error": float(np.max(error)),
            "stress_balance_bound": STRESS_BALANCE_BOUND,
            "stress_balance_flagged": np.flatnonzero(error > STRESS_BALANCE_BOUND).tolist()}


def stress_balance_error(history):
    """Per record, max over the axes of |sigma_wall - diag(sigma_contact + sigma_capillary +
    sigma_clusters)| / p (p the mean wall stress): how far the wall stress and the Love–Weber
    stress (Eq. 3.41) of the contacts, bridges and liquid clusters inside are from the balance
    that holds in equilibrium."""
    inside = history["sigma_contact"]
    for name in ("sigma_capillary", "sigma_clusters"):
        if name in history:
            inside = inside + history[name]
    wall = history["sigma_wall"]
    return (np.abs(np.diagonal(inside, axis1=1, axis2=2) - wall).max(axis=1)
            / np.abs(mean_stress(wall)))


def parameters(config):
    """Flat name -> value of a configuration (a LaboratoryConfig), named as the command's
    options (history file attributes, campaign tables): the sample's from its fields'
    Parameters, the loading's (``loading_parameters``: a triaxial's shear, a path's own
    options and rate); the rest, values
    derived from the fields (the suction, the water content in %), in the columns' order of
    earlier campaign tables."""
    bridges = config.bridges
    flat = flat_options(config.sample)          # the recorded fields, keyed by their options
    flat.update(config.loading_parameters())
    flat.update({"suction": config.suction, "wet_steps": config.wet_steps,
                 "wetting": config.wetting,
                 "vtk_every": config.vtk_every, "checkpoint_every": config.checkpoint_every,
                 "sample": config.sample_path})
    if bridges is not None:
        flat.update({"contact_angle": bridges.contact_angle, "bridges": bridges.model,
                     "surface_tension": bridges.surface_tension,
                     "persist_bridges": bridges.persist, "control": bridges.control,
                     "water_content_percent": (None if bridges.water_content is None
                                               else 100.0 * bridges.water_content),
                     # the regime with clusters; otherwise, at a water content, where a
                     # ruptured bridge's liquid goes (the old --liquid shared|lost)
                     "liquid": (config.liquid if config.liquid != "pendular" else
                                (None if bridges.water_content is None else bridges.liquid)),
                     "table_resolution": (None if bridges.table_resolution is None else
                                          ",".join(map(str, bridges.table_resolution)))})
        if config.liquid == "clusters":
            flat["entry_suction"] = config.entry_suction
    return flat


class LaboratoryTest:
    """A laboratory test of ``config`` (a pendular.procedures.config.LaboratoryConfig of the
    subclass's ``CONFIG``): the sample, its wetting and its outputs, and the loading path that
    the subclass declares (``loading``: a pendular.procedures.loading.LoadingPath;
    ``summarize``; ``plot``).

    ``run(out)`` prepares the sample (or loads ``config.sample_path``), wets it at the confining
    stress (bridges at every contact, six walls servoed until static), loads it along the path
    and writes into ``out``: history.h5, summary.json, the test's figure (``FIGURE``), plots/,
    vtk/ (ParaView), sample.h5 (the sample the loading starts from, with the configuration),
    with checkpoint_every checkpoint.h5 and, with ``vtk_prep``, vtk_prep/ (ParaView frames of
    the preparation and wetting). Returns the summary (dict). A run stopped before its end
    (pendular.io.outputs) names in summary.json the phase it reached: "prepare", "wet",
    "shear" (the loading) or "write".
    """

    #: The test's command name (output folder label), configuration type and figure.
    NAME = "triaxial"
    CONFIG = LaboratoryConfig
    FIGURE = "triaxial.png"
    #: Progress-bar label of the loading.
    PROGRESS = "shear"
    #: Whether the loading ends, its results written, when the axial walls leave the sample
    #: (guards.AxialContactLost), rather than failing.
    ENDS_AT_CONTACT_LOSS = False

    def __init__(self, config, *, force=False):
        if not isinstance(config, self.CONFIG):
            raise TypeError(f"config must be a {self.CONFIG.__name__}, got "
                            f"{type(config).__name__}")
        config = self._sized(config)
        self.config = config
        check_feasible(config, force=force)
        if config.bridges is not None and config.bridges.suction is not None:
            # check the bridges against the sample's radii before any preparation
            from pendular.capillary import sample_radius_ratios

            radii = config.sample.radii()
            config.bridges.build().load_tables(float(radii.min()), float(radii.max()),
                                               radius_ratios=sample_radius_ratios(radii))

    @staticmethod
    def _sized(config):
        """``config`` with the count and sizes of its prepared sample where not given
        (sized_as_sample), once the sample exists: a campaign builds its tests before it
        prepares their shared samples, and ``start`` sizes them then."""
        if config.sample_path is None or not os.path.isfile(config.sample_path):
            return config
        return dataclasses.replace(config, sample=sized_as_sample(config.sample,
                                                                  config.sample_path))

    # ------------------------------------------------------------ phases
    def start(self, options=None, writers=()):
        """(static sample at the confining stress, preparation report, the host holding it);
        ``writers`` watch the preparation or the equilibrium of a loaded sample (e.g. the
        vtk_prep VtkWriter); ``options`` (RunOptions): its device is where the preparation or
        the loaded sample's equilibrium runs, and the returned simulation's runs (the wetting
        after it)."""
        options = RunOptions.of(options)
        self.config = config = self._sized(self.config)
        if config.sample_path is not None:
            return self.load_sample(config.sample_path, options, writers)
        return prepare_sample(config.sample, progress=options.progress, threads=options.threads,
                              writers=writers, device=options.device)

    def load_sample(self, path, options=None, writers=()):
        """(sample saved at ``path`` servoed at the confining stress and run until static on
        the device of ``options`` (RunOptions), its report; the simulation's runs go on
        there); ``writers`` watch the equilibrium (phase "sample")."""
        options = RunOptions.of(options)
        progress = options.progress
        sample = self.config.sample
        particles, walls, report, _ = load_sample(path, expected=sample)
        sim = servoed_simulation(particles, walls, sample, sample.confining,
                                 threads=options.threads)
        sim.device = options.device
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

    def run(self, out, options=None, **settings):
        """The whole test into the folder ``out`` (class docstring), run as ``options`` say
        (pendular.procedures.run_options.RunOptions; ``settings``: its fields one by one):
        ``stop_after``: stop the shear after this many steps as an interruption would (raises
        Interrupted); ``plots``: False leaves out triaxial.png and plots/ (a run timed for its
        physics, as the trade-off study's: the figures' cost is not the physics').
        ``vtk_prep``: ParaView frames of the preparation and wetting into ``out``/vtk_prep/
        (``prep_writer``): True every ``prep_vtk_period`` steps, a positive integer every that
        many steps, False (default) or 0 none. Output only: the results are the same.
        ``device``: where every phase runs (the preparation or a loaded sample's equilibrium,
        the wetting, the loading), "cpu" or "gpu" (``check_device``)."""
        options = RunOptions.of(options, **settings)
        if (self.config.liquid == "clusters" and options.device != "cpu"
                and self.config.sample.periodic):
            raise ValueError(f"--liquid clusters runs on the GPU between walls only: --device "
                             f"{options.device} does not apply with --periodic (the cell's "
                             "stress would need the clusters' virial on the device)")
        check_device(options.device)
        check_stages_device(self.stages(), options.device)
        vtk_prep = options.vtk_prep
        if vtk_prep is not True and vtk_prep is not False:
            options = RunOptions.of(options, vtk_prep=check_int("vtk_prep", vtk_prep, low=0))
        if self.config.sample_path is not None:       # checked before the folder is touched
            load_sample(self.config.sample_path, expected=self.config.sample)
        with OutputFolder(out, self.NAME) as folder:
            for name in self.outputs():
                folder.claim(name)
            with whole_run(laboratory_plan(self.config, self.PROGRESS),
                           enabled=options.progress):
                return self._run(folder, options)

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

    def _run(self, folder, options):
        config, out, progress = self.config, folder.path, options.progress
        started = time.perf_counter()
        frames = self.prep_writer(out, options.vtk_prep)
        writers = () if frames is None else (frames,)
        folder.phase = "prepare"
        pause_point(folder.phase)
        sim, preparation = self.start(options, writers)        # runs on the device
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
        before_shear = plain({"config": config_to_dict(config), "preparation": preparation,
                               "wetting": wetting, "preparation_time_s": prepared - started,
                               "pre_shear_time_s": time.perf_counter() - started})
        sample_file = os.path.join(out, "sample.h5")
        save_sample(sample_file, sim, preparation, before_shear,
                    identity={"seed": config.sample.seed})
        run = _PathRun(sim, self, folder, before_shear, run_identity(config, sample_file))
        if run.checkpoint is not None:
            run.checkpoint.write(sim)
        return run.finish(progress, options.stop_after, options.plots)

    @classmethod
    def resume(cls, out, options=None, **settings):
        """Continue the interrupted run of folder ``out`` from its checkpoint.h5, with the
        configuration stored in its sample.h5, run as ``options`` say (RunOptions;
        ``settings``: its fields one by one): its loading on their device (whichever device
        wrote the checkpoint); returns the summary."""
        options = RunOptions.of(options, **settings)
        device = options.device

        def no_checkpoint(sample_file):
            stored = config_from_dict(load_sample(sample_file)[3].get("config"), sample_file)
            return ("the run stopped before its first checkpoint" if
                    getattr(stored, "checkpoint_every", 0) > 0 else
                    "the run was started with --checkpoint-every 0, which writes none")

        sample_file, checkpoint = resume_files(out, "in the preparation or the wetting",
                                               no_checkpoint)
        with OutputFolder(out, f"{cls.NAME} --resume", keep=True) as folder:
            particles, walls, _, before_shear = load_sample(sample_file)
            config = stored_run(config_from_dict(before_shear.get("config"), sample_file), out,
                                cls, cls.NAME, device)
            sim = servoed_simulation(particles, walls, config.sample, config.confining,
                                     threads=options.threads)
            if config.bridges is not None:   # its state (liquid, films) comes from the checkpoint
                sim.forces.append(config.bridges.build(
                    before_shear["wetting"].get("formation_suction_pa"), closed=True))
            identity = run_identity(config, sample_file)
            test = cls.__new__(cls)          # the stored run, checked when it started
            test.config = config
            run = _PathRun(sim, test, folder, before_shear, identity)
            dt = sim.dt                      # the loading's time step, set from its sample
            state = load_checkpoint(checkpoint, sim, expected_identity=identity)
            if sim.dt != dt:                 # a checksum can be forged
                raise ValueError(f"{checkpoint}: dt = {sim.dt:g} s is not this run's time step, "
                                 f"{dt:g} s (set from its sample.h5): an edited checkpoint")
            position = sim.particles.position   # two centres at one point have no normal
            order = np.lexsort(position.T[::-1])
            same = np.flatnonzero(np.all(position[order[1:]] == position[order[:-1]], axis=1))
            if len(same):
                i, j = sorted((int(order[same[0]]), int(order[same[0] + 1])))
                raise ValueError(f"{checkpoint}: particles {i} and {j} share the position "
                                 f"{position[i].tolist()} m: an edited checkpoint")
            if (not isinstance(state, dict) or state.get("phase") != "shear"
                    or state.get("steps") != run.steps
                    or not isinstance(state.get("start_step"), int)
                    or not isinstance(state.get("shear_time_s"), (int, float))):
                raise ValueError(f"{checkpoint} does not belong to this run's loading")
            start = state["start_step"]
            end = math.inf if run.steps is None else start + run.steps
            if not start <= sim.step <= end:
                # a checksum can be forged: the step must lie in this loading
                raise ValueError(f"{checkpoint}: step = {sim.step} is outside the valid range "
                                 f"[{start}, {end}] of this run's loading (an edited checkpoint)")
            run.resumed(state)
            sim.device = device
            return run.finish(options.progress, options.stop_after, options.plots)

    # ------------------------------------------------------------ the path of the test
    def outputs(self):
        """Files and folders the test owns in its output folder (pendular.io.outputs)."""
        return ("history.h5", "summary.json", self.FIGURE, "plots", "vtk", "sample.h5",
                "checkpoint.h5", "vtk_prep") + (("pores",) if self.config.liquid == "clusters"
                                                else ())

    def loading(self, sim):
        """The LoadingPath of the test attached to the static sample ``sim`` (time step set)."""
        raise NotImplementedError

    def stages(self):
        """The stages of the loading known before it runs, for the checks made then
        (loading.check_stages_device); [] by default."""
        return []

    def summarize(self, history):
        """The test's results from its ``history`` (dict of arrays)."""
        raise NotImplementedError

    def derived(self, history):
        """The recorded ``history`` (dict of arrays) with the columns the test computes from
        its rows (none here)."""
        return history

    def frame_fields(self, path):
        """(field data function of sim, time axis name) of the ParaView frames of the loading
        ``path`` (pendular.io.vtk.VtkWriter): the axial strain, in % on the time axis."""
        axial = path.axial
        return (lambda s: axial_strain_fields(axial.strain(s.walls))), "axial_strain_percent"

    def plot(self, history, out, title):
        """The test's figures into the folder ``out``, ``title`` the run's parameters."""
        raise NotImplementedError


def run_identity(config, sample_file):
    """What a checkpoint of this run must carry (pendular.utils.integrity): the configuration's hash, the
    seed and the checksum of the sample the loading started from."""
    return {"config_hash": config_hash(config_to_dict(config)), "seed": config.sample.seed,
            "sample_checksum": checksum(sample_file)}


class _PathRun:
    """The loading of a LaboratoryTest with its writers in a fixed order (recorder, ParaView,
    checkpoint), so that a resumed run builds the same simulation; ``finish`` runs the
    rest of the path and writes the outputs."""

    def __init__(self, sim, test, folder, before_shear, identity):
        self.sim, self.test, self.config, self.before_shear = sim, test, test.config, before_shear
        self.folder, self.out = folder, folder.path
        config = self.config
        out = folder.path
        sim.dt = timestep(sim, config.sample)   # from the state the loading starts from
        self.path = test.loading(sim)
        self.steps = self.path.steps           # None: known only as the path runs
        self.start_step = sim.step
        self.shear_time = 0.0        # seconds spent loading by earlier (interrupted) runs
        # frames spread over the loading, or over its estimate when its stages end otherwise
        self.vtk_period = frame_period(
            config.vtk_every, config.vtk_frames,
            self.steps if self.steps is not None else config.estimated_steps(),
            self.path.recorder.period * VTK_RECORDS)
        field_data, time_axis = test.frame_fields(self.path)
        self.vtk = frames_writer(sim, out, self.vtk_period, field_data=field_data,
                                 time_axis=time_axis)
        self.cluster_updates = None
        clusters = cluster_operation(sim)
        if clusters is not None:            # after the recorder: its rows show the update
            recorder = self.path.recorder
            closed = config.bridges.water_content is not None     # the liquid held: a volume
            self.cluster_updates = ClusterUpdates(
                sim, clusters, recorder.period, CLUSTER_RECORDS, recorder.origin,
                None if self.vtk is None else PoreFrames(os.path.join(out, "pores"),
                                                         time_axis), field_data,
                before_shear["wetting"]["liquid_initial"] if closed else None)
            sim.writers.append(self.cluster_updates)
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
                "config": self.before_shear["config"], "path": self.path.state()}

    def resumed(self, state):
        """Take the progress of the checkpoint loaded into the simulation."""
        self.start_step = state["start_step"]
        self.shear_time = state["shear_time_s"]
        where = state.get("path")
        if where is None and self.steps is not None:
            # a checkpoint that holds no path: a shear's one stage
            where = {"stage": 0, "stage_start": self.start_step, "stage_steps": self.steps}
        if not isinstance(where, dict):
            raise ValueError("the checkpoint does not say where its loading path stood")
        self.path.resume(self.sim, where)
        self._clock = time.perf_counter()

    def finish(self, progress, stop_after, plots=True):
        """Run the rest of the path (raising Interrupted at ``stop_after`` steps or on Ctrl-C)
        and write the outputs (the figures if ``plots``); returns the summary. Interrupted, it
        keeps the history so far (summary ``completed`` false), unless the folder holds the
        finished results of an earlier run, which are then kept instead."""
        sim, path = self.sim, self.path
        label = self.test.PROGRESS if progress else None
        budget = math.inf if stop_after is None else stop_after
        self._clock = time.perf_counter()
        try:
            if pausing_at("shear"):          # tests: Ctrl-C halfway through the loading
                half = int(min(path.steps_left(sim), budget)) // 2
                budget -= path.run(sim, max_steps=half)
                pause_point("shear")
            path.run(sim, max_steps=None if budget == math.inf else budget, progress=label)
        except KeyboardInterrupt:
            pass
        except AxialContactLost as error:
            if not self.test.ENDS_AT_CONTACT_LOSS:
                return self._failed(error)
            path.recorder.record(sim)            # the record of the loss ends the history
            self.shear_time += time.perf_counter() - self._clock
            if self.vtk is not None:
                self.vtk.close(sim)
            return self.write_outputs(plots=plots, stopped=str(error))
        except (SampleCrushed, StageFailed) as error:
            return self._failed(error)
        self.shear_time += time.perf_counter() - self._clock
        if not path.done:
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

    def _failed(self, error):
        """Keep the history of a loading that ``error`` stopped (unless the folder holds the
        finished results of an earlier run), then raise it."""
        self.shear_time += time.perf_counter() - self._clock
        if not self.folder.earlier_results:
            self.write_outputs(completed=False, error=str(error))
        raise error

    def write_outputs(self, completed=True, plots=True, error=None, stopped=None):
        """history.h5, summary.json (``completed``: whether the loading reached its end;
        ``error``: what stopped it, if not an interruption; ``stopped``: why a completed
        loading ended before its last stage's end) and, for a completed run, the plots unless
        ``plots`` is False."""
        sim, config, out = self.sim, self.config, self.out
        sample = config.sample
        preparation = self.before_shear["preparation"]
        history = self.test.derived(self.path.recorder.arrays())
        summary = self.test.summarize(history)
        rate = config.rate()
        sheared = sim.step - self.start_step
        loaded = history["unbalanced_force"][1:]      # none when the first stage failed at once
        summary.update({
            "completed": completed,
            "initial_porosity": preparation["porosity"],
            "initial_coordination": preparation["coordination"],
            "wall_time_s": self.before_shear["pre_shear_time_s"] + self.shear_time,
            "preparation_time_s": self.before_shear["preparation_time_s"],
            "shear_time_s": self.shear_time,
            "steps": self.steps if self.steps is not None else sheared,
            "preparation_steps": preparation["steps"],
            "particle_steps_per_s": (len(sim.particles) * sheared / self.shear_time
                                     if self.shear_time > 0.0 else None),
            "dt": sim.dt,
            "strain_rate": rate,
            "inertial_number": inertial_number(rate, sample.radius, sample.density,
                                               config.reference_pressure()),
            "max_unbalanced_force": float(np.max(loaded)) if len(loaded) else None,
            "mean_unbalanced_force": float(np.mean(loaded)) if len(loaded) else None,
            "threads": numba.get_num_threads(),
            "device": sim.device,
            "grading": grading(sim.particles.radius),
            **self.before_shear["wetting"],
        })
        if "clusters" in history:
            summary.update(cluster_summary(
                history, summary.get("peak_index", -1),
                "clusters_at_peak" if "peak_index" in summary else "clusters_final"))
            summary.update({"cluster_updates": self.cluster_updates.updates,
                            "cluster_update_time_s": self.cluster_updates.time_s})
        wetting = self.before_shear["wetting"]
        if "wet_porosity" in wetting:
            before, after = preparation["porosity"], wetting["wet_porosity"]
            summary.update({"porosity_before_wetting": before, "porosity_after_wetting": after,
                            "void_ratio_before_wetting": before / (1.0 - before),
                            "void_ratio_after_wetting": after / (1.0 - after)})
        if "liquid_bridges" in history:
            # the closed amount, which water-content stages change (path.liquid_total)
            initial = np.asarray(history.get("liquid_total",
                                             self.before_shear["wetting"]["liquid_initial"]))
            total = history["liquid_bridges"] + history["liquid_film"] + history["liquid_lost"]
            summary.update({
                "liquid_balance_error": float(np.max(np.abs(total - initial) / initial)),
                "liquid_lost_fraction": float(history["liquid_lost"][-1]
                                              / np.ravel(initial)[-1])})
        summary = plain(summary)              # NumPy scalars as plain floats and ints
        summary["units"] = {k: v for k, v in SUMMARY_UNITS.items() if k in summary}
        attributes = {k: v for k, v in parameters(config).items() if v is not None}
        attributes.update({"timestep": preparation["timestep"], "dt": sim.dt,
                           "strain_rate": rate, "vtk_every": self.vtk_period})
        if not completed:
            summary["phase"] = "shear"
        if error is not None:
            summary["error"] = error
        if stopped is not None:
            summary["stopped"] = stopped
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
                  f"to {summary['stress_balance_error']:.1%}): the loading is not quasi-static "
                  "there (summary.json stress_balance_flagged)", file=sys.stderr)
        if summary.get("axial_contact_lost"):
            print("warning: the axial stress fell to 0: the axial walls, which cannot pull, left "
                  "the sample before it failed in extension, and the shear ended there; the "
                  "peak is that of the walls' release, not of the sample, and phi_peak_deg is "
                  "null (summary.json axial_contact_lost); raise --confining", file=sys.stderr)
        if not plots:
            return summary
        self.test.plot(history, out, run_label(parameters(config),
                                               float(history["porosity"][0])))
        return summary


def plain(data):
    """``data`` with NumPy scalars and arrays as JSON values."""
    return json.loads(json.dumps(data, default=lambda v: v.tolist() if hasattr(v, "tolist")
                                 else str(v)))
