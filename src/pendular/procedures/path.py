"""Loading paths from a table, and the few functions that compose a hydro-mechanical path in
Python.

A path table is a TOML file of ``[[stage]]`` entries, run in their order by
``pendular path PATH.toml`` (``PathTest``). An entry is one of:

- a stage: the keys of pendular.procedures.loading.Stage, read from its fields, so that a
  field added to Stage is a key here: ``stress = {x = 500, y = 500}`` [Pa],
  ``strain_rate = {z = 0.5}`` [1/s, compression positive; 0 holds the walls], ``mean_stress``
  [Pa], ``b``, ``max_strain_rate`` [1/s], ``volume = "constant"`` (undrained: x and y hold
  the volume), ``suction`` [Pa] with ``suction_rate`` [Pa/s] (a ramp; none: a step) on a
  sample wetted at a suction, ``water_content`` [%, as --water-content] on one wetted at a
  water content (pendular.procedures.hydraulic), and ``until``, its end (``UNTIL_KINDS``):
  ``{strain = 0.05, axis = "z"}``, ``{stress = 5000, axis = "z", strain_limit = 0.2}``,
  ``"static"`` or ``{static = true, max_steps = 100000, unbalanced = 0.01, tolerance = 0.01,
  check_every = 200}`` (no ``until``: static);
- a group repeated: ``repeat = N`` and ``stages``, its entries (stages or groups) run N
  times in turn, e.g. the cycles of a cyclic loading; they follow as ``[[stage.stages]]``
  tables or inline, ``stages = [{...}, {...}]``. A group is an entry of the same
  ``[[stage]]`` list because TOML keeps the order of one list, not that between two.

Values may be named instead of written (``NAMES``): a stress or mean stress ``"confining"``,
the confining stress the path starts from (--confining); a strain rate ``"quasi-static"`` or
``"-quasi-static"`` (unloading), the rate of the inertial-number rule
(pendular.procedures.config.quasi_static_rate, --inertial-number at the lowest stress of the
path, or --strain-rate). The sample, its wetting and the outputs are the command line's
options (those of ``pendular triaxial``), so one table runs on any sample, dry or wet.

Every unknown key is refused with the file, the entry ("stage 2", "stage 3.1": the first
entry of the group at entry 3) and the valid keys; a value Stage refuses, with its field,
prefixed by the same. The parsed entries are stored as plain data in the configuration
(pendular.procedures.path.TablePathConfig), so a run resumes without its table.

A stage's water key needs the sample wetted as it says (``check_water``), and a suction
within the bridge tables for the sample's radii (``check_suctions``), both refused before
anything runs. The summary (``path_summary``) gives each stage's strain changes and, for the
stages that change the water, ``water_stages`` and the ``collapse_strain`` of wetting.

In Python, ``run_path`` runs stages on a scene and returns their history (a Stage's
``suction`` or ``water_content`` changes the water within a path), ``change_suction``
brings suction-controlled bridges to a new suction at a held stress in increments; with
pendular.procedures.triaxial's ``equilibrate`` and ``wet`` they compose any path of stress
and suction (examples/loading_path_api.py). Stresses compression positive [Pa].
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from pendular.dem.record import HistoryRecorder
from pendular.dem.walls import StressServo
from pendular.homogenize.invariants import deviator_stress, mean_stress
from pendular.io.plots import plot_path
from pendular.io.schema import peak_reached
from pendular.procedures.columns import (capillary_operation, friction_angle, history_columns, k0,
    void_ratio)
from pendular.procedures.command import LaboratoryCommand
# BridgeConfig and PrepareConfig: the types of the inherited fields bridges and sample,
# which the documentation reads here (typing.get_type_hints of the configuration)
from pendular.procedures.config import BridgeConfig, MAX_RECORDS, PathConfig, registered
from pendular.procedures.equilibrium import equilibrate
from pendular.procedures.hydraulic import water_content
from pendular.procedures.laboratory import LaboratoryTest, stress_balance
from pendular.procedures.loading import (AXIS_NAMES, AxisStrain, LoadingPath, Stage, Static,
    Strain, Stress)
from pendular.procedures.options import (framed, laboratory_fields, laboratory_options,
    path_rate_options)
from pendular.procedures.preparation import PrepareConfig, check_soft_contacts, servo_speed
from pendular.utils.parameters import Option, fail, fields_of, option_of, parameter
from pendular.utils.toml_file import read_toml
from pendular.utils.validate import check_int, check_positive


@registered
@dataclass
class TablePathConfig(PathConfig):
    """A loading path read from a table (pendular.procedures.path): PathConfig's sample,
    bridges, outputs, rate (``inertial_number`` at the lowest stress of the path, or
    ``strain_rate``: the value of the name 'quasi-static') and row spacing, and ``stages``:
    the table's [[stage]] entries as plain data (numbers, the names 'confining' and
    'quasi-static', groups repeated), built into pendular.procedures.loading.Stage objects by
    ``loading_stages``; ``source``: the table's file, named in errors; ``records``: history
    rows over a path of one stage ending at a strain, as ShearConfig.records (None: a row
    every ``record_strain``)."""

    stages: list = parameter(default_factory=list, kind=None, recorded=False,
                             help="the table's [[stage]] entries, as plain data")
    source: str = parameter("path table", kind=str, help="the table's file, named in errors")
    records: int | None = parameter(None, kind=int, low=2, high=MAX_RECORDS, flag="--records",
                                    help="history rows over a path of one stage ending at a "
                                         "strain, as pendular triaxial's --records (default: a "
                                         "row every --record-strain)")

    TEST = "a loading path"

    def __post_init__(self):
        super().__post_init__()
        stages = self.loading_stages()       # every entry checked, named by file and stage
        if self.records is not None:
            from pendular.procedures.loading import Strain

            if len(stages) != 1 or not isinstance(stages[0].until, Strain):
                raise fail(self, "records", f"records = {self.records} applies to a path of "
                           f"one stage ending at a strain (a triaxial's); {self.source} has "
                           f"{len(stages)} stage(s): leave it out (a row every "
                           "--record-strain)")

    def loading_stages(self):
        """The pendular.procedures.loading.Stage list of the table (ValueError naming the
        source, the entry and the key)."""


        return build_stages(self.stages, self.source, confining=self.sample.confining,
                            rate=self.rate(), sample=self.sample,
                            wetting=wetting_of(self.bridges))

    def stage_rates(self):
        """[(where, rate, steps)] of each stage of the table that moves an axis: 'FILE: stage
        N', its fastest |strain rate| or |shear rate| [1/s] and, when it ends at a strain
        whose start is known (the path's start, or the end of an earlier stage at a strain
        of that axis, not moved since), its steps estimated before anything runs (the strain
        to go over the strain of a step, ``strain_per_step``), else None."""
        from pendular.procedures.loading import ShearStrain, Strain

        start = {"x": 0.0, "y": 0.0, "z": 0.0, "shear": 0.0}      # None: not known
        found = []
        for label, stage in labelled_stages(self.stages, self.source,
                                            confining=self.sample.confining, rate=self.rate()):
            rates = {**stage.strain_rate, "shear": stage.shear_rate}
            until = stage.until
            ends = isinstance(until, (Strain, ShearStrain))
            axis = "shear" if isinstance(until, ShearStrain) else getattr(until, "axis", None)
            steps = None
            if ends and start[axis] is not None:
                try:
                    steps = (abs(until.value - start[axis])
                             / self.strain_per_step(abs(rates[axis])))
                except ValueError:              # a strain per step that underflows
                    steps = math.inf
            for name in start:
                if ends and name == axis:
                    start[name] = until.value
                elif rates.get(name, 0.0) != 0.0 or name in stage.stress or name in stage.free:
                    start[name] = None
            fastest = max(abs(value) for value in rates.values())
            if fastest > 0.0:
                found.append((f"{self.source}: {label}", fastest, steps))
        return found

    def reference_pressure(self):
        """The lowest stress of the path [Pa] (path.lowest_stress): the confining
        stress or a lower target of a stage."""

        return lowest_stress(self.stages, self.source, self.sample.confining)

    def path_parameters(self):
        """The path's own options, named as the command's (pendular.procedures.triaxial
        .parameters)."""
        return {"path": self.source, "records": self.records}


#: Most stages of a path once its groups are repeated.
MAX_STAGES = 100_000
#: Names a value may take instead of a number, by kind: stresses [Pa], strain rates [1/s].
STRESS_NAMES = ("confining",)
RATE_NAMES = ("quasi-static", "-quasi-static")
#: The fields of Stage (or of an end) that take named values, and which.
NAMES = {"stress": STRESS_NAMES, "mean_stress": STRESS_NAMES, "strain_rate": RATE_NAMES,
         "max_strain_rate": RATE_NAMES, "shear_rate": RATE_NAMES}
#: The fields of Stage that hold a value per axis ({axis: value}).
AXIS_FIELDS = tuple(f.name for f in dataclasses.fields(Stage) if f.default_factory is dict)
#: Keys of an entry that repeats a group of entries.
GROUP_KEYS = ("repeat", "stages")
#: History columns of a path beyond columns.history_columns.
PATH_COLUMNS = {"void_ratio": void_ratio, "k0": k0}


class Until(NamedTuple):
    """An end of a stage as a table writes it: the class, the field its key sets (None: the
    key is ``true``), the names that value may take."""

    kind: type
    value: str | None = None
    names: tuple = ()


#: The ends of a stage by their table key: ``until = {strain = 0.05}`` is Strain(value=0.05).
UNTIL_KINDS = {"strain": Until(Strain, "value"),
               "stress": Until(Stress, "value", STRESS_NAMES),
               "static": Until(Static)}


# ---------------------------------------------------------------- reading a table

def read_table(path):
    """The fields of a TablePathConfig from the TOML file ``path``: {'stages': the entries as
    plain data, 'source': the path as given}. ValueError naming the file (unreadable, not
    TOML, unknown keys, no stage)."""
    source = os.fspath(path)
    table = read_toml(path, source)
    unknown = sorted(set(table) - {"stage"})
    if unknown:
        raise ValueError(f"{source}: unknown key {unknown[0]!r}; valid: stage (the sample, "
                         "wetting and output options are given on the command line)")
    entries = table.get("stage", [])
    parse_entries(entries, source)
    return {"stages": entries, "source": source}


def stage_keys():
    """The keys of a stage in a table: the fields of loading.Stage."""
    return tuple(f.name for f in dataclasses.fields(Stage))


def parse_entries(entries, source):
    """[(label, stage entry)] of the table's ``entries`` with their groups repeated; each
    entry's keys checked (ValueError naming ``source``, the entry and the key, with the
    valid keys)."""
    if not isinstance(entries, list) or not entries:
        raise ValueError(f"{source}: no stage; valid: at least one [[stage]] table "
                         "(pendular.procedures.path)")
    stages = []
    _expand(entries, source, "stage ", stages)
    return stages


def _expand(entries, source, prefix, stages):
    keys = stage_keys()
    for number, entry in enumerate(entries, 1):
        label = f"{prefix}{number}"
        if not isinstance(entry, dict):
            raise ValueError(f"{source}: {label} = {entry!r}; valid: a table of "
                             f"{', '.join(keys)}")
        if "repeat" in entry or "stages" in entry:
            _expand_group(entry, source, label, stages)
            continue
        unknown = [key for key in entry if key not in keys]
        if unknown:
            raise ValueError(f"{source}: {label}: unknown key {unknown[0]!r}; valid: "
                             f"{', '.join(keys)} (a stage), or {', '.join(GROUP_KEYS)} (a "
                             "group repeated)")
        stages.append((label, entry))
        if len(stages) > MAX_STAGES:
            raise ValueError(f"{source}: {label}: the path has more than {MAX_STAGES} stages "
                             "once its groups are repeated; valid: at most that many")


def _expand_group(entry, source, label, stages):
    other = [key for key in entry if key not in GROUP_KEYS]
    if other:
        raise ValueError(f"{source}: {label}: key {other[0]!r} beside repeat and stages; "
                         f"valid: {', '.join(GROUP_KEYS)} (a group: give {other[0]!r} to the "
                         "stages in it)")
    repeat = entry.get("repeat")
    if isinstance(repeat, str):         # text where a count belongs, refused as _value does
        raise ValueError(f"{source}: {label}: repeat = {repeat!r} is text; valid: a number, "
                         f"an integer in [1, {MAX_STAGES}]")
    try:
        times = check_int("repeat", repeat, low=1, high=MAX_STAGES)
    except ValueError as error:
        raise ValueError(f"{source}: {label}: {error}") from None
    inner = entry.get("stages")
    if not isinstance(inner, list) or not inner:
        raise ValueError(f"{source}: {label}: stages = {inner!r}; valid: a non-empty list of "
                         "stages repeated")
    for _ in range(times):
        _expand(inner, source, f"{label}.", stages)


# ---------------------------------------------------------------- building the stages

def _value(name, value, values):
    """``value`` of key ``name`` as a number, its name resolved through ``values`` (name ->
    number) when the key takes names (NAMES); other values as they are, for the dataclass to
    check, except a boolean where a number is expected."""
    names = NAMES.get(name.split("[")[0], ())
    if isinstance(value, str) and value in names:
        return values[value]
    if isinstance(value, str) and names:
        raise ValueError(f"{name} = {value!r}; valid: a number or "
                         f"{' or '.join(repr(n) for n in names)}")
    if isinstance(value, bool):
        raise ValueError(f"{name} = {value!r} is not a number")
    return value


def _until(value, values):
    """The end of a stage (UNTIL_KINDS) of its table value."""
    valid = (f"valid: one of {', '.join(repr(k) for k in UNTIL_KINDS)}, e.g. "
             "{strain = 0.05, axis = 'z'}, {stress = 5000, axis = 'z'} or 'static'")
    if isinstance(value, str):
        kind = UNTIL_KINDS.get(value)
        if kind is None or kind.value is not None:
            raise ValueError(f"until = {value!r}; {valid}" + (
                "" if kind is None else f" ({value!r} needs its value: {{{value} = ...}})"))
        return kind.kind()
    if not isinstance(value, dict):
        raise ValueError(f"until = {value!r}; {valid}")
    named = [key for key in value if key in UNTIL_KINDS]
    if len(named) != 1:
        raise ValueError(f"until = {value!r} names {len(named)} ends; {valid}")
    kind = UNTIL_KINDS[named[0]]
    given = dict(value)
    marker = given.pop(named[0])
    fields = [f.name for f in dataclasses.fields(kind.kind) if f.name != kind.value]
    unknown = [key for key in given if key not in fields]
    if unknown:
        raise ValueError(f"until: unknown key {unknown[0]!r}; valid: "
                         f"{', '.join([named[0], *fields])}")
    options = {key: _value(f"until {key}", item, values) for key, item in given.items()}
    if kind.value is None:
        if marker is not True:
            raise ValueError(f"until {named[0]} = {marker!r}; valid: true")
    else:
        if isinstance(marker, str) and marker in kind.names:
            marker = values[marker]
        elif isinstance(marker, (str, bool)):
            raise ValueError(f"until {named[0]} = {marker!r}; valid: a number"
                             + "".join(f" or {n!r}" for n in kind.names))
        options[kind.value] = marker
    return kind.kind(**options)


def _stage(entry, values):
    """The Stage of one table entry (keys checked), its named values resolved."""
    fields = {}
    for key, value in entry.items():
        if key == "until":
            fields[key] = _until(value, values)
        elif key in AXIS_FIELDS and not isinstance(value, dict):
            raise ValueError(f"{key} = {value!r}; valid: a value per axis, e.g. "
                             f"{key} = {{x = 500, y = 500}}")
        elif isinstance(value, dict):
            fields[key] = {axis: _value(f"{key}[{axis!r}]", item, values)
                           for axis, item in value.items()}
        else:
            fields[key] = _value(key, value, values)
    return Stage(**fields)


def build_stages(entries, source, *, confining, rate, sample=None, wetting=None):
    """The loading.Stage list of a table's ``entries`` (read_table), groups repeated;
    ``confining`` [Pa] and ``rate`` [1/s] are the values of the names 'confining' and
    'quasi-static'; with ``sample`` (a PrepareConfig), every stress is checked against its
    contacts (preparation.check_soft_contacts); with ``wetting`` (WETTINGS: how the sample
    is wetted), every stage's water keys against it (check_water). ValueError naming
    ``source`` and the entry."""
    return [stage for _, stage in labelled_stages(entries, source, confining=confining,
                                                  rate=rate, sample=sample, wetting=wetting)]


def labelled_stages(entries, source, *, confining, rate, sample=None, wetting=None):
    """[(label, loading.Stage)] of build_stages, each with its entry's label ('stage 3.1')."""
    values = {"confining": confining, "quasi-static": rate, "-quasi-static": -rate}
    stages = []
    for label, entry in parse_entries(entries, source):
        try:
            stage = _stage(entry, values)
            for name, value in stage_stresses(stage) if sample is not None else ():
                check_soft_contacts(name, value, sample.young, sample.contact, sample.poisson)
            if wetting is not None:
                check_water(stage, wetting)
        except (ValueError, TypeError) as error:
            raise ValueError(f"{source}: {label}: {error}") from None
        stages.append((label, stage))
    return stages


