"""Outputs of the triaxial scenario: ParaView series, plots, checkpoints and --resume. Every run
is scenarios/triaxial.py's command run in-process (the same pendular.cli.run_command, without
a new interpreter: the script's own process is tested in test_triaxial.py and
test_faults.py)."""

import contextlib
import io
import json
import os
import xml.etree.ElementTree as ElementTree

import h5py
import meshio
import numpy as np
import pytest

from conftest import assert_drawn, run_in_process
from pendular.cli import run_command

PARTICLES = 150
BASE = ["--particles", str(PARTICLES), "--max-strain", "0.01", "--inertial-number", "2e-3",
        "--checkpoint-every", "50", "--quiet"]
KINDS = {"dry": [], "wet": ["--suction", "30000"]}


def in_process(capsys, *arguments):
    """(exit status, stderr) of scenarios/triaxial.py's command run in-process."""
    return run_in_process("triaxial", arguments, capsys, prog="triaxial.py")


@pytest.fixture(scope="module", params=sorted(KINDS))
def finished(request, tmp_path_factory):
    """(kind, folder) of an uninterrupted run."""
    out = tmp_path_factory.mktemp(request.param) / "run"
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        status = run_command("triaxial", [*BASE, *KINDS[request.param], "--out", str(out)],
                             prog="triaxial.py")
    assert status == 0, err.getvalue()
    return request.param, out


def frames(pvd):
    """The .vtu files of a .pvd collection, in order, with their times."""
    collection = ElementTree.parse(pvd).getroot().find("Collection")
    return [(float(d.get("timestep")), os.path.join(os.path.dirname(pvd), d.get("file")))
            for d in collection.findall("DataSet")]


def test_paraview_series_read_back_with_meshio(finished):
    kind, out = finished
    particles = frames(out / "vtk" / "particles.pvd")
    assert len(particles) > 20                       # about 50 frames over the shear
    times = [time for time, _ in particles]
    assert times == sorted(times) and len(set(times)) == len(times)
    with h5py.File(out / "history.h5") as handle:          # the time axis is the strain [%]
        assert times[-1] == pytest.approx(100 * handle["history"]["axial_strain"][-1], rel=1e-12)
        assert handle.attrs["vtk_every"] > 0
    with h5py.File(out / "sample.h5") as handle:
        radius = handle["radius"][()]
    with h5py.File(out / "history.h5") as handle:
        history = {name: handle["history"][name][()] for name in ("axial_strain", "sigma_wall",
                                                                   "coordination")}
    for _, path in (particles[0], particles[-1]):
        mesh = meshio.read(path)
        order = np.argsort(mesh.point_data["id"])
        assert np.array_equal(mesh.point_data["id"][order], np.arange(PARTICLES))
        assert np.array_equal(mesh.point_data["radius"][order], radius)    # the sample's
        # the frame is a history record: its strain, and its contacts the record's 2 Nc / N
        row = np.flatnonzero(history["axial_strain"] == mesh.field_data["axial_strain"][0])
        assert len(row) == 1
        coordination = mesh.point_data["coordination"]
        assert coordination.mean() == pytest.approx(history["coordination"][row[0]], rel=1e-12)
        force = mesh.point_data["contact_force"]
        assert np.all((force > 0.0) == (coordination > 0))        # rattlers carry nothing
        assert np.all(np.isfinite(mesh.point_data["velocity"]))
        bridges = mesh.point_data["bridges"]
        assert (bridges.sum() > 0) == (kind == "wet")
        assert np.all(bridges >= coordination) if kind == "wet" else not bridges.any()
    walls = meshio.read(frames(out / "vtk" / "walls.pvd")[-1][1])
    assert walls.cells_dict["quad"].shape == (6, 4)
    # the mean of each axis's two walls is the history's wall stress of the last record
    stress = walls.cell_data["normal_stress"][0]
    assert 0.5 * (stress[0::2] + stress[1::2]) == pytest.approx(history["sigma_wall"][-1],
                                                                rel=1e-12)
    assert len(frames(out / "vtk" / "bridges.pvd")) == len(particles)
    if kind == "wet":          # meshio cannot read the empty (cell-less) files of a dry run
        lines = meshio.read(frames(out / "vtk" / "bridges.pvd")[-1][1])
        count = len(lines.cells_dict["line"])
        assert 2 * count == meshio.read(particles[-1][1]).point_data["bridges"].sum()
        force, volume = lines.cell_data["force"][0], lines.cell_data["volume"][0]
        assert np.all(force > 0.0) and np.all(volume > 0.0)       # attractive, holds liquid
        # a bridge's filling angles [deg] lie in (0, 90)
        for name in ("delta1", "delta2"):
            angle = lines.cell_data[name][0]
            assert np.all((angle > 0.0) & (angle < 90.0)), name


