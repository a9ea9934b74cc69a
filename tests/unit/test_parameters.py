"""Parameters declared once (pendular.utils.parameters): a field's metadata drives its
validation, its option (pendular.procedures.options), its flat key and its unit; the command
line and Python build the same configuration from the same options; errors name the field in
Python, the key in tables and options given by key, and the flag on the command line."""

import dataclasses
import math

import pytest

from pendular.cli import command_parser, main
from pendular.io.schema import OPTION_UNITS
from pendular.procedures.registry import COMMANDS, config_from_options, options_of
from pendular.studies.campaign import sweep_from_table
from pendular.procedures.config import BridgeConfig, LaboratoryConfig, PathConfig, ShearConfig
from pendular.procedures.cyclic import CyclicConfig
from pendular.procedures.isotropic import IsotropicConfig
from pendular.procedures.oedometer import OedometerConfig
from pendular.procedures.simple_shear import SimpleShearConfig
from pendular.procedures.swcc import SwccConfig
from pendular.procedures.path import TablePathConfig
from pendular.procedures.tension import TensionConfig, tension_sample
from pendular.procedures.triaxial import TriaxialConfig
from pendular.procedures.preparation import MAX_PARTICLES, PrepareConfig
from pendular.utils.parameters import (Option, OptionError, Parameter, ParameterError,
    default_of, option_from, option_values, parameters_of, spec_of, validate)
from pendular.cli.commands import chapter4 as chapter4_command
from pendular.studies import chapter5, crosscheck, envelope, extremes, tradeoff

#: (config, field, low, high, low inclusive, high inclusive)
BOUNDS = [
    (PrepareConfig, "porosity", 0.30, 0.60, True, True),
    (PrepareConfig, "damping", 0.0, 1.0, True, False),
    (PrepareConfig, "timestep_safety", 0.0, 1.0, False, True),
    (PrepareConfig, "friction_deg", 0.0, 90.0, True, False),
    (PrepareConfig, "particles", 2, MAX_PARTICLES, True, True),
    (ShearConfig, "inertial_number", 0.0, 1.0, False, True),
    (BridgeConfig, "contact_angle", 0.0, 90.0, True, False),
]
#: The options of ``pendular triaxial`` made from their fields' metadata.
GENERATED = {"particles", "confining", "seed", "periodic", "radius", "radius_spread",
             "porosity", "friction", "prep_friction", "rolling_friction", "twisting_friction",
             "gravity", "wall_friction", "young", "contact", "poisson", "restitution", "wall_young",
             "wall_poisson", "wall_restitution", "wall_rolling_friction",
             "wall_twisting_friction", "damping",
             "timestep_safety",
             "timestep_rule", "skin_factor", "sample", "contact_angle", "bridges",
             "surface_tension", "rupture_liquid", "wall_bridges", "wetting", "liquid",
             "entry_suction", "persist_bridges",
             "wet_steps",
             "table_resolution", "max_strain", "direction", "b", "constant_p", "drainage",
             "inertial_number", "strain_rate", "records", "vtk_every", "vtk_frames",
             "checkpoint_every"}
LOADING_COMMANDS = ("triaxial", "oedometer", "isotropic", "path", "cyclic", "simple-shear")
#: The sample, wetting and output options every laboratory command shares (generated on the
#: triaxial).
LABORATORY = GENERATED - {"max_strain", "direction", "b", "constant_p", "drainage", "records",
                          "inertial_number", "strain_rate"}
RATE = {"inertial_number", "strain_rate"}
SIZES = {"radius", "radius_spread"}
#: Each command's own options made from their fields' metadata: an option written by hand
#: instead would be missing.
OWN_GENERATED = {
    "oedometer": {"axial_stress", "unload_to", "record_strain"} | RATE,
    "isotropic": {"stresses", "stage_steps", "record_strain"} | RATE,
    "cyclic": {"amplitude_q", "amplitude_strain", "cycles", "record_strain"} | RATE,
    "path": {"record_strain", "records"} | RATE,
    "simple-shear": {"normal_stress", "constant_volume", "max_strain", "inertial_number",
                     "shear_rate", "record_strain", "stage_steps"},
    "tension": {"roughness", "form_gap", "contact_angle", "surface_tension", "inertial_number",
                "max_strain", "residual", "grip_depth", "void_ratio_tolerance", "vtk_frames",
                "vtk_every", "checkpoint_every", "particles", "confining", "friction",
                "young", "seed", "periodic", "liquid", "entry_suction"} | SIZES,
    "swcc": {"particles", "confining", "suctions", "contact_angle", "surface_tension",
             "form_gap", "stage_steps", "record_every", "friction", "prep_friction",
             "seed", "checkpoint_every", "liquid", "entry_suction"} | SIZES,
}
#: Options whose default is the command's own, not its field's (the field's otherwise).
COMMAND_DEFAULTS = {("tension", "particles"), ("tension", "confining"), ("swcc", "particles"),
                    ("simple-shear", "periodic")}