#: How a path's sample is wetted, for its stages' water keys: dry, at a suction
#: (suction-controlled bridges: ``suction`` stages), at a water content (a closed amount of
#: liquid: ``water_content`` stages).
WETTINGS = ("dry", "suction", "water_content")


def wetting_of(bridges):
    """The WETTINGS entry of a configuration's bridges (pendular.procedures.config.BridgeConfig
    or None)."""
    if bridges is None:
        return "dry"
    return "suction" if bridges.water_content is None else "water_content"


def check_water(stage, wetting):
    """ValueError naming the key when ``stage`` changes water that a sample wetted as
    ``wetting`` (WETTINGS) does not hold that way."""
    if stage.suction is not None and wetting != "suction":
        raise ValueError(f"suction = {stage.suction:g} Pa needs a sample wetted at a suction "
                         "(--suction > 0: suction-controlled bridges)" + (
                             "; at --water-content give water_content [%]"
                             if wetting == "water_content" else ""))
    if stage.water_content is not None and wetting != "water_content":
        raise ValueError(f"water_content = {stage.water_content:g} % needs a sample wetted at "
                         "a water content (--water-content: a closed amount of liquid)" + (
                             "; at --suction give suction [Pa]" if wetting == "suction" else ""))


def check_suctions(config):
    """ValueError naming the table, the stage and ``suction`` when a stage's suction is outside
    the range of the bridge tables for the sample's radii (CapillaryBridges.set_suction),
    before anything runs. ``config``: a TablePathConfig."""
    stages = labelled_stages(config.stages, config.source, confining=config.sample.confining,
                             rate=1.0)
    asked = [(label, stage.suction) for label, stage in stages if stage.suction is not None]
    if not asked or config.bridges is None or config.bridges.suction is None:
        return
    from pendular.capillary import sample_radius_ratios

    radii = config.sample.radii()
    bridges = config.bridges.build()
    bridges.load_tables(float(radii.min()), float(radii.max()),
                        radius_ratios=sample_radius_ratios(radii))
    for label, value in asked:
        try:
            bridges.set_suction(value)
        except ValueError as error:
            raise ValueError(f"{config.source}: {label}: {error}") from None


