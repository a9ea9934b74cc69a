"""What a user can do wrong with chapter4, chapter5, extremes, swcc, tradeoff and crosscheck ends in one
``<prog>: error: ...`` line naming the option or the path (exit status 2), never a traceback
(issue 36): an output folder that is a file or lies under one, values beyond 2**63 and NaN,
a damaged sample (JSON attributes) or run history, a non-finite tensor reaching the
anisotropy's eigen-solver, an SWCC stage that runs out of --stage-steps.

Option and path cases run in-process through pendular.cli.run_command; they are refused before
anything runs. The --stage-steps case prepares 60 spheres.
"""

import types

import h5py
import numpy as np
import pytest

from conftest import refused, run_in_process

from pendular.studies.chapter5 import check_history
from pendular.utils.integrity import stamp, verify
from pendular.dem.sample import load_sample, save_sample
from pendular.dem.state import Particles, Walls
from pendular.homogenize.fabric import principal_anisotropy

BIG = "18446744073709551617"      # 2**64 + 1
#: Small, valid options of each command (what a case adds is refused before anything runs).
BASE = {
    "chapter4": ["--points", "10"],
    "extremes": ["--quick"],
    "chapter5": ["--particles", "60", "--suctions", "0", "--confining", "750",
                 "--max-strain", "0.002", "--quiet"],
    "swcc": ["--particles", "60", "--suctions", "3000,10000", "--quiet"],
}


# ---------------------------------------------------------------- output folders
@pytest.mark.parametrize("name", sorted(BASE))
def test_an_output_folder_that_is_a_file_is_refused_naming_it(name, tmp_path, capsys):
    path = tmp_path / "results.txt"
    path.write_text("the user's own file\n")
    refused(*run_in_process(name, BASE[name] + ["--out", str(path)], capsys), str(path), "a file")
    assert path.read_text() == "the user's own file\n"


@pytest.mark.parametrize("name", sorted(BASE))
def test_an_output_folder_under_a_file_is_refused_naming_it(name, tmp_path, capsys):
    path = tmp_path / "results.txt"
    path.write_text("x")
    out = path / "sub"
    line = refused(*run_in_process(name, BASE[name] + ["--out", str(out)], capsys), str(out),
                   "cannot create the folder")
    assert "Errno" not in line


