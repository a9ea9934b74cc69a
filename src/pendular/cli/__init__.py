"""The ``pendular`` command: ``pendular <command> [options]`` (``pendular --help`` lists them).

Each command lives in ``pendular.cli.commands.<name>`` with ``add_arguments(parser)`` and
``run(args)``; ``scenarios/*.py`` call ``main`` with their command's name. A failure a user can
cause (bad option, bad or missing file, unusable output folder) ends in one line
``<prog>: error: <what is wrong>`` and exit status 2, never a traceback; an interrupted run exits
with 130, in one line, whenever Ctrl-C comes (while Python imports the command's modules too:
this module imports only the standard library at its top, and the rest inside ``main``).
"""

from __future__ import annotations

import argparse
import difflib
import importlib
import json
import sys

#: Command name -> (module under pendular.cli.commands, one-line description); a laboratory
#: test's line is its own (pendular.procedures.registry, read by ``descriptions``).
COMMANDS = {
    "triaxial": ("triaxial", None),
    "oedometer": ("oedometer", None),
    "isotropic": ("isotropic", None),
    "simple-shear": ("simple_shear", None),
    "cyclic": ("cyclic", None),
    "path": ("path", None),
    "tension": ("tension", None),
    "swcc": ("swcc", None),
    "chapter4": ("chapter4", "regular packings of thesis Ch. 4: tables and figures"),
    "chapter5": ("chapter5", "thesis Table 5.3 campaign of triaxial tests"),
    "campaign": ("campaign", "sweep of a laboratory command's options from a TOML table"),
    "envelope": ("envelope", "Mohr–Coulomb strength envelope of triaxials at several stresses"),
    "calibrate": ("calibrate", "Bayesian calibration of a test's parameters to a measured curve"),
    "tradeoff": ("tradeoff", "speed against accuracy of the numerical settings"),
    "extremes": ("extremes", "grid of extreme settings: each runs or is refused clearly"),
    "crosscheck": ("crosscheck", "the same packing sheared by pendular and YADE"),
    "impact": ("impact", "one collision of a sphere with a sphere or a wall: the contact law"),
}


def descriptions():
    """Command name -> its line in ``pendular --help`` (a laboratory test's from its
    LaboratoryCommand)."""
    from pendular.procedures.registry import COMMANDS as LABORATORY

    return {name: text if text is not None else LABORATORY[name].description
            for name, (_, text) in COMMANDS.items()}


#: Exit status of a run stopped by Ctrl-C or --stop-after.
INTERRUPTED = 130


class Formatter(argparse.RawDescriptionHelpFormatter):
    """Help that states an option's default once, after its text, unless the text already
    gives it or there is none (units are in the text)."""

    def _get_help_string(self, action):
        text = action.help or ""
        if (not action.option_strings or "default" in text.lower()
                or action.default in (None, argparse.SUPPRESS) or isinstance(action.default, bool)):
            return text
        return f"{text} (default: %(default)s)"


class Parser(argparse.ArgumentParser):
    """An argument parser that takes options only as written in full (no abbreviations) and
    answers a mistake in one line, with the closest option or command when there is one."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, allow_abbrev=False, **kwargs)

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}{self._suggestion(message)}; "
                     f"'{self.prog} --help' lists them\n")

    def _suggestion(self, message):
        """' (did you mean X?)' for an unknown option or an invalid choice close to a valid one."""
        if message.startswith("unrecognized arguments:"):
            words = message.split(":", 1)[1].split()
            known = [o for action in self._actions for o in action.option_strings]
        elif "invalid choice:" in message:
            words = [message.split("invalid choice:", 1)[1].split("'")[1]]
            known = [c for action in self._actions for c in (action.choices or ())]
        else:
            return ""
        for word in words:
            close = difflib.get_close_matches(word.split("=")[0], known, n=1, cutoff=0.7)
            if close:
                return f" (did you mean {close[0]}?)"
        return ""


class UsageError(Exception):
    """A user's mistake found after parsing (printed as one ``error:`` line)."""