def stage_stresses(stage):
    """[(name, stress [Pa])] of the stress targets of ``stage``: its servoed stresses, mean
    stress and stress end."""
    found = [(f"stress[{axis!r}]", value) for axis, value in stage.stress.items()]
    if stage.mean_stress is not None:
        found.append(("mean_stress", stage.mean_stress))
    if isinstance(stage.until, Stress):
        found.append(("until stress", stage.until.value))
    return found


def lowest_stress(entries, source, confining):
    """The lowest stress of a table's path [Pa], where its quasi-static rate is taken: of
    ``confining`` and every positive stress target of its stages (stage_stresses; they do
    not depend on the rate, so the stages are built at 1 1/s here)."""
    stages = build_stages(entries, source, confining=confining, rate=1.0)
    return min([confining] + [value for stage in stages for _, value in stage_stresses(stage)
                              if value > 0.0])


# ---------------------------------------------------------------- the test

class PathTest(LaboratoryTest):
    """The loading path of a table (``config``: pendular.procedures.path.TablePathConfig),
    on the sample and wetting of LaboratoryTest: history with ``void_ratio``, ``k0`` and
    ``stage`` (rows every ``record_strain``, or ``records`` rows over one stage ending at a
    strain as a triaxial's), summary of ``path_summary``; figure path.png (plot_path: the q-p
    and q'-p' stress paths, the stresses and strains against the history row)."""

    NAME = "path"
    CONFIG = TablePathConfig
    FIGURE = "path.png"
    PROGRESS = "stage"

    def __init__(self, config, *, force=False):
        super().__init__(config, force=force)
        check_suctions(config)

    def stages(self):
        return self.config.loading_stages()

    def loading(self, sim):
        config = self.config
        stages = config.loading_stages()
        columns = dict(PATH_COLUMNS)
        if any(stage.water_content is not None for stage in stages):
            bridges = capillary_operation(sim)
            columns.update({"water_content": lambda s: water_content(s, bridges) / 100.0,
                            "liquid_total": lambda s: bridges.liquid_initial})
        if len(stages) == 1:                  # LoadingPath names the stages of a longer path
            columns["stage"] = lambda s: 0
        return LoadingPath(sim, stages, records=config.records,
                           record_every=config.record_every(sim.dt), columns=columns)

    def summarize(self, history):
        stages = self.config.loading_stages()
        return {**path_summary(history, len(stages), stages), **stress_balance(history)}

    def plot(self, history, out, title):
        stages = len(self.config.loading_stages())
        label = (f"{os.path.basename(self.config.source)}, {stages} "
                 f"stage{'s' if stages > 1 else ''}")
        plot_path(history, os.path.join(out, self.FIGURE), f"{title}\n{label}")


