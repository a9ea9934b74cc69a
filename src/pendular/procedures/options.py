"""The options the laboratory commands share, declared once, and how they build a configuration.

The sample (``SAMPLE``, ``size_options``), its wetting (``WETTING``), the rate
(``rate_options``) and the outputs (``output_options``) of every laboratory test, made from
the configuration fields' Parameters (``option_of``); ``laboratory_fields`` builds a
LaboratoryConfig's fields from their values, checking what spans several options. Each
test's module declares its own options and its ``build(values, given)`` with them
(``CommandOptions``; pendular.procedures.registry lists the tests, and its
``config_from_options(command, options)`` builds a configuration from a flat mapping key ->
value: the command line's parsed options, a row of a campaign table, a Python dict). An
option not given takes its declared default, an option equal to its default counts as not
given. Errors name the key (OptionError, ParameterError); the command line names the flag
instead (``on_command_line``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Callable

from pendular.dem.grading import MAX_RADIUS_RATIO, read_grading_curve
from pendular.procedures.config import (BridgeConfig, LaboratoryConfig, MIN_SAMPLE_PARTICLES,
    MIN_TABLE_NODES, PathConfig, ShearConfig, check_steps_count)
from pendular.procedures.preparation import PrepareConfig
from pendular.utils.parameters import (Option, OptionError, Parameter, ParameterError, fields_of,
    flag_of, option_from, option_of, spec_of)


def options_named(config, names, **changes):
    """The Options of fields ``names`` of ``config`` (option_of, each with ``changes``)."""
    return tuple(option_of(config, name, **changes) for name in names)


# ---------------------------------------------------------------- the sample

def size_options(**radius):
    """The sizes of a sample (pendular.dem.grading): --radius (``radius``: option_of's
    settings of its field, e.g. a command's default), --radius-spread, --psd."""
    return (option_of(PrepareConfig, "radius", unset=True, **radius),
            option_of(PrepareConfig, "radius_spread",
                      help="radii uniform in R(1 ± S), R = --radius (0: equal spheres; a "
                           f"radius ratio of at most {MAX_RADIUS_RATIO:g})"),
            Option("psd", "grading curve, CSV rows 'diameter [m], percent passing by mass' "
                          "from 0 to 100 % (a sieve analysis); sets the sizes instead of "
                          "--radius", kind=str, metavar="FILE"))


def sample_sizes(values):
    """The size fields of a PrepareConfig (radius_spread, radius and psd where given) of
    ``values`` of size_options; the grading curve read from its file."""
    if values["psd"] is not None and values["radius"] is not None:
        raise OptionError(lambda name: f"{name('radius')} and {name('psd')}: give one (the "
                                       "grading curve sets the sizes)")
    sizes = {"radius_spread": values["radius_spread"]}
    if values["radius"] is not None:
        sizes["radius"] = values["radius"]
    if values["psd"] is not None:
        sizes["psd"] = read_grading_curve(values["psd"])
    return sizes


_SAMPLE_CELL = ((option_of(PrepareConfig, "particles", low=MIN_SAMPLE_PARTICLES),)
                + options_named(PrepareConfig, ("confining", "seed", "periodic")))
_MATERIAL = options_named(PrepareConfig, ("porosity", "friction_deg", "prep_friction_deg",
                                          "rolling_friction", "twisting_friction", "gravity",
                                          "wall_friction", "young", "contact", "poisson",
                                          "restitution", "wall_young", "wall_poisson",
                                          "wall_restitution", "wall_rolling_friction",
                                          "wall_twisting_friction", "damping",
                                          "timestep_safety",
                                          "timestep_rule", "skin_factor"))
#: A laboratory test's PrepareConfig fields set by their options as they are (sizes apart).
PREPARATION = _SAMPLE_CELL + _MATERIAL
#: A laboratory test's sample: its preparation, sizes and material, or a prepared --sample.
SAMPLE = (_SAMPLE_CELL + size_options() + _MATERIAL
          + (option_of(LaboratoryConfig, "sample_path"),))
#: Options of the preparation alone, which a run from a prepared --sample does not use.
PREPARATION_OPTIONS = ("porosity", "prep_friction")

# ---------------------------------------------------------------- wetting

#: The suction of a laboratory test's bridges, 0 for a dry test.
SUCTION = dataclasses.replace(spec_of(BridgeConfig, "suction"), low_inclusive=True,
                              help="matric suction (0: dry)")
#: The water content of a laboratory test's bridges, in percent of the grains' mass (the
#: configuration holds the fraction).
WATER_CONTENT = Parameter("%", "gravimetric water content held by volume-controlled bridges "
                          "at constant liquid volume, instead of --suction", 0.0, 100.0,
                          low_inclusive=False, flag="--water-content")
#: The bridges' own fields set by their options as they are, at a suction or a water content.
BRIDGES = options_named(BridgeConfig, ("contact_angle", "model", "surface_tension", "liquid",
                                       "wall_bridges"))
#: A wet laboratory test: at a suction or a water content.
WETTING = ((option_from(SUCTION, 0.0, checked=True),) + BRIDGES[:3]
           + (option_from(WATER_CONTENT, None, checked=True), *BRIDGES[3:],
              option_of(LaboratoryConfig, "wetting"), option_of(LaboratoryConfig, "liquid"),
              option_of(LaboratoryConfig, "entry_suction"),
              option_of(BridgeConfig, "persist"),
              option_of(LaboratoryConfig, "wet_steps"),
              option_of(BridgeConfig, "table_resolution", metavar="NS,ND",
                        help="bridge table nodes in suction and in distance (exact default "
                             "350,80; toroidal 64,80)")))
#: Wetting options, each refused without a wet test when given (not at its default).
WET_ONLY = ("contact_angle", "table_resolution", "bridges", "surface_tension",
            "persist_bridges", "wetting", "wall_bridges")


def table_resolution(value):
    """(nodes in suction, nodes in distance) of --table-resolution 'NS,ND' (or a list), or
    None."""
    if value is None:
        return None
    try:
        nodes = tuple(int(v) for v in (value.split(",") if isinstance(value, str) else value))
    except (TypeError, ValueError):
        nodes = ()
    if len(nodes) != 2 or min(nodes) < MIN_TABLE_NODES:
        raise OptionError(lambda name: f"{name('table_resolution')} {value!r}: two integers "
                                       f"NS,ND, each in [{MIN_TABLE_NODES}, inf), expected")
    return nodes


# ---------------------------------------------------------------- loading and outputs

def rate_options(config):
    """The loading rate of ``config`` (ShearConfig or PathConfig): an inertial number or a
    strain rate."""
    return options_named(config, ("inertial_number", "strain_rate"))


def path_rate_options():
    """What every loading path command sets of its PathConfig: its rate (rate_options) and
    the strain between its history records (record_strain)."""
    return rate_options(PathConfig) + (option_of(PathConfig, "record_strain"),)


#: Steps between checkpoints of a run (every command that resumes: the laboratory tests,
#: tension, swcc; a run setting of the last two, not a field of their configurations, so
#: checked as it is read).
CHECKPOINT_EVERY = dataclasses.replace(option_of(
    LaboratoryConfig, "checkpoint_every", checked=True,
    help="steps between checkpoints DIR/checkpoint.h5 (0: none)"), least=0)


def output_options(frames):
    """ParaView frames (--vtk-every or --vtk-frames; ``frames``: the loading's length is known
    before it runs, else --vtk-frames takes its estimate, or 0 alone: ``framed``) and
    checkpoints of a laboratory test."""
    every = dataclasses.replace(option_of(
        LaboratoryConfig, "vtk_every",
        help="steps between ParaView frames of the loading (default: " + (
            f"about {LaboratoryConfig.vtk_frames} frames" if frames else
            f"about {LaboratoryConfig.vtk_frames} frames over a loading whose length is "
            "estimated before it runs, else a frame every 10 history rows") + "; 0: no "
            "ParaView output)"),
        least=0, group="frames")
    count = dataclasses.replace(option_of(
        LaboratoryConfig, "vtk_frames", unset=True,
        help="ParaView frames over the loading (0: none; at most one a step; " + (
            "" if frames else "a path whose stages end at a stress or at equilibrium takes "
            "0 only; ") + "instead of --vtk-every"), least=0, group="frames")
    return every, count, CHECKPOINT_EVERY


def framed(build):
    """The configuration builder ``build`` of a loading path with --vtk-frames: spread over
    the loading's estimated length (estimated_steps: a simple shear, a strain-controlled
    cyclic test), 0 for no frames; OptionError naming it for other frames on a path of
    unknown length (its stages end at a stress or at equilibrium)."""
    def build_framed(values, given):
        config = build(values, given)
        frames = values["vtk_frames"]
        if frames is None:
            return config
        steps = config.estimated_steps()
        if steps is None and frames > 0:
            raise OptionError(lambda name: (
                f"{name('vtk_frames')} {frames}: this path's length is not known before it "
                "runs (its stages end at a stress or at equilibrium), so frames cannot be "
                f"spread over it; give {name('vtk_every')} STEPS, or {name('vtk_frames')} 0 "
                "for none"))
        if steps is not None:
            steps_count("vtk_frames", frames, steps, "the loading")
        return dataclasses.replace(config, vtk_frames=frames)
    return build_framed


def laboratory_fields(values, given, path):
    """The fields of a LaboratoryConfig from ``values`` of SAMPLE, WETTING and output_options
    (``given``: the keys not at their defaults), with the path's own, built by ``path()``
    after the sample and before the bridges: a ShearConfig or the path's fields as a dict.
    OptionError naming the options for a wetting option without a wet test, a preparation
    option with --sample."""
    suction, water = values["suction"], values["water_content"]
    if water is not None and suction > 0.0:
        raise OptionError(lambda name: f"{name('suction')} and {name('water_content')}: give "
                                       "one (at a water content the suction is an output)")
    if water is not None and (values["bridges"] == "toroidal" or values["persist_bridges"]):
        raise OptionError(lambda name: f"{name('water_content')} uses volume-controlled exact "
                                       f"bridges: {name('bridges')} toroidal and "
                                       f"{name('persist_bridges')} do not apply")
    if values["rupture_liquid"] is not None and water is None:
        raise OptionError(lambda name: f"{name('rupture_liquid')} needs "
                                       f"{name('water_content')}")
    wet_only = [key for key in WET_ONLY if key in given]
    if suction == 0.0 and water is None and wet_only:
        raise OptionError(lambda name: f"{', '.join(map(name, wet_only))} need(s) a wet test: "
                                       f"give {name('suction')} > 0")
    if values["sample"] is not None:
        preparation = [key for key in PREPARATION_OPTIONS if key in given]
        if preparation:
            raise OptionError(lambda name: f"{', '.join(map(name, preparation))} do(es) not "
                              f"apply with {name('sample')} {values['sample']}: the sample is "
                              "already prepared (only its equilibrium and the loading run); "
                              f"leave out {name('sample')} to prepare one")
    sample = PrepareConfig(**fields_of(values, PREPARATION), **sample_sizes(values))
    own = path()
    own = {"shear": own} if isinstance(own, ShearConfig) else own
    bridges = None
    options = {**fields_of(values, BRIDGES),
               "table_resolution": table_resolution(values["table_resolution"])}
    if suction > 0.0:
        bridges = BridgeConfig(suction, persist=values["persist_bridges"], **options)
    elif water is not None:
        bridges = BridgeConfig(water_content=water / 100.0, control="volume", **options)
    return {"sample": sample, "bridges": bridges, "sample_path": values["sample"],
            "wet_steps": values["wet_steps"], "vtk_every": values["vtk_every"],
            "checkpoint_every": values["checkpoint_every"], "wetting": values["wetting"],
            "liquid": values["liquid"], "entry_suction": values["entry_suction"],
            **own}


def steps_count(key, value, steps, phase, low=0):
    """ParameterError naming ``key`` when its count ``value`` exceeds the ``steps`` of
    ``phase`` (check_steps_count)."""
    try:
        check_steps_count(key, value, steps, phase, low)
    except ValueError as error:
        raise ParameterError(key, str(error), flag_of(key)) from None


# ---------------------------------------------------------------- the commands


def path_command(kind, own, check=None):
    """The configuration builder of a loading path of dataclass ``kind`` (a PathConfig) whose
    own options are ``own``; ``check(values)`` first, when given."""
    def build(values, given):
        if check is not None:
            check(values)
        return kind(**laboratory_fields(values, given, lambda: fields_of(values, own)))
    return build


# ---------------------------------------------------------------- direct tension


# ---------------------------------------------------------------- SWCC


# ---------------------------------------------------------------- the declarations

@dataclass(frozen=True)
class CommandOptions:
    """A command's ``options`` (in the order its help lists them) and ``build(values,
    given)``, its configuration of the options' values (every key) and the keys given (not at
    their defaults)."""

    options: tuple
    build: Callable


def laboratory_options(own, build, frames=False, first=(), sample=SAMPLE):
    """A laboratory test's options: ``first``, the ``sample``'s, the wetting's, ``own``, the
    outputs'."""
    return CommandOptions(first + sample + WETTING + own + output_options(frames), build)


