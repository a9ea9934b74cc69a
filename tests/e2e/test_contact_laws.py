"""A laboratory command with Hertz–Mindlin contacts: `pendular triaxial --contact
hertz-mindlin` prepares and shears a sample, records its law, and refuses a bad material in
one line."""

import json
import subprocess
import sys

import h5py

from conftest import refused, run_in_process, summary_of


def test_a_hertz_mindlin_triaxial_runs_and_records_its_law(tmp_path):
    out = tmp_path / "hertz"
    subprocess.run([sys.executable, "-m", "pendular", "triaxial", "--contact", "hertz-mindlin",
                    "--poisson", "0.25", "--restitution", "0.5", "--particles", "100",
                    "--max-strain", "0.01", "--quiet", "--out", str(out)],
                   check=True, capture_output=True, text=True, timeout=600)
    summary = summary_of(out)
    assert summary["peak_q"] > 0.0
    with h5py.File(out / "history.h5") as handle:
        sample = json.loads(handle.attrs["config"])["fields"]["sample"]["fields"]
    assert (sample["contact"], sample["poisson"], sample["restitution"]) == (
        "hertz-mindlin", 0.25, 0.5)


def test_a_laboratory_command_refuses_a_poisson_ratio_of_a_half(tmp_path, capsys):
    status, err = run_in_process("triaxial", ["--contact", "hertz-mindlin", "--poisson", "0.5",
                                              "--out", tmp_path / "run"], capsys)
    refused(status, err, "--poisson", "(-1, 0.5)")
