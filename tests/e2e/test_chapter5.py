"""The Chapter 5 campaign (pendular.studies.chapter5): its grid, envelopes and report as library code;
scenarios/chapter5.py on 2 suctions x 2 confining stresses in 2 processes, reused when started
again; the library on a Dask cluster."""

import csv
import dataclasses
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from pendular.cli import run_command
from pendular.studies.chapter5 import Chapter5Campaign, Chapter5Grid, envelopes, write_report
from pendular.procedures.config import ShearConfig
from pendular.procedures.reference import FIG_5_5, TABLE_5_3

from conftest import ROOT, assert_drawn, requires

SCENARIO = os.path.join(ROOT, "scenarios", "chapter5.py")
KEYS = ("suction", "confining", "peak_axial_stress", "peak_q", "p_at_peak",
        "saturation_at_peak", "peak_q_effective", "p_effective_at_peak",
        "peak_q_effective_complete", "p_effective_complete_at_peak")
#: campaign.json's "arguments" as scenarios/chapter5.py wrote them before the library.
ARGUMENTS = ["particles", "suctions", "confining", "jobs", "out", "seed", "max_strain",
             "inertial_number", "prep_friction", "scheduler"]
SMALL = ["--particles", "120", "--suctions", "0,30000", "--confining", "500,1000",
         "--max-strain", "0.015", "--inertial-number", "3e-3", "--jobs", "2"]


# ---------------------------------------------------------------- library, no runs

def test_grid_from_the_shipped_table_with_overrides():
    grid = Chapter5Grid.from_table(particles=300, suctions=[0, 30000.0], seed=None)
    assert grid.particles == 300 and grid.seed == 0 and grid.suctions == [0.0, 30000.0]
    assert grid.confining == [250.0, 500.0, 750.0, 1000.0] and grid.max_strain == 0.25
    wet = grid.run(30000.0, 500.0, "/x")
    assert wet.bridges.suction == 30000.0 and wet.sample.confining == 500.0
    assert wet.sample_path == "/x/samples/c500.h5" and wet.sample == grid.sample(500.0)
    assert grid.run(0.0, 250.0, "/x").bridges is None
    assert dataclasses.replace(grid.run(0.0, 750.0, "/x"), sample_path=None).shear == \
        ShearConfig(max_strain=0.25, inertial_number=3e-4)


@pytest.mark.parametrize("values, message", [
    ({"suctions": [-1.0]}, "suctions = -1.0 Pa is outside the valid range [0, inf] Pa"),
    ({"confining": [0.0]}, "confining = 0.0 Pa is outside the valid range (0, 1e+07] Pa"),
    ({"confining": [500, 500]}, "must not repeat a value"),
    ({"suctions": []}, "--suctions: at least one value expected"),
])
def test_grid_refuses_bad_values(values, message):
    with pytest.raises(ValueError) as error:
        Chapter5Grid(**{"suctions": [0.0], "confining": [500.0], **values})
    assert message in str(error.value)


def test_grid_tables_name_what_a_chapter5_grid_cannot_hold(tmp_path):
    table = tmp_path / "grid.toml"
    table.write_text("[fixed]\nparticles = 200\nfriction = 30\n[sweep]\nsuction = [0]\n"
                     "confining = [250]\n")
    with pytest.raises(ValueError, match="a Chapter 5 grid has no fixed.friction"):
        Chapter5Grid.from_table(table)
    table.write_text("[fixed]\nparticles = 200\n")
    with pytest.raises(ValueError, match="no suctions"):
        Chapter5Grid.from_table(table)
    assert Chapter5Grid.from_table(table, suctions=[0], confining=[250]).particles == 200


def _row(suction, confining, q, p, q_eff=None, p_eff=None, q_complete=None, p_complete=None):
    return {"suction": suction, "confining": confining, "peak_axial_stress": confining + q,
            "peak_q": q, "p_at_peak": p, "saturation_at_peak": 0.01 if suction else 0.0,
            "peak_q_effective": q if q_eff is None else q_eff,
            "p_effective_at_peak": p if p_eff is None else p_eff,
            "peak_q_effective_complete": q if q_complete is None else q_complete,
            "p_effective_complete_at_peak": p if p_complete is None else p_complete,
            "axial_strain_at_peak": 0.05, "saturation_at_20_percent": None,
            "folder": f"runs/s{suction:g}_c{confining:g}"}


