"""pendular swcc --liquid clusters: the main drying and wetting curves with liquid clusters, their
figures in swcc.json, the pore units in ParaView, and the settings it refuses."""

import json

import numpy as np
import pytest

from pendular import read_history
from pendular.cli import run_command
from pendular.io.schema import undeclared_keys

SMALL = ["--particles", "150", "--quiet"]


def test_swcc_with_clusters_dries_from_saturation_and_wets_back(tmp_path):
    out = tmp_path / "swcc"
    assert run_command("swcc", [*SMALL, "--suctions", "3000,20000,300000", "--liquid",
                                "clusters", "--out", str(out)], prog="swcc.py") == 0
    result = json.loads((out / "swcc.json").read_text())
    assert not undeclared_keys(result, "swcc")
    drying, wetting = result["drying"], result["wetting"]
    assert [r["saturation"] for r in drying] == sorted((r["saturation"] for r in drying),
                                                       reverse=True)
    assert drying[0]["clusters"] >= 1 and drying[0]["liquid_in_clusters"] > 0.5
    assert drying[-1]["clusters"] == 0 and drying[-1]["liquid_in_bridges"] == 1.0
    for row in drying + wetting:
        assert row["liquid_in_bridges"] + row["liquid_in_clusters"] == pytest.approx(1.0)
        assert 0.0 <= row["liquid_in_trimers"] <= row["liquid_in_bridges"]
        assert row["saturation"] <= row["saturation_pore_units"]
        assert np.isfinite(row["chi_with_clusters"])
    # at 20 kPa drying holds pore units that wetting has not filled again
    assert drying[1]["filled_units"] > wetting[1]["filled_units"]
    assert result["hysteresis"][1]["saturation_difference"] > 0.0
    history = read_history(out / "history.h5")
    for column in ("clusters", "liquid_in_bridges", "liquid_in_clusters",
                   "liquid_in_largest_cluster", "largest_cluster_percolates",
                   "trimers", "liquid_in_trimers", "saturation_pore_units"):
        assert np.isfinite(history[column].values).all(), column
    assert history["clusters"].values.max() >= 1
    assert history["saturation"].values.max() == pytest.approx(
        max(r["saturation"] for r in drying), rel=0.2)
    assert (out / "pores" / "pores.pvd").exists()
    assert len(list((out / "pores").glob("pores_*.vtu"))) == 5       # the turning point apart


def test_the_mayer_stowe_princen_entry_drains_sooner(tmp_path):
    """Its throats' entry suctions lie below the inscribed ones (water, theta = 0), so the
    drying from saturation holds fewer units at 20 kPa; the choice is in the configuration."""
    filled = {}
    for entry in ("inscribed", "mayer-stowe-princen"):
        out = tmp_path / entry
        assert run_command("swcc", [*SMALL, "--suctions", "3000,20000,300000", "--liquid",
                                    "clusters", "--entry-suction", entry, "--out", str(out)],
                           prog="swcc.py") == 0
        result = json.loads((out / "swcc.json").read_text())
        assert result["config"]["fields"]["entry_suction"] == entry
        filled[entry] = result["drying"][1]["filled_units"]
    assert filled["mayer-stowe-princen"] < filled["inscribed"]


@pytest.mark.parametrize("argv, words", [
    (["--liquid", "drops"], ["--liquid", "pendular", "clusters"]),
    (["--liquid", "clusters", "--entry-suction", "circle"],
     ["--entry-suction", "inscribed", "mayer-stowe-princen"]),
    (["--entry-suction", "mayer-stowe-princen"], ["--entry-suction", "--liquid clusters"]),
])
def test_bad_cluster_settings_are_refused(argv, words, tmp_path, capsys):
    with pytest.raises(SystemExit) as stop:
        run_command("swcc", [*SMALL, *argv, "--out", str(tmp_path / "x")], prog="swcc.py")
    err = capsys.readouterr().err
    assert stop.value.code == 2 and "Traceback" not in err
    for word in words:
        assert word in err, err