# ---------------------------------------------------------------- option values
CASES = {
    "chapter4 points 2**64": ("chapter4", ["--points", BIG], ["--points", "[10, 400]"]),
    "chapter4 points nan": ("chapter4", ["--points", "nan"], ["--points"]),
    "extremes threads 2**64": ("extremes", ["--threads", BIG], ["--threads"]),
    "swcc stage steps 2**64": ("swcc", ["--stage-steps", BIG], ["--stage-steps", "100000000"]),
    "swcc confining nan": ("swcc", ["--confining", "nan"], ["confining", "not finite"]),
    "swcc confining 1 Pa": ("swcc", ["--confining", "1"], ["--confining", "valid minimum 5 Pa"]),
    "swcc suctions nan": ("swcc", ["--suctions", "nan,3000"], ["--suctions", "not finite"]),
    "swcc contact angle 2**64": ("swcc", ["--contact-angle", BIG], ["--contact-angle",
                                                                     "[0, 90) deg"]),
    "chapter5 particles 2**64": ("chapter5", ["--particles", BIG], ["particles", "10000000"]),
    "chapter5 suctions nan": ("chapter5", ["--suctions", "nan"], ["--suctions", "[0, inf]"]),
    "chapter5 confining 0": ("chapter5", ["--confining", "0"], ["--confining", "(0, 1e+07]"]),
    "chapter5 max strain nan": ("chapter5", ["--max-strain", "nan"], ["--max-strain",
                                                                       "not finite"]),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_values_beyond_range_are_refused_naming_the_option(case, tmp_path, capsys):
    name, argv, words = CASES[case]
    refused(*run_in_process(name, BASE[name] + argv + ["--out", str(tmp_path / "out")], capsys),
            *words)
    assert not (tmp_path / "out").exists()


#: A study's option refused as it is read, naming the flag (command, argv, words).
STUDY_OPTIONS = {
    "chapter4 points 9": ("chapter4", ["--points", "9"], ["--points = 9", "[10, 400]"]),
    "chapter5 suctions not numbers": ("chapter5", ["--suctions", "0,a"],
                                      ["--suctions = '0,a'", "comma-separated"]),
    "tradeoff particles 10": ("tradeoff", ["--particles", "10"],
                              ["--particles = 10", "[50, inf]"]),
    "tradeoff seeds 1": ("tradeoff", ["--knob", "damping", "--seeds", "1"],
                         ["--seeds = 1", "[2, 100]"]),
    "tradeoff seeds without knob": ("tradeoff", ["--seeds", "3"],
                                    ["--seeds and --jobs belong to a --knob study"]),
    "crosscheck settle steps -1": ("crosscheck", ["--settle-steps", "-1"],
                                   ["--settle-steps = -1", "[0, 100000000]"]),
    "crosscheck records 1": ("crosscheck", ["--records", "1"], ["--records = 1", "[2, "]),
    "crosscheck wet periodic": ("crosscheck", ["--periodic", "--suction", "1e4"],
                                ["--suction 10000.0 Pa with --periodic"]),
}


@pytest.mark.parametrize("case", sorted(STUDY_OPTIONS))
def test_a_studys_options_are_checked_as_they_are_read_naming_the_flag(case, tmp_path, capsys):
    name, argv, words = STUDY_OPTIONS[case]
    line = refused(*run_in_process(name, argv + ["--out", str(tmp_path / "out")], capsys),
                   *words)
    assert "no YADE executable" not in line           # checked before YADE is looked for
    assert not (tmp_path / "out").exists()


CROSSCHECK = {
    "confining inf": (["--confining", "inf"], ["--confining", "(0, inf)"]),
    "radius nan": (["--radius", "nan"], ["radius", "not finite"]),
    "seed 2**64": (["--seed", BIG], ["seed", "4294967295"]),
    "suction nan": (["--suction", "nan"], ["--suction", "[0, inf)"]),
}


@pytest.mark.parametrize("case", sorted(CROSSCHECK))
def test_crosscheck_checks_its_options_before_looking_for_yade(case, tmp_path, capsys):
    argv, words = CROSSCHECK[case]
    line = refused(*run_in_process("crosscheck", ["--particles", "60", "--quiet", *argv, "--out",
                                           str(tmp_path / "out")], capsys), *words)
    assert "YADE" not in line


def test_crosscheck_packing_that_is_a_folder_is_refused_naming_it(tmp_path, capsys):
    refused(*run_in_process("crosscheck", ["--particles", "60", "--packing", str(tmp_path), "--out",
                                    str(tmp_path / "out")], capsys),
            str(tmp_path), "is a folder", "packing.txt")


# ---------------------------------------------------------------- an SWCC stage's step limit
def test_an_swcc_stage_out_of_steps_names_stage_steps(tmp_path, capsys):
    line = refused(*run_in_process("swcc", BASE["swcc"] + ["--stage-steps", "10", "--out",
                                                    str(tmp_path / "out")], capsys),
                   "--stage-steps = 10", "suction 3000 Pa (drying)", "raise --stage-steps")
    assert "--wet-steps" not in line


# ---------------------------------------------------------------- damaged files
def write_sample(path):
    """A stamped sample of 64 touching spheres (R = 1 mm) on a cubic lattice."""
    radius = 1e-3
    axis = radius + 2.0 * radius * 0.995 * np.arange(4)
    position = np.array(np.meshgrid(axis, axis, axis, indexing="ij")).reshape(3, -1).T
    particles = Particles(np.ascontiguousarray(position), np.full(64, radius), 2650.0)
    walls = Walls.box(np.zeros(3), np.full(3, axis[-1] + radius))
    save_sample(path, types.SimpleNamespace(particles=particles, walls=walls), {"steps": 1},
                {"radius": radius})
    return str(path)


def restamped(path, name, text):
    """The sample at ``path`` with attribute ``name`` replaced by ``text`` and stamped again (a
    checksum that holds over a damaged content: a writer's bug, or a forger)."""
    identity = verify(path, kind="file")
    with h5py.File(path, "r+") as handle:
        handle.attrs[name] = text
    stamp(path, identity)
    return path


@pytest.mark.parametrize("name, text, words", [
    ("config", "{broken", ["'config'", "not readable JSON"]),
    ("report", "[1,", ["'report'", "not readable JSON"]),
    ("config", "[1, 2]", ["'config'", "a JSON list, not an object"]),
])
def test_a_sample_with_a_damaged_json_attribute_is_refused_naming_it(tmp_path, name, text,
                                                                     words):
    path = restamped(write_sample(tmp_path / "sample.h5"), name, text)
    with pytest.raises(ValueError) as error:
        load_sample(path)
    for word in [path, *words]:
        assert word in str(error.value)


def test_triaxial_from_a_sample_with_damaged_json_ends_in_one_line(tmp_path, capsys):
    path = restamped(write_sample(tmp_path / "sample.h5"), "report", "[1,")
    refused(*run_in_process("triaxial", ["--particles", "64", "--sample", path, "--out",
                                  str(tmp_path / "out")], capsys), path, "'report'")


def test_a_reused_run_with_a_damaged_history_names_it_and_the_remedy(tmp_path):
    folder = tmp_path / "runs" / "s0_c750"
    folder.mkdir(parents=True)
    with pytest.raises(ValueError, match="no such file") as error:
        check_history(str(folder))
    assert str(folder) in str(error.value)
    (folder / "history.h5").write_bytes(bytes(range(256)))
    with pytest.raises(ValueError, match="not a readable pendular history") as error:
        check_history(str(folder))
    assert f"delete the run folder {folder}" in str(error.value)


# ---------------------------------------------------------------- the eigen-solver
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_the_anisotropy_of_a_non_finite_tensor_is_refused_not_left_to_the_eigensolver(bad):
    tensor = np.diag([1.0, 1.0, 2.0])
    tensor[0, 1] = tensor[1, 0] = bad
    with pytest.raises(ValueError, match="not finite") as error:
        principal_anisotropy(tensor)
    assert "diverged" in str(error.value)
    assert np.isnan(principal_anisotropy(np.zeros((3, 3))))        # undefined, not an error
    assert principal_anisotropy(np.diag([1.0, 1.0, 2.0])) == pytest.approx(2.5 / 4.0)
