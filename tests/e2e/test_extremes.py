"""The --quick extremes grid (pendular.studies.extremes): no case fails, refusals name the parameter,
the JSON report is complete; and the command line."""

import json
import math
import os
import subprocess
import sys

from pendular.studies import extremes

from conftest import ROOT



def test_quick_grid_has_no_failed_case_and_writes_the_report(tmp_path, capsys):
    counts = extremes.run_grid(str(tmp_path), quick=True)
    report = json.loads((tmp_path / "extremes.json").read_text())
    cases = report["cases"]
    failed = [(c["parameter_varied"], c["value"], c["message"]) for c in cases
              if c["status"] == "failed"]
    assert not failed and counts["failed"] == 0
    assert report["counts"] == counts
    assert sum(report["counts"].values()) == len(cases) == len(extremes.cases(quick=True))
    assert report["counts"]["ok"] > 0 and report["counts"]["refused"] > 0
    for case in cases:
        if case["status"] == "ok":
            assert not case["must_be_refused"]
            for name, bound in report["bounds"].items():
                assert case["checks"][name] <= bound, (case["parameter_varied"], name)
        else:
            # the message names the parameter, its value and the valid range
            assert f"{case['parameter']} = " in case["message"]
            assert "valid range" in case["message"]
    refused = {(c["parameter_varied"], c["value"]): c for c in cases if c["status"] == "refused"}
    for key in (("contact_angle", 90.0), ("timestep_safety", 1.5), ("suction", 1e8)):
        assert refused[key]["parameter"] == key[0]
    # the base case ran wet: bridges, a small saturation, walls in compression
    base = cases[0]
    assert base["status"] == "ok" and base["state"]["bridges"] > 0
    assert 0.0 < base["state"]["saturation"] < 0.1
    assert math.isfinite(base["checks"]["max_speed_over_wave_speed"])
    assert "ok:" in capsys.readouterr().out


def test_command_line_requires_an_output_folder():
    result = subprocess.run([sys.executable, os.path.join(ROOT, "scenarios", "extremes.py")],
                            capture_output=True, text=True)
    assert result.returncode == 2 and "--out" in result.stderr