#: Configurations whose every field declares a Parameter, but their nested configurations.
DECLARED = (PrepareConfig, ShearConfig, BridgeConfig, LaboratoryConfig, PathConfig,
            OedometerConfig, IsotropicConfig, CyclicConfig, TablePathConfig, SimpleShearConfig,
            TensionConfig, SwccConfig)
NESTED = {"sample", "bridges", "shear"}


def build(config, name, value):
    """``config`` with field ``name`` = ``value`` (the bridges at a suction)."""
    return config(**({"suction": 1e4} if config is BridgeConfig else {}), **{name: value})


def nudge(value, up):
    """The next float (integer) above or below ``value``."""
    if isinstance(value, int):
        return value + (1 if up else -1)
    return math.nextafter(value, math.inf if up else -math.inf)


@pytest.mark.parametrize("config, name, low, high, low_inclusive, high_inclusive", BOUNDS)
def test_the_metadata_bounds_are_the_validation_bounds(config, name, low, high, low_inclusive,
                                                       high_inclusive):
    spec = spec_of(config, name)
    assert (spec.low, spec.high, spec.low_inclusive, spec.high_inclusive) == (
        low, high, low_inclusive, high_inclusive)
    for bound, inclusive, outward in ((low, low_inclusive, False), (high, high_inclusive, True)):
        if inclusive:
            assert getattr(build(config, name, bound), name) == bound
        else:
            with pytest.raises(ParameterError, match=rf"^{name} = .* is outside the valid range"):
                build(config, name, bound)
        inside = nudge(bound, not outward)
        assert getattr(build(config, name, inside), name) == inside
        with pytest.raises(ParameterError) as refused:
            build(config, name, nudge(bound, outward))
        assert refused.value.name == name and str(refused.value).startswith(f"{name} = ")


def test_validate_converts_and_refuses_by_kind():
    sample = PrepareConfig(particles=300.0, seed=3)
    assert type(sample.particles) is int and sample.particles == 300
    with pytest.raises(ParameterError, match=r"^timestep_rule = 'fast' is not one of"):
        PrepareConfig(timestep_rule="fast")
    with pytest.raises(ParameterError, match=r"^periodic = 'yes': valid values True or False"):
        PrepareConfig(periodic="yes")
    sample.damping = math.nan                   # validate checks an existing instance too
    with pytest.raises(ParameterError, match=r"^damping = nan is not finite"):
        validate(sample)


def test_python_names_the_field_and_the_command_line_the_flag(capsys):
    with pytest.raises(ParameterError, match=r"^friction_deg = 95.0 deg is outside the valid "
                                             r"range \[0, 90\) deg$"):
        PrepareConfig(friction_deg=95.0)
    with pytest.raises(ParameterError, match=r"^particles = 20 is outside the valid range "
                                             r"\[50, "):
        TriaxialConfig(sample=PrepareConfig(particles=20))
    for argv, expected in (("--friction=95", "--friction = 95.0 deg is outside"),
                           ("--particles=20", "--particles = 20 is outside the valid range [50, "),
                           ("--inertial-number=2", "--inertial-number = 2.0 is outside the valid "
                                                   "range (0, 1]")):
        with pytest.raises(SystemExit) as stop:
            main(["triaxial", argv])
        assert stop.value.code == 2
        line = capsys.readouterr().err.strip()
        assert line.startswith("pendular triaxial: error: " + expected), line
        assert "\n" not in line


def test_a_table_names_its_key(tmp_path):
    table = tmp_path / "t.toml"
    table.write_text('command = "triaxial"\n[fixed]\nparticles = 60\n[sweep]\n'
                     'prep_friction = [0.5, 95]\n')
    with pytest.raises(ValueError, match=r"prep_friction = 95 \(\[sweep\]\): prep_friction = "
                                         r"95.0 deg is outside the valid range \[0, 90\) deg"):
        sweep_from_table(table)


