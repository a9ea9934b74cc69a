"""Campaign tables read as command lines: each row of a TOML parameter table
(pendular.studies.campaign.read_table) becomes the options of its command, parsed and checked
by that command's own parser, so a table key is exactly an option (``pendular campaign``)."""

from __future__ import annotations

import json
import os
import re

from pendular.cli import UsageError, command_parser
from pendular.utils.parameters import ParameterError
from pendular.studies.campaign import (CAMPAIGN_OPTIONS, PATH_OPTIONS, Run, read_table,
                                       run_name, table_rows)


def options_argv(options: dict) -> list[str]:
    """Command-line options of a table row (underscores -> dashes; true flags; lists joined
    with commas; ``--option=value``, so that a value starting with '-' stays a value)."""
    argv = []
    for key, value in options.items():
        flag = "--" + key.replace("_", "-")
        if value is True:
            argv.append(flag)
        elif value is False:
            continue
        else:
            text = ",".join(map(str, value)) if isinstance(value, list) else str(value)
            argv.append(f"{flag}={text}")
    return argv


def _mentions(text: str, key: str) -> bool:
    """Whether the error ``text`` names the option ``key`` (as --key-with-dashes or key)."""
    flag = "--" + key.replace("_", "-")
    return re.search(rf"(?<![\w-])({re.escape(flag)}|{re.escape(key)})(?![\w-])",
                     text) is not None


class _Refused(Exception):
    """argparse's error, raised instead of printed (parser.error replaced)."""


def sweep_from_table(path: str | os.PathLike) -> tuple[str, list[Run]]:
    """(command, [Run]) of the TOML table at ``path``; each run's configuration is parsed and
    validated by the command's own options (ValueError naming the table, the run and the
    table key with its section)."""
    source = f"table = {os.fspath(path)!r}"
    table = read_table(path)
    command, rows, varied = table_rows(table, source)
    parser, module = command_parser(command)

    def refuse(message):
        raise _Refused(message)

    parser.error = refuse
    actions = {action.dest: action for action in parser._actions}
    known = set(vars(parser.parse_args([]))) - set(CAMPAIGN_OPTIONS)

    def where(index, key):
        """The section of the table that gives run ``index`` its ``key``."""
        if key not in varied[index]:
            return "[fixed]"
        return "[sweep]" if table.get("sweep") else f"row {index + 1} of [[runs]]"

    def setting(index, key):
        return f"{key} = {json.dumps(rows[index][key], default=str)} ({where(index, key)})"

    unknown = {}
    for index, row in enumerate(rows):
        for key in row:
            if key != "name" and key not in known:
                unknown.setdefault(key, index)
    if unknown:
        described = []
        for key, index in unknown.items():
            note = ("set by the campaign" if key in CAMPAIGN_OPTIONS else
                    f"write {key.replace('-', '_')}" if key.replace("-", "_") in known else "")
            described.append(f"{key} ({where(index, key)}{': ' + note if note else ''})")
        raise ValueError(f"{source}: {', '.join(described)}: not an option of {command} in a "
                         f"table; see 'pendular {command} --help'")
    folder = os.path.dirname(os.path.abspath(os.fspath(path)))
    runs = []
    for index, (row, keys) in enumerate(zip(rows, varied)):
        name = run_name(row, keys)
        if "name" in row and (isinstance(row["name"], bool)
                              or not isinstance(row["name"], (str, int))):
            raise ValueError(f"{source}: {setting(index, 'name')}: a folder name (a string) "
                             "expected")
        options = {}
        for key, value in row.items():
            if key == "name":
                continue
            if actions[key].nargs == 0 and not isinstance(value, bool):
                raise ValueError(f"{source}: run {name}: {setting(index, key)}: a flag, true "
                                 "or false expected")
            if actions[key].nargs != 0 and isinstance(value, bool):
                raise ValueError(f"{source}: run {name}: {setting(index, key)}: "
                                 f"--{key.replace('_', '-')} takes a value, not true or false")
            if key in PATH_OPTIONS and isinstance(value, str) and not os.path.isabs(value):
                value = os.path.join(folder, value)
            options[key] = value
        try:
            args = parser.parse_args(options_argv(options))
            config = module.config_from(args)
        except (_Refused, ValueError, UsageError, ArithmeticError) as error:
            if isinstance(error, ParameterError) and error.flag:   # a field: name its table key
                error = error.named(error.key)
            # the command's own checks name its options: point at the table keys that set them
            named = [key for key in options if _mentions(str(error), key)] or list(options)
            raise ValueError(f"{source}: run {name}: "
                             f"{', '.join(setting(index, key) for key in named)}: "
                             f"{error}") from None
        try:
            runs.append(Run(name, config, force=bool(getattr(args, "force", False))))
        except ValueError as error:
            raise ValueError(f"{source}: "
                             f"{setting(index, 'name') if 'name' in row else 'run ' + name}: "
                             f"{error}") from None
    names = [run.name for run in runs]
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise ValueError(f"{source}: runs {', '.join(repeated)} repeat a folder name: give "
                         "each [[runs]] row a distinct name or distinct values")
    return command, runs

