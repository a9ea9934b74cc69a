"""Runs that used to end in a traceback after their loading started now end in one line or
run: a first stage that fails at once (no history row of the loading), a path stage whose
``until`` stress is already reached. Each runs from one 60-sphere sample prepared once.
"""

import pytest

from conftest import refused, run_in_process, summary_of

#: A stage of a path table whose axial stress end is ``{}`` Pa, compressing z.
UNTIL_STRESS = """[[stage]]
stress = {{x = "confining", y = "confining"}}
strain_rate = {{z = "quasi-static"}}
until = {{stress = {}, axis = "z"}}
"""


@pytest.fixture(scope="module")
def sample(tmp_path_factory):
    """sample.h5 of ``pendular triaxial --particles 60`` (at the default confining 750 Pa)."""
    from pendular.cli import run_command

    out = tmp_path_factory.mktemp("sample") / "prep"
    assert run_command("triaxial", ["--particles", "60", "--max-strain", "1e-4", "--quiet",
                                    "--out", str(out)]) == 0
    return str(out / "sample.h5")


def test_a_first_stage_out_of_steps_names_stage_steps(sample, tmp_path, capsys):
    line = refused(*run_in_process("isotropic", ["--particles", "60", "--sample", sample,
                                                 "--stage-steps", "1", "--quiet", "--out",
                                                 str(tmp_path / "out")], capsys),
                   "stage 1", "not static after 1 steps", "--stage-steps")
    assert "zero-size" not in line
    assert summary_of(tmp_path / "out")["max_unbalanced_force"] is None   # no loading rows


@pytest.mark.parametrize("stress", ["750", "500"])
def test_a_stage_whose_stress_is_reached_ends_at_once(stress, sample, tmp_path, capsys):
    """Its until stress the sample's (confining) stress, or below it while z is compressed."""
    table = tmp_path / "path.toml"
    table.write_text(UNTIL_STRESS.format(stress))
    status, err = run_in_process("path", [table, "--particles", "60", "--sample", sample,
                                          "--quiet", "--out", tmp_path / "out"], capsys)
    assert status == 0, err
    assert summary_of(tmp_path / "out")["stages"][0]["stage"] == 0


def test_resuming_a_run_that_wrote_no_checkpoints_says_why(sample, capsys):
    """The sample's own run (finished, --checkpoint-every 0) cannot be resumed; its folder is
    left as it was."""
    import os

    folder = os.path.dirname(sample)
    before = sorted(os.listdir(folder))
    refused(*run_in_process("triaxial", ["--resume", folder], capsys),
            "checkpoint.h5 is missing", "--checkpoint-every 0")
    assert sorted(os.listdir(folder)) == before