def test_plots_are_written(finished):
    kind, out = finished
    names = {"q_p.png", "volumetric_strain.png", "stress_path.png"} | (
        {"capillary_stress.png", "saturation.png"} if kind == "wet" else set())
    assert set(os.listdir(out / "plots")) == names
    for name in names:
        assert_drawn(out / "plots" / name)
    assert_drawn(out / "triaxial.png")


def test_resumed_run_has_the_history_of_an_uninterrupted_one(finished, tmp_path, capsys):
    kind, out = finished
    run = tmp_path / "interrupted"
    status, err = in_process(capsys, *BASE, *KINDS[kind], "--out", run, "--stop-after", "237")
    assert status == 130, err
    assert (run / "checkpoint.h5").exists()
    partial = json.loads((run / "summary.json").read_text())     # what was sheared is kept
    assert partial["completed"] is False
    with h5py.File(run / "history.h5") as handle:
        assert 0 < len(handle["history"]["step"]) < 500       # fewer rows than the full run
    status, err = in_process(capsys, "--resume", run, "--quiet")
    assert status == 0, err
    with h5py.File(out / "history.h5") as whole, h5py.File(run / "history.h5") as resumed:
        expected, got = whole["history"], resumed["history"]
        assert set(got) == set(expected)
        assert len(got["step"]) > 100
        for name in expected:
            assert np.array_equal(got[name][()], expected[name][()]), name
        assert resumed.attrs["particles"] == PARTICLES
    assert (run / "summary.json").exists() and (run / "plots" / "q_p.png").exists()
    # the ParaView series continues across the interruption without repeated frames
    steps = [os.path.basename(path) for _, path in frames(run / "vtk" / "particles.pvd")]
    assert steps == [os.path.basename(p) for _, p in frames(out / "vtk" / "particles.pvd")]


def test_resume_refuses_new_arguments_and_runs_without_checkpoint(tmp_path, capsys):
    status, err = in_process(capsys, "--resume", tmp_path, "--suction", "1000")
    assert status != 0 and "--suction" in err
    status, err = in_process(capsys, "--resume", tmp_path)
    assert status != 0 and "sample.h5" in err


def test_a_run_at_a_water_content_resumes_with_its_liquid_account(tmp_path, capsys):
    """The closed liquid (--water-content, shared at rupture) comes back from the checkpoint:
    the resumed history has the uninterrupted one's liquid columns, to the bit (60 spheres, no
    ParaView frames: their series across a resume is checked above)."""
    argv = [*BASE[2:], "--particles", "60", "--water-content", "1", "--rupture-liquid", "shared",
            "--vtk-frames", "0"]
    whole, run = tmp_path / "whole", tmp_path / "interrupted"
    status, err = in_process(capsys, *argv, "--out", whole)
    assert status == 0, err
    status, err = in_process(capsys, *argv, "--out", run, "--stop-after", "237")
    assert status == 130, err
    status, err = in_process(capsys, "--resume", run, "--quiet")
    assert status == 0, err
    with h5py.File(whole / "history.h5") as full, h5py.File(run / "history.h5") as resumed:
        expected, got = full["history"], resumed["history"]
        assert {"liquid_bridges", "liquid_film", "liquid_lost"} <= set(got) == set(expected)
        for name in expected:
            assert np.array_equal(got[name][()], expected[name][()]), name
    summary = json.loads((run / "summary.json").read_text())
    assert summary["completed"] and summary["liquid_balance_error"] < 1e-9
