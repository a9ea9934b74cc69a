"""The numbers the docs quote have one source: the JSON that a script of docs/figures wrote
beside its figures, handed to MyST as substitutions (docs/conf.py)."""

import glob
import importlib.util
import json
import os
import re

from conftest import ROOT

DOCS = os.path.join(ROOT, "docs")
FIGURES = os.path.join(DOCS, "figures")


def load_script(name, folder=FIGURES):
    """A script of docs/figures (or ``folder``) as a module (they are not a package)."""
    spec = importlib.util.spec_from_file_location(name, os.path.join(folder, f"{name}.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def substitutions():
    """Every substitution of docs/figures/*.json, as docs/conf.py gathers them."""
    names = {}
    for path in sorted(glob.glob(os.path.join(FIGURES, "*.json"))):
        with open(path, encoding="utf-8") as handle:
            names.update(json.load(handle).get("substitutions", {}))
    return names


def test_every_quoted_number_is_defined():
    defined = substitutions()
    for page in glob.glob(os.path.join(DOCS, "**", "*.md"), recursive=True):
        with open(page, encoding="utf-8") as handle:
            quoted = set(re.findall(r"\{\{\s*(\w+)\s*\}\}", handle.read()))
        assert quoted <= set(defined), (page, sorted(quoted - set(defined)))


def test_the_readme_numbers_are_those_of_the_run_they_come_with():
    """wet_triaxial.json's numbers are its summary's, as the script rounds them (no hand edit),
    and its run is the README's main job."""
    script = load_script("make_readme_figure")
    with open(os.path.join(FIGURES, "wet_triaxial.json"), encoding="utf-8") as handle:
        record = json.load(handle)
    expected = script.substitutions(record["summary"])
    assert {k: record["substitutions"][k] for k in expected} == expected
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as handle:
        readme = handle.read()
    assert "python " + " ".join(script.COMMAND) + " --out runs/quick" in readme
    for figure in record["figures"]:
        assert os.path.isfile(os.path.join(FIGURES, figure)), figure


def test_the_dilatancy_numbers_are_those_of_its_measures():
    script = load_script("make_wet_dilatancy")
    with open(os.path.join(FIGURES, "wet_dilatancy.json"), encoding="utf-8") as handle:
        record = json.load(handle)
    expected = script.substitutions(record["measures"])
    assert {k: record["substitutions"][k] for k in expected} == expected


def test_the_stiffness_numbers_are_those_of_its_cases():
    script = load_script("bench_stiffness", os.path.join(ROOT, "benchmarks"))
    with open(os.path.join(FIGURES, "material_stiffness.json"), encoding="utf-8") as handle:
        record = json.load(handle)
    assert record["substitutions"] == script.substitutions(record["cases"])
