"""Oedometric (K0) compression and unloading, dry or wet: its configuration, stages, summary,
test and command.

``oedometer_stages``: the lateral walls fixed, the axial ones pushed in at the path's rate
until the axial stress is reached, then optionally pulled back; ``oedometer_summary``: K0,
the constrained modulus, the compression and swelling indices against the axial stress;
``OedometerTest``: the test (pendular.procedures.laboratory.LaboratoryTest); ``COMMAND``:
``pendular oedometer``. Stresses compression positive [Pa]; strains compression positive.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

from pendular.homogenize.invariants import lateral_stress
from pendular.io.plots import plot_compression, plot_stress_path, write_plots
from pendular.procedures.columns import COMPRESSION_COLUMNS, k0
from pendular.procedures.command import LaboratoryCommand
from pendular.procedures.compression import (effective_diagonal, index_of_slope, stage_ends,
    tangent_modulus)
# BridgeConfig and PrepareConfig: the types of the inherited fields bridges and sample,
# which the documentation reads here (typing.get_type_hints of the configuration)
from pendular.procedures.config import BridgeConfig, PathConfig, check_soft, registered
from pendular.procedures.laboratory import LaboratoryTest, stress_balance
from pendular.procedures.loading import LoadingPath, Stage, Stress
from pendular.procedures.options import (framed, laboratory_options, options_named, path_command,
    path_rate_options)
from pendular.procedures.preparation import MAX_STRESS, PrepareConfig
from pendular.utils.parameters import fail, parameter


@registered
@dataclass
class OedometerConfig(PathConfig):
    """Oedometric (K0) compression (pendular.procedures.oedometer.oedometer_stages): the lateral
    walls fixed, the axial ones pushed in at the path's rate until the axial stress is
    ``axial_stress`` [Pa] (above the confining stress the sample starts from), then, with
    ``unload_to`` [Pa] (below ``axial_stress``, above 0), pulled back until it is that."""

    axial_stress: float = parameter(10000.0, unit="Pa", low=0.0, high=MAX_STRESS,
                                    flag="--axial-stress",
                                    help="axial stress the compression ends at, above "
                                         "--confining")
    unload_to: float | None = parameter(None, unit="Pa", low=0.0, high=MAX_STRESS,
                                        low_inclusive=False,
                                        flag="--unload-to",
                                        help="then unload to this axial stress, below "
                                             "--axial-stress")

    TEST = "an oedometer test"

    def __post_init__(self):
        super().__post_init__()
        confining = self.sample.confining
        if self.axial_stress <= confining:
            raise fail(self, "axial_stress", f"axial_stress = {self.axial_stress:g} Pa is "
                       f"outside the valid range ({confining:g}, {MAX_STRESS:g}] Pa: the "
                       "compression "
                       f"starts from the confining stress (--confining {confining:g} Pa)")
        check_soft(self, "axial_stress", self.axial_stress)
        if self.unload_to is not None and self.unload_to >= self.axial_stress:
            raise fail(self, "unload_to", f"unload_to = {self.unload_to:g} Pa is outside the "
                       f"valid range (0, {self.axial_stress:g}) Pa: an unloading ends below "
                       f"the load (--axial-stress {self.axial_stress:g} Pa)")

    def reference_pressure(self):
        """The lowest axial stress of the path [Pa]: the confining stress, or ``unload_to``."""
        return min(self.sample.confining, self.unload_to or math.inf)

    def path_parameters(self):
        return {"axial_stress": self.axial_stress, "unload_to": self.unload_to}


def oedometer_stages(axial_stress, rate, unload_to=None):
    """Stages of an oedometric (K0) test: the lateral walls held, the axial walls compressed at
    ``rate`` [1/s] until the axial stress is ``axial_stress`` [Pa], then with ``unload_to``
    [Pa] pulled back at the same rate until it is that."""
    held = {"x": 0.0, "y": 0.0}
    stages = [Stage(strain_rate={**held, "z": rate}, until=Stress(axial_stress))]
    if unload_to is not None:
        stages.append(Stage(strain_rate={**held, "z": -rate}, until=Stress(unload_to)))
    return stages


def oedometer_summary(history, axial_stress, unload_to=None):
    """Results of an oedometric test's history (oedometer_stages; columns ``void_ratio`` and,
    with unloading, ``stage``): at the end of the loading (the target ``axial_stress`` [Pa])
    ``k0`` = sigma_lateral / sigma_axial, the axial and lateral stresses, axial strain and void
    ratio; ``constrained_modulus`` [Pa] = (sigma_v - sigma_v0) / (eps_a - eps_a0) over the
    loading (secant from the start) and ``constrained_modulus_tangent`` over its last fifth
    of stress (least squares); ``compression_index`` = -Delta e / Delta log10 sigma_v over the
    loading; with ``unload_to``: the same at the end of the unloading,
    ``constrained_modulus_unloading`` (secant) and ``swelling_index``. A wet history adds
    ``k0_effective`` and the indices against the effective vertical stress (Eq. 3.43)."""
    sigma = history["sigma_wall"]
    strain = history["axial_strain"]
    void = history["void_ratio"]
    ends = stage_ends(history, 2 if unload_to is not None else 1)
    loaded = ends[0]
    axial, lateral = sigma[:, 2], lateral_stress(sigma)
    summary = {
        "k0": float(lateral[loaded] / axial[loaded]),
        "axial_stress_target": float(axial_stress),
        "axial_stress_at_load": float(axial[loaded]),
        "lateral_stress_at_load": float(lateral[loaded]),
        "axial_strain_at_load": float(strain[loaded]),
        "initial_void_ratio": float(void[0]),
        "void_ratio_at_load": float(void[loaded]),
        "constrained_modulus": float((axial[loaded] - axial[0]) / (strain[loaded] - strain[0])),
        "constrained_modulus_tangent": tangent_modulus(strain[:loaded + 1],
                                                        axial[:loaded + 1]),
        "compression_index": index_of_slope(void[0], void[loaded], axial[loaded], axial[0]),
    }
    if summary["constrained_modulus_tangent"] is None:
        summary["constrained_modulus_tangent_note"] = (
            "not measured: fewer than 3 records, or no strain, in the top fifth of the "
            "loading's stress")
    effective = effective_diagonal(history)
    if effective is not None:
        summary["k0_effective"] = float(lateral_stress(effective[loaded])
                                        / effective[loaded, 2])
        summary["compression_index_effective"] = index_of_slope(void[0], void[loaded],
                                                        effective[loaded, 2], effective[0, 2])
    if unload_to is not None and len(ends) == 2:
        final = ends[1]
        summary.update({
            "unload_to": float(unload_to),
            "k0_final": float(lateral[final] / axial[final]),
            "axial_stress_final": float(axial[final]),
            "axial_strain_final": float(strain[final]),
            "void_ratio_final": float(void[final]),
            "constrained_modulus_unloading": float((axial[loaded] - axial[final])
                                                   / (strain[loaded] - strain[final])),
            "swelling_index": index_of_slope(void[final], void[loaded], axial[loaded],
                                             axial[final]),
        })
        if effective is not None:
            summary["swelling_index_effective"] = index_of_slope(void[final], void[loaded],
                                                         effective[loaded, 2],
                                                         effective[final, 2])
    return summary


class OedometerTest(LaboratoryTest):
    """An oedometric (K0) test of ``config`` (pendular.procedures.oedometer.OedometerConfig;
    oedometer_stages): history with ``void_ratio`` and ``k0`` (and ``stage`` with an
    unloading), summary of oedometer_summary; figure oedometer.png (e-log sigma_v and
    K0), plots/ (stress path, and against axial strain as the triaxial's)."""

    NAME = "oedometer"
    CONFIG = OedometerConfig
    FIGURE = "oedometer.png"
    PROGRESS = "oedometer"

    def loading(self, sim):
        config = self.config
        rate = config.rate()
        return LoadingPath(sim, oedometer_stages(config.axial_stress, rate, config.unload_to),
                           record_every=config.record_every(sim.dt),
                           columns={**COMPRESSION_COLUMNS, "k0": k0})

    def summarize(self, history):
        config = self.config
        return {**oedometer_summary(history, config.axial_stress, config.unload_to),
                **stress_balance(history)}

    def plot(self, history, out, title):
        plot_compression(history, os.path.join(out, self.FIGURE), title, stress="axial")
        plot_stress_path(history, os.path.join(out, "plots", "stress_path.png"), title)
        write_plots(history, os.path.join(out, "plots"), title, direction=None)


# ---------------------------------------------------------------- the command


#: Each loading path's own options (its fields set by them as they are).
OEDOMETER_OWN = (options_named(OedometerConfig, ("axial_stress", "unload_to"))
                 + path_rate_options())

#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular oedometer --particles 1000 --axial-stress 10000 --unload-to 2000 "
           "--out runs/oedometer",
           "K0, the constrained modulus and the compression and swelling indices of a loading to "
           "10 kPa and an unloading to 2 kPa; e-log sigma_v in oedometer.png")

#: Summary keys printed at the end.
SHOWN = ("k0", "k0_effective", "axial_stress_at_load", "lateral_stress_at_load",
         "axial_strain_at_load", "initial_void_ratio", "void_ratio_at_load",
         "constrained_modulus", "constrained_modulus_tangent", "compression_index",
         "compression_index_effective", "k0_final", "void_ratio_final",
         "constrained_modulus_unloading", "swelling_index", "swelling_index_effective",
         "initial_porosity", "wall_time_s", "particle_steps_per_s")

#: The oedometer command (pendular.procedures.registry).
COMMAND = LaboratoryCommand(
    name="oedometer",
    description="oedometric (K0) compression and unloading, dry or wet",
    test=OedometerTest,
    declared=laboratory_options(
        OEDOMETER_OWN, framed(path_command(OedometerConfig, OEDOMETER_OWN))),
    shown=SHOWN, example=EXAMPLE, out="runs/oedometer")