def _diagonal(history, name):
    """(rows, 3) diagonal of a tensor column of ``history``, or None without it."""
    if name not in history:
        return None
    return np.diagonal(history[name], axis1=1, axis2=2)


#: Columns of a wet history each stage's end lists (path_summary).
WATER_COLUMNS = ("suction", "saturation", "water_content")


def wetting_strains(rows, stages, history):
    """The strains of the stages of a path (loading.Stage list ``stages``, their end rows
    ``rows`` of path_summary) that change its water: ``water_stages``, one entry per such
    stage (its index, ``suction_before`` and ``suction_after`` [Pa], or
    ``water_content_before`` and ``water_content_after`` [-, a fraction, as the history's
    column], the axial and volumetric strain changes over
    the stage, compression positive), and, when one of them wets the sample (the suction
    lowered, the water content raised), ``collapse_strain`` [-]: the volumetric strain of
    those stages (at a held stress, the collapse on wetting; positive a compression) and
    ``collapse_axial_strain`` [-]."""
    found, collapse, axial = [], 0.0, 0.0
    wets = False
    for number, (stage, row) in enumerate(zip(stages, rows)):
        key = ("suction" if stage.suction is not None else
               "water_content" if stage.water_content is not None else None)
        if key is None or key not in history:
            continue
        start = rows[number - 1]["row"] if number else 0
        was, now = float(history[key][start]), row[key]
        entry = {"stage": number, f"{key}_before": was, f"{key}_after": now,
                 "axial_strain_change": row["axial_strain_change"],
                 "volumetric_strain_change": row["volumetric_strain_change"]}
        found.append(entry)
        wetting = now < was if key == "suction" else now > was
        if wetting:
            wets = True
            collapse += entry["volumetric_strain_change"]
            axial += entry["axial_strain_change"]
    if not found:
        return {}
    summary = {"water_stages": found}
    if wets:
        summary.update({"collapse_strain": collapse, "collapse_axial_strain": axial})
    return summary


