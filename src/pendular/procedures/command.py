"""What a laboratory test declares to the rest of pendular: its ``LaboratoryCommand``.

Each test's module (pendular.procedures.triaxial, oedometer, isotropic, simple_shear, cyclic,
path, tension, swcc) ends with one ``COMMAND``, a LaboratoryCommand: its name, one-line
description, test class and configuration, declared options and how they build the
configuration, the summary keys its command prints, its worked example and its default
output folder. ``pendular.procedures.registry`` lists these modules; the command line
(pendular.cli), the campaigns and their TOML tables (pendular.studies.campaign) and the
docs' command reference read every test from there, so a new test is one module, its tests
and its docs page, plus its line in the registry.
"""

from __future__ import annotations

from dataclasses import dataclass

from pendular.procedures.options import CommandOptions


@dataclass(frozen=True)
class LaboratoryCommand:
    """A laboratory test as its command runs it.

    name: the command (``pendular <name>``); description: its line in ``pendular --help``;
    test: the test class (``test(config).run(out, run_options)``, ``test.resume(out,
    run_options)``; its ``CONFIG`` the configuration dataclass); declared: its options in
    the order its help lists them and ``build(values, given)``, the configuration of their
    values (pendular.procedures.options.CommandOptions); shown: the summary keys printed at
    the end (a list of records among them printed as a table of ``columns``, default every
    column); example: (a command line, what it gives) for --help and docs/commands.md; out:
    the default output folder."""

    name: str
    description: str
    test: type
    declared: CommandOptions
    shown: tuple
    example: tuple
    out: str
    columns: tuple | None = None

    @property
    def config(self):
        """The configuration dataclass of the test."""
        return self.test.CONFIG

    @property
    def options(self):
        """The declared Options (pendular.utils.parameters.Option), in the help's order."""
        return self.declared.options
