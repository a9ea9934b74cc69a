"""Each command's options, declared once, and the configuration they build.

``options_of(command)`` lists a command's options (pendular.utils.parameters.Option: key, flag,
default, kind, help with unit and range), made from the configuration fields' Parameters
(``option_of``) wherever an option sets a field; ``config_from_options(command, options)``
builds and checks the configuration from a flat mapping key -> value (the command line's parsed
options, a row of a campaign table, a Python dict); an option not given takes its declared
default, an option equal to its default counts as not given. Errors name the key
(OptionError, ParameterError); the command line names the flag instead (``on_command_line``).
The command line (pendular.cli) makes its parser from the same declarations and adds only how
a run is watched (output folder, threads, progress, resume).

    config = config_from_options("triaxial", {"particles": 300, "suction": 30000,
                                              "max_strain": 0.02})
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Callable

from pendular.dem.grading import MAX_RADIUS_RATIO, read_grading_curve
from pendular.procedures.config import (AXIAL_STRAIN_LIMIT, MAX_AXIAL_STRAIN,
    MAX_TENSION_PARTICLES, MIN_AXIAL_STRAIN, MIN_SAMPLE_PARTICLES, MIN_SIMPLE_SHEAR_PARTICLES,
    MIN_TENSION_PARTICLES, SPECIFIC_GRAVITY_PARAMETER, TENSION_RANGES, TENSION_SAMPLE,
    VOID_RATIO_PARAMETER, WATER_DENSITY, BridgeConfig, CyclicConfig, IsotropicConfig,
    LaboratoryConfig, OedometerConfig, PathConfig, ShearConfig, SimpleShearConfig, SwccConfig,
    TablePathConfig, TensionConfig, TriaxialConfig, check_steps_count, tension_sample)
from pendular.procedures.preparation import PrepareConfig
from pendular.procedures.reference import KIM_RADIUS, SPECIFIC_GRAVITY
from pendular.utils.parameters import (Option, OptionError, Parameter, ParameterError, fields_of,
    flag_of, option_from, option_of, option_values, spec_of)


def _options(config, names, **changes):
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
                + _options(PrepareConfig, ("confining", "seed", "periodic")))
_MATERIAL = _options(PrepareConfig, ("porosity", "friction_deg", "prep_friction_deg",
                                     "rolling_friction", "twisting_friction", "gravity",
                                     "wall_friction", "young", "contact", "poisson", "restitution", "damping",
                                     "timestep_safety", "timestep_rule", "skin_factor"))
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
BRIDGES = _options(BridgeConfig, ("contact_angle", "model", "surface_tension", "liquid",
                                   "wall_bridges"))
#: A wet laboratory test: at a suction or a water content.
WETTING = ((option_from(SUCTION, 0.0, checked=True),) + BRIDGES[:3]
           + (option_from(WATER_CONTENT, None, checked=True), *BRIDGES[3:],
              option_of(LaboratoryConfig, "wetting"), option_of(BridgeConfig, "persist"),
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
    if len(nodes) != 2 or min(nodes) < 4:
        raise OptionError(lambda name: f"{name('table_resolution')} {value!r}: two integers "
                                       "NS,ND, each in [4, inf), expected")
    return nodes


# ---------------------------------------------------------------- loading and outputs

def rate_options(config):
    """The loading rate of ``config`` (ShearConfig or PathConfig): an inertial number or a
    strain rate."""
    return _options(config, ("inertial_number", "strain_rate"))


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
            _steps_count("vtk_frames", frames, steps, "the loading")
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
    if values["liquid"] is not None and water is None:
        raise OptionError(lambda name: f"{name('liquid')} needs {name('water_content')}")
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
            **own}


def _steps_count(key, value, steps, phase, low=0):
    """ParameterError naming ``key`` when its count ``value`` exceeds the ``steps`` of
    ``phase`` (check_steps_count)."""
    try:
        check_steps_count(key, value, steps, phase, low)
    except ValueError as error:
        raise ParameterError(key, str(error), flag_of(key)) from None


# ---------------------------------------------------------------- the commands

#: A triaxial shear's own options.
SHEAR = (_options(ShearConfig, ("max_strain", "direction", "b", "constant_p", "drainage"))
         + rate_options(ShearConfig) + (option_of(ShearConfig, "records"),))


def axial_strain(strain):
    """The final axial strain ``strain`` of a triaxial shear (--max-strain); ParameterError
    outside [MIN_AXIAL_STRAIN, MAX_AXIAL_STRAIN], saying why (AXIAL_STRAIN_LIMIT)."""
    if not MIN_AXIAL_STRAIN <= strain <= MAX_AXIAL_STRAIN:              # NaN included
        raise ParameterError("max_strain", f"max_strain = {strain:g} is outside the valid "
                             f"range [{MIN_AXIAL_STRAIN:g}, {MAX_AXIAL_STRAIN:g}]: "
                             f"{AXIAL_STRAIN_LIMIT}", "--max-strain")
    return strain


def triaxial_config(values, given):
    """The TriaxialConfig of ``values`` (its shear's steps bounding --vtk-frames and
    --records)."""
    axial_strain(values["max_strain"])
    if values["records"] is not None:
        spec_of(ShearConfig, "records").check("records", values["records"])
    fields = laboratory_fields(values, given, lambda: ShearConfig(**fields_of(values, SHEAR)))
    frames = values["vtk_frames"]
    config = TriaxialConfig(**fields, **({} if frames is None else {"vtk_frames": frames}))
    # counts given beyond the shear's steps would silently give one a step (the defaults may)
    steps = config.shear_steps()
    phase = f"the shear to --max-strain {config.shear.max_strain:g}"
    if frames is not None:
        _steps_count("vtk_frames", frames, steps, phase)
    if values["records"] is not None:
        _steps_count("records", values["records"], steps, phase, low=2)
    return config


def path_command(kind, own, check=None):
    """The configuration builder of a loading path of dataclass ``kind`` (a PathConfig) whose
    own options are ``own``; ``check(values)`` first, when given."""
    def build(values, given):
        if check is not None:
            check(values)
        return kind(**laboratory_fields(values, given, lambda: fields_of(values, own)))
    return build


def amplitude_given(values):
    """OptionError unless one of the cyclic amplitudes is given."""
    if values["amplitude_q"] is None and values["amplitude_strain"] is None:
        raise OptionError(lambda name: f"give {name('amplitude_q')} PA (stress control) or "
                                       f"{name('amplitude_strain')} X (strain control)")


def table_path_config(values, given):
    """The TablePathConfig of ``values`` and the path table (ValueError naming its file,
    entry and key)."""
    from pendular.procedures.path_table import read_table

    if values["table"] is None:
        raise ValueError("PATH.toml is missing: give the path table (or --resume DIR)")
    return TablePathConfig(**laboratory_fields(values, given, lambda: {
        **read_table(values["table"]), **fields_of(values, PATH_OWN)}))


def simple_shear_config(values, given):
    """The SimpleShearConfig of ``values``: always in a periodic cell (walls cannot shear a
    sample)."""
    return SimpleShearConfig(**laboratory_fields({**values, "periodic": True}, given,
                                                 lambda: fields_of(values, SIMPLE_SHEAR_OWN)))


#: A simple shear's sample: always in a periodic cell, --periodic implied.
SIMPLE_SHEAR_SAMPLE = tuple(
    dataclasses.replace(option, default=True, help="a periodic cell, with Lees–Edwards images "
                                                   "(implied: walls cannot shear a sample)")
    if option.key == "periodic" else
    option_of(PrepareConfig, "particles", low=MIN_SIMPLE_SHEAR_PARTICLES)
    if option.key == "particles" else option for option in SAMPLE)


#: Each loading path's own options (its fields set by them as they are).
OEDOMETER_OWN = (_options(OedometerConfig, ("axial_stress", "unload_to"))
                 + rate_options(PathConfig) + (option_of(PathConfig, "record_strain"),))
ISOTROPIC_OWN = (_options(IsotropicConfig, ("stresses", "stage_steps"))
                 + rate_options(PathConfig) + (option_of(PathConfig, "record_strain"),))
CYCLIC_OWN = (tuple(dataclasses.replace(option, group="amplitude") for option in _options(
                  CyclicConfig, ("amplitude_q", "amplitude_strain")))
              + (option_of(CyclicConfig, "cycles"),) + rate_options(PathConfig)
              + (option_of(PathConfig, "record_strain"),))
SIMPLE_SHEAR_OWN = _options(SimpleShearConfig, ("normal_stress", "constant_volume",
                                                "max_strain", "inertial_number", "strain_rate",
                                                "record_strain", "stage_steps"))
PATH_OWN = (rate_options(PathConfig) + (option_of(PathConfig, "record_strain"),
                                        option_of(TablePathConfig, "records")))
#: The path table of ``pendular path``.
PATH_TABLE = Option("table", "the path table (not with --resume: the run keeps its own)",
                    kind=str, metavar="PATH.toml", positional=True)

# ---------------------------------------------------------------- direct tension

#: A direct tension's sample: Kim's sand by default (TENSION_SAMPLE), the tension's ranges.
TENSION_SAMPLE_OPTIONS = {
    "particles": option_of(PrepareConfig, "particles", default=TENSION_SAMPLE["particles"],
                           low=MIN_TENSION_PARTICLES, high=MAX_TENSION_PARTICLES),
    "confining": option_of(PrepareConfig, "confining", default=TENSION_SAMPLE["confining"],
                           low=TENSION_RANGES["confining"][0],
                           high=TENSION_RANGES["confining"][1],
                           help="isotropic stress of preparation and wetting"),
    "friction": option_of(PrepareConfig, "friction_deg",
                          help="contact friction during wetting and pull"),
    "young": option_of(PrepareConfig, "young", high=TENSION_RANGES["young"][1]),
    "seed": option_of(PrepareConfig, "seed", help="random seed of the samples"),
    "periodic": option_of(PrepareConfig, "periodic",
                          help="a periodic cell instead of six walls: no grips, the cell pulled "
                               "along z at zero lateral stress; the void ratio is the whole "
                               "cell's"),
}
#: A direct tension's sizes: Kim's radius by default, the tension's range.
TENSION_SIZES = size_options(default=KIM_RADIUS, low=TENSION_RANGES["radius"][0],
                             high=TENSION_RANGES["radius"][1])
#: The cases of a direct tension: every water content [%] at every void ratio.
TENSION_VOID_RATIO = option_from(dataclasses.replace(
    VOID_RATIO_PARAMETER, help="void ratio(s) of the core, comma separated (default: Kim's "
                               "0.72, 0.58)"), None, many=True, distinct=True)
TENSION_WATER_CONTENT = option_from(dataclasses.replace(
    WATER_CONTENT, low=None, high=None,
    help="gravimetric water content(s), comma separated, each at most the pendular limit of "
         "its void ratio's packing (default: Kim's for his void ratios, else 0.5,1,2)"),
    None, many=True, distinct=True)
#: A direct tension's own fields set by their options as they are.
TENSION_OWN = {name: option_of(TensionConfig, name) for name in (
    "roughness", "form_gap", "contact_angle", "surface_tension", "inertial_number",
    "max_strain", "residual", "grip_depth", "void_ratio_tolerance")}
TENSION_FRAMES = (dataclasses.replace(option_of(TensionConfig, "vtk_frames"), group="frames"),
                  dataclasses.replace(option_of(TensionConfig, "vtk_every"), least=0,
                                      group="frames"))
#: A direct tension's options, in the order of its help.
TENSION = ((TENSION_VOID_RATIO, TENSION_OWN["roughness"], TENSION_WATER_CONTENT,
            TENSION_SAMPLE_OPTIONS["particles"], TENSION_OWN["form_gap"])
           + TENSION_SIZES
           + (TENSION_OWN["contact_angle"], TENSION_OWN["surface_tension"],
              option_from(SPECIFIC_GRAVITY_PARAMETER, SPECIFIC_GRAVITY),
              TENSION_SAMPLE_OPTIONS["confining"], TENSION_SAMPLE_OPTIONS["friction"],
              TENSION_SAMPLE_OPTIONS["young"])
           + tuple(TENSION_OWN[name] for name in ("inertial_number", "max_strain", "residual",
                                                  "grip_depth", "void_ratio_tolerance"))
           + TENSION_FRAMES + (CHECKPOINT_EVERY, TENSION_SAMPLE_OPTIONS["seed"],
                               TENSION_SAMPLE_OPTIONS["periodic"]))


def tension_config(values, given):
    """The TensionConfig of ``values``: its cases every water content [%] at every void ratio
    (pendular.procedures.tension.cases_of), the sample's density from the specific gravity."""
    from pendular.procedures.tension import cases_of

    cases = cases_of(values["void_ratio"], values["water_content"])
    depth = values["grip_depth"]
    if values["periodic"] and depth is not None:
        raise OptionError(lambda name: f"{name('grip_depth')} = {depth:g} does not apply to "
                                       f"{name('periodic')}: a periodic cell has no walls, so "
                                       "no grips")
    sample = tension_sample(**fields_of(values, TENSION_SAMPLE_OPTIONS.values()),
                            **sample_sizes(values),
                            density=values["specific_gravity"] * WATER_DENSITY)
    return TensionConfig(sample=sample, cases=cases,
                         **fields_of(values, (*TENSION_OWN.values(), *TENSION_FRAMES)))


