"""``pendular path PATH.toml`` as a user runs it: the Chapter 5 triaxial as a table gives, bit
for bit, the history of ``pendular triaxial``; each shipped table of examples/paths/ runs at a
small size; a multi-stage path resumes without its table; bad input is refused in one line;
and the Python API example of a hydro-mechanical path (examples/loading_path_api.py) runs. The
runs whose test is not about the preparation start from one sample prepared for the module
(--sample); the dry triaxial and its table prepare their own."""

import os
import runpy

import numpy as np
import pytest

from conftest import ROOT, assert_drawn, history_of, refused, run_in_process, summary_of
from pendular.dem.checkpoint import checkpoint_extra_state
from pendular.dem.sample import save_sample
from pendular.procedures.preparation import PrepareConfig, prepare_sample

PATHS = os.path.join(ROOT, "examples", "paths")
SMALL = ["--particles", "150", "--confining", "750", "--seed", "2", "--quiet"]


@pytest.fixture(scope="module")
def sample(tmp_path_factory):
    """["--sample", PATH] of the sample SMALL prepares, saved once for the module."""
    config = PrepareConfig(particles=150, confining=750.0, seed=2)
    sim, report = prepare_sample(config, progress=False)
    path = tmp_path_factory.mktemp("sample") / "sample.h5"
    save_sample(str(path), sim, report, identity={"seed": config.seed})
    return ["--sample", path]


@pytest.mark.parametrize("wet", [[], ["--suction", "30000"]], ids=["dry", "wet"])
def test_the_triaxial_as_a_table_is_the_triaxial_bit_for_bit(wet, sample, tmp_path, capsys):
    """The shipped triaxial.toml (to 25 % strain) with --records as the triaxial's: the same
    rows, every column of the triaxial's history equal to the last bit (dry: both prepare
    their sample; wet: both start from the module's)."""
    options = [*SMALL, *wet, "--inertial-number", "1e-2", "--records", "60",
               "--vtk-every", "0", *(sample if wet else [])]
    status, err = run_in_process("triaxial", [*options, "--max-strain", "0.25",
                                              "--out", tmp_path / "triaxial"], capsys)
    assert status == 0, err
    status, err = run_in_process("path", [os.path.join(PATHS, "triaxial.toml"), *options,
                                          "--out", tmp_path / "path"], capsys)
    assert status == 0, err
    expected, got = history_of(tmp_path / "triaxial"), history_of(tmp_path / "path")
    assert 61 <= len(expected["step"]) <= 63          # a row every steps // records, and the end
    assert expected["axial_strain"][-1] == pytest.approx(0.25, rel=1e-3)
    for name in ("sigma_wall", "axial_strain"):
        assert np.array_equal(got[name], expected[name]), name
    for name in expected:                                  # and every other column
        assert np.array_equal(got[name], expected[name], equal_nan=True), name
    assert np.all(got["stage"] == 0)
    triaxial, path = summary_of(tmp_path / "triaxial"), summary_of(tmp_path / "path")
    assert path["strain_rate"] == triaxial["strain_rate"]
    end = path["stages"][0]
    assert end["q"] == pytest.approx(expected["sigma_wall"][-1, 2]
                                     - expected["sigma_wall"][-1, :2].mean())
    if wet:
        assert "q_effective" in end and "sigma_effective" in got


def test_the_oedometer_table_loads_unloads_and_reloads(sample, tmp_path, capsys):
    out = tmp_path / "oedometer"
    status, err = run_in_process("path", [os.path.join(PATHS, "oedometer_unload.toml"),
                                          *SMALL, *sample, "--out", out], capsys)
    assert status == 0, err
    history, summary = history_of(out), summary_of(out)
    sigma, stage = history["sigma_wall"], history["stage"]
    assert sorted(set(stage)) == [0, 1, 2]
    ends = [row["row"] for row in summary["stages"]]
    targets = (10000.0, 2000.0, 20000.0)
    for row, target, sign in zip(ends, targets, (1, -1, 1)):
        # each stage stops at the first record past its target, within a step's change
        assert sign * (sigma[row, 2] - target) >= 0.0
        assert abs(sigma[row, 2] - target) < 0.01 * target
    # lateral walls held: the volumetric strain is the axial strain
    assert np.allclose(history["volumetric_strain"], history["axial_strain"], atol=1e-12)
    void = [row["void_ratio"] for row in summary["stages"]]
    assert void[1] > void[0] > void[2]          # swells on unloading, compacts past 10 kPa
    assert summary["has_peak"] is False and "peak_q" not in summary
    assert summary["stages"][0]["p"] == pytest.approx(sigma[ends[0]].mean())
    for name in ("path.png", "sample.h5", "vtk"):
        assert (out / name).exists()
    assert_drawn(out / "path.png")


def test_the_cyclic_table_cycles_between_its_axial_stresses(sample, tmp_path, capsys):
    out = tmp_path / "cyclic"
    status, err = run_in_process("path", [os.path.join(PATHS, "cyclic.toml"), *SMALL, *sample,
                                          "--vtk-every", "0", "--out", out], capsys)
    assert status == 0, err
    history, summary = history_of(out), summary_of(out)
    assert len(summary["stages"]) == 11 and sorted(set(history["stage"])) == list(range(11))
    axial = [row["sigma_wall"][2] for row in summary["stages"]]
    assert all(1600.0 <= value < 1616.0 for value in axial[0::2])
    assert all(990.0 < value <= 1000.0 for value in axial[1::2])
    lateral = history["sigma_wall"][:, :2]
    assert np.abs(lateral / 750.0 - 1.0).max() < 0.05        # servoed at the confining stress
    # the strain accumulates over the cycles (ratcheting), never back to where it started
    strain = [row["axial_strain"] for row in summary["stages"]]
    assert strain[-1] > strain[0] > 0.0


