"""`pendular simple-shear` as a user runs it: drained (with a consolidation to the normal
stress) and wet at constant volume, their outputs and keys, a resumed run bit for bit, and bad
input refused in one line."""

import subprocess
import sys

import numpy as np
import pytest

from conftest import assert_drawn, history_of, refused, run_in_process, summary_of
from pendular.dem.sample import save_sample
from pendular.procedures.preparation import PrepareConfig, prepare_sample

SMALL = ["--particles", "200", "--seed", "4", "--max-strain", "0.02", "--quiet"]


@pytest.fixture(scope="module")
def drained_run(tmp_path_factory):
    """A dry drained shear at 600 Pa from a sample at 750 Pa, with checkpoints."""
    out = tmp_path_factory.mktemp("simple_shear") / "drained"
    subprocess.run([sys.executable, "-m", "pendular", "simple-shear", *SMALL, "--normal-stress",
                    "600", "--checkpoint-every", "1000", "--out", str(out)],
                   check=True, capture_output=True, text=True, timeout=600)
    return out


def test_a_drained_shear_writes_its_history_summary_and_figures(drained_run):
    summary, (history, units) = summary_of(drained_run), history_of(drained_run, units=True)
    rows = len(history["step"])
    assert history["sigma_wall"].shape == (rows, 3) and history["axial_strain"].shape == (rows,)
    for name in ("shear_strain", "shear_stress", "normal_stress", "stage"):
        assert history[name].shape == (rows,), name
    assert units["shear_stress"] == units["normal_stress"] == "Pa"
    assert units["shear_strain"] == "1"
    shear = history["stage"] == 1
    assert np.all(history["shear_strain"][~shear] == 0.0)
    assert 0.02 <= history["shear_strain"][-1] < 0.02 * 1.001     # to the step past it
    assert np.all(np.diff(history["shear_strain"][shear]) > 0.0)
    np.testing.assert_array_equal(history["normal_stress"], history["sigma_wall"][:, 2])
    # consolidated to the normal stress, held there through the shear
    assert np.mean(history["normal_stress"][shear]) == pytest.approx(600.0, rel=0.02)
    contact = history["sigma_contact"]
    np.testing.assert_allclose(history["shear_stress"][shear],
                               -0.5 * (contact[shear, 0, 2] + contact[shear, 2, 0]),
                               rtol=0.05, atol=0.02 * 600.0)
    for key, unit in (("peak_shear_stress", "Pa"), ("phi_peak_deg", "deg"),
                      ("shear_strain_at_peak", "1"), ("residual_stress_ratio", "1"),
                      ("phi_residual_deg", "deg"), ("max_dilatancy", "1"),
                      ("dilatancy_angle_deg", "deg")):
        assert summary[key] is not None and summary["units"][key] == unit, key
    ratio = history["shear_stress"][shear] / history["normal_stress"][shear]
    assert summary["peak_stress_ratio"] == pytest.approx(np.max(ratio))
    assert summary["phi_peak_deg"] == pytest.approx(np.degrees(np.arctan(np.max(ratio))))
    assert 0.1 < summary["peak_stress_ratio"] < 1.0 and summary["completed"]
    assert "max_volume_change" not in summary
    assert_drawn(drained_run / "simple_shear.png")
    # read back by the tests below: the frames, and the checkpoint that --resume continues
    for name in ("sample.h5", "checkpoint.h5", "vtk/particles.pvd"):
        assert (drained_run / name).stat().st_size > 0, name


def test_the_paraview_frames_follow_the_shear_strain_and_draw_pairs_through_the_shear(
        drained_run):
    """The series' time axis is gamma in %, and each contact line, through a z face of the
    sheared cell included, is as long as its pair's branch vector: at most the sum of the
    radii (a line missing the shift delta would span the cell)."""
    import meshio

    pvd = (drained_run / "vtk" / "particles.pvd").read_text()
    assert "shear_strain_percent" in pvd
    times = [float(part.split('"')[0]) for part in pvd.split('timestep="')[1:]]
    history = history_of(drained_run)
    assert times[-1] == pytest.approx(100.0 * history["shear_strain"][-1], rel=0.05)
    last = sorted((drained_run / "vtk").glob("contacts_*.vtu"))[-1]
    lines = meshio.read(last)
    particles = meshio.read(str(last).replace("contacts_", "particles_"))
    ends = lines.points[lines.cells_dict["line"]]
    length = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
    assert len(length) > 0
    assert length.max() <= 2.0 * particles.point_data["radius"].max()


def test_a_resumed_shear_has_the_history_of_an_uninterrupted_one(drained_run, tmp_path,
                                                                   capsys):
    out = tmp_path / "stopped"
    steps = summary_of(drained_run)["steps"]
    argv = [*SMALL, "--normal-stress", "600", "--checkpoint-every", "1000", "--out", out]
    status, _ = run_in_process("simple-shear", [*argv, "--stop-after", str(int(0.7 * steps))],
                               capsys)
    assert status == 130 and summary_of(out)["completed"] is False
    status, err = run_in_process("simple-shear", ["--resume", out, "--quiet"], capsys)
    assert status == 0, err
    expected, got = history_of(drained_run), history_of(out)
    for name in expected:
        assert np.array_equal(got[name], expected[name], equal_nan=True), name