def positive_int(name, low=0):
    """argparse type: an integer >= ``low`` (the error names the option)."""
    def parse(text):
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} {text!r}: an integer expected") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"{name} {value} is outside the valid range "
                                             f"[{low}, inf)")
        return value
    return parse


def add_run_options(parser, threads_default=None):
    """Options every command shares: --threads (``threads_default``: None lets a run choose:
    all of Numba's threads from 500 spheres on, else 1), --quiet."""
    parser.add_argument("--threads", type=positive_int("--threads", 1), default=threads_default,
                        help="Numba threads of a run" + (
                            " (None: all from 500 spheres on, else 1)"
                            if threads_default is None else ""))
    parser.add_argument("--quiet", action="store_true",
                        help="no progress bars, and the results in the form scripts read: "
                             "the summary's main keys as JSON, alone on stdout (messages go to "
                             "stderr; without --quiet: one line or table row per result, to 4 "
                             "significant figures, with units)")


def add_device_option(parser, runs):
    """--device: where ``runs`` (what the command runs, in its help) run, "cpu" or "gpu"; a
    run option, as --threads: not part of a run's configuration (docs/gpu.md)."""
    from pendular.dem.simulation import DEVICES

    parser.add_argument("--device", choices=DEVICES, default="cpu",
                        help=f"where {runs} run: cpu, or gpu (numba-cuda, pip install -e "
                             "'.[gpu]'; docs/gpu.md)")


def add_executor_options(parser):
    """Options of commands that run many tests: --jobs, --scheduler, and --threads (per run,
    default 1), --quiet, --device (every run's)."""
    parser.add_argument("--jobs", type=positive_int("--jobs", 1), default=1,
                        help="parallel processes")
    parser.add_argument("--scheduler", metavar="ADDRESS", default=None,
                        help="run on the Dask cluster of this scheduler (e.g. tcp://host:8786) "
                             "instead of --jobs local processes")
    add_run_options(parser, threads_default=1)
    add_device_option(parser, "the preparations and the runs")


def start_executor_run(args):
    """Check the options of add_executor_options and --out before anything is made (errors
    naming the option; --device: that it can run here), and apply --threads; the
    pendular.procedures.run_options.RunOptions of them, passed once to the command's run."""
    from pendular.dem.simulation import check_device
    from pendular.procedures.run_options import RunOptions
    from pendular.studies.campaign import check_jobs

    if args.out == "":
        raise UsageError("--out '': an output folder is required")
    set_threads(args.threads)
    check_jobs(args.jobs)
    check_device(args.device)
    return RunOptions(device=args.device, threads=args.threads, progress=not args.quiet,
                      jobs=args.jobs, scheduler=args.scheduler)


def add_declared_options(parser, options):
    """Add to ``parser`` the declared ``options`` (pendular.utils.parameters.Option; a
    laboratory command's: pendular.procedures.registry.options_of, a study's: its module's) in
    their order: flag and aliases, default (a list's as its comma text), type (an integer with
    a least value checked as it is parsed), choices, metavar, help; a flag stores true; the
    options of one group exclude each other. Each action of an option that sets a
    configuration field records it as ``action.parameter`` = (config, field)."""
    groups = {}
    for option in options:
        where = parser
        if option.group is not None:
            if option.group not in groups:
                groups[option.group] = parser.add_mutually_exclusive_group()
            where = groups[option.group]
        settings = {"help": option.help.replace("%", "%%")}
        if option.positional:
            action = where.add_argument(option.key, metavar=option.metavar, nargs="?",
                                        default=option.default, **settings)
        elif option.kind is bool:
            action = where.add_argument(option.flag, *option.aliases, action="store_true",
                                        default=option.default, **settings)
        else:
            settings["default"] = option.default
            if option.many and option.default is not None:
                settings["default"] = ",".join(f"{value:g}" for value in option.default)
            if option.choices is not None:
                settings["choices"] = option.choices
            elif option.least is not None:
                settings["type"] = positive_int(option.flag, option.least)
            elif option.kind in (int, float) and not option.many:
                settings["type"] = option.kind
            if option.metavar is not None:
                settings["metavar"] = option.metavar
            action = where.add_argument(option.flag, *option.aliases, **settings)
        if option.field is not None:
            action.parameter = option.field


