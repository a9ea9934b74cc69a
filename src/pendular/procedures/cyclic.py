"""Cyclic triaxial loading, stress- or strain-controlled: its stages, its loops' measures and
the test (``pendular cyclic``).

The path (``cyclic_stages``) starts from the isotropic confining stress sigma_c with the
lateral walls servoed at sigma_c and the axial (z) walls driven at the path's strain rate: a
first loading to the amplitude, then per cycle an unloading to minus the amplitude and a
reloading back. Stress control: q = sigma_z - (sigma_x + sigma_y) / 2 between +A and -A
(``Stress`` ends on z at sigma_c +- A); strain control: the axial strain between +X and -X
from the start (``Strain`` ends). Stage 0 is the first loading, stages 2k - 1 and 2k the
unloading and reloading of cycle k (1-based): the history's ``cycle`` is 0 on the first
loading and k on cycle k. The axial walls cannot pull: a run whose axial stress falls to 0
stops (pendular.procedures.guards.AxialStressGuard, StageFailed).

The measures of a loop (``loop_measures``; Kramer 1996, "Geotechnical Earthquake
Engineering", Ch. 6, the equivalent linear model, with q for tau and the axial strain for
gamma): the secant modulus E_sec = (q_max - q_min) / (eps_max - eps_min) and the damping ratio
D = W_D / (4 pi W_S), W_D the loop's area (the oint of q d eps_a, the work of q per unit
volume dissipated in a cycle) and W_S = 1/2 (Delta q / 2)(Delta eps / 2) the strain energy
at the amplitudes. Stresses compression positive [Pa], strains compression positive.
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass

import numpy as np

from pendular.homogenize.invariants import deviator_stress, lateral_stress
from pendular.io.plots import plot_cyclic, plot_stress_path
from pendular.io.schema import peak_reached
from pendular.procedures.columns import COMPRESSION_COLUMNS, friction_angle
from pendular.procedures.command import LaboratoryCommand
# BridgeConfig and PrepareConfig: the types of the inherited fields bridges and sample,
# which the documentation reads here (typing.get_type_hints of the configuration)
from pendular.procedures.config import (BridgeConfig, MIN_AXIAL_STRAIN, PathConfig, check_soft,
    registered)
from pendular.procedures.guards import AxialStressGuard
from pendular.procedures.laboratory import LaboratoryTest, stress_balance
from pendular.procedures.loading import LoadingPath, Stage, Strain, Stress
from pendular.procedures.options import (framed, laboratory_options, options_named, path_command,
    path_rate_options)
from pendular.utils.parameters import OptionError, fail, option_of, parameter
from pendular.procedures.preparation import PrepareConfig


#: Most cycles of a cyclic triaxial test: liquefaction tests run tens to hundreds of cycles,
#: resilient-modulus tests about 2,000 (AASHTO T 307: up to 1,000 to condition, then 15
#: sequences of 100).
MAX_CYCLES = 10_000


#: Largest axial strain amplitude of a strain-controlled cyclic test [-]: cyclic triaxial tests
#: measure modulus and damping from about 1e-5 to a few % (Kramer 1996, Ch. 6); beyond, the
#: extension half of a cycle pulls the sample apart rather than cycling it.
MAX_CYCLIC_STRAIN = 0.05


@registered
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


#: Least history rows of a half-cycle under strain control: a loop's area needs its shape.
MIN_BRANCH_RECORDS = 20
#: Least fall of q after its peak in a half-cycle, over the peak, that makes it a failure
#: peak [-]: a plateau's records scatter by 1-3 % at a few hundred spheres.
FAILURE_DROP = 0.05


def cyclic_stages(confining, rate, cycles, *, amplitude_q=None, amplitude_strain=None):
    """Stages of a cyclic triaxial path (module docstring) from the isotropic ``confining``
    stress [Pa] at the axial strain rate ``rate`` [1/s] > 0: a first loading, then ``cycles``
    times an unloading and a reloading; the lateral walls servoed at ``confining``. One of
    ``amplitude_q`` [Pa] (ends at the axial stress confining +- A) and ``amplitude_strain``
    [-] (ends at the axial strain +- X)."""
    if (amplitude_q is None) == (amplitude_strain is None):
        raise ValueError("give one of amplitude_q (Pa) and amplitude_strain")
    if amplitude_q is not None:
        ends = {1.0: Stress(confining + amplitude_q), -1.0: Stress(confining - amplitude_q)}
    else:
        ends = {1.0: Strain(amplitude_strain), -1.0: Strain(-amplitude_strain)}

    def stage(sign):
        return Stage(stress={"x": confining, "y": confining}, strain_rate={"z": sign * rate},
                     until=ends[sign])

    return [stage(1.0)] + [stage(sign) for _ in range(cycles) for sign in (-1.0, 1.0)]


def cycle_of(stage):
    """The cycle (1-based; 0: the first loading) of the stage of index ``stage``."""
    return (stage + 1) // 2


class CyclicPath(LoadingPath):
    """The LoadingPath of ``cyclic_stages`` (same options): its history adds ``cycle``
    (cycle_of the running stage) and an AxialStressGuard stops it when the axial stress falls
    to 0."""

    def __init__(self, sim, stages, *, columns=None, **options):
        columns = {**(columns or {}), "cycle": lambda s: cycle_of(self.stage)}
        super().__init__(sim, stages, columns=columns, **options)
        sim.writers.append(AxialStressGuard(
            lambda s: (f"stage {self.stage + 1} ({self.stages[self.stage].describe()}), "
                       f"cycle {cycle_of(self.stage)}, axial strain "
                       f"{self.axial.strain(s.walls):.3g}"),
            "lower --amplitude-strain or raise --confining"))


# ---------------------------------------------------------------- results

def loop_measures(strain, q):
    """(secant modulus [Pa], damping ratio [-], W_D [Pa], W_S [Pa]) of one loop of axial
    strains ``strain`` [-] and deviator stresses ``q`` [Pa] in the order travelled (Kramer
    1996, Ch. 6): E_sec = (q_max - q_min) / (eps_max - eps_min); W_D = the oint of
    q d eps (trapezoids, closed by the chord from the last point to the first: a loop that
    ratchets does not close), positive for a loop travelled clockwise in the (eps, q) plane
    (loading above unloading); W_S = 1/2 (Delta q / 2)(Delta eps / 2); D = W_D / (4 pi W_S).
    The modulus and the damping ratio are None where Delta eps (or Delta q) is 0."""
    strain = np.asarray(strain, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    span_q, span_strain = float(np.ptp(q)), float(np.ptp(strain))
    closed_strain, closed_q = np.append(strain, strain[0]), np.append(q, q[0])
    dissipated = float(np.sum(0.5 * (closed_q[1:] + closed_q[:-1]) * np.diff(closed_strain)))
    stored = 0.5 * (span_q / 2.0) * (span_strain / 2.0)
    modulus = span_q / span_strain if span_strain > 0.0 else None
    damping = dissipated / (4.0 * math.pi * stored) if stored > 0.0 else None
    return modulus, damping, dissipated, stored


def damping_resolution(strain, q, lateral, target, stored):
    """The resolution [-] of a loop's damping ratio (loop_measures): the loop area that the
    measurement itself can make, over 4 pi W_S (``stored`` [Pa]). Two parts, each an area
    over the strain travelled sum |d eps| (``strain`` [-] in the order travelled): the
    lateral stress's departure from its ``target`` [Pa] (the servo's lag),
    sum |lateral - target| |d eps| (trapezoids), and the scatter of the records of ``q``
    [Pa], its noise estimated from their second differences (median absolute deviation,
    robust to the loop's turning points: s = median |q[i+1] - 2 q[i] + q[i-1]| /
    (0.6745 sqrt 6)) times sum |d eps|. None where W_S is 0 or the loop has fewer than 3
    records."""
    strain = np.asarray(strain, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    if not stored > 0.0 or len(q) < 3:
        return None
    travel = np.abs(np.diff(strain))
    off = np.abs(np.asarray(lateral, dtype=np.float64) - target)
    lag = float(np.sum(0.5 * (off[1:] + off[:-1]) * travel))
    noise = float(np.median(np.abs(q[2:] - 2.0 * q[1:-1] + q[:-2]))) / (0.6745 * math.sqrt(6.0))
    return (lag + noise * float(np.sum(travel))) / (4.0 * math.pi * stored)


def _resolved(row, name, damping, resolution):
    """Fill ``row`` with the damping ratio ``name`` measured against its ``resolution``: the
    value, or None with a note when it does not exceed the resolution (a damping ratio is not
    negative: a negative one is the measurement's own error)."""
    row[name] = damping
    row[f"{name}_measured"] = damping
    row[f"{name}_resolution"] = resolution
    if damping is not None and resolution is not None and damping <= resolution:
        row[name] = None
        row[f"{name}_note"] = (f"below resolution: {name} {damping:.2g} <= {resolution:.2g}, "
                               "the loop area that the lateral servo's lag and the records' "
                               "scatter can make")


def _stage_end(stage, k):
    """Last row of stage ``k`` (stage index per row), None if it has none."""
    rows = np.flatnonzero(stage == k)
    return int(rows[-1]) if len(rows) else None


def _failure_peak(strain, q, stage):
    """Row of the largest |q| at a failure peak of a half-cycle, None without one: q (or -q
    on an unloading) peaks before the half-cycle's end (schema.peak_reached) and falls after
    it by at least FAILURE_DROP of the peak."""
    found = None
    for k in np.unique(stage):
        rows = np.flatnonzero(stage == k)
        sign = 1.0 if k % 2 == 0 else -1.0           # even stages load, odd ones unload
        branch = sign * q[rows]
        peak = int(np.argmax(branch))
        if (len(rows) < 2 or not peak_reached(strain[rows], branch)
                or branch[-1] > branch[peak] - FAILURE_DROP * abs(branch[peak])):
            continue
        if found is None or abs(q[rows[peak]]) > abs(q[found]):
            found = int(rows[peak])
    return found


def cyclic_summary(history, cycles, complete=True, confining=None):
    """Results of a cyclic path's history (cyclic_stages with ``cycles`` cycles; columns
    ``sigma_wall``, ``axial_strain``, ``volumetric_strain``, ``stage``); ``complete``: whether
    the path reached its end (else the last cycle recorded, cut short, is left out).

    ``cycles``: one row per complete cycle: ``cycle`` (1-based), ``secant_modulus`` [Pa] and
    ``damping_ratio`` [-] of its loop (loop_measures over the rows from the end of the cycle
    before, at +A, to its own end), ``dissipated_energy`` W_D and ``strain_energy`` W_S [Pa],
    ``q_max``, ``q_min`` [Pa], ``axial_strain_max``, ``axial_strain_min``,
    ``axial_strain_increment`` over the cycle and ``axial_strain_accumulated`` since the end
    of the first loading (ratcheting), ``volumetric_strain`` at its end (from the start of
    the path) and ``volumetric_strain_increment`` over it, ``records`` (rows of the loop).
    Top level: ``secant_modulus_first`` / ``_last``, ``damping_ratio_first`` / ``_last``,
    ``axial_strain_accumulated``, ``volumetric_strain_accumulated`` after the last cycle,
    ``axial_strain_at_load`` and ``q_at_load`` at the end of the first loading,
    ``cycles_completed``. A damping ratio below its resolution (``damping_resolution``
    about the lateral stress ``confining`` [Pa], default the first record's) is None, with
    ``damping_ratio_measured``, ``damping_ratio_resolution`` and ``damping_ratio_note`` in its
    row (``damping_ratio_effective_*`` of q') and ``damping_ratio_note`` at the top naming the
    cycles. ``phi_peak_deg`` (columns.friction_angle of the wall stresses) only
    where a half-cycle has a failure peak (q falls after it by FAILURE_DROP or more). A wet
    history adds, per cycle and at the top, the modulus and damping ratio of the effective
    stress (Eq. 3.43; ``*_effective``)."""
    sigma = np.asarray(history["sigma_wall"], dtype=np.float64)
    strain = np.asarray(history["axial_strain"], dtype=np.float64)
    volumetric = np.asarray(history["volumetric_strain"], dtype=np.float64)
    stage = np.asarray(history["stage"])
    q = deviator_stress(sigma)
    effective = None
    if "sigma_effective" in history:
        effective = deviator_stress(np.diagonal(history["sigma_effective"], axis1=1, axis2=2))
    lateral = lateral_stress(sigma)
    target = lateral[0] if confining is None else confining
    loaded = _stage_end(stage, 0)
    rows = []
    start = loaded
    last_stage = int(stage.max())
    for k in range(1, cycles + 1):
        end = _stage_end(stage, 2 * k)
        if end is None or (2 * k == last_stage and not complete):
            break
        loop = slice(start, end + 1)
        modulus, damping, dissipated, stored = loop_measures(strain[loop], q[loop])
        resolution = damping_resolution(strain[loop], q[loop], lateral[loop], target, stored)
        row = {"cycle": k, "secant_modulus": modulus, "dissipated_energy": dissipated, "strain_energy": stored,
               "q_max": float(q[loop].max()), "q_min": float(q[loop].min()),
               "axial_strain_max": float(strain[loop].max()),
               "axial_strain_min": float(strain[loop].min()),
               "axial_strain_increment": float(strain[end] - strain[start]),
               "axial_strain_accumulated": float(strain[end] - strain[loaded]),
               "volumetric_strain": float(volumetric[end]),
               "volumetric_strain_increment": float(volumetric[end] - volumetric[start]),
               "records": end + 1 - start}
        _resolved(row, "damping_ratio", damping, resolution)
        if effective is not None:
            modulus, damping, _, stored = loop_measures(strain[loop], effective[loop])
            row["secant_modulus_effective"] = modulus
            _resolved(row, "damping_ratio_effective", damping, damping_resolution(
                strain[loop], effective[loop], lateral[loop], target, stored))
        rows.append(row)
        start = end
    summary = {"cycles": rows, "cycles_completed": len(rows),
               "axial_strain_at_load": float(strain[loaded]), "q_at_load": float(q[loaded])}
    suffixes = ("", "_effective") if effective is not None else ("",)
    for suffix in suffixes:
        for name in ("secant_modulus", "damping_ratio"):
            summary[f"{name}_first{suffix}"] = rows[0][name + suffix] if rows else None
            summary[f"{name}_last{suffix}"] = rows[-1][name + suffix] if rows else None
    below = [row["cycle"] for row in rows if "damping_ratio_note" in row]
    if below:
        summary["damping_ratio_note"] = (
            f"below resolution in cycle(s) {', '.join(map(str, below))}: the damping ratio is "
            "null there, its measured value, resolution and note in the cycle's row")
    summary["axial_strain_accumulated"] = rows[-1]["axial_strain_accumulated"] if rows else None
    summary["volumetric_strain_accumulated"] = (float(volumetric[start] - volumetric[loaded])
                                                if rows else None)
    peak = _failure_peak(strain, q, stage)
    if peak is not None:
        summary["phi_peak_deg"] = float(friction_angle(sigma[peak]))
    return summary


# ---------------------------------------------------------------- the test

class CyclicTest(LaboratoryTest):
    """A cyclic triaxial test of ``config`` (pendular.procedures.cyclic.CyclicConfig;
    cyclic_stages): history with ``void_ratio``, ``stage`` and ``cycle``, summary of
    cyclic_summary; figure cyclic.png (the q-eps_a loops, and the secant modulus and damping
    ratio against the cycle). Rows every ``record_strain`` of the path's rate and, under
    strain control, at least MIN_BRANCH_RECORDS a half-cycle."""

    NAME = "cyclic"
    CONFIG = CyclicConfig
    FIGURE = "cyclic.png"
    PROGRESS = "cyclic"

    def loading(self, sim):
        config = self.config
        rate = config.rate()
        stages = cyclic_stages(config.confining, rate, config.cycles,
                               amplitude_q=config.amplitude_q,
                               amplitude_strain=config.amplitude_strain)
        every = config.record_every(sim.dt)
        if not config.stress_controlled:
            branch = 2.0 * config.amplitude_strain / (rate * sim.dt)       # steps
            every = max(1, min(every, int(branch // MIN_BRANCH_RECORDS)))
        self.path = CyclicPath(sim, stages, record_every=every, columns=COMPRESSION_COLUMNS)
        return self.path

    def summarize(self, history):
        path = getattr(self, "path", None)
        complete = path is None or path.done
        return {**cyclic_summary(history, self.config.cycles, complete,
                                 self.config.confining),
                **stress_balance(history)}

    def plot(self, history, out, title):
        config = self.config
        amplitude = (f"q = ±{config.amplitude_q:g} Pa" if config.stress_controlled
                     else f"εa = ±{100.0 * config.amplitude_strain:g} %")
        label = f"{title}, {amplitude}, {config.cycles} cycle" + ("s" if config.cycles > 1
                                                                 else "")
        plot_cyclic(history, cyclic_summary(history, config.cycles)["cycles"],
                    os.path.join(out, self.FIGURE), label)
        plot_stress_path(history, os.path.join(out, "plots", "stress_path.png"), label)


# ---------------------------------------------------------------- the command


CYCLIC_OWN = (tuple(dataclasses.replace(option, group="amplitude") for option in options_named(
                  CyclicConfig, ("amplitude_q", "amplitude_strain")))
              + (option_of(CyclicConfig, "cycles"),) + path_rate_options())


def amplitude_given(values):
    """OptionError unless one of the cyclic amplitudes is given."""
    if values["amplitude_q"] is None and values["amplitude_strain"] is None:
        raise OptionError(lambda name: f"give {name('amplitude_q')} PA (stress control) or "
                                       f"{name('amplitude_strain')} X (strain control)")


#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular cyclic --particles 1000 --amplitude-q 200 --cycles 10 --out runs/cyclic",
           "ten cycles of q = +-200 Pa: the secant modulus and damping ratio of each loop (null "
           "below its resolution) and the accumulated strains; cyclic.png")

#: Summary keys printed at the end.
SHOWN = ("cycles", "secant_modulus_first", "secant_modulus_last", "damping_ratio_first",
         "damping_ratio_last", "secant_modulus_first_effective",
         "secant_modulus_last_effective", "damping_ratio_first_effective",
         "damping_ratio_last_effective", "axial_strain_accumulated",
         "volumetric_strain_accumulated", "phi_peak_deg", "initial_porosity", "wall_time_s",
         "particle_steps_per_s", "damping_ratio_note")

#: The cyclic command (pendular.procedures.registry).
COMMAND = LaboratoryCommand(
    name="cyclic",
    description="cyclic triaxial loading, stress- or strain-controlled",
    test=CyclicTest,
    declared=laboratory_options(
        CYCLIC_OWN, framed(path_command(CyclicConfig, CYCLIC_OWN, check=amplitude_given))),
    shown=SHOWN, example=EXAMPLE, out="runs/cyclic")