@pytest.mark.parametrize("command", LOADING_COMMANDS + ("tension", "swcc"))
def test_generated_options_hold_the_dataclass_defaults(command):
    parser, _ = command_parser(command)
    generated = [action for action in parser._actions if hasattr(action, "parameter")]
    if command == "triaxial":       # an option written by hand instead would be missing here
        assert {action.dest for action in generated} == GENERATED
    else:
        shared = LABORATORY if command in LOADING_COMMANDS else set()
        assert {action.dest for action in generated} == shared | OWN_GENERATED[command]
    declared = {option.key: option for option in options_of(command)}
    for action in generated:
        config, name = action.parameter
        spec = spec_of(config, name)
        option = declared[action.dest]
        assert action.option_strings == [spec.flag] == [option.flag]
        if (command, action.dest) not in COMMAND_DEFAULTS:     # None: the field's default
            assert option.default in (None, default_of(config, name)), spec.flag
        shown = option.default if not spec.many else ",".join(f"{v:g}" for v in option.default)
        assert action.default == shown, spec.flag         # the command line's is the declared
        if spec.choices is not None:
            assert tuple(action.choices) == spec.choices
        elif spec.kind in (int, float) and not spec.many and option.least is None:
            assert action.type is spec.kind


def test_help_states_units_and_ranges():
    parser, _ = command_parser("triaxial")
    text = parser.format_help()
    for action in parser._actions:
        if not hasattr(action, "parameter"):
            continue
        spec = spec_of(*action.parameter)
        if spec.kind is float:
            unit = "-" if spec.unit == "1" else spec.unit
            assert f"[{unit}], valid range {spec.valid_range()}" in " ".join(
                parser._get_formatter()._expand_help(action).split()), spec.flag
    assert "[Pa], valid range [0, 1e+07]" in " ".join(text.split())     # --confining


def test_option_units_follow_the_metadata():
    for config in DECLARED:
        for item, spec in parameters_of(config):
            if spec.recorded and spec.kind in (int, float) and spec.key(item.name) in OPTION_UNITS:
                assert OPTION_UNITS[spec.key(item.name)] == spec.unit, item.name
    for item, spec in parameters_of(PrepareConfig) + parameters_of(ShearConfig):
        if spec.recorded and spec.kind in (int, float):
            assert spec.key(item.name) in OPTION_UNITS, item.name


def test_every_field_of_the_configurations_declares_a_parameter():
    for config in DECLARED:
        assert [item.name for item in dataclasses.fields(config) if item.name not in NESTED] == [
            item.name for item, _ in parameters_of(config)], config.__name__


SMALL = PrepareConfig(particles=100)


@pytest.mark.parametrize("command, argv, expected", [
    ("oedometer", [], OedometerConfig()),
    ("isotropic", [], IsotropicConfig()),
    ("simple-shear", [], SimpleShearConfig(sample=PrepareConfig(periodic=True))),
    ("cyclic", ["--amplitude-q=300"], CyclicConfig(amplitude_q=300.0)),
    ("tension", [], TensionConfig()),
    ("swcc", [], SwccConfig(sample=PrepareConfig(particles=1000))),
])
def test_the_default_command_line_builds_the_dataclass_defaults(command, argv, expected):
    parser, module = command_parser(command)
    assert module.config_from(parser.parse_args(argv)) == expected
    given = {"amplitude_q": 300} if argv else {}            # as a table or Python gives it
    assert config_from_options(command, given) == expected


