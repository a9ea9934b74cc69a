"""What the laboratory commands refuse, in one ``<prog>: error: ...`` line naming what the user
typed (exit status 2), never a traceback or a run without an end: output periods beyond any
run, loading rates a path table sets itself, ranges that start where the help says.

Every case runs in-process through pendular.cli.run_command and is refused before anything
runs, unless its docstring says otherwise.
"""

import os

import pytest

from conftest import ROOT, refused, run_in_process

#: A small laboratory run (each case adds to it).
SMALL = ["--particles", "60", "--quiet"]
#: A path table of three stages (K0 loading, unloading, reloading).
OEDOMETER_TABLE = os.path.join(ROOT, "examples", "paths", "oedometer_unload.toml")
#: An output period beyond 2**64.
HUGE = "99999999999999999999"


def refused_here(capsys, tmp_path, command, argv, *words):
    """``pendular command argv --out OUT`` refused in one line holding ``words``, OUT not made;
    the line."""
    out = tmp_path / "out"
    line = refused(*run_in_process(command, [*argv, "--out", str(out)], capsys), *words)
    assert not out.exists()
    return line


# ---------------------------------------------------------------- output periods
@pytest.mark.parametrize("command", ["triaxial", "oedometer", "isotropic", "path"])
@pytest.mark.parametrize("option", ["--vtk-every", "--checkpoint-every"])
def test_an_output_period_beyond_any_run_is_refused_naming_it(command, option, tmp_path,
                                                              capsys):
    table = [OEDOMETER_TABLE] if command == "path" else []
    refused_here(capsys, tmp_path, command, [*table, *SMALL, option, HUGE],
                 f"{option} = {HUGE}", "valid range [0, ")