def add_command_options(parser, command):
    """Add to ``parser`` the options of the configuration of ``command``
    (pendular.procedures.options)."""
    from pendular.procedures.registry import options_of

    add_declared_options(parser, options_of(command))


def command_config(command, args):
    """The configuration of ``command`` from the parsed options ``args`` (those it declares:
    pendular.procedures.registry.config_from_options; its errors name the keys, and
    ``on_command_line`` the flags)."""
    from pendular.procedures.registry import config_from_options, options_of

    keys = {option.key for option in options_of(command)}
    return config_from_options(command, {key: value for key, value in vars(args).items()
                                         if key in keys})


def declared_values(options, args):
    """The values of the declared ``options`` (add_declared_options) from the parsed options
    ``args``: each read and checked as its Option declares (pendular.utils.parameters.
    option_values; its errors name the keys, and ``on_command_line`` the flags)."""
    from pendular.utils.parameters import option_values

    keys = {option.key for option in options}
    return option_values(options, {key: value for key, value in vars(args).items()
                                   if key in keys})[0]


def set_threads(threads):
    """Apply --threads (error naming it outside [1, NUMBA_NUM_THREADS])."""
    import numba

    from pendular.utils.threads import configure as configure_threading, use_threads

    configure_threading()
    if threads is None:
        return
    if not 1 <= threads <= numba.config.NUMBA_NUM_THREADS:
        raise UsageError(f"--threads {threads} is outside the valid range "
                         f"[1, {numba.config.NUMBA_NUM_THREADS}]")
    use_threads(threads)


def command_parser(name, prog=None):
    """(argparse parser of command ``name``, its module); the help ends with the module's
    worked ``EXAMPLE`` (command line, what it gives)."""
    import textwrap

    module = importlib.import_module(f"pendular.cli.commands.{COMMANDS[name][0]}")
    epilog = None
    if hasattr(module, "EXAMPLE"):          # every command has one (tests/unit/test_cli.py)
        line, gives = module.EXAMPLE
        epilog = f"example:\n  {line}\n" + textwrap.fill(
            gives, 92, initial_indent="    ", subsequent_indent="    ")
    parser = Parser(prog=prog or f"pendular {name}", description=module.__doc__,
                    formatter_class=Formatter, epilog=epilog)
    module.add_arguments(parser)
    return parser, module


#: The old values of --rupture-liquid, once given as --liquid (now the liquid regime).
RUPTURE_LIQUIDS = ("shared", "lost")


def deprecated_liquid(parser, argv):
    """``argv`` with ``--liquid shared|lost`` (the old name of ``--rupture-liquid``) renamed,
    one warning line on stderr, for a command that has --rupture-liquid (its --liquid, if
    any, is the regime: pendular|clusters)."""
    flags = {flag for action in parser._actions for flag in action.option_strings}
    if "--rupture-liquid" not in flags:
        return argv
    renamed = list(argv)
    for k, word in enumerate(renamed):
        value = (word.partition("=")[2] if word.startswith("--liquid=")
                 else renamed[k + 1] if word == "--liquid" and k + 1 < len(renamed) else None)
        if value in RUPTURE_LIQUIDS:
            renamed[k] = word.replace("--liquid", "--rupture-liquid", 1)
            print(f"warning: --liquid {value} is deprecated: it is now --rupture-liquid "
                  f"{value} (--liquid chooses the liquid regime, pendular|clusters)",
                  file=sys.stderr)
    return renamed


