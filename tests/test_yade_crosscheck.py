"""YADE cross-check (scenarios/yade_crosscheck.py) on 300 spheres, wet, 1 % axial strain.

Skipped without a ``yade`` executable on PATH. Both codes start the shear from the same exported
packing, so the wall stresses and the degree of saturation at the start must agree to round-off
and table interpolation; the shear then follows the same law in both (--mimic-yade), and the
peak deviator stress and Sr at peak must agree within a few per cent (measured: 0.1 % and
0.04 %). Takes about 10 s (plus the 300-sphere preparation, cached under .cache/, the first time).
"""

import importlib.util
import json
import math
import os
import shutil

import pytest

pytestmark = pytest.mark.skipif(shutil.which("yade") is None and shutil.which("yadedaily") is None,
                                reason="YADE (the cross-check reference) is not installed")

SCRIPT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scenarios",
                      "yade_crosscheck.py")
#: Tolerances of the agreement checks [-]: start of the shear (same packing), peak (same law).
START_TOLERANCE = 1e-3
PEAK_TOLERANCE = 0.05


def load_scenario():
    spec = importlib.util.spec_from_file_location("yade_crosscheck", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_wet_crosscheck_agrees(tmp_path):
    load_scenario().main(["--particles", "300", "--suction", "30000", "--max-strain", "0.01",
                          "--records", "50", "--mimic-yade", "--quiet",
                          "--out", str(tmp_path)])
    with open(tmp_path / "crosscheck.json") as handle:
        result = json.load(handle)
    assert (tmp_path / "crosscheck.png").stat().st_size > 0
    for key in ("peak_q_rel_diff", "saturation_rel_diff", "volumetric_strain_at_peak_diff",
                "start_sigma_rel_diff", "start_saturation_rel_diff"):
        assert math.isfinite(result[key]), key
    for code in ("pendular", "yade"):
        summary = result[code]
        for key in ("peak_q", "p_at_peak", "axial_strain_at_peak", "volumetric_strain_at_peak",
                    "saturation_at_peak", "bridges_at_peak", "porosity_at_peak",
                    "seconds_per_step", "particle_steps_per_s"):
            assert math.isfinite(summary[key]) and summary[key] >= 0.0, (code, key)
        assert summary["final_axial_strain"] == pytest.approx(0.01, rel=0.01)
        assert summary["peak_q"] > 0.0
    # same packing, same bridges: the start of the shear is the same state in both codes
    assert result["start_sigma_rel_diff"] < START_TOLERANCE
    assert abs(result["start_saturation_rel_diff"]) < START_TOLERANCE
    assert result["pendular"]["start"]["bridges"] == result["yade"]["start"]["bridges"] > 0
    # the same shear law: the peak agrees
    assert abs(result["peak_q_rel_diff"]) < PEAK_TOLERANCE
    assert abs(result["saturation_rel_diff"]) < PEAK_TOLERANCE
    assert abs(result["volumetric_strain_at_peak_diff"]) < 1e-3
