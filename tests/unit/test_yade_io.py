"""YADE text files: sphere packings (export/ymport.textExt) and plot.saveDataTxt histories."""

import bz2
import gzip

import numpy as np
import pytest

from conftest import ROOT, requires

from pendular.interop.yade.formats import (read_plot_data, read_plot_headers, read_spheres,
    write_spheres)

# Written by YADE 2023.02a itself:
#   plot.addData(i=0, t=0.0, sz=1.5e3)
#   plot.addData(i=100, t=1.25e-4, sz=1843.25, eps=Vector3(1e-3, 2, 3))
#   plot.saveDataTxt(name, headers={'confining': 750.0, 'run': 'dry'})
SAVE_DATA_TXT = (
    "# confining=\t750.0\n"
    "# run=\tdry\n"
    "# eps_x\t\teps_y\t\teps_z\t\ti\t\tsz\t\tt\n"
    "nan\tnan\tnan\t0\t1500.0\t0.0\n"
    "0.001\t2.0\t3.0\t100\t1843.25\t0.000125\n"
)

# The start of a file written by yade.export.textExt(name, format='x_y_z_r', comment='packing').
EXPORT_TEXT_EXT = "#format x_y_z_r\n# packing\n0.1\t0.2\t0.3\t0.05\n1e-05\t2e-05\t3e-05\t2.4e-05\n"


@pytest.fixture
def packing():
    rng = np.random.default_rng(7)
    positions = rng.uniform(0.0, 5e-4, size=(50, 3))
    radii = rng.uniform(2.0e-5, 2.8e-5, size=50)
    return positions, radii


def test_round_trip_is_exact(tmp_path, packing):
    positions, radii = packing
    path = tmp_path / "spheres.txt"
    assert write_spheres(path, positions, radii, [0, 0, 0], [5e-4, 5e-4, 6e-4]) == 50
    read_pos, read_rad, lo, hi = read_spheres(path)
    np.testing.assert_array_equal(read_pos, positions)
    np.testing.assert_array_equal(read_rad, radii)
    np.testing.assert_array_equal(lo, [0, 0, 0])
    np.testing.assert_array_equal(hi, [5e-4, 5e-4, 6e-4])
    assert read_pos.dtype == np.float64 and read_pos.flags.c_contiguous


def test_layout_is_the_one_ymport_reads(tmp_path, packing):
    positions, radii = packing
    path = tmp_path / "spheres.txt"
    write_spheres(path, positions, radii)
    lines = path.read_text().splitlines()
    assert lines[0] == "#format x_y_z_r"
    assert all(line.strip() for line in lines)  # ymport.textExt fails on a blank line
    assert len(lines[1].split("\t")) == 4 and float(lines[1].split("\t")[3]) == radii[0]
    assert read_spheres(path)[2] is None  # no box given, none recorded
    assert not [p for p in tmp_path.iterdir() if p.name != "spheres.txt"]  # temp file gone


def test_reads_yade_export(tmp_path):
    path = tmp_path / "export.txt"
    path.write_text(EXPORT_TEXT_EXT)
    positions, radii, lo, hi = read_spheres(path)
    np.testing.assert_allclose(positions, [[0.1, 0.2, 0.3], [1e-5, 2e-5, 3e-5]])
    np.testing.assert_allclose(radii, [0.05, 2.4e-5])
    assert lo is None and hi is None


@pytest.mark.parametrize("text, message", [
    ("#format x_y_z_r\n0 0 0\n", "line 2: expected 4 columns"),
    ("#format x_y_z_r\n0 0 0 1e-5 3\n", "line 2: expected 4 columns"),
    ("#format x_y_z_r\n0 0 0 1e-5\n0 abc 0 1e-5\n", "line 3: y = 'abc' is not a number"),
    ("#format x_y_z_r\n0 nan 0 1e-5\n", "line 2: y = 'nan' is not finite"),
    ("#format x_y_z_r\n0 0 1e400 1e-5\n", "line 2: z = '1e400' is not finite"),
    ("#format x_y_z_r\n0 0 0 0\n", "line 2: radius r = 0 must be > 0"),
    ("#format x_y_z_r\n0 0 0 -1e-5\n", "line 2: radius r = -1e-5 must be > 0"),
    ("#format x_y_z_r_matId\n0 0 0 1e-5 1\n", "line 1: unsupported sphere format 'x_y_z_r_matId'"),
    ("#format x_y_z_r\n# box_lo 0 0 0 box_hi 1 1\n", "line 2: box line must read"),
    ("#format x_y_z_r\n# box_lo 0 0 0 box_hi 1 -1 1\n0 0 0 1\n", "line 2: box_hi"),
    ("#format x_y_z_r\n# box_lo 0 0 0 box_hi 1 one 1\n0 0 0 1\n",
     "line 2: box coordinate 'one' is not a number"),
    ("#format x_y_z_r\n# box_lo 0 inf 0 box_hi 1 1 1\n0 0 0 1\n",
     "line 2: box coordinate 'inf' is not finite"),
    ("#format x_y_z_r\n# only comments\n", "no sphere found"),
])
def test_bad_sphere_file_refused(tmp_path, text, message):
    path = tmp_path / "bad.txt"
    path.write_text(text)
    with pytest.raises(ValueError) as error:
        read_spheres(path)
    assert message in str(error.value)
    assert str(path) in str(error.value)


