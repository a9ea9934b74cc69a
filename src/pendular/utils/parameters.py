"""Parameters declared once: a configuration field carries its unit, valid range, help text and
command-line flag as metadata (``parameter``); from it ``validate`` checks a configuration,
``option_of`` declares the option that sets it (``Option``: key, flag, default, kind, help with
unit and range; ``option_from`` one of a Parameter of its own, such as a study's knob, checked as
it is read), ``option_values`` reads a command's options given by key, ``fields_of`` reads the
fields back from them and ``flat_options`` makes the flat rows of a run.
pendular.procedures.options declares each laboratory command's options with them, each study
(pendular.studies) its own; the command line and campaign tables read options through them.

Errors name the field in Python and the option's key in tables (``particles = 1 is outside the
valid range [2, ...]``); ``ParameterError`` carries the field's name and flag, and
``OptionError`` the keys of the options it names, so that the command line names the option the
user typed instead (``on_command_line``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from pendular.utils.validate import check_int, check_range

#: Key of a field's Parameter in its dataclasses metadata.
METADATA_KEY = "pendular.parameter"


class ParameterError(ValueError):
    """A configuration value outside its valid set; the message starts with the field's
    ``name``, ``flag`` is the command-line option that sets it (None without one)."""

    def __init__(self, name, message, flag=None):
        super().__init__(message)
        self.name = name
        self.flag = flag

    def named(self, label):
        """The message with its leading field name replaced by ``label`` (a flag, a table key)."""
        text = str(self)
        return label + text[len(self.name):] if text.startswith(self.name) else text

    @property
    def key(self):
        """The name of a table key or flat row: the flag's (``--prep-friction`` ->
        prep_friction), else the field's."""
        return key_of(self.flag) if self.flag else self.name

    @property
    def keys(self):
        """The options the error names (its key)."""
        return (self.key,)

    def on_command_line(self):
        """The message as the command line says it: naming the flag."""
        return self.named(self.flag) if self.flag else str(self)


class OptionError(ValueError):
    """An error of options given by key (a parsed command line, a table row, a Python mapping):
    ``say(name)`` writes the message, naming each option as ``name(key)`` gives it. str()
    names them by key, as tables and Python do; ``on_command_line()`` by flag. ``keys``: the
    options it names, in the order it names them."""

    def __init__(self, say):
        self.keys = []
        super().__init__(say(self._keyed))
        self._say = say

    def _keyed(self, key):
        if key not in self.keys:
            self.keys.append(key)
        return key

    def on_command_line(self):
        """The message as the command line says it: naming the flags."""
        return self._say(flag_of)


def flag_of(key):
    """The command-line flag of the option ``key``: prep_friction -> --prep-friction."""
    return "--" + key.replace("_", "-")


def key_of(flag):
    """The key of the option ``flag`` (its argparse dest, a table's key): --prep-friction ->
    prep_friction."""
    return flag[2:].replace("-", "_")