#: (command, option, value, the configuration refusing the field's value, field, its message)
REFUSED = [
    ("oedometer", "--axial-stress", "500", lambda: OedometerConfig(sample=SMALL,
                                                                   axial_stress=500.0),
     "axial_stress", "= 500 Pa is outside the valid range (750, 1e+07] Pa"),
    ("oedometer", "--unload-to", "0", lambda: OedometerConfig(sample=SMALL, unload_to=0.0),
     "unload_to", "= 0.0 Pa is outside the valid range (0, 1e+07] Pa"),
    ("isotropic", "--stage-steps", "0", lambda: IsotropicConfig(sample=SMALL, stage_steps=0),
     "stage_steps", "= 0 is outside the valid range [1, 100000000]"),
    ("cyclic", "--cycles", "0", lambda: CyclicConfig(sample=SMALL, amplitude_q=100.0,
                                                     cycles=0),
     "cycles", "= 0 is outside the valid range [1, 10000]"),
    ("simple-shear", "--shear-rate", "-1", lambda: SimpleShearConfig(
        sample=PrepareConfig(particles=100, periodic=True), strain_rate=-1.0),
     "strain_rate", "= -1.0 1/s is outside the valid range (0, 1e+06] 1/s"),
    ("tension", "--residual", "1", lambda: TensionConfig(residual=1.0),
     "residual", "= 1.0 is outside the valid range (0, 1)"),
    ("tension", "--specific-gravity", "0.5", lambda: TensionConfig(
        sample=tension_sample(density=500.0)),
     "specific_gravity", "= 0.5 is outside the valid range [1, 10]"),
    ("swcc", "--record-every", "0", lambda: SwccConfig(sample=SMALL, record_every=0),
     "record_every", "= 0 is outside the valid range [1, inf]"),
]


@pytest.mark.parametrize("command, option, value, build, name, message", REFUSED)
def test_errors_name_the_field_in_python_and_the_flag_on_the_command_line(
        command, option, value, build, name, message, capsys):
    with pytest.raises(ParameterError) as refused:
        build()
    assert str(refused.value).startswith(f"{name} {message}"), str(refused.value)
    amplitude = ["--amplitude-q=100"] if command == "cyclic" and option != "--amplitude-q" else []
    argv = [command, "--particles=100", *amplitude, f"{option}={value}", "--out=/nonexistent/x"]
    if option == "--unload-to":
        argv.insert(2, "--axial-stress=5000")
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    line = capsys.readouterr().err.strip()
    assert f"error: {option} = " in line and "\n" not in line, line


def test_a_list_field_checks_each_value():
    assert IsotropicConfig(sample=SMALL, stresses=[500, 1000]).stresses == [500.0, 1000.0]
    with pytest.raises(ParameterError, match=r"^stresses = 0 Pa is outside the valid range"):
        IsotropicConfig(sample=SMALL, stresses=[500.0, 0])
    with pytest.raises(ParameterError, match=r"^suctions = 3000.0: a list of numbers expected"):
        SwccConfig(sample=SMALL, suctions=3000.0)


@pytest.mark.parametrize("command, argv, options", [
    ("triaxial", ["--particles", "300", "--suction", "30000", "--table-resolution", "100,40",
                  "--persist-bridges", "--max-strain", "0.02", "--vtk-every", "0"],
     {"particles": 300, "suction": 30000, "table_resolution": [100, 40],
      "persist_bridges": True, "max_strain": "0.02", "vtk_every": 0}),
    ("triaxial", ["--water-content", "1.5", "--rupture-liquid", "lost", "--friction", "20"],
     {"water_content": 1.5, "rupture_liquid": "lost", "friction": 20}),
    ("isotropic", ["--stresses", "500,1000", "--sample", "s.h5"],
     {"stresses": [500, 1000], "sample": "s.h5"}),
    ("isotropic", ["--stresses", "800"] + ["--stresses", "500,1000"],
     {"stresses": "500,1000"}),
    ("simple-shear", ["--shear-rate", "2", "--constant-volume"],
     {"shear_rate": 2, "constant_volume": True, "periodic": False}),
    ("tension", ["--void-ratio", "0.72", "--water-content", "1,2", "--specific-gravity", "2.7"],
     {"void_ratio": 0.72, "water_content": [1, 2], "specific_gravity": 2.7}),
    ("swcc", ["--suctions", "3000,30000", "--radius-spread", "0.2", "--particles", "60"],
     {"suctions": [3000, 30000], "radius_spread": 0.2, "particles": 60}),
])
def test_python_and_the_command_line_build_the_same_configuration(command, argv, options):
    """config_from_options takes the options by key as a table or Python gives them (numbers,
    their text, lists, comma text, flags) and builds what the command line builds."""
    parser, module = command_parser(command)
    assert config_from_options(command, options) == module.config_from(parser.parse_args(argv))