@pytest.mark.parametrize("positions, radii, box, message", [
    (np.zeros((2, 2)), np.ones(2), (None, None), "positions must have shape (N, 3)"),
    (np.zeros((2, 3)), np.ones(3), (None, None), "radii must have shape (2,)"),
    (np.zeros((0, 3)), np.ones(0), (None, None), "no sphere"),
    (np.array([[0, 0, np.inf]]), np.ones(1), (None, None), "positions[0, 2] = inf"),
    (np.zeros((2, 3)), np.array([1.0, 0.0]), (None, None),
     "radii[1] = 0.0 m must be finite and > 0"),
    (np.zeros((1, 3)), np.ones(1), ([0, 0, 0], None), "box_lo and box_hi must be given together"),
    (np.zeros((1, 3)), np.ones(1), ([0, 0, 0], [1, 0, 1]), "must exceed box_lo"),
])
def test_bad_spheres_not_written(tmp_path, positions, radii, box, message):
    path = tmp_path / "never.txt"
    with pytest.raises(ValueError) as error:
        write_spheres(path, positions, radii, *box)
    assert message in str(error.value)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("opener, suffix", [(open, ".txt"), (gzip.open, ".txt.gz"),
                                            (bz2.open, ".txt.bz2")])
def test_reads_save_data_txt(tmp_path, opener, suffix):
    path = str(tmp_path / ("history" + suffix))
    with opener(path, "wt") as out:
        out.write(SAVE_DATA_TXT)
    data = read_plot_data(path)
    assert list(data) == ["eps_x", "eps_y", "eps_z", "i", "sz", "t"]
    np.testing.assert_array_equal(data["i"], [0, 100])
    np.testing.assert_array_equal(data["sz"], [1500.0, 1843.25])
    np.testing.assert_array_equal(data["t"], [0.0, 1.25e-4])
    assert np.isnan(data["eps_x"][0]) and data["eps_z"][1] == 3.0
    assert data["sz"].dtype == np.float64
    assert read_plot_headers(path) == {"confining": "750.0", "run": "dry"}


def test_plot_data_without_headers_rows_or_numbers(tmp_path):
    path = tmp_path / "plain.txt"
    path.write_text("# t\t\tphase\n0.0\tdry run\n0.5\twet\n")
    data = read_plot_data(path)
    np.testing.assert_array_equal(data["t"], [0.0, 0.5])
    assert data["phase"].tolist() == ["dry run", "wet"]  # tab separated: spaces kept
    assert read_plot_headers(path) == {}
    path.write_text("# t\t\tsz\n")
    assert {k: v.size for k, v in read_plot_data(path).items()} == {"t": 0, "sz": 0}


@pytest.mark.parametrize("text, message", [
    ("0.0\t1.0\n", "line 1: expected a '# name1 name2 ...' line"),
    ("# a\t\tb\n1\t2\n3\n", "line 3: expected 2 values (a b), got 1"),
    ("# a\t\ta\n1\t2\n", "repeated column names"),
    ("", "empty file"),
    ("# not a header\n# a\t\tb\n1\t2\n", "line 1: header line must read '# key=value'"),
])
def test_bad_plot_data_refused(tmp_path, text, message):
    path = tmp_path / "bad.txt"
    path.write_text(text)
    with pytest.raises(ValueError) as error:
        read_plot_headers(path) if "header" in message else read_plot_data(path)
    assert message in str(error.value)
    assert str(path) in str(error.value)


# --- the YADE driver (benchmarks/), run only where YADE is installed -------------------------

def _runner():
    import importlib.util
    from pathlib import Path

    path = Path(ROOT) / "benchmarks" / "yade_runner.py"
    spec = importlib.util.spec_from_file_location("yade_runner", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_runner_says_when_yade_is_missing(monkeypatch):
    runner = _runner()
    monkeypatch.setenv("PATH", "")
    with pytest.raises(RuntimeError, match="no YADE executable"):
        runner.run_yade_triaxial({"spheres": "none.txt"}, threads=1)


@requires("yade")
def test_yade_driver_end_to_end(tmp_path):
    runner = _runner()
    positions, radii, lo, hi = runner.random_packing(150, 2.4e-5, 0.5, seed=3)
    write_spheres(tmp_path / "spheres.txt", positions, radii, lo, hi)
    config = {"spheres": str(tmp_path / "spheres.txt"), "young": 1e6, "poisson": 0.3,
              "friction_deg": 18.0, "density": 2650.0, "damping": 0.2, "dt": 6e-7,
              "confining": 750.0, "strain_rate": 10.0, "max_vel": 0.05, "steps": 300,
              "warmup_steps": 1500, "record_every": 100, "history": str(tmp_path / "h.txt.gz")}
    result = runner.run_yade_triaxial(config, threads=1, timeout=120)
    assert result["particles"] == 150 and result["steps"] == 300 and result["threads"] == 1
    assert result["particle_steps_per_s"] > 0
    assert result["sigma_wall"][0] == pytest.approx(750.0, rel=0.05)  # servoed lateral walls
    assert result["sigma_wall"][1] == pytest.approx(750.0, rel=0.05)
    assert result["sigma_wall"][2] > 0.0  # z walls (strain controlled) loaded too
    assert 0.3 < result["porosity"] < 0.5 and result["coordination"] > 2.0
    history = read_plot_data(tmp_path / "h.txt.gz")
    assert history["i"].tolist() == list(range(100, 1801, 100))