@dataclass(frozen=True)
class Parameter:
    """What a configuration field declares (``parameter`` makes one): ``unit`` ('1' for
    dimensionless), valid range [low, high] (bounds open with ``*_inclusive`` False, None for
    none), ``choices`` of a text field, ``kind`` (float, int, str, bool; None: checked by hand
    in the configuration), command-line ``flag``, ``help`` (without unit or range: added from
    these), ``unset``: the option's default is None, meaning the configuration's default
    (stated in the help), ``metavar`` of the option, ``recorded``: one of a run's flat options
    (``flat_options``), ``many``: the field is a list, each value of ``kind`` in the range (its
    option, a comma list, is written by hand)."""

    unit: str
    help: str
    low: float | None = None
    high: float | None = None
    low_inclusive: bool = True
    high_inclusive: bool = True
    flag: str | None = None
    choices: tuple | None = None
    kind: type | None = float
    unset: bool = False
    metavar: str | None = None
    recorded: bool = True
    many: bool = False

    def valid_range(self):
        """The range as errors and help state it, e.g. '(0, 1]'."""
        text = (lambda bound: str(int(bound))) if self.kind is int else "{:g}".format
        low = "-inf" if self.low is None else text(self.low)
        high = "inf" if self.high is None else text(self.high)
        return (f"{'[' if self.low_inclusive else '('}{low}, {high}"
                f"{']' if self.high_inclusive else ')'}")

    def key(self, name):
        """The field's name in flat rows and tables: its option's (``--prep-friction`` ->
        prep_friction), else the field's ``name``."""
        return key_of(self.flag) if self.flag else name

    def check(self, name, value, optional=False):
        """``value`` of field ``name`` converted to its kind (ParameterError outside the
        parameter's valid set); None passes where ``optional``."""
        if (value is None and optional) or self.kind is None:
            return value
        if self.many:
            if isinstance(value, (str, bytes)) or not np.iterable(value):
                raise ParameterError(name, f"{name} = {value!r}: a list of numbers expected",
                                     self.flag)
            return [dataclasses.replace(self, many=False).check(name, item) for item in value]
        if self.kind is bool:
            if not isinstance(value, (bool, np.bool_)):
                raise ParameterError(name, f"{name} = {value!r}: valid values True or False",
                                     self.flag)
            return bool(value)
        if self.choices is not None:
            if value not in self.choices:
                raise ParameterError(name, f"{name} = {value!r} is not one of {self.choices}",
                                     self.flag)
            return value
        try:
            if self.kind is int:
                return check_int(name, value, low=0 if self.low is None else int(self.low),
                                 high=None if self.high is None else int(self.high))
            if self.kind is float:
                return check_range(name, value, -math.inf if self.low is None else self.low,
                                   math.inf if self.high is None else self.high,
                                   low_inclusive=self.low_inclusive,
                                   high_inclusive=self.high_inclusive,
                                   unit="" if self.unit == "1" else self.unit)
        except ValueError as error:
            raise ParameterError(name, str(error), self.flag) from None
        return value

    def option_help(self, default):
        """The option's help: text, unit, range, and the configuration's ``default`` where
        the option's own is None (``unset``)."""
        text = self.help
        if self.kind in (int, float):
            text += f" [{'-' if self.unit == '1' else self.unit}]"
            if self.low is not None or self.high is not None:
                text += f", valid range {self.valid_range()}"
        if self.unset and "default" not in text:
            text += f" (default {default:g})" if isinstance(default, float) else \
                f" (default {default})"
        return text


def parameter(default=dataclasses.MISSING, *, unit="1", help, low=None, high=None,
              low_inclusive=True, high_inclusive=True, flag=None, choices=None, kind=float,
              unset=False, metavar=None, recorded=True, many=False,
              default_factory=dataclasses.MISSING):
    """A dataclass field of ``default`` (or ``default_factory``, for a list) declaring its
    Parameter (see there) in its metadata."""
    if kind is int and not (low_inclusive and high_inclusive):
        raise ValueError(f"{help}: integer ranges are closed")
    spec = Parameter(unit, help, low, high, low_inclusive, high_inclusive, flag,
                     None if choices is None else tuple(choices), kind, unset, metavar, recorded,
                     many)
    return dataclasses.field(default=default, default_factory=default_factory,
                             metadata={METADATA_KEY: spec})


def spec_of(config, name):
    """The Parameter of field ``name`` of the dataclass (or instance) ``config``; KeyError
    for a field that declares none."""
    for item in dataclasses.fields(config):
        if item.name == name:
            return item.metadata[METADATA_KEY]
    raise KeyError(f"{type(config).__name__ if not isinstance(config, type) else config.__name__}"
                   f" has no field {name!r}")


def parameters_of(config):
    """(field, Parameter) of the fields of ``config`` that declare one, in field order."""
    return [(item, item.metadata[METADATA_KEY]) for item in dataclasses.fields(config)
            if METADATA_KEY in item.metadata]


def validate(config):
    """Check and convert every declared field of the dataclass instance ``config`` in place
    (ParameterError naming the first field outside its valid set); a field whose default is
    None may be None. Cross-field checks stay in the configuration's ``__post_init__``."""
    for item, spec in parameters_of(config):
        setattr(config, item.name, spec.check(item.name, getattr(config, item.name),
                                              optional=item.default is None))


def fail(config, name, message):
    """ParameterError of field ``name`` of ``config`` (``message`` starts with the name)."""
    return ParameterError(name, message, spec_of(config, name).flag)


