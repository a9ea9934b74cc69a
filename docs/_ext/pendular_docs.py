"""Pages generated from the code when the docs build, so that nothing is written twice.

On ``builder-inited`` this writes, under ``docs/_generated/`` (not in git):

- ``outputs_tables.md``: every history column (pendular.io.columns.HISTORY_COLUMNS), summary key
  with its meaning and the commands writing it (SUMMARY_KEYS), run option (OPTION_UNITS), sample and checkpoint dataset (pendular.dem.sample.DATASETS,
  pendular.dem.checkpoint.DATASETS) with its units, the ParaView frames' field data
  (pendular.io.schema.VTK_FIELDS) and the ParaView fields as declared in pendular.io.vtk's
  docstring;
- ``commands.md``: ``pendular --help`` and, per command, its worked example (the command module's
  ``EXAMPLE``: a laboratory test's is that of its LaboratoryCommand in
  pendular.procedures.registry, with its description and options) above its ``--help``, as
  the command prints it;
- ``api/pendular.md``: the public names of ``pendular``; ``api/<package>.md``: one page per
  sub-package, its docstring and every module in it.

A file is rewritten only when its text changes, so that an incremental build stays incremental.
"""

import argparse
import importlib
import io
import os
import pkgutil
import textwrap
from contextlib import redirect_stdout

#: Sub-packages with an API page, in the order of the layers (lowest first).
API_PACKAGES = ("pendular.utils", "pendular.dem", "pendular.capillary", "pendular.homogenize",
                "pendular.io", "pendular.procedures", "pendular.studies",
                "pendular.interop.yade", "pendular.cli")

#: Modules that are not imported as a library: ``python -m`` entry points, and the driver
#: script run by YADE's own Python (it imports yade).
SKIPPED = ("__main__", ".scripts")


def _write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    if os.path.exists(path):
        with open(path, encoding="utf-8") as handle:
            if handle.read() == text:
                return
    with open(path, "w", encoding="utf-8") as handle:
        handle.write(text)


def _cell(text):
    """Text safe inside a Markdown table cell."""
    return str(text).replace("|", "\\|").replace("\n", " ")


def _units(units):
    return "–" if units == "1" else f"`{units}`"


def outputs_tables():
    """The Markdown of the outputs reference's tables."""
    from pendular.dem import checkpoint, sample
    from pendular.dem.grading import GRADING_UNITS
    from pendular.io import columns, schema, vtk

    lines = ["## History datasets (`history.h5`, group `history`)", "",
             "One row per record; the dimensions after `record` are `axis` and `component` "
             "(x, y, z) or `grip` (z−, z+). `–`: dimensionless.", "",
             "| dataset | units | dimensions | dtype | written by | equation | description |",
             "|---|---|---|---|---|---|---|"]
    for name, column in columns.HISTORY_COLUMNS.items():
        dims = ", ".join(("record", *column.dims))
        commands = ", ".join(f"`{command}`" for command in column.commands)
        lines.append(f"| `{name}` | {_units(column.units)} | {dims} | {column.dtype} | "
                     f"{commands} | {_cell(column.equation)} | {_cell(column.description)} |")
    lines += ["", "## Summary keys (`summary.json`, `tension.json` cases, campaign rows)", "",
              "Every key a command writes, declared once in `pendular.io.schema.SUMMARY_KEYS` "
              "(a test fails when a command writes a key not declared for it). `null`: a "
              "measure that could not be taken, its `*_note` saying why. A nested record's "
              "fields and their units follow its table.", "",
              "| key | units | written by | meaning |", "|---|---|---|---|"]
    nested = []
    for name, key in schema.SUMMARY_KEYS.items():
        units = "fields below" if isinstance(key.units, dict) else _units(key.units)
        commands = ", ".join(f"`{command}`" for command in key.commands)
        lines.append(f"| `{name}` | {units} | {commands} | {_cell(key.description)} |")
        if isinstance(key.units, dict):
            nested.append((name, key.units))
    for name, units in nested:
        lines += ["", f"Fields of `{name}`: "
                  + ", ".join(f"`{field}` [{_units(unit)}]" for field, unit in units.items())
                  + "."]
    lines += ["", "## Calibration posterior (`posterior.csv` of `pendular calibrate`)", "",
              "One row per sample of every iteration; the fitted options, between `run` and "
              "`weight`, in their own units (Run options, below).", "",
              "| column | units | meaning |", "|---|---|---|"]
    lines += [f"| `{name}` | {_units(column.units)} | {_cell(column.description)} |"
              for name, column in schema.POSTERIOR_COLUMNS.items()]
    lines += ["", "## Run options (campaign rows, `history.h5` attributes)", "",
              "The options of a run as its command names them (underscores for dashes; "
              "`pendular <command> --help` explains each):", "",
              ", ".join(f"`{name}` [{_units(unit)}]"
                        for name, unit in sorted(schema.OPTION_UNITS.items())) + "."]
    lines += ["", "## Sample datasets (`sample.h5`)", "",
              "| dataset | units | description |", "|---|---|---|"]
    lines += [f"| `{name}` | {_units(units)} | {_cell(text)} |"
              for name, (units, text) in sample.DATASETS.items()]
    lines += ["", "## Checkpoint datasets (`checkpoint.h5`)", "",
              "| group / dataset | units | description |", "|---|---|---|"]
    lines += [f"| `{group}/{name}` | {_units(units)} | {_cell(text)} |"
              for group, datasets in checkpoint.DATASETS.items()
              for name, (units, text) in datasets.items()]
    lines += ["", "## ParaView series (`vtk/*.pvd`)", "",
              "Field data of every frame (`pendular.io.schema.VTK_FIELDS`; a series' time axis, "
              "the `.pvd` timestep, is one of them, named in a comment of the `.pvd` file):", "",
              "| field | units | description |", "|---|---|---|"]
    lines += [f"| `{name}` | {_units(column.units)} | {_cell(column.description)} |"
              for name, column in schema.VTK_FIELDS.items()]
    lines += ["", "As declared in `pendular.io.vtk` (series: "
              + ", ".join(f"`{name}`" for name in vtk.SERIES) + "):", "", "```text",
              textwrap.dedent(vtk.__doc__).strip(), "```", ""]
    return "\n".join(lines)


