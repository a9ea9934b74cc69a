"""The README as a user reads it: its Python example runs and prints what the run computed, and
its two set-up commands stay the ones outside checks run."""

import json
import os
import re
import subprocess
import sys

import pytest

from conftest import ROOT

README = os.path.join(ROOT, "README.md")
#: The README's first two lines of shell: install and run the main job; run the tests.
SETUP_COMMANDS = (
    "python3 -m venv .venv && . .venv/bin/activate && pip install -e . && python "
    "scenarios/triaxial.py --particles 1000 --suction 30000 --out runs/quick",
    "python -m pip install -e '.[test]' && python -m pytest -q",
)


def code_blocks(language):
    """The README's fenced code blocks in ``language``, in order."""
    with open(README, encoding="utf-8") as handle:
        text = handle.read()
    return re.findall(rf"^```{language}\n(.*?)^```", text, flags=re.S | re.M)


def test_the_setup_commands_are_the_first_block():
    assert code_blocks("bash")[0].splitlines() == list(SETUP_COMMANDS)


@pytest.fixture(scope="module")
def python_example(tmp_path_factory):
    """The README's Python block(s) run as a script in an empty folder: (folder, stdout)."""
    blocks = code_blocks("python")
    assert blocks, "the README has no Python example"
    folder = tmp_path_factory.mktemp("readme")
    script = folder / "readme_example.py"
    script.write_text("\n".join(blocks), encoding="utf-8")
    done = subprocess.run([sys.executable, str(script)], cwd=folder, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return folder, done.stdout


def test_the_python_example_prints_the_run_it_made(python_example):
    """The printed peak, strain and saturation are the summary's, and the run is a wet test
    at 750 Pa: the bridges make it stronger than a dry sample."""
    folder, stdout = python_example
    with open(folder / "runs" / "readme" / "summary.json") as handle:
        summary = json.load(handle)
    match = re.search(r"peak q = ([\d.]+) Pa at axial strain ([\d.]+), Sr = ([\d.]+)", stdout)
    assert match, stdout
    peak_q, strain, saturation = map(float, match.groups())
    assert peak_q == pytest.approx(summary["peak_q"], abs=0.05)
    assert strain == pytest.approx(summary["axial_strain_at_peak"], abs=5e-5)
    assert saturation == pytest.approx(summary["saturation_at_peak"], abs=5e-5)
    assert summary["completed"] is True
    assert summary["lateral_stress"] == pytest.approx(750.0, rel=0.01)
    assert peak_q > 1500.0       # a dry sample peaks at about 1.1 kPa here (thesis Table 5.3)
    assert 0.0 < saturation < 0.1              # pendular regime at 30 kPa


def test_the_python_example_reads_the_history_by_strain(python_example):
    """The second print is the wall stress (x, y, z) [Pa] of the record nearest 2 % strain:
    lateral stresses held at 750 Pa, the axial one above them."""
    _, stdout = python_example
    line = stdout.strip().splitlines()[-1]
    assert line.endswith("Pa (x, y, z)"), line
    stress = [float(value) for value in line.strip("[]").split("]")[0].split()]
    assert len(stress) == 3
    assert stress[0] == pytest.approx(750.0, rel=0.02)
    assert stress[1] == pytest.approx(750.0, rel=0.02)
    assert stress[2] > stress[0]