def default_of(config, name):
    """The default of field ``name`` of the dataclass ``config``."""
    item = next(item for item in dataclasses.fields(config) if item.name == name)
    if item.default_factory is not dataclasses.MISSING:
        return item.default_factory()
    return item.default


@dataclass(frozen=True)
class Option:
    """An option of a command, given by ``key`` (its argparse dest and a table's key; its flag
    ``--key-with-dashes``): ``help`` as the command's help shows it, ``default`` when not given
    (None: the configuration's, or none), ``kind`` of its value (float, int, str, bool: a flag
    given or not; None: passed as given, read by the configuration that takes it),
    ``choices``, ``metavar``, ``many``: a list of ``kind``, on the command line a comma list
    (``distinct``: no value twice), ``least``: an integer refused below this as it is read,
    ``group``: the options of one group exclude each other, ``positional``: the command line
    takes it without a flag, ``aliases``: its other flags on the command line, ``field``: the
    (configuration, field) it sets as it is, whose Parameter declares it (``option_of``),
    ``valid``: the Parameter whose valid set each value is checked against as it is read (a
    study's own knob; an option that sets a field leaves that to its configuration)."""

    key: str
    help: str
    default: object = None
    kind: type | None = float
    choices: tuple | None = None
    metavar: str | None = None
    many: bool = False
    distinct: bool = False
    least: int | None = None
    group: str | None = None
    positional: bool = False
    aliases: tuple = ()
    field: tuple | None = None
    valid: Parameter | None = None

    @property
    def flag(self):
        """The command-line flag: --key-with-dashes."""
        return flag_of(self.key)

    def read(self, value):
        """``value`` given to the option (from a command line, a table or Python) as its kind
        (a text parsed, a comma list split); OptionError naming the key when it is not one,
        ParameterError naming it (and the flag) outside the option's ``valid`` set."""
        if self.kind is None:
            return value
        if self.kind is bool:
            if not isinstance(value, (bool, np.bool_)):
                raise OptionError(lambda name: f"{name(self.key)} = {value!r}: a flag, true or "
                                               "false expected")
            return bool(value)
        if not self.many:
            return self._checked(self._one(value))
        return [self._checked(item) for item in self._list(value)]

    def _checked(self, value):
        """One ``value`` checked against the option's ``valid`` set, where it declares one."""
        return value if self.valid is None else self.valid.check(self.key, value)

    def _list(self, value):
        """The values of a list option (a comma text, a list or one value), each of its kind,
        none twice where ``distinct``."""
        items = value.split(",") if isinstance(value, str) else (
            list(value) if isinstance(value, (list, tuple)) else [value])
        try:
            values = [self._one(item) for item in items]
        except OptionError:
            raise OptionError(lambda name: f"{name(self.key)} = {value!r} is not a "
                                           "comma-separated list of numbers") from None
        for k, item in enumerate(values):
            if self.distinct and item in values[:k]:
                raise OptionError(lambda name: f"{name(self.key)} = {value!r} repeats "
                                               f"{item:g}: give each value once")
        return values

    def _one(self, value):
        """One value of the option's kind (not a list)."""
        if isinstance(value, (bool, np.bool_)):
            raise OptionError(lambda name: f"{name(self.key)} = {value!r}: a value expected, "
                                           "not true or false")
        if self.kind is str:
            if not isinstance(value, str):
                raise OptionError(lambda name: f"{name(self.key)} = {value!r}: a text expected")
        else:
            value = self._number(value)
        if self.choices is not None and value not in self.choices:
            raise OptionError(lambda name: f"{name(self.key)} = {value!r} is not one of "
                                           f"{self.choices}")
        if self.least is not None and value < self.least:
            raise OptionError(lambda name: f"{name(self.key)} = {value} is outside the valid "
                                           f"range [{self.least}, inf)")
        return value

    def _number(self, value):
        """``value`` (a number or its text) as the option's kind, int or float."""
        what = "an integer" if self.kind is int else "a number"
        try:
            if self.kind is float:
                return float(value)
            if isinstance(value, (int, np.integer)):
                return int(value)
            if isinstance(value, str):
                return int(value.strip())
            if float(value).is_integer():
                return int(value)
        except (TypeError, ValueError, OverflowError):
            pass
        raise OptionError(lambda name: f"{name(self.key)} = {value!r}: {what} expected")