def test_a_wet_shear_at_constant_volume_keeps_its_volume(tmp_path, capsys):
    out = tmp_path / "wet"
    status, err = run_in_process("simple-shear", [*SMALL, "--suction", "30000",
                                                  "--constant-volume", "--out", out], capsys)
    assert status == 0, err
    summary, history = summary_of(out), history_of(out)
    assert "stage" not in history                 # at the confining stress: no consolidation
    assert summary["max_volume_change"] == 0.0
    assert np.all(history["volumetric_strain"] == 0.0)
    assert history["saturation"][-1] > 0.0 and history["bridges"][-1] > 0
    assert summary["peak_shear_stress"] > 0.0 and summary["phi_peak_deg"] > 0.0
    assert "max_dilatancy" not in summary
    # the effective stress of Eq. 3.43 adds the capillary stress psi to the net one
    psi = history["psi"]
    tau = history["shear_stress"] - 0.5 * (psi[:, 0, 2] + psi[:, 2, 0])
    ratio = tau / (history["normal_stress"] + psi[:, 2, 2])
    assert summary["peak_stress_ratio_effective"] == pytest.approx(ratio.max())
    assert summary["phi_peak_effective_deg"] == pytest.approx(
        np.degrees(np.arctan(ratio.max())))
    assert summary["phi_peak_effective_deg"] < summary["phi_peak_deg"]   # psi_zz > 0
    assert_drawn(out / "simple_shear.png")


@pytest.mark.parametrize("liquid", [["--suction", "20000"], ["--water-content", "4"]])
def test_a_shear_with_liquid_clusters_records_them_in_the_sheared_cell(liquid, tmp_path, capsys,
                                                                      monkeypatch):
    """--liquid clusters: the pore units cut from the sheared cell's images, updated during
    the shear, their history columns, and the cell's stress (the normal stress its servo
    holds, the shear stress) the contacts', bridges' and clusters' Love–Weber sums."""
    from pendular.io.schema import undeclared_keys
    from pendular.procedures import laboratory

    monkeypatch.setattr(laboratory, "CLUSTER_RECORDS", 5)      # updates within 20 records
    out = tmp_path / "clusters"
    status, err = run_in_process("simple-shear", [
        "--particles", "60", "--seed", "3", "--max-strain", "0.02", "--record-strain", "0.001",
        *liquid, "--liquid", "clusters", "--quiet", "--out", out], capsys)
    assert status == 0, err
    summary, history = summary_of(out), history_of(out)
    rows = len(history["step"])
    for name in ("clusters", "liquid_in_bridges", "liquid_in_clusters",
                 "liquid_in_largest_cluster", "trimers", "liquid_in_trimers", "saturation",
                 "saturation_pore_units", "water_content"):
        assert history[name].shape == (rows,), name
    assert history["largest_cluster_percolates"].shape == (rows, 3)
    assert history["sigma_clusters"].shape == history["chi_with_clusters"].shape == (rows, 3, 3)
    assert (history["clusters"] > 0).all()
    np.testing.assert_allclose(history["liquid_in_bridges"] + history["liquid_in_clusters"],
                               1.0, rtol=0, atol=1e-12)
    if liquid[0] == "--water-content":
        np.testing.assert_allclose(history["water_content"], 0.04, rtol=1e-2)
    updates = summary["cluster_updates"]
    assert updates >= 3 and summary["clusters_final"]["clusters"] > 0
    assert len(list((out / "pores").glob("pores_*.vtu"))) == updates + 1
    inside = history["sigma_contact"] + history["sigma_capillary"] + history["sigma_clusters"]
    scale = np.abs(history["sigma_wall"]).max()
    np.testing.assert_allclose(np.diagonal(inside, axis1=1, axis2=2), history["sigma_wall"],
                               rtol=0, atol=1e-3 * scale)
    np.testing.assert_allclose(-0.5 * (inside[:, 0, 2] + inside[:, 2, 0]),
                               history["shear_stress"], rtol=0, atol=1e-3 * scale)
    assert summary["stress_balance_flagged"] == []
    assert undeclared_keys(summary, "simple-shear") == []


@pytest.mark.parametrize("arguments, words", [
    (["--max-strain", "-0.1"], ("--max-strain = -0.1", "[1e-06, 10]")),
    (["--max-strain", "20"], ("--max-strain = 20", "[1e-06, 10]")),
    (["--normal-stress", "-5"], ("--normal-stress = -5", "(0, 1e+07]")),
    (["--shear-rate", "0"], ("--shear-rate = 0", "(0, 1e+06]")),
    (["--record-strain", "0.5"], ("--record-strain = 0.5",)),
    (["--inertial-number", "0.5"], ("inertial number", "(0, 0.01]")),
])
def test_bad_input_is_refused_in_one_line(arguments, words, tmp_path, capsys):
    status, err = run_in_process("simple-shear", ["--particles", "200", *arguments,
                                                  "--out", tmp_path / "bad"], capsys)
    refused(status, err, *words)
    assert not (tmp_path / "bad").exists()


def test_a_sample_in_walls_is_refused_in_one_line(tmp_path, capsys):
    """A sample prepared in six walls (the smallest a simple shear takes, 60 spheres)."""
    config = PrepareConfig(particles=60, seed=1)
    sim, report = prepare_sample(config, progress=False)
    save_sample(str(tmp_path / "walls.h5"), sim, report)
    status, err = run_in_process("simple-shear", ["--particles", "60", "--sample",
                                                  tmp_path / "walls.h5",
                                                  "--out", tmp_path / "walls"], capsys)
    refused(status, err, "six walls", "periodic")