def run_command(name, argv, prog=None):
    """Parse ``argv`` for command ``name`` and run it; returns the exit status."""
    import numba

    from pendular.utils.interrupt import catching_interrupts, pause_point

    parser, module = command_parser(name, prog)
    pause_point("import")
    args = parser.parse_args(deprecated_liquid(parser, argv))
    try:
        with catching_interrupts():
            return module.run(args) or 0
    except (UsageError, ValueError, FileNotFoundError, IsADirectoryError,
            NotADirectoryError, PermissionError) as error:
        # a configuration names its field; the command line names the option the user typed
        text = error.on_command_line() if hasattr(error, "on_command_line") else error
        parser.exit(2, f"{parser.prog}: error: {text}\n")
    except (ArithmeticError, MemoryError, numba.core.errors.NumbaError) as error:
        # a value the configurations' ranges let through but this run cannot hold (the ranges
        # refuse such values where they enter; this is the last line of defence)
        first = str(error).strip().splitlines()[0] if str(error).strip() else ""
        parser.exit(2, f"{parser.prog}: error: a setting is out of this run's reach "
                       f"({type(error).__name__}{': ' + first if first else ''}): check the "
                       "options' magnitudes (particles, radius, young, rates, resolutions)\n")
    except KeyboardInterrupt:
        parser.exit(INTERRUPTED, f"{parser.prog}: interrupted\n")


def main(argv=None, prog=None):
    """``pendular <command> ...``; with ``prog`` (a scenario's file name) and argv starting
    with the command, that command alone. Ctrl-C before the command runs (while its modules
    are imported) also ends in one line, with exit status 130."""
    try:
        return _main(list(sys.argv[1:] if argv is None else argv), prog)
    except KeyboardInterrupt:
        print(f"{prog or 'pendular'}: interrupted", file=sys.stderr)
        return INTERRUPTED


def _main(argv, prog):
    if prog is not None:
        return run_command(argv[0], argv[1:], prog)
    from pendular.utils.version import software_version

    parser = Parser(
        prog="pendular", usage="pendular [-h] [-V] <command> [options]",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="DEM of wet granular media in the pendular regime (Khosravani 2014).",
        epilog="commands:\n" + "\n".join(f"  {name:<11} {text}"
                                         for name, text in descriptions().items())
        + "\n\n'pendular <command> --help' shows a command's options with their defaults.")
    parser.add_argument("-V", "--version", action="version",
                        version=f"pendular {software_version()}")
    parser.add_argument("command", choices=list(COMMANDS), metavar="command",
                        help="one of: " + ", ".join(COMMANDS))
    if not argv:
        parser.print_help(sys.stderr)
        return 2
    command, options = argv[0], argv[1:]
    if command.startswith("-") and command not in ("-h", "--help", "-V", "--version"):
        parser.error(f"unrecognized arguments: {command}")
    args = parser.parse_args([command])
    return run_command(args.command, options)


