"""Isotropic loading and unloading in stages: its configuration, stages, summary, test and
command.

``isotropic_stages``: the six walls servoed to each stress in turn, each stage until static;
``isotropic_summary``: e against log p at each stage's end, the compression and swelling
indices; ``IsotropicTest``: the test (pendular.procedures.laboratory.LaboratoryTest);
``COMMAND``: ``pendular isotropic``. Stresses compression positive [Pa].
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from pendular.homogenize.invariants import mean_stress
from pendular.io.plots import plot_compression, plot_stress_path
from pendular.procedures.columns import COMPRESSION_COLUMNS
from pendular.procedures.command import LaboratoryCommand
from pendular.procedures.compression import compression_indices, effective_diagonal, stage_ends
# BridgeConfig and PrepareConfig: the types of the inherited fields bridges and sample,
# which the documentation reads here (typing.get_type_hints of the configuration)
from pendular.procedures.config import (BridgeConfig, PathConfig, check_soft, registered,
    stage_steps_parameter)
from pendular.procedures.laboratory import LaboratoryTest, stress_balance
from pendular.procedures.loading import AXIS_NAMES, LoadingPath, Stage, Static
from pendular.procedures.options import (framed, laboratory_options, options_named, path_command,
    path_rate_options)
from pendular.procedures.preparation import MAX_STRESS, PrepareConfig
from pendular.utils.parameters import fail, parameter


#: Fewest stresses of an isotropic path: a loading (or unloading) needs two.
MIN_ISOTROPIC_STAGES = 2


@registered
@dataclass
class IsotropicConfig(PathConfig):
    """Isotropic loading and unloading in stages (pendular.procedures.isotropic.isotropic_stages):
    the six walls servoed to each of ``stresses`` [Pa] (each > 0, in any order, at least
    MIN_ISOTROPIC_STAGES) in turn, each stage run until static; the walls move at most at the
    path's rate. ``stage_steps``: most steps of a stage."""

    stresses: list[float] = parameter(
        default_factory=lambda: [500.0, 1000.0, 2000.0, 5000.0, 2000.0, 500.0], many=True,
        unit="Pa", low=0.0, high=MAX_STRESS, low_inclusive=False, flag="--stresses",
        metavar="P1,P2,...", help="isotropic stresses of the stages, each > 0, in any order")
    stage_steps: int = stage_steps_parameter(2_000_000,
                                             "most steps of a stage to reach equilibrium")

    TEST = "an isotropic test"

    def __post_init__(self):
        super().__post_init__()
        listed = ",".join(f"{v:g}" for v in self.stresses)
        if len(self.stresses) < MIN_ISOTROPIC_STAGES:
            raise fail(self, "stresses", f"stresses = {listed}: at least "
                       f"{MIN_ISOTROPIC_STAGES} stresses [Pa] expected (a loading or unloading "
                       "goes from one to the next)")
        for k in range(1, len(self.stresses)):
            if self.stresses[k] == self.stresses[k - 1]:
                raise fail(self, "stresses", f"stresses = {listed}: stage {k + 1} repeats the "
                           f"{self.stresses[k]:g} Pa of stage {k}; valid: each stress unlike "
                           "the one before (a stage to the stress it holds does nothing)")
        for value in self.stresses:
            check_soft(self, "stresses", value)

    def reference_pressure(self):
        """The lowest stress of the path [Pa]: the confining or the least of ``stresses``."""
        return min(self.sample.confining, *self.stresses)

    def path_parameters(self):
        return {"stresses": ",".join(f"{v:g}" for v in self.stresses),
                "stage_steps": self.stage_steps}


def isotropic_stages(stresses, rate, *, max_steps=200000, unbalanced=0.01, tolerance=0.01):
    """Stages of an isotropic loading and unloading: the six walls servoed to each of
    ``stresses`` [Pa] in turn, at most at the strain rate ``rate`` [1/s], each until static
    (``unbalanced``, ``tolerance``) within ``max_steps``."""
    return [Stage(stress={axis: value for axis in AXIS_NAMES}, max_strain_rate=rate,
                  until=Static(max_steps, unbalanced, tolerance)) for value in stresses]


