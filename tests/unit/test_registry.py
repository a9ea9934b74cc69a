"""The registry of laboratory tests (pendular.procedures.registry) is what the command line,
the campaigns and the configurations' JSON form read, and RunOptions is one run's settings."""

import pytest

from pendular.cli import COMMANDS as CLI_COMMANDS, command_parser, descriptions
from pendular.procedures.config import CONFIG_TYPES
from pendular.procedures.registry import COMMANDS, MODULES, command_of, options_of
from pendular.procedures.run_options import RunOptions
from pendular.studies.run_kinds import PROCEDURES


def test_every_module_registers_one_command_under_its_own_name():
    assert [module.COMMAND.name for module in MODULES] == list(COMMANDS)
    assert list(COMMANDS) == ["triaxial", "oedometer", "isotropic", "simple-shear", "cyclic",
                              "path", "tension", "swcc"]
    for command in COMMANDS.values():
        assert command.test.CONFIG is command.config
        assert CONFIG_TYPES[command.config.__name__] is command.config


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_the_command_line_takes_each_command_from_the_registry(name):
    command = COMMANDS[name]
    assert name in CLI_COMMANDS and descriptions()[name] == command.description
    parser, module = command_parser(name)
    assert module.EXAMPLE == command.example
    flags = {flag for action in parser._actions for flag in action.option_strings}
    for option in options_of(name):
        assert option.positional or option.flag in flags, option.key
    assert parser.get_default("out") == command.out


def test_a_campaign_runs_every_registered_test():
    assert list(PROCEDURES) == list(COMMANDS)
    for name, procedure in PROCEDURES.items():
        assert procedure.test is COMMANDS[name].test


def test_an_unknown_command_is_refused_naming_the_valid_ones():
    with pytest.raises(ValueError, match="valid: triaxial, oedometer"):
        command_of("oedometre")


def test_run_options_take_their_fields_one_by_one_and_refuse_others():
    options = RunOptions.of(RunOptions(device="cpu", threads=2), progress=False)
    assert (options.device, options.threads, options.progress) == ("cpu", 2, False)
    assert RunOptions.of(None) == RunOptions()
    with pytest.raises(TypeError, match="threds"):
        RunOptions.of(None, threds=1)