def test_envelopes_recover_the_mohr_coulomb_line_of_their_peaks():
    phi, cohesion = 25.0, 300.0
    sin_phi = math.sin(math.radians(phi))
    slope = 6 * sin_phi / (3 - sin_phi)
    q0 = cohesion * 6 * math.cos(math.radians(phi)) / (3 - sin_phi)
    rows = [_row(0.0, c, slope * p, p) for c, p in ((250.0, 400.0), (750.0, 1200.0))]
    rows += [_row(30000.0, c, slope * p + q0, p, slope * (p + 900.0), p + 900.0,
                  1.1 * slope * (p + 950.0), p + 950.0)
             for c, p in ((250.0, 2000.0), (750.0, 2900.0))]
    rows.append(_row(15000.0, 250.0, 5000.0, 2000.0))         # one stress only: no fit
    fits = envelopes(rows)
    assert sorted(fits) == ["0", "30000"]
    assert fits["0"]["phi_deg"] == pytest.approx(phi) and abs(fits["0"]["cohesion"]) < 1e-6
    assert fits["30000"]["phi_deg"] == pytest.approx(phi)
    assert fits["30000"]["cohesion"] == pytest.approx(cohesion)
    assert fits["30000"]["phi_eff_deg"] == pytest.approx(phi)             # Eq. 3.43: on the
    assert abs(fits["30000"]["cohesion_eff"]) < 1e-6                      # dry line
    steeper = math.degrees(math.asin(3 * 1.1 * slope / (6 + 1.1 * slope)))
    assert fits["30000"]["phi_eff_complete_deg"] == pytest.approx(steeper)  # its own fit
    assert abs(fits["30000"]["cohesion_eff_complete"]) < 1e-6
    # fits through the origin: the same lines here, which pass through it
    assert fits["30000"]["phi_eff_c0_deg"] == pytest.approx(phi)
    assert fits["30000"]["phi_eff_complete_c0_deg"] == pytest.approx(steeper)
    assert fits["0"]["phi_c0_deg"] == pytest.approx(phi)
    assert fits["30000"]["phi_c0_deg"] > phi                           # net: cohesion shows
    falling = [_row(0.0, 250.0, 900.0, 500.0), _row(0.0, 750.0, 100.0, 900.0)]
    fit = envelopes(falling)["0"]
    assert fit["phi_deg"] is None and "outside the Mohr–Coulomb range" in fit["errors"][0]


def test_report_sets_every_cell_beside_the_thesis(tmp_path):
    rows = [_row(0.0, 250.0, 350.0, 370.0), _row(30000.0, 250.0, 5400.0, 2050.0)]
    figure = tmp_path / "plots" / "envelopes.png"
    grid = Chapter5Grid(suctions=[0.0, 30000.0], confining=[250.0], particles=120)
    write_report(tmp_path / "report.md", rows, envelopes(rows), grid,
                 {"envelopes": str(figure)}, str(tmp_path))
    report = (tmp_path / "report.md").read_text()
    assert "# Chapter 5 campaign: 120 spheres, seed 0" in report
    assert "| 0 | 250 | 600 | 591 | +1.5 % |" in report            # ours beside Table 5.3
    assert "| 15000 | 1000 |  | 8018 |  |" in report                # a thesis cell not run
    assert "| 30000 | 250 | 1.000 |  | 2.20 |" in report             # Sr beside Fig. 5.5
    assert "(no suction has two confining stresses)" in report
    secant = math.degrees(math.asin(3 * (350 / 370) / (6 + 350 / 370)))   # one peak's own line
    assert f"| 350 | 370 | {secant:.2f} | {secant:.2f} | runs/s0_c250 |" in report
    assert "![envelopes](plots/envelopes.png)" in report
    assert TABLE_5_3[(300000, 750)] == 8289 and FIG_5_5[30000] == 0.022


# ---------------------------------------------------------------- the scenario, 2 x 2 runs


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    out = tmp_path_factory.mktemp("chapter5") / "campaign"
    subprocess.run([sys.executable, SCENARIO, *SMALL, "--out", str(out)],
                   check=True, capture_output=True, text=True, timeout=900)
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
            # the interface term adds more
            assert run["p_effective_complete_at_peak"] > run["p_effective_at_peak"]
    for lateral in (500, 1000):
        assert (out / "samples" / f"c{lateral}.h5").exists()