def test_options_given_by_key_are_refused_naming_the_key():
    with pytest.raises(OptionError) as refused:
        config_from_options("triaxial", {"suction": 1000, "water_content": 1})
    assert str(refused.value).startswith("suction and water_content: give one")
    assert refused.value.keys == ["suction", "water_content"]
    assert refused.value.on_command_line().startswith("--suction and --water-content: give one")
    with pytest.raises(ParameterError) as refused:       # a field's error, named by its key
        config_from_options("triaxial", {"prep_friction": 95})
    assert str(refused.value).startswith("prep_friction = 95.0 deg is outside the valid range")
    assert refused.value.on_command_line().startswith("--prep-friction = 95.0 deg")
    for options, message in (
            ({"partciles": 300}, r"^partciles: not an option of triaxial; valid: particles, "),
            ({"vtk_every": 5, "vtk_frames": 3}, r"^vtk_every and vtk_frames: give one$"),
            ({"particles": "many"}, r"^particles = 'many': an integer expected$"),
            ({"particles": 300.5}, r"^particles = 300.5: an integer expected$"),
            ({"particles": False}, r"^particles = False: a value expected, not true or false"),
            ({"persist_bridges": 1}, r"^persist_bridges = 1: a flag, true or false expected$"),
            ({"bridges": "cylinder"}, r"^bridges = 'cylinder' is not one of \('exact', "),
            ({"vtk_every": -1}, r"^vtk_every = -1 is outside the valid range \[0, inf\)$"),
            ({"suction": 1000, "table_resolution": "3,40"},
             r"^table_resolution '3,40': two integers NS,ND, each in \[4, inf\), expected$")):
        with pytest.raises(ValueError, match=message):
            config_from_options("triaxial", options)
    with pytest.raises(OptionError, match=r"^stresses = '500,x' is not a comma-separated list"):
        config_from_options("isotropic", {"stresses": "500,x"})
    with pytest.raises(OptionError, match=r"^void_ratio = \[0.72, 0.72\] repeats 0.72"):
        config_from_options("tension", {"void_ratio": [0.72, 0.72]})
    with pytest.raises(ValueError, match="command = 'dance' builds no configuration"):
        config_from_options("dance", {})


def test_an_option_reads_numbers_text_and_lists():
    number = Option("x", "a number")
    assert number.read("2.5") == 2.5 and number.read(3) == 3.0 and type(number.read(3)) is float
    count = Option("n", "a count", kind=int, least=1)
    assert count.read("12") == 12 and count.read(4.0) == 4
    assert count.read(2**70) == 2**70                       # exact beyond float's 2**53
    with pytest.raises(OptionError, match=r"^n = 0 is outside the valid range \[1, inf\)"):
        count.read(0)
    values = Option("v", "a list", many=True)
    assert values.read("1,2.5") == values.read([1, 2.5]) == [1.0, 2.5]
    assert values.read(7) == [7.0]                          # a table's single value
    assert Option("flag", "a flag", kind=bool).read(True) is True
    assert Option("raw", "as given", kind=None).read([3, 4]) == [3, 4]


def test_every_option_of_a_command_is_declared_once():
    for command in COMMANDS:
        keys = [option.key for option in options_of(command)]
        assert len(keys) == len(set(keys)), command
        for option in options_of(command):
            if option.field is not None:
                config, name = option.field
                assert spec_of(config, name).flag == option.flag, (command, option.key)


def test_a_checked_option_refuses_values_outside_its_parameter():
    points = option_from(Parameter("1", "states", 10, 400, kind=int, flag="--points"), 40,
                         checked=True)
    assert points.read("12") == 12 and points.default == 40
    assert "[-], valid range [10, 400]" in points.help
    with pytest.raises(ParameterError) as refused:
        points.read(401)
    assert str(refused.value) == "points = 401 is outside the valid range [10, 400]"
    assert refused.value.on_command_line() == "--points = 401 is outside the valid range [10, 400]"
    stresses = option_from(Parameter("Pa", "stresses", 0.0, low_inclusive=False,
                                     flag="--stresses"), None, checked=True, many=True)
    assert stresses.read("5,7") == [5.0, 7.0]
    with pytest.raises(ParameterError, match=r"^stresses = 0.0 Pa is outside the valid range "
                                             r"\(0, inf\] Pa$"):
        stresses.read("5,0")
    unchecked = option_from(Parameter("1", "states", 10, 400, kind=int, flag="--points"), 40)
    assert unchecked.read(5) == 5                      # left to the configuration