def path_summary(history, count=None, stages=None):
    """Results of a loading path's history (columns sigma_wall, axial_strain,
    volumetric_strain, void_ratio and, for several stages, stage) of ``count`` stages (None:
    those recorded): ``stages``, the end state of each (its row, step, axial and volumetric
    strain, void ratio, wall stresses sigma_wall [Pa], p and q [Pa]; wet, p' and q' of the
    effective stress, Eq. 3.43; a stage that ended at once, static already, ends where the
    one before did); ``initial_void_ratio`` and ``final_void_ratio``; ``has_peak``: whether
    the largest q of the path is a peak within a stage, past its first row and one that the
    stage went past (pendular.io.schema.peak_reached over its rows), and then ``peak_q``,
    ``p_at_peak``, ``axial_strain_at_peak``, ``phi_peak_deg`` (columns.friction_angle),
    ``peak_index``, ``peak_stage`` and, wet, ``peak_q_effective``, ``p_effective_at_peak``,
    ``phi_peak_effective_deg``. Each stage's entry also gives its ``axial_strain_change`` and
    ``volumetric_strain_change`` and, wet, the WATER_COLUMNS at its end; with the path's
    ``stages`` (loading.Stage), the strains of those that change the water
    (wetting_strains)."""
    sigma = history["sigma_wall"]
    stage = np.asarray(history.get("stage", np.zeros(len(sigma), dtype=np.int64)))
    count = int(stage[-1]) + 1 if count is None else count
    effective = _diagonal(history, "sigma_effective")
    p, q = mean_stress(sigma), deviator_stress(sigma)
    rows = []
    before = 0
    for number in range(count):
        row = int(np.flatnonzero(stage <= number)[-1])
        entry = {"stage": number, "row": row, "step": int(history["step"][row]),
                 "axial_strain": float(history["axial_strain"][row]),
                 "volumetric_strain": float(history["volumetric_strain"][row]),
                 "axial_strain_change": float(history["axial_strain"][row]
                                              - history["axial_strain"][before]),
                 "volumetric_strain_change": float(history["volumetric_strain"][row]
                                                   - history["volumetric_strain"][before]),
                 "void_ratio": float(history["void_ratio"][row]),
                 "sigma_wall": sigma[row].tolist(), "p": float(p[row]), "q": float(q[row])}
        if effective is not None:
            entry.update({"p_effective": float(mean_stress(effective[row])),
                          "q_effective": float(deviator_stress(effective[row]))})
        for name in WATER_COLUMNS:
            if name in history:
                entry[name] = float(history[name][row])
        rows.append(entry)
        before = row
    void = history["void_ratio"]
    summary = {"stages": rows, "initial_void_ratio": float(void[0]),
               "final_void_ratio": float(void[-1])}
    if stages is not None:
        summary.update(wetting_strains(rows, stages, history))
    peak = int(np.argmax(q))
    within = np.flatnonzero(stage == stage[peak])
    summary["has_peak"] = bool(q[peak] > 0.0 and peak > within[0]
                               and peak_reached(history["axial_strain"][within], q[within]))
    if not summary["has_peak"]:
        return summary
    summary.update({"peak_q": float(q[peak]), "p_at_peak": float(p[peak]),
                    "axial_strain_at_peak": float(history["axial_strain"][peak]),
                    "phi_peak_deg": float(friction_angle(sigma[peak])),
                    "peak_index": peak, "peak_stage": int(stage[peak])})
    if effective is not None:
        summary.update({"peak_q_effective": float(deviator_stress(effective[peak])),
                        "p_effective_at_peak": float(mean_stress(effective[peak])),
                        "phi_peak_effective_deg": float(friction_angle(effective[peak]))})
    return summary