def isotropic_summary(history, stresses):
    """Results of an isotropic path's history (isotropic_stages to ``stresses`` [Pa]; columns
    ``void_ratio`` and ``stage``): ``stages``, one row per stage end (target, p [Pa], void
    ratio, volumetric strain, and wet p' of the effective stress, Eq. 3.43), and
    ``compression_index`` / ``swelling_index`` = Delta e per log10 p over the steps between
    successive listed stresses that load / unload (the stage from the confining stress to the
    first listed one is the path's start, not a step of it); wet, the same against p'
    (``*_effective``)."""
    void = history["void_ratio"]
    p = mean_stress(history["sigma_wall"])
    effective = effective_diagonal(history)
    ends = stage_ends(history, len(stresses))
    rows = []
    for k, row in enumerate(ends):
        entry = {"stage": k, "target": float(stresses[k]), "p": float(p[row]),
                 "void_ratio": float(void[row]),
                 "volumetric_strain": float(history["volumetric_strain"][row]),
                 "step": int(history["step"][row])}
        if effective is not None:
            entry["p_effective"] = float(effective[row].mean())
        rows.append(entry)
    compression, swelling = compression_indices([r["void_ratio"] for r in rows],
                                                [r["p"] for r in rows])
    summary = {"stages": rows, "initial_void_ratio": float(void[0]),
               "final_void_ratio": float(void[-1]), "compression_index": compression,
               "swelling_index": swelling}
    if effective is not None:
        compression, swelling = compression_indices([r["void_ratio"] for r in rows],
                                         [r["p_effective"] for r in rows])
        summary.update({"compression_index_effective": compression,
                        "swelling_index_effective": swelling})
    return summary


class IsotropicTest(LaboratoryTest):
    """Isotropic loading and unloading in stages of ``config``
    (pendular.procedures.isotropic.IsotropicConfig; isotropic_stages): history with
    ``void_ratio`` and ``stage``, summary of isotropic_summary; figure isotropic.png
    (e-log p, net and effective, and the volumetric strain)."""

    NAME = "isotropic"
    CONFIG = IsotropicConfig
    FIGURE = "isotropic.png"
    PROGRESS = "stage"

    def loading(self, sim):
        config = self.config
        sample = config.sample
        stages = isotropic_stages(config.stresses, config.rate(), max_steps=config.stage_steps,
                                  unbalanced=sample.equilibrium_unbalanced,
                                  tolerance=sample.stress_tolerance)
        return LoadingPath(sim, stages, record_every=config.record_every(sim.dt),
                           columns=COMPRESSION_COLUMNS)

    def summarize(self, history):
        return {**isotropic_summary(history, self.config.stresses), **stress_balance(history)}

    def plot(self, history, out, title):
        plot_compression(history, os.path.join(out, self.FIGURE), title, stress="mean")
        plot_stress_path(history, os.path.join(out, "plots", "stress_path.png"), title)


# ---------------------------------------------------------------- the command


ISOTROPIC_OWN = (options_named(IsotropicConfig, ("stresses", "stage_steps"))
                 + path_rate_options())

#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular isotropic --particles 1000 --stresses 1000,2000,4000,2000,1000 "
           "--out runs/isotropic",
           "e against log p at the end of each stage, with the compression and swelling indices; "
           "isotropic.png")

#: Summary keys printed at the end.
SHOWN = ("stages", "initial_void_ratio", "final_void_ratio", "compression_index",
         "swelling_index", "compression_index_effective", "swelling_index_effective",
         "initial_porosity", "wall_time_s", "particle_steps_per_s")

#: The isotropic command (pendular.procedures.registry).
COMMAND = LaboratoryCommand(
    name="isotropic",
    description="isotropic loading and unloading in stages: e against log p",
    test=IsotropicTest,
    declared=laboratory_options(
        ISOTROPIC_OWN, framed(path_command(IsotropicConfig, ISOTROPIC_OWN))),
    shown=SHOWN, example=EXAMPLE, out="runs/isotropic")
