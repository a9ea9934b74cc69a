"""The command line's own manners: short answers, no abbreviations, a suggestion for a typo,
each default stated once, a run's summary with units."""

import argparse
import re

import pytest

from pendular.cli import COMMANDS, command_parser, format_summary, main


def run(argv, capsys):
    try:
        status = main(argv)
    except SystemExit as stop:
        status = stop.code
    out = capsys.readouterr()
    return status, out.out, out.err


def test_a_bare_pendular_lists_the_commands(capsys):
    status, out, err = run([], capsys)
    assert status == 2 and "usage: pendular [-h] [-V] <command> [options]" in err
    assert "triaxial" in err and "required" not in err     # no internal argument names


@pytest.mark.parametrize("flag", ["-V", "--version"])
def test_the_version_is_one_line(flag, capsys):
    status, out, err = run([flag], capsys)
    assert status == 0 and re.fullmatch(r"pendular \S+\n", out)


@pytest.mark.parametrize("argv, suggestion", [
    (["triaxal"], "did you mean triaxial?"),
    (["triaxial", "--partciles", "300"], "did you mean --particles?"),
    (["triaxial", "--part", "300"], "did you mean --particles?"),        # no abbreviations
])
def test_a_typo_is_one_line_with_the_closest_name(argv, suggestion, capsys):
    status, out, err = run(argv, capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1, err
    assert suggestion in err and "--help' lists them" in err


def test_each_default_is_stated_once_and_none_is_not_stated():
    parser, _ = command_parser("triaxial")
    text = " ".join(parser.format_help().split())
    assert "(default: None)" not in text and "(default: False)" not in text
    for option in ("--contact-angle", "--surface-tension", "--particles", "--confining"):
        help_text = text.split(option, 2)[2].split(" --", 1)[0]
        assert help_text.lower().count("default") == 1, (option, help_text)


def test_a_summary_is_printed_with_units_and_four_figures():
    summary = {"peak_q": 5088.184391328918, "initial_porosity": 0.4357227169474057,
               "steps": 12000, "units": {"peak_q": "Pa", "initial_porosity": "1"}}
    lines = format_summary(summary, ["peak_q", "initial_porosity", "steps", "absent"]).split("\n")
    assert [line.split() for line in lines] == [["peak_q", "5088", "Pa"],
                                                ["initial_porosity", "0.4357"],
                                                ["steps", "12000"]]


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_command_has_a_help_listing_its_options(command, capsys):
    status, out, err = run([command, "--help"], capsys)
    assert status == 0 and err == "" and out.startswith(f"usage: pendular {command}")
    parser, _ = command_parser(command)
    for action in parser._actions:
        for flag in action.option_strings if action.help != argparse.SUPPRESS else ():
            assert flag in out, (command, flag)


def test_every_command_has_a_worked_example_that_its_parser_takes(monkeypatch):
    """Each command's EXAMPLE (docs/commands.md and the end of --help) is a command line its
    own parser accepts, with a configuration it builds where the command has one, so that an
    example cannot outlive a renamed option."""
    import shlex

    from conftest import ROOT
    from pendular.cli import COMMANDS, command_parser

    monkeypatch.chdir(ROOT)                       # the path table of the example
    for name in COMMANDS:
        parser, module = command_parser(name)
        line, gives = module.EXAMPLE
        words = shlex.split(line)
        assert words[:2] == ["pendular", name] and gives, name
        args = parser.parse_args(words[2:])
        if hasattr(module, "config_from"):
            module.config_from(args)
        assert line in parser.format_help()
