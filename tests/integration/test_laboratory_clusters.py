"""Liquid clusters in the laboratory tests at a suction (``--liquid clusters``;
pendular.procedures.loading_clusters): above every pore unit's filling suction they are the
pendular run bit for bit; where units fill, the history and summary hold the clusters' figures,
the wall stress balances the contacts', bridges' and clusters' stresses, and pores/ holds the
units; at a water content the closed liquid is held; what is not built is refused by one error
line naming the options."""

import json

import numpy as np
import pytest

from conftest import refused, run_in_process
from pendular import BridgeConfig, PrepareConfig, ShearConfig, TriaxialConfig, TriaxialTest
from pendular import read_history
from pendular.io.schema import undeclared_keys
from pendular.procedures import laboratory
from pendular.procedures.registry import config_from_options
from pendular.utils.parameters import ParameterError

#: A short fixed-seed triaxial (as the golden test's).
SAMPLE = PrepareConfig(particles=60, seed=3)
SHEAR = ShearConfig(max_strain=0.01, inertial_number=2e-3, records=20)


@pytest.mark.parametrize("periodic", [False, True])
def test_clusters_above_every_filling_suction_are_the_pendular_run(periodic, tmp_path):
    """At 300 kPa no pore unit fills (their filling suctions are some 20-50 kPa for R =
    24 µm): the clusters' history is the persisting bridges' bit for bit, between walls and
    in a periodic cell (whose stress is then the gathered one of the pair forces)."""
    histories = []
    for liquid in ("pendular", "clusters"):
        sample = PrepareConfig(particles=SAMPLE.particles, seed=SAMPLE.seed, periodic=periodic)
        config = TriaxialConfig(sample=sample, shear=SHEAR, vtk_frames=0, liquid=liquid,
                                bridges=BridgeConfig(300000.0, persist=True))
        summary = TriaxialTest(config).run(tmp_path / liquid, progress=False, plots=False)
        histories.append(read_history(tmp_path / liquid / "history.h5"))
    pendular, clusters = histories
    assert summary["clusters_at_peak"]["clusters"] == 0
    assert (clusters["clusters"].values == 0).all()
    for name in pendular.data_vars:
        assert np.array_equal(pendular[name].values, clusters[name].values), name