def test_option_values_take_defaults_and_refuse_unknown_keys_and_two_of_a_group():
    options = (Option("a", "a number", default=1.0), Option("b", "b", kind=int, group="g"),
               Option("c", "c", kind=int, group="g"))
    assert option_values(options, {"a": "2", "b": None}) == ({"a": 2.0, "b": None, "c": None},
                                                             {"a"})
    assert option_values(options, {"a": 1})[1] == set()          # at its default: not given
    with pytest.raises(OptionError, match=r"^d: not an option of a study; valid: a, b, c$"):
        option_values(options, {"d": 1}, "a study")
    with pytest.raises(OptionError, match=r"^b and c: give one$"):
        option_values(options, {"b": 1, "c": 2})


# ---------------------------------------------------------------- the studies' options

#: Each study command's declared options.
STUDY_OPTIONS = {"chapter4": lambda: (chapter4_command.POINTS,),
                 "chapter5": chapter5.grid_options, "crosscheck": lambda: crosscheck.OPTIONS,
                 "envelope": envelope.envelope_options,
                 "tradeoff": lambda: tradeoff.OPTIONS, "extremes": lambda: extremes.OPTIONS}
#: Each study command's options of how it runs (folder, threads, processes, device, output), the
#: only ones written by hand.
RUN_OPTIONS = {"chapter4": {"out", "threads", "quiet"},
               "chapter5": {"out", "jobs", "scheduler", "threads", "quiet", "device"},
               "envelope": {"out", "jobs", "scheduler", "threads", "quiet", "device", "force"},
               "crosscheck": {"out", "threads", "concurrent", "quiet", "device"},
               "tradeoff": {"out"}, "extremes": {"out", "threads", "quiet"}}


@pytest.mark.parametrize("command", sorted(STUDY_OPTIONS))
def test_a_study_command_makes_its_parser_from_its_declared_options(command):
    parser, _ = command_parser(command)
    declared = {option.key: option for option in STUDY_OPTIONS[command]()}
    actions = {action.dest: action for action in parser._actions if action.dest != "help"}
    assert set(actions) == set(declared) | RUN_OPTIONS[command]
    for key, option in declared.items():
        action = actions[key]
        assert action.option_strings == [option.flag, *option.aliases]
        shown = option.default if not option.many or option.default is None else \
            ",".join(f"{v:g}" for v in option.default)
        assert action.default == shown and action.metavar == option.metavar, key
        assert tuple(action.choices or ()) == tuple(option.choices or ()), key
        if option.field is not None:         # made from the field it sets
            assert action.parameter == option.field
            assert spec_of(*option.field).flag == option.flag, key


def test_the_tradeoff_study_declares_its_fields_options():
    assert [(option.key, option.default) for option in tradeoff.OPTIONS[:4]] == [
        (name, default_of(tradeoff.Study, name)) for name in ("particles", "max_strain",
                                                              "seed", "quick")]
    values = option_values(tradeoff.OPTIONS, {"particles": "300", "max_strain": 0.02})[0]
    assert tradeoff.study_of("t", values) == tradeoff.Study("t", particles=300, max_strain=0.02)
    seeds = tradeoff.study_of("t", {**values, "knob": "damping", "jobs": 2})
    assert seeds == tradeoff.SeedStudy("t", "damping", seeds=6, particles=300, max_strain=0.02,
                                       jobs=2)
    for given, message, line in (
            ({"knob": "damping", "quick": True},
             "knob studies one knob across samples: quick and docs belong",
             "--knob studies one knob across samples: --quick and --docs belong"),
            ({"seeds": 3}, "seeds and jobs belong to a knob study: give knob",
             "--seeds and --jobs belong to a --knob study: give --knob")):
        with pytest.raises(OptionError) as refused:
            tradeoff.study_of("t", {**values, **given})
        assert str(refused.value).startswith(message)
        assert refused.value.on_command_line().startswith(line)
    with pytest.raises(ParameterError) as refused:
        tradeoff.Study("t", particles=10)
    assert str(refused.value).startswith("particles = 10 is outside the valid range [50, inf]")
    assert refused.value.on_command_line().startswith("--particles = 10 is outside")
    with pytest.raises(ParameterError) as refused:            # the last sample's seed
        tradeoff.SeedStudy("t", "damping", seeds=6, seed=tradeoff.MAX_SEED - 2)
    assert refused.value.on_command_line().startswith("--seed = ")