def test_envelopes_for_both_suctions(campaign):
    _, data = campaign
    envelopes = data["envelopes"]
    assert sorted(envelopes) == ["0", "30000"]
    for fit in envelopes.values():
        for key in ("phi_deg", "cohesion", "phi_eff_deg", "cohesion_eff",
                    "phi_eff_complete_deg", "cohesion_eff_complete"):
            assert math.isfinite(fit[key]), key
        assert 0.0 <= fit["phi_deg"] < 90.0
    dry = envelopes["0"]
    assert dry["phi_eff_deg"] == dry["phi_deg"] and dry["cohesion_eff"] == dry["cohesion"]
    assert dry["phi_eff_complete_deg"] == dry["phi_deg"]


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
    assert_drawn(out / "plots" / "envelopes.png")


def test_campaign_figures(campaign):
    out, _ = campaign
    for name in ("q_ev", "q_p_effective", "polar_psi", "polar_fabric", "anisotropy"):
        path = out / "plots" / f"{name}.png"
        assert_drawn(path)
        assert f"plots/{name}.png" in (out / "report.md").read_text()


def test_directional_value_of_a_tensor_is_its_quadratic_form():
    from pendular.studies.chapter5_figures import directional

    tensor = np.array([[2.0, 0.0, 0.5], [0.0, 7.0, 0.0], [0.5, 0.0, 3.0]])
    angles = np.linspace(0.0, 2 * np.pi, 13)
    normals = np.stack([np.sin(angles), np.zeros_like(angles), np.cos(angles)], axis=1)
    expected = np.einsum("ai,ij,aj->a", normals, tensor, normals)
    assert np.allclose(directional(tensor, angles), expected, rtol=1e-14)
    assert directional(tensor, np.array([0.0]))[0] == 3.0          # axial direction: T_zz


def test_rerun_reuses_finished_runs(campaign, capsys):
    """The scenario's command started again in-process (pendular.cli.run_command, as
    scenarios/chapter5.py runs it)."""
    out, data = campaign
    stamps = {p: p.stat().st_mtime_ns for p in (out / "runs").glob("*/history.h5")}
    samples = {p: p.stat().st_mtime_ns for p in (out / "samples").glob("*.h5")}
    capsys.readouterr()
    assert run_command("chapter5", [*SMALL, "--suction", "0,30000", "--out", str(out)],
                       prog="chapter5.py") == 0
    printed = capsys.readouterr().out
    assert "4 finished runs" in printed and "0 run" in printed
    assert {p: p.stat().st_mtime_ns for p in stamps} == stamps        # nothing re-run
    assert {p: p.stat().st_mtime_ns for p in samples} == samples      # nor prepared
    with open(out / "campaign.json") as handle:
        assert json.load(handle)["runs"] == data["runs"]
    with open(out / "campaign.csv") as handle:
        assert [r["status"] for r in csv.DictReader(handle)] == ["reused"] * 4


def test_campaign_json_keeps_its_keys(campaign):
    out, data = campaign
    assert list(data) == ["arguments", "runs", "envelopes", "thesis"]
    assert list(data["arguments"]) == ARGUMENTS
    assert data["arguments"]["out"] == str(out) and data["arguments"]["jobs"] == 2
    assert data["arguments"]["suctions"] == [0.0, 30000.0]
    assert list(data["thesis"]) == ["table_5_3", "fig_5_5_saturation", "dry_friction_deg"]


@requires("dask.distributed")
def test_campaign_on_a_dask_cluster(tmp_path):
    import dask.distributed as distributed

    out = tmp_path / "dask"
    grid = Chapter5Grid(suctions=[30000.0], confining=[500.0, 1000.0], particles=120,
                        max_strain=0.01, inertial_number=3e-3)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        campaign = Chapter5Campaign(grid).run(out, scheduler=cluster.scheduler_address,
                                              progress=False)
    runs = campaign["runs"]
    assert campaign["reused"] == 0 and sorted(r["confining"] for r in runs) == [500, 1000]
    for run in runs:
        assert run["peak_axial_stress"] > run["confining"]
        assert 0.0 < run["saturation_at_peak"] < 1.0
        assert (out / run["folder"] / "history.h5").exists()
    assert campaign["arguments"]["scheduler"] == cluster.scheduler_address