# ---------------------------------------------------------------- SWCC

#: An SWCC's sample (1,000 spheres by default), own fields and material.
SWCC_SAMPLE = (option_of(PrepareConfig, "particles", default=1000, low=MIN_SAMPLE_PARTICLES),
               option_of(PrepareConfig, "confining"))
SWCC_OWN = _options(SwccConfig, ("suctions", "contact_angle", "surface_tension", "form_gap",
                                 "stage_steps", "record_every"))
SWCC_MATERIAL = _options(PrepareConfig, ("friction_deg", "prep_friction_deg", "seed"))


def swcc_config(values, given):
    """The SwccConfig of ``values``."""
    sample = PrepareConfig(**fields_of(values, SWCC_SAMPLE + SWCC_MATERIAL),
                           **sample_sizes(values))
    return SwccConfig(sample=sample, **fields_of(values, SWCC_OWN))


# ---------------------------------------------------------------- the declarations

@dataclass(frozen=True)
class CommandOptions:
    """A command's ``options`` (in the order its help lists them) and ``build(values,
    given)``, its configuration of the options' values (every key) and the keys given (not at
    their defaults)."""

    options: tuple
    build: Callable


def _laboratory(own, build, frames=False, first=(), sample=SAMPLE):
    """A laboratory test's options: ``first``, the ``sample``'s, the wetting's, ``own``, the
    outputs'."""
    return CommandOptions(first + sample + WETTING + own + output_options(frames), build)