def test_an_interrupted_path_resumes_to_the_same_history_without_its_table(sample, tmp_path,
                                                                          capsys):
    table = tmp_path / "cycles.toml"
    with open(os.path.join(PATHS, "cyclic.toml")) as shipped:
        table.write_text(shipped.read().replace("repeat = 5", "repeat = 2"))
    options = [*SMALL, *sample, "--vtk-every", "0", "--checkpoint-every", "2000"]
    whole, stopped = tmp_path / "whole", tmp_path / "stopped"
    status, err = run_in_process("path", [table, *options, "--out", whole], capsys)
    assert status == 0, err
    steps = summary_of(whole)["steps"]
    status, _ = run_in_process("path", [table, *options, "--out", stopped,
                                        "--stop-after", str(int(0.6 * steps))], capsys)
    assert status == 130 and summary_of(stopped)["completed"] is False
    table.unlink()                                  # the run keeps its stages
    status, err = run_in_process("path", ["--resume", stopped, "--quiet"], capsys)
    assert status == 0, err
    expected, got = history_of(whole), history_of(stopped)
    for name in expected:
        assert np.array_equal(got[name], expected[name], equal_nan=True), name


def test_a_path_stopped_in_a_stage_of_other_controls_resumes_bit_for_bit(sample, tmp_path,
                                                                        capsys):
    """A suction ramp, then a compression at a strain rate: a checkpoint of the second stage
    loads into that stage's controls (LoadingPath.enter_stage), not the first's."""
    table = tmp_path / "dry_then_load.toml"
    table.write_text("[[stage]]\nstress = {x = 750, y = 750, z = 750}\nsuction = 20000\n"
                     "suction_rate = 2e6\n[[stage]]\nstrain_rate = {z = 'quasi-static'}\n"
                     "stress = {x = 750, y = 750}\nuntil = {strain = 0.003, axis = 'z'}\n")
    options = [*SMALL, *sample, "--suction", "30000", "--vtk-every", "0", "--no-plots",
               "--checkpoint-every", "250"]
    whole, stopped = tmp_path / "whole", tmp_path / "stopped"
    status, err = run_in_process("path", [table, *options, "--out", whole], capsys)
    assert status == 0, err
    stages = summary_of(whole)["stages"]
    steps = summary_of(whole)["steps"]
    second = stages[1]["step"] - stages[0]["step"]      # the second stage's steps
    status, _ = run_in_process("path", [table, *options, "--out", stopped, "--stop-after",
                                        str(steps - second // 2)], capsys)
    assert status == 130
    assert checkpoint_extra_state(stopped / "checkpoint.h5")["path"]["stage"] == 1
    status, err = run_in_process("path", ["--resume", stopped, "--quiet"], capsys)
    assert status == 0, err
    expected, got = history_of(whole), history_of(stopped)
    for name in expected:
        assert np.array_equal(got[name], expected[name], equal_nan=True), name


@pytest.mark.parametrize("table, arguments, words", [
    ("[[stage]]\nstress = {x = 750, y = 750, z = 750}\n[[stage]]\nstres = {x = 5}\n", [],
     ("path.toml: stage 2: unknown key 'stres'; valid: stress, strain_rate",)),
    ("[[stage]]\nstress = {x = 750, y = 750}\nstrain_rate = {z = 'quasi-static'}\n", [],
     ("path.toml: stage 1: until static needs",)),
    ("", [], ("path.toml: no stage",)),
    ("[sample]\nparticles = 100\n", [], ("unknown key 'sample'", "command line")),
    ("[[stage]]\nstress = {x = 750, y = 750, z = 1000}\n", ["--records", "50"],
     ("--records = 50 applies to a path of one stage",)),
    ("[[stage]]\nstress = {x = 750, y = 750, z = 1000}\n", ["--particles", "10"],
     ("--particles = 10",)),
    ("[[stage]]\nstress = {x = 750, y = 750, z = 1000}\n", ["--resume", "somewhere"],
     ("--resume", "cannot be changed")),
    (None, [], ("PATH.toml is missing",)),
])
def test_bad_input_is_refused_in_one_line(table, arguments, words, tmp_path, capsys):
    argv = []
    if table is not None:
        (tmp_path / "path.toml").write_text(table)
        argv = [tmp_path / "path.toml"]
    out = tmp_path / "out"
    status, err = run_in_process("path", [*argv, "--particles", "100", *arguments,
                                          "--out", out], capsys)
    refused(status, err, *words)
    assert not out.exists()


def test_the_python_api_example_composes_wetting_loading_drying_and_unloading(
        tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    found = runpy.run_path(os.path.join(ROOT, "examples", "loading_path_api.py"))
    loading, drying, unloading = found["loading"], found["drying"], found["unloading"]
    assert 10000.0 <= loading["sigma_wall"][-1, 2] < 10100.0
    # the drying: the suction in equal ratios from 30 to 300 kPa, sigma_v held, x and y fixed
    assert np.allclose(drying["suction"], np.geomspace(30e3, 300e3, 5), rtol=1e-12)
    assert np.abs(drying["sigma_wall"][1:, 2] / 10e3 - 1.0).max() < 0.01
    assert np.all(drying["saturation"][1:] < drying["saturation"][:-1])
    assert drying["volumetric_strain"] == pytest.approx(drying["axial_strain"], abs=1e-12)
    assert 1000.0 >= unloading["sigma_wall"][-1, 2] > 990.0
    assert unloading["void_ratio"][-1] > drying["void_ratio"][-1]    # it swells back