def commands_page():
    """The Markdown of every command's help, as ``pendular ... --help`` prints it."""
    from pendular import cli

    main = io.StringIO()
    with redirect_stdout(main):
        try:
            cli.main(["--help"])
        except SystemExit:
            pass
    lines = ["## `pendular --help`", "", "```text", main.getvalue().rstrip(), "```", ""]
    for name in cli.COMMANDS:
        parser, module = cli.command_parser(name)
        lines += [f"## `pendular {name}`", ""]
        if hasattr(module, "EXAMPLE"):
            line, gives = module.EXAMPLE
            lines += ["```bash", line, "```", "", f"{gives[0].upper()}{gives[1:]}.", ""]
        lines += ["```text", parser.format_help().rstrip(), "```", ""]
    return "\n".join(lines)


def _modules(package):
    module = importlib.import_module(package)
    names = [info.name for info in pkgutil.walk_packages(module.__path__, package + ".")]
    return [name for name in sorted(names) if not any(skip in name for skip in SKIPPED)]


def api_page(package):
    """The Markdown of a sub-package's API page: its docstring, then each module's members."""
    lines = [f"# `{package}`", "", "```{eval-rst}",
             f".. automodule:: {package}", "   :no-members:", "```", ""]
    for name in _modules(package):
        importlib.import_module(name)
        lines += [f"## `{name}`", "", "```{eval-rst}", f".. automodule:: {name}",
                  "   :members:", "   :show-inheritance:", "```", ""]
    return "\n".join(lines)


def public_page():
    """The Markdown of the public names of ``pendular`` (``from pendular import ...``)."""
    import inspect

    import pendular

    lines = ["# `pendular`: the public names", "", "```{eval-rst}", ".. automodule:: pendular",
             "   :no-members:", "```", ""]
    for name in pendular.__all__:
        if name == "__version__":
            continue
        kind = "autoclass" if inspect.isclass(getattr(pendular, name)) else "autofunction"
        options = ["   :members:", "   :show-inheritance:"] if kind == "autoclass" else []
        lines += [f"## `{name}`", "", "```{eval-rst}", f".. {kind}:: pendular.{name}",
                  *options, "```", ""]
    return "\n".join(lines)


def generate(app):
    folder = os.path.join(app.srcdir, "_generated")
    _write(os.path.join(folder, "outputs_tables.md"), outputs_tables())
    _write(os.path.join(folder, "commands.md"), commands_page())
    _write(os.path.join(folder, "api", "pendular.md"), public_page())
    for package in API_PACKAGES:
        _write(os.path.join(folder, "api", package + ".md"), api_page(package))


def setup(app):
    app.connect("builder-inited", generate)
    return {"parallel_read_safe": True, "parallel_write_safe": True}


if __name__ == "__main__":      # print one generated page: python docs/_ext/pendular_docs.py
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("page", choices=["outputs", "commands", "pendular", *API_PACKAGES])
    page = parser.parse_args().page
    print({"outputs": outputs_tables, "commands": commands_page, "pendular": public_page}.get(
        page, lambda: api_page(page))())