COMMANDS = {
    "triaxial": _laboratory(SHEAR, triaxial_config, frames=True),
    "oedometer": _laboratory(OEDOMETER_OWN, framed(path_command(OedometerConfig,
                                                                OEDOMETER_OWN))),
    "isotropic": _laboratory(ISOTROPIC_OWN, framed(path_command(IsotropicConfig,
                                                                ISOTROPIC_OWN))),
    "simple-shear": _laboratory(SIMPLE_SHEAR_OWN, framed(simple_shear_config),
                                sample=SIMPLE_SHEAR_SAMPLE),
    "cyclic": _laboratory(CYCLIC_OWN, framed(path_command(CyclicConfig, CYCLIC_OWN,
                                                          check=amplitude_given))),
    "path": _laboratory(PATH_OWN, framed(table_path_config), first=(PATH_TABLE,)),
    "tension": CommandOptions(TENSION, tension_config),
    "swcc": CommandOptions(SWCC_SAMPLE + SWCC_OWN + size_options() + SWCC_MATERIAL
                           + (CHECKPOINT_EVERY,), swcc_config),
}


def options_of(command):
    """The Options of ``command`` (a key of COMMANDS), in the order its help lists them."""
    if command not in COMMANDS:
        raise ValueError(f"command = {command!r} builds no configuration; valid: "
                         f"{', '.join(COMMANDS)}")
    return COMMANDS[command].options


def config_from_options(command, options=None):
    """The checked configuration of ``command`` (a key of COMMANDS) from ``options``: option
    key -> value (a number or its text, a flag's bool, a list or comma text of a list); keys
    not given, or given None, take their declared defaults. OptionError or ParameterError
    naming the key (``on_command_line``: the flag), ValueError naming the file of a path
    table or grading curve."""
    values, given = option_values(options_of(command), options, command)
    try:
        return COMMANDS[command].build(values, given)
    except ParameterError as error:
        raise ParameterError(error.key, error.named(error.key), error.flag) from None
