"""The Chapter 5 campaign (pendular.chapter5, pendular.campaign) through its command line:
2 suctions x 2 confining stresses, 2 processes; reuse; a Dask cluster."""

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENARIO = os.path.join(ROOT, "scenarios", "chapter5.py")
KEYS = ("suction", "confining", "peak_axial_stress", "peak_q", "p_at_peak",
        "saturation_at_peak", "peak_q_effective", "p_effective_at_peak")


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    out = tmp_path_factory.mktemp("chapter5") / "campaign"
    subprocess.run([sys.executable, SCENARIO, "--particles", "120", "--suctions", "0,30000",
                    "--confining", "500,1000", "--max-strain", "0.01",
                    "--inertial-number", "3e-3", "--jobs", "2", "--out", str(out)],
                   check=True, capture_output=True, text=True, timeout=300)
    with open(out / "campaign.json") as handle:
        return out, json.load(handle)


def test_runs_cover_every_cell_with_finite_peaks(campaign):
    out, data = campaign
    runs = data["runs"]
    assert sorted((r["suction"], r["confining"]) for r in runs) == [
        (0, 500), (0, 1000), (30000, 500), (30000, 1000)]
    for run in runs:
        for key in KEYS:
            assert isinstance(run[key], (int, float)) and math.isfinite(run[key]), (run, key)
        assert run["peak_axial_stress"] > run["confining"] > 0
        folder = out / "runs" / f"s{run['suction']:.0f}_c{run['confining']:.0f}"
        for name in ("history.h5", "summary.json", "sample.h5", "plots/q_p.png"):
            assert (folder / name).exists(), (folder, name)
        if run["suction"] == 0:
            assert run["peak_q_effective"] == run["peak_q"]
            assert run["p_effective_at_peak"] == run["p_at_peak"]
            assert run["saturation_at_peak"] == 0.0
        else:
            assert 0.0 < run["saturation_at_peak"] < 1.0
            assert run["p_effective_at_peak"] > run["p_at_peak"]   # psi adds compression
    for lateral in (500, 1000):
        assert (out / "samples" / f"c{lateral}.h5").exists()


def test_envelopes_for_both_suctions(campaign):
    _, data = campaign
    envelopes = data["envelopes"]
    assert sorted(envelopes) == ["0", "30000"]
    for fit in envelopes.values():
        for key in ("phi_deg", "cohesion", "phi_eff_deg", "cohesion_eff"):
            assert math.isfinite(fit[key]), key
        assert 0.0 <= fit["phi_deg"] < 90.0
    dry = envelopes["0"]
    assert dry["phi_eff_deg"] == dry["phi_deg"] and dry["cohesion_eff"] == dry["cohesion"]


def test_report_and_plot(campaign):
    out, data = campaign
    report = (out / "report.md").read_text()
    for run in data["runs"]:
        row = f"| {run['suction']:.0f} | {run['confining']:.0f} | {run['peak_axial_stress']:.0f} |"
        assert row in report, row
        assert f"runs/s{run['suction']:.0f}_c{run['confining']:.0f}" in report
    assert "| 0 | 500 |" in report and "| 1207 |" in report      # thesis Table 5.3 beside ours
    assert "| 300000 | 750 |  | 8289 |" in report                 # thesis cell we did not run
    assert "2.20" in report                                       # Fig. 5.5 at 30 kPa
    assert (out / "plots" / "envelopes.png").stat().st_size > 0


def test_campaign_figures(campaign):
    out, _ = campaign
    for name in ("q_ev", "q_p_effective", "polar_psi", "polar_fabric", "anisotropy"):
        path = out / "plots" / f"{name}.png"
        assert path.stat().st_size > 0, path
        assert f"plots/{name}.png" in (out / "report.md").read_text()


def test_directional_value_of_a_tensor_is_its_quadratic_form():
    from pendular.chapter5_figures import directional

    tensor = np.array([[2.0, 0.0, 0.5], [0.0, 7.0, 0.0], [0.5, 0.0, 3.0]])
    angles = np.linspace(0.0, 2 * np.pi, 13)
    normals = np.stack([np.sin(angles), np.zeros_like(angles), np.cos(angles)], axis=1)
    expected = np.einsum("ai,ij,aj->a", normals, tensor, normals)
    assert np.allclose(directional(tensor, angles), expected, rtol=1e-14)
    assert directional(tensor, np.array([0.0]))[0] == 3.0          # axial direction: T_zz


def test_rerun_reuses_finished_runs(campaign):
    out, data = campaign
    stamps = {p: p.stat().st_mtime_ns for p in (out / "runs").glob("*/history.h5")}
    result = subprocess.run([sys.executable, SCENARIO, "--particles", "120", "--suctions",
                             "0,30000", "--confining", "500,1000", "--max-strain", "0.01",
                             "--inertial-number", "3e-3", "--jobs", "2", "--out", str(out)],
                            check=True, capture_output=True, text=True, timeout=120)
    assert "4 finished runs" in result.stdout
    assert {p: p.stat().st_mtime_ns for p in stamps} == stamps        # nothing re-run
    with open(out / "campaign.json") as handle:
        assert json.load(handle)["runs"] == data["runs"]


def test_campaign_on_a_dask_cluster(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    out = tmp_path / "dask"
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        subprocess.run([sys.executable, SCENARIO, "--particles", "120", "--suctions", "30000",
                        "--confining", "500,1000", "--max-strain", "0.01",
                        "--inertial-number", "3e-3", "--scheduler", cluster.scheduler_address,
                        "--out", str(out)], check=True, capture_output=True, text=True,
                       timeout=300)
    with open(out / "campaign.json") as handle:
        runs = json.load(handle)["runs"]
    assert sorted(r["confining"] for r in runs) == [500, 1000]
    for run in runs:
        assert run["peak_axial_stress"] > run["confining"]
        assert 0.0 < run["saturation_at_peak"] < 1.0
        assert (out / run["folder"] / "history.h5").exists()
