"""Outputs of the triaxial scenario: ParaView series, plots, checkpoints and --resume."""

import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ElementTree

import h5py
import meshio
import numpy as np
import pytest

from conftest import ROOT

SCENARIO = os.path.join(ROOT, "scenarios", "triaxial.py")
PARTICLES = 150
BASE = ["--particles", str(PARTICLES), "--max-strain", "0.01", "--inertial-number", "2e-3",
        "--checkpoint-every", "50", "--quiet"]
KINDS = {"dry": [], "wet": ["--suction", "30000"]}


def triaxial(*arguments, check=True):
    return subprocess.run([sys.executable, SCENARIO, *arguments], capture_output=True,
                          text=True, check=check)


@pytest.fixture(scope="module", params=sorted(KINDS))
def finished(request, tmp_path_factory):
    """(kind, folder) of an uninterrupted run."""
    out = tmp_path_factory.mktemp(request.param) / "run"
    triaxial(*BASE, *KINDS[request.param], "--out", str(out))
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
    for _, path in (particles[0], particles[-1]):
        mesh = meshio.read(path)
        assert len(mesh.points) == PARTICLES
        assert mesh.point_data["radius"].shape == (PARTICLES,)
        assert np.all(mesh.point_data["radius"] > 0)
        for name in ("velocity", "contact_force", "coordination", "bridges"):
            assert len(mesh.point_data[name]) == PARTICLES, name
        bridges = mesh.point_data["bridges"]
        assert (bridges.sum() > 0) == (kind == "wet")
    walls = meshio.read(frames(out / "vtk" / "walls.pvd")[-1][1])
    assert walls.cells_dict["quad"].shape == (6, 4)
    assert len(frames(out / "vtk" / "bridges.pvd")) == len(particles)
    if kind == "wet":          # meshio cannot read the empty (cell-less) files of a dry run
        lines = meshio.read(frames(out / "vtk" / "bridges.pvd")[-1][1])
        count = len(lines.cells_dict["line"])
        assert 2 * count == meshio.read(particles[-1][1]).point_data["bridges"].sum()
        for name in ("force", "volume", "delta1", "delta2"):
            assert lines.cell_data[name][0].shape == (count,), name


def test_plots_are_written(finished):
    kind, out = finished
    names = {"q_p.png", "volumetric_strain.png", "stress_path.png"} | (
        {"capillary_stress.png", "saturation.png"} if kind == "wet" else set())
    assert set(os.listdir(out / "plots")) == names
    for name in names:
        assert (out / "plots" / name).stat().st_size > 0
    assert (out / "triaxial.png").stat().st_size > 0


def test_resumed_run_has_the_history_of_an_uninterrupted_one(finished, tmp_path):
    kind, out = finished
    run = tmp_path / "interrupted"
    stopped = triaxial(*BASE, *KINDS[kind], "--out", str(run), "--stop-after", "237",
                       check=False)
    assert stopped.returncode == 130, stopped.stderr
    assert (run / "checkpoint.h5").exists()
    partial = json.loads((run / "summary.json").read_text())     # what was sheared is kept
    assert partial["completed"] is False
    with h5py.File(run / "history.h5") as handle:
        assert 0 < len(handle["history"]["step"]) < 500       # fewer rows than the full run
    triaxial("--resume", str(run), "--quiet")
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


def test_resume_refuses_new_arguments_and_runs_without_checkpoint(tmp_path):
    changed = triaxial("--resume", str(tmp_path), "--suction", "1000", check=False)
    assert changed.returncode != 0 and "--suction" in changed.stderr
    missing = triaxial("--resume", str(tmp_path), check=False)
    assert missing.returncode != 0 and "sample.h5" in missing.stderr


def test_a_run_at_a_water_content_resumes_with_its_liquid_account(tmp_path):
    """The closed liquid (--water-content, shared at rupture) comes back from the checkpoint:
    the resumed history has the uninterrupted one's liquid columns, to the bit."""
    argv = [*BASE, "--water-content", "1", "--liquid", "shared"]
    whole, run = tmp_path / "whole", tmp_path / "interrupted"
    triaxial(*argv, "--out", str(whole))
    stopped = triaxial(*argv, "--out", str(run), "--stop-after", "237", check=False)
    assert stopped.returncode == 130, stopped.stderr
    triaxial("--resume", str(run), "--quiet")
    with h5py.File(whole / "history.h5") as full, h5py.File(run / "history.h5") as resumed:
        expected, got = full["history"], resumed["history"]
        assert {"liquid_bridges", "liquid_film", "liquid_lost"} <= set(got) == set(expected)
        for name in expected:
            assert np.array_equal(got[name][()], expected[name][()]), name
    summary = json.loads((run / "summary.json").read_text())
    assert summary["completed"] and summary["liquid_balance_error"] < 1e-9