# ---------------------------------------------------------------- composing in Python

def run_path(sim, stages, *, records=None, record_every=None, columns=None, progress=None,
             **options):
    """Run ``stages`` (loading.Stage) on the static scene ``sim`` as one loading.LoadingPath
    (``records``, ``record_every`` and the servo ``options`` are its own) recording also
    PATH_COLUMNS and ``columns``; returns its history (dict of arrays). The path's recorder
    and guard leave ``sim.writers`` at its end, so that paths, equilibria and suction changes
    (``change_suction``) follow one another on one scene."""
    writers = list(sim.writers)
    path = LoadingPath(sim, stages, records=records, record_every=record_every,
                       columns={**PATH_COLUMNS, **(columns or {})}, **options)
    try:
        path.run(sim, progress=progress)
    finally:
        sim.writers = writers
    return path.recorder.arrays()


def change_suction(sim, bridges, suction, *, stress, increments=4, max_velocity=None,
                   unbalanced=0.01, tolerance=0.01, max_steps=200000, progress=None):
    """Bring the suction of the suction-controlled ``bridges`` (capillary.CapillaryBridges in
    the forces of ``sim``) to ``suction`` [Pa] at a held stress: the walls of each axis of
    ``stress`` ({axis: Pa}) servoed at it (at most at ``max_velocity`` [m/s]; None: the
    scene's servo speed), those of the other axes fixed (e.g. {'z': sigma_v}: drying at a
    constant vertical stress, no lateral strain). The suction changes in ``increments`` steps
    of equal ratio, each run until static (equilibrium.equilibrate with ``unbalanced``,
    ``tolerance``, ``max_steps``). Returns the history of the state before and after each
    increment (columns.history_columns, strains from the start, with PATH_COLUMNS)."""
    if bridges.control != "suction":
        raise ValueError(f"control = {bridges.control!r}: change_suction needs "
                         "suction-controlled bridges (volume-controlled ones hold their liquid)")
    suction = check_positive("suction", suction, "Pa")
    held = Stage(stress=stress, strain_rate={a: 0.0 for a in AXIS_NAMES if a not in stress})
    increments = check_int("increments", increments, low=1)
    if max_velocity is None:
        servo = next((op for op in sim.controls if isinstance(op, StressServo)), None)
        max_velocity = servo.max_velocity if servo is not None else servo_speed(sim.walls,
                                                                                 sim.dt)
    if sim.contacts is None:
        sim.evaluate_forces()
    axial = AxisStrain(2, sim.walls.lengths()[2])
    recorder = HistoryRecorder(1, {**history_columns(sim, axial, sim.walls.volume(),
                                                     capillary_operation(sim)),
                                   **PATH_COLUMNS})
    recorder.record(sim)
    sim.controls = [StressServo(axis, target, max_velocity)
                    for axis, target in held.stress.items()]
    steps = np.geomspace(bridges.suction, suction, increments + 1)[1:]
    steps[-1] = suction
    for value in steps:
        bridges.set_suction(float(value))
        equilibrate(sim, unbalanced=unbalanced, tolerance=tolerance, max_steps=max_steps,
                    progress=progress, phase=f"equilibrium at suction {value:.4g} Pa")
        recorder.record(sim)
    return recorder.arrays()


