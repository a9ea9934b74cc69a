"""What a campaign runs: each laboratory command's test, the file of its result, its summary
and its options (``PROCEDURES``, a Procedure per command of pendular.procedures.registry:
triaxial, oedometer, isotropic, cyclic, simple-shear, path, tension, swcc), used by pendular.studies.campaign to run a configuration,
to reuse a finished run and to write its campaign.csv row."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from typing import Any, Callable, Union

from pendular.procedures.config import same_config, stored_config
from pendular.procedures.cyclic import CyclicConfig
from pendular.procedures.isotropic import IsotropicConfig
from pendular.procedures.laboratory import LaboratoryTest, parameters
from pendular.procedures.oedometer import OedometerConfig
from pendular.procedures.path import TablePathConfig
from pendular.procedures.registry import COMMANDS
from pendular.procedures.run_options import RunOptions
from pendular.procedures.simple_shear import SimpleShearConfig
from pendular.procedures.swcc import SwccConfig
from pendular.procedures.tension import TensionConfig
from pendular.procedures.triaxial import TriaxialConfig
from pendular.utils.parameters import Option, flat_options

#: What a campaign runs: the configuration of a laboratory command (PROCEDURES).
RunConfig = Union[TriaxialConfig, OedometerConfig, IsotropicConfig, CyclicConfig,
                  SimpleShearConfig, TablePathConfig, TensionConfig, SwccConfig]
#: The option of a laboratory test's run beside its configuration (Run.force).
FORCE = Option("force", "run settings refused as not quasi-static or too long (experts)",
               kind=bool)
#: Keys of a triaxial summary.json that every finished run has (numbers); a summary without
#: them is damaged and its run is done again.
SUMMARY_KEYS = ("peak_axial_stress", "peak_q", "p_at_peak", "axial_strain_at_peak")
#: Keys (numbers) of every finished laboratory test's summary.json (LaboratoryTest).
LABORATORY_KEYS = ("initial_porosity", "wall_time_s")


def tension_summary(result: dict) -> dict:
    """One summary row of a tension run: its first case's scalars (a campaign run of the
    tension command holds one void ratio and one water content)."""
    case = result["cases"][0]
    return {k: v for k, v in case.items() if isinstance(v, (int, float, str, bool))}


def swcc_summary(result: dict) -> dict:
    """The key figures of an SWCC run (swcc.json, pendular.procedures.swcc): the porosity of
    the dry sample, the bridges formed across gaps, the largest difference in Sr between the
    drying and the wetting branch (``max_saturation_hysteresis``), the wall time [s], and at
    every suction S [Pa] of each branch its Sr, chi and volumetric strain
    (``saturation_drying_S``, ``chi_wetting_S``, ``volumetric_strain_drying_S``)."""
    row = {"initial_porosity": float(result["preparation"]["porosity"]),
           "bridges_formed_across_gaps": int(result["bridges_formed_across_gaps"]),
           "max_saturation_hysteresis": max(float(h["saturation_difference"])
                                            for h in result["hysteresis"]),
           "wall_time_s": float(result["wall_time_s"])}
    for branch in ("drying", "wetting"):
        for stage in result[branch]:
            for key in ("saturation", "chi", "volumetric_strain"):
                row[f"{key}_{branch}_{float(stage['suction']):g}"] = float(stage[key])
    return row


def swcc_options(config: SwccConfig) -> dict:
    """An SWCC run's options, flat and named as the command's: its sample's and its own."""
    return {**flat_options(config.sample), **flat_options(config)}


def tension_options(config: TensionConfig) -> dict:
    """A tension run's options, flat and named as the command's (its void ratio and water
    content are its summary's ``*_target`` columns)."""
    return {k: v for k, v in config.options().items() if k != "cases"}


@dataclass(frozen=True)
class Procedure:
    """How a campaign runs the tests of one command: ``test`` its class (``test(config)``, a
    laboratory test's with ``force``, checks the configuration; ``.run(folder, options)`` runs
    it, with the options' ``threads`` where ``threaded``), ``config`` its configuration's class,
    ``result`` the file a finished run leaves with its result, ``summary(result)`` the run's
    summary (the scalars of which are its campaign.csv columns), ``options(config)`` its flat
    options (the other columns), ``keys`` the numbers a finished laboratory summary holds (else
    it is damaged and the run is done again). A laboratory test
    (pendular.procedures.laboratory.LaboratoryTest) stores its configuration in its sample.h5,
    the others in their result."""

    test: type
    config: type
    result: str = "summary.json"
    summary: Callable[[dict], dict] = dict
    options: Callable[[Any], dict] = parameters
    keys: tuple = LABORATORY_KEYS
    threaded: bool = True

    @property
    def laboratory(self) -> bool:
        """Whether the test is a LaboratoryTest (run settings checked, ``force`` taken)."""
        return issubclass(self.test, LaboratoryTest)

    def start(self, config: RunConfig, force: bool = False):
        """The test of ``config``, checked before anything runs (ValueError)."""
        return self.test(config, force=force) if self.laboratory else self.test(config)

    def run(self, config: RunConfig, folder: str, options: RunOptions | None = None,
            force: bool = False) -> dict:
        """Run the test of ``config`` into ``folder`` as ``options`` say (RunOptions; their
        threads only where ``threaded``); its summary."""
        if not self.threaded:
            options = RunOptions.of(options, threads=None)
        return self.summary(self.start(config, force).run(folder, options))

    def finished(self, config: RunConfig, folder: str) -> dict | None:
        """The summary of a run of ``folder`` that finished with an equal configuration, or
        None (also for a damaged result: the run is done again)."""
        path = os.path.join(folder, self.result)
        if not os.path.isfile(path):
            return None
        try:
            with open(path) as handle:
                result = json.load(handle)
        except (OSError, ValueError, RecursionError):
            return None
        if not isinstance(result, dict):
            return None
        stored = (stored_config(os.path.join(folder, "sample.h5"), "config") if self.laboratory
                  else result.get("config"))
        if not same_config(stored, config):
            return None
        if self.laboratory:
            whole = all(isinstance(result.get(key), (int, float))
                        and not isinstance(result.get(key), bool) for key in self.keys)
            return result if whole and result.get("completed", True) is True else None
        try:
            return self.summary(result)
        except (KeyError, IndexError, TypeError, AttributeError, ValueError):
            return None


#: What a campaign keeps of a command's run where it differs from a LaboratoryTest's
#: (Procedure's fields by command).
OWN = {"triaxial": {"keys": SUMMARY_KEYS},
       "tension": {"result": "tension.json", "summary": tension_summary,
                   "options": tension_options, "keys": (), "threaded": False},
       "swcc": {"result": "swcc.json", "summary": swcc_summary, "options": swcc_options,
                "keys": ()}}
#: Each laboratory command a campaign runs, by its name: every test of the registry.
PROCEDURES = {name: Procedure(command.test, command.config, **OWN.get(name, {}))
              for name, command in COMMANDS.items()}


def procedure_of(config: Any) -> Procedure:
    """The Procedure running ``config`` (TypeError naming the configurations a campaign
    runs)."""
    for procedure in PROCEDURES.values():
        if type(config) is procedure.config:
            return procedure
    raise TypeError(f"config must be the configuration of a laboratory command ("
                    f"{', '.join(p.config.__name__ for p in PROCEDURES.values())}), got "
                    f"{type(config).__name__}")


def run_options_of(command: str) -> tuple:
    """A run's own options of a table of ``command`` beside its configuration's (Run's):
    ``force`` for a laboratory test."""
    return (FORCE,) if PROCEDURES[command].laboratory else ()
