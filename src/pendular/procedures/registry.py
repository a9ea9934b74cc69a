"""Every laboratory test, registered once: ``COMMANDS``, name -> LaboratoryCommand.

Each test's module declares its ``COMMAND`` (pendular.procedures.command.LaboratoryCommand:
its configuration, options, test class, printed summary keys, worked example); this module
lists those modules, in the order ``pendular --help`` shows them. The command line
(pendular.cli), the campaigns and their TOML tables (pendular.studies.campaign,
pendular.studies.run_kinds) and the docs' command reference (docs/_ext) read the tests from
here. A new test: its module with its ``COMMAND``, one line in ``MODULES``, its tests and its
docs page.

``options_of(command)`` lists a command's options; ``config_from_options(command, options)``
builds and checks its configuration from a flat mapping key -> value (the command line's
parsed options, a row of a campaign table, a Python dict; pendular.procedures.options).

    config = config_from_options("triaxial", {"particles": 300, "suction": 30000,
                                              "max_strain": 0.02})
"""

from __future__ import annotations

from pendular.procedures import (cyclic, isotropic, oedometer, path, simple_shear, swcc, tension,
    triaxial)
from pendular.utils.parameters import ParameterError, option_values

#: The modules of the laboratory tests, in the order of ``pendular --help``.
MODULES = (triaxial, oedometer, isotropic, simple_shear, cyclic, path, tension, swcc)
#: Command name -> its LaboratoryCommand.
COMMANDS = {module.COMMAND.name: module.COMMAND for module in MODULES}


def command_of(name):
    """The LaboratoryCommand ``name``; ValueError naming the valid ones."""
    if name not in COMMANDS:
        raise ValueError(f"command = {name!r} builds no configuration; valid: "
                         f"{', '.join(COMMANDS)}")
    return COMMANDS[name]


def options_of(name):
    """The Options of command ``name``, in the order its help lists them."""
    return command_of(name).options


def config_from_options(name, options=None):
    """The checked configuration of command ``name`` from ``options``: option key -> value (a
    number or its text, a flag's bool, a list or comma text of a list); keys not given, or
    given None, take their declared defaults. OptionError or ParameterError naming the key
    (``on_command_line``: the flag), ValueError naming the file of a path table or grading
    curve."""
    values, given = option_values(options_of(name), options, name)
    try:
        return command_of(name).declared.build(values, given)
    except ParameterError as error:
        raise ParameterError(error.key, error.named(error.key), error.flag) from None