def option_of(config, name, default=dataclasses.MISSING, checked=False, **changes):
    """The Option of field ``name`` of the dataclass ``config`` from its Parameter: key and
    flag, kind, choices, metavar, a list's comma form, help with unit and range, default (the
    field's, or None where ``unset``). A command's own setting overrides: ``default`` (the
    field's value when not given; with ``unset``, stated in the help) and ``changes`` to the
    Parameter (e.g. ``help``, ``low``, ``high``, ``unset``); ``checked``: the option checks
    its values against that Parameter as it reads them (a range of the command's own, beside
    the configuration's)."""
    spec = dataclasses.replace(spec_of(config, name), **changes)
    if spec.flag is None:
        raise ValueError(f"{config.__name__}.{name}: no option (no flag)")
    value = default_of(config, name) if default is dataclasses.MISSING else default
    if spec.kind is bool and value is not False:
        raise ValueError(f"{config.__name__}.{name}: a flag's default is False")
    return option_from(spec, value, field=(config, name), checked=checked)


def option_from(spec, default, field=None, checked=False, **changes):
    """The Option of the Parameter ``spec`` (its flag, kind, choices, help with unit and
    range) whose value is ``default`` when not given (None on the option where ``unset``);
    ``checked``: each value read is checked against ``spec`` (ParameterError naming the
    option), as a study's own knob is; ``changes``: the Option's own (e.g. ``many``,
    ``group``)."""
    declared = {"key": key_of(spec.flag), "help": spec.option_help(default),
                "default": None if spec.unset else default, "kind": spec.kind,
                "choices": spec.choices, "metavar": spec.metavar, "many": spec.many,
                "field": field}
    option = Option(**{**declared, **changes})
    if checked:
        valid = dataclasses.replace(spec, flag=option.flag, many=False)
        option = dataclasses.replace(option, valid=valid)
    return option


def option_values(options, given, owner="the command"):
    """(values, keys given) of the declared ``options`` (Option) from ``given``: key -> value
    (a number or its text, a flag's bool, a list or comma text of a list), each read as its
    option's kind (Option.read); a key not given, or given None, takes its declared default,
    and a value equal to its default counts as not given. OptionError naming an unknown key
    (not an option of ``owner``) or two given options of one group."""
    declared = {option.key: option for option in options}
    given = dict(given or {})
    unknown = [key for key in given if key not in declared]
    if unknown:
        raise OptionError(lambda name: f"{', '.join(map(name, unknown))}: not an option of "
                                       f"{owner}; valid: {', '.join(declared)}")
    values = {key: option.default if given.get(key) is None else option.read(given[key])
              for key, option in declared.items()}
    changed = {key for key, option in declared.items() if values[key] != option.default}
    groups = {}
    for key, option in declared.items():
        if key in changed and option.group is not None:
            groups.setdefault(option.group, []).append(key)
    for keys in groups.values():
        if len(keys) > 1:
            raise OptionError(lambda name: f"{' and '.join(map(name, keys))}: give one")
    return values, changed


def fields_of(values, options):
    """{field: value} of the ``options`` (Option) that set a configuration field as it is,
    from ``values`` (key -> value, every key present); an option at None leaves its field at
    the configuration's default."""
    return {option.field[1]: values[option.key] for option in options
            if option.field is not None and values[option.key] is not None}


def flat_options(config, exclude=()):
    """Flat key -> value of the recorded fields of the dataclass instance ``config`` (keys as
    its options are named, Parameter.key), in field order, but ``exclude`` (keys)."""
    return {spec.key(item.name): getattr(config, item.name)
            for item, spec in parameters_of(config)
            if spec.recorded and spec.key(item.name) not in exclude}


def option_field(key, parts):
    """(part, field) of the flat option ``key`` in a configuration whose nested parts are
    ``parts`` (part name -> dataclass), e.g. 'friction' -> ('sample', 'friction_deg')."""
    for part, kind in parts.items():
        for item, spec in parameters_of(kind):
            if spec.key(item.name) == key:
                return part, item.name
    raise KeyError(f"{key!r} is not an option of {', '.join(parts)}")