def test_a_triaxial_where_pores_fill_records_its_clusters(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(laboratory, "CLUSTER_RECORDS", 10)     # updates within 40 records
    out = tmp_path / "clusters"
    status, err = run_in_process("triaxial", [
        "--particles", "200", "--suction", "20000", "--liquid", "clusters", "--max-strain",
        "0.01", "--records", "40", "--vtk-frames", "5", "--quiet", "--out", out], capsys)
    assert status == 0, err
    history = read_history(out / "history.h5")
    clusters = history["clusters"].values
    assert clusters.min() > 0
    total = history["liquid_in_bridges"].values + history["liquid_in_clusters"].values
    assert np.allclose(total, 1.0, rtol=0, atol=1e-12)
    chi = np.trace(history["chi"].values, axis1=1, axis2=2) / 3
    with_clusters = np.trace(history["chi_with_clusters"].values, axis1=1, axis2=2) / 3
    assert (with_clusters > chi).all()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stress_balance_flagged"] == []          # the clusters' stress counted
    assert summary["cluster_updates"] == 4                  # every 10 of the 40 records
    peak = summary["clusters_at_peak"]
    assert peak["clusters"] == clusters[summary["peak_index"]]
    assert peak["p_effective_with_clusters"] == pytest.approx(
        summary["p_at_peak"] + peak["chi_with_clusters"] * 20000.0, rel=1e-12)
    assert summary["clusters_wet"]["clusters"] > 0
    assert undeclared_keys(summary, "triaxial") == []
    frames = sorted((out / "pores").glob("pores_*.vtu"))
    assert len(frames) == 5 and (out / "pores" / "pores.pvd").exists()   # wetted + 4 updates


def test_a_triaxial_at_a_water_content_holds_its_water_in_bridges_and_clusters(tmp_path,
                                                                             monkeypatch):
    """The closed liquid (LiquidClusters.hold_volume) at the wetting and at every update;
    between updates the bridges follow their gaps at the suction found."""
    monkeypatch.setattr(laboratory, "CLUSTER_RECORDS", 10)     # updates within 20 records
    config = TriaxialConfig(sample=SAMPLE, shear=SHEAR, vtk_frames=0, liquid="clusters",
                            bridges=BridgeConfig(water_content=0.02, control="volume"))
    summary = TriaxialTest(config).run(tmp_path, progress=False, plots=False)
    history = read_history(tmp_path / "history.h5")
    assert summary["clusters_wet"]["clusters"] > 0
    assert summary["cluster_updates"] == 2
    water = history["water_content"].values
    assert water[0] == pytest.approx(0.02, rel=1e-9)           # the wetting's solution
    assert np.abs(water / 0.02 - 1.0).max() < 1e-2      # bridges formed at new contacts
    suction = history["suction"].values
    assert len(np.unique(suction)) == 3                     # the wetting's, then two updates
    assert summary["formation_suction_pa"] == suction[0]
    assert undeclared_keys(summary, "triaxial") == []


def test_a_periodic_triaxial_counts_its_clusters_in_the_cells_stress(tmp_path, monkeypatch):
    """--periodic: the pore units cut from the grains' images, the cell's stress (the stress
    its servo holds) the contacts', bridges' and clusters' Love–Weber sums."""
    monkeypatch.setattr(laboratory, "CLUSTER_RECORDS", 10)     # updates within 20 records
    config = TriaxialConfig(sample=PrepareConfig(particles=60, seed=3, periodic=True),
                            shear=SHEAR, vtk_frames=0, liquid="clusters",
                            bridges=BridgeConfig(20000.0))
    summary = TriaxialTest(config).run(tmp_path, progress=False, plots=False)
    history = read_history(tmp_path / "history.h5")
    assert summary["clusters_wet"]["clusters"] > 0 and summary["cluster_updates"] == 2
    assert (history["clusters"].values > 0).all()
    inside = history["sigma_contact"].values + history["sigma_capillary"].values
    clusters = history["sigma_clusters"].values
    assert np.abs(clusters).max() > 0.1 * np.abs(inside).max()
    wall = history["sigma_wall"].values
    np.testing.assert_allclose(np.diagonal(inside + clusters, axis1=1, axis2=2), wall,
                               rtol=0, atol=1e-3 * np.abs(wall).max())
    assert undeclared_keys(summary, "triaxial") == []


@pytest.mark.parametrize("options, words", [
    ({}, ["--liquid", "--suction"]),
    ({"suction": 20000.0, "drainage": "undrained"}, ["--liquid", "--drainage"]),
    ({"suction": 20000.0, "bridges": "toroidal"}, ["--liquid", "--bridges"]),
])
def test_what_clusters_do_not_support_is_refused(options, words):
    with pytest.raises(ParameterError) as error:
        config_from_options("triaxial", {"liquid": "clusters", "particles": 60, **options})
    for word in words:
        assert word in str(error.value), (word, str(error.value))


@pytest.mark.parametrize("command, argv, words", [
    ("oedometer", [], ["--liquid", "--suction"]),
    ("simple-shear", ["--suction", "20000", "--bridges", "toroidal"], ["--liquid", "--bridges"]),
])
def test_the_command_line_refuses_them_in_one_line(command, argv, words, capsys, tmp_path):
    status, err = run_in_process(command, ["--liquid", "clusters", "--particles", "60", *argv,
                                           "--out", tmp_path / "out"], capsys)
    refused(status, err, *words)


def test_clusters_in_a_periodic_cell_on_the_gpu_are_refused_before_anything_runs(tmp_path):
    config = TriaxialConfig(sample=PrepareConfig(particles=60, seed=3, periodic=True),
                            shear=SHEAR, vtk_frames=0, liquid="clusters",
                            bridges=BridgeConfig(20000.0))
    with pytest.raises(ValueError, match="--liquid clusters runs on the GPU between walls "
                                         "only: --device gpu .*--periodic"):
        TriaxialTest(config).run(tmp_path / "out", device="gpu", progress=False)
    assert not (tmp_path / "out").exists()