# ---------------------------------------------------------------- the command


PATH_OWN = path_rate_options() + (option_of(TablePathConfig, "records"),)

#: The path table of ``pendular path``.
PATH_TABLE = Option("table", "the path table (not with --resume: the run keeps its own)",
                    kind=str, metavar="PATH.toml", positional=True)


def table_path_config(values, given):
    """The TablePathConfig of ``values`` and the path table (ValueError naming its file,
    entry and key)."""

    if values["table"] is None:
        raise ValueError("PATH.toml is missing: give the path table (or --resume DIR)")
    return TablePathConfig(**laboratory_fields(values, given, lambda: {
        **read_table(values["table"]), **fields_of(values, PATH_OWN)}))


#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular path examples/paths/oedometer_unload.toml --particles 1000 --out runs/path",
           "the stages of a TOML table run in turn: each stage's end state in summary.json, the "
           "stress path in plots/")

#: Summary keys printed at the end.
SHOWN = ("stages", "initial_void_ratio", "final_void_ratio", "has_peak", "peak_q", "p_at_peak",
         "axial_strain_at_peak", "phi_peak_deg", "peak_q_effective", "p_effective_at_peak",
         "phi_peak_effective_deg", "water_stages", "collapse_strain", "collapse_axial_strain",
         "initial_porosity", "wall_time_s", "particle_steps_per_s")

#: The path command (pendular.procedures.registry).
COMMAND = LaboratoryCommand(
    name="path",
    description="any loading path from a TOML table of stages, dry or wet",
    test=PathTest,
    declared=laboratory_options(PATH_OWN, framed(table_path_config), first=(PATH_TABLE,)),
    shown=SHOWN, example=EXAMPLE, out="runs/path")