def test_the_chapter5_options_state_the_tables_values_and_override_them(tmp_path):
    table = tmp_path / "grid.toml"
    table.write_text("[fixed]\nparticles = 200\ninertial_number = 1e-3\n[sweep]\n"
                     "suction = [0, 30000]\nconfining = [250]\n")
    options = {option.key: option for option in chapter5.grid_options(str(table))}
    assert "(table: 200)" in options["particles"].help
    assert "(table: 0,30000)" in options["suctions"].help
    assert "(table: 0.001)" in options["inertial_number"].help
    assert all(option.default is None for option in options.values())
    values = option_values(options.values(), {"confining": "500,750", "seed": 3})[0]
    assert chapter5.grid_from_options(values, str(table)) == chapter5.Chapter5Grid(
        suctions=[0.0, 30000.0], confining=[500.0, 750.0], particles=200, seed=3,
        inertial_number=1e-3)
    parser, _ = command_parser("chapter5")
    assert parser.parse_args(["--suction", "0,1000"]).suctions == "0,1000"     # its alias


def test_the_crosscheck_options_build_its_default_configuration():
    values = option_values(crosscheck.OPTIONS, {})[0]
    assert crosscheck.crosscheck_from_options(values) == crosscheck.crosscheck_config()
    given = option_values(crosscheck.OPTIONS, {"suction": "1e4", "settle_steps": 0,
                                               "records": 50, "mimic_yade": True})[0]
    assert crosscheck.crosscheck_from_options(given) == crosscheck.crosscheck_config(
        suction=1e4, settle_steps=1, records=50, mimic_yade=True)
    for given, message in (({"confining": "inf"}, "confining = inf is not finite; valid range "
                                                  "(0, inf) Pa"),
                           ({"suction": -5}, "suction = -5.0 Pa is outside the valid range "
                                             "[0, inf) Pa"),
                           ({"settle_steps": -1}, "settle_steps = -1 is outside the valid range "
                                                  "[0, 100000000]")):
        with pytest.raises(ParameterError) as refused:
            option_values(crosscheck.OPTIONS, given)
        assert str(refused.value) == message
        assert refused.value.on_command_line() == "--" + message.replace("_", "-", 1)
    with pytest.raises(OptionError, match=r"^suction 10000.0 Pa with periodic: "):
        crosscheck.crosscheck_from_options({**values, "suction": 1e4, "periodic": True})


def test_every_laboratory_command_takes_vtk_frames_where_it_can_spread_them():
    """--vtk-frames on every command that writes ParaView series: over the loading's length or
    its estimate (simple shear, strain-controlled cyclic); 0 (none) on a path of unknown
    length, where other counts are refused naming the option."""
    for command in ("triaxial", "oedometer", "isotropic", "simple-shear", "cyclic", "path",
                    "tension"):
        assert "vtk_frames" in {option.key for option in options_of(command)}, command
    shear = config_from_options("simple-shear", {"vtk_frames": 7})
    assert shear.vtk_frames == 7 and shear.estimated_steps() > 7
    cyclic = config_from_options("cyclic", {"vtk_frames": 4, "amplitude_strain": 1e-3})
    assert cyclic.vtk_frames == 4
    assert config_from_options("oedometer", {"vtk_frames": 0}).vtk_frames == 0
    with pytest.raises(OptionError) as refused:
        config_from_options("oedometer", {"vtk_frames": 5})
    assert "length is not known before it runs" in str(refused.value)


def test_the_old_liquid_option_is_a_deprecated_alias_of_rupture_liquid(capsys):
    from pendular.cli import command_parser, deprecated_liquid

    parser, _ = command_parser("triaxial")
    assert deprecated_liquid(parser, ["--water-content", "1", "--liquid", "lost"]) == \
        ["--water-content", "1", "--rupture-liquid", "lost"]
    assert deprecated_liquid(parser, ["--liquid=shared"]) == ["--rupture-liquid=shared"]
    assert capsys.readouterr().err.count("deprecated") == 2
    assert deprecated_liquid(parser, ["--liquid", "clusters"]) == ["--liquid", "clusters"]
    swcc, _ = command_parser("swcc")              # its --liquid is the regime
    assert deprecated_liquid(swcc, ["--liquid", "clusters"]) == ["--liquid", "clusters"]
    assert swcc.parse_args(["--liquid", "clusters"]).liquid == "clusters"