def format_value(value):
    """A summary value as the terminal shows it: a float to 4 significant figures (without an
    exponent below a million: 30000, not 3e+04), a flag as true/false (as in summary.json),
    None as '-', anything else as it is."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        text = f"{value:.4g}"
        return f"{float(text):.0f}" if "e+" in text and abs(value) < 1e6 else text
    return "-" if value is None else str(value)


def _shown(unit):
    """Whether a unit is printed: not for a dimensionless value, record indices or no unit."""
    return isinstance(unit, str) and unit not in ("1", "record")


def _with_unit(name, unit):
    """``name [unit]``, or the name alone for a unit not shown or one the name ends with
    (``tensile_strength_pa``)."""
    return f"{name} [{unit}]" if _shown(unit) and not name.endswith(f"_{unit.lower()}") else name


def _is_table(value):
    """Whether a summary value is a list of records (an isotropic path's ``stages``)."""
    return isinstance(value, list) and bool(value) and all(isinstance(r, dict) for r in value)


def format_table(rows, units, columns=None, width=100):
    """Lines of a table of ``rows`` (dicts): a header ``name [unit]`` (``units``: column ->
    unit), then one line per row, numbers to 4 significant figures, right-aligned. ``columns``:
    those shown (default: every column holding a number, flag or text). A table wider than
    ``width`` characters is cut into blocks of columns, one under the other (a blank line
    between), each led by the first column (the row's name: stage, cycle). A row's notes
    (``*_note``) are left out by default."""
    if columns is None:               # a row's notes are summed up in a line of their own
        columns = [name for name in dict.fromkeys(k for row in rows for k in row)
                   if all(not isinstance(row.get(name), (list, dict)) for row in rows)
                   and not name.endswith("_note")]
    header = [_with_unit(name, units.get(name)) for name in columns]
    cells = [[format_value(row.get(name)) for name in columns] for row in rows]
    widths = [max(len(text) for text in column) for column in zip(header, *cells)]
    blocks = [[0]]
    for index in range(1, len(columns)):
        if len(blocks[-1]) > 1 and sum(widths[k] + 2 for k in blocks[-1]) + widths[index] > width:
            blocks.append([0])
        blocks[-1].append(index)
    lines = []
    for block in blocks:
        lines += [""] if lines else []
        lines += ["  ".join(line[k].rjust(widths[k]) for k in block) for line in (header, *cells)]
    return lines


def format_summary(summary, keys, columns=None):
    """Lines ``name  value unit`` of the ``keys`` of a run's ``summary`` that it holds, numbers
    to 4 significant figures (format_value), units from the summary's own ``units`` block, else
    from pendular.io.schema.SUMMARY_UNITS; a list of records (an isotropic path's ``stages``)
    as a table under its name (format_table, with ``columns``), the units of its columns from
    the key's own units (a dict), else from those of the summary."""
    from pendular.io.schema import SUMMARY_UNITS

    units = {**SUMMARY_UNITS, **summary.get("units", {})}
    shown = [key for key in keys if key in summary]
    width = max((len(key) for key in shown if not _is_table(summary[key])), default=0)
    lines = []
    for key in shown:
        value = summary[key]
        if _is_table(value):
            table_units = units.get(key) if isinstance(units.get(key), dict) else units
            lines.append(f"  {key}:")
            lines += [f"    {line}" if line else "" for line in
                      format_table(value, table_units, columns)]
            continue
        unit = units.get(key)
        if isinstance(value, dict):        # e.g. steps by phase: one line, each with its unit
            inner = unit if isinstance(unit, dict) else {}
            value = ", ".join(f"{name} {format_value(item)}"
                              + (f" {inner[name]}" if _shown(inner.get(name)) else "")
                              for name, item in value.items())
        elif isinstance(value, list):      # e.g. record indices
            value = ", ".join(format_value(item) for item in value) or "none"
        lines.append(f"  {key:<{width}}  {format_value(value)}"
                     + (f" {unit}" if _shown(unit) and value is not None else ""))
    return "\n".join(lines)


def print_result(quiet, line, **results):
    """The closing ``line`` of a command (its counts, its folder) on stdout; with ``quiet``
    (--quiet) on stderr instead, and ``results`` (JSON values) as JSON alone on stdout."""
    if quiet:
        print(line, file=sys.stderr)
        print(json.dumps(results, indent=2))
    else:
        print(line)


def print_summary(summary, keys, quiet=False, columns=None):
    """Print the ``keys`` of a run's ``summary``: format_summary's lines, or with ``quiet``
    (--quiet, for scripts) the same keys as JSON, values unrounded."""
    if quiet:
        print(json.dumps({key: summary[key] for key in keys if key in summary}, indent=2,
                         default=lambda value: value.tolist()))
    else:
        print(format_summary(summary, keys, columns))
