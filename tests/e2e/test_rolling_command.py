"""pendular triaxial with rolling and twisting resistance and gravity as a user runs it: a run
stopped and resumed from its checkpoint gives the history of an uninterrupted one (the
springs are per-pair state of the checkpoint), and the options are recorded in the history.
The runs write no figures (--no-plots, also accepted by a resume)."""

import h5py
import numpy as np

from conftest import history_of, run_in_process, summary_of

SMALL = ["--particles", "60", "--rolling-friction", "0.2", "--twisting-friction", "0.1",
         "--gravity", "9.81", "--max-strain", "0.01", "--vtk-every", "0", "--quiet",
         "--checkpoint-every", "200", "--no-plots"]


def test_a_resumed_run_with_rolling_resistance_and_gravity_has_an_uninterrupted_history(
        tmp_path, capsys):
    whole, out = tmp_path / "whole", tmp_path / "stopped"
    status, err = run_in_process("triaxial", [*SMALL, "--out", whole], capsys)
    assert status == 0, err
    assert not (whole / "triaxial.png").exists() and not (whole / "plots").exists()
    steps = summary_of(whole)["steps"]
    status, _ = run_in_process("triaxial", [*SMALL, "--out", out,
                                            "--stop-after", str(int(0.6 * steps))], capsys)
    assert status == 130 and summary_of(out)["completed"] is False
    status, err = run_in_process("triaxial", ["--resume", out, "--quiet", "--no-plots"], capsys)
    assert status == 0, err
    assert not (out / "triaxial.png").exists() and not (out / "plots").exists()
    expected, got = history_of(whole), history_of(out)
    for name in expected:
        assert np.array_equal(got[name], expected[name], equal_nan=True), name
    with h5py.File(whole / "history.h5") as handle:
        attributes = dict(handle.attrs)
    recorded = {key: value for key, value in attributes.items()
                if key in ("rolling_friction", "twisting_friction", "gravity")}
    assert recorded == {"rolling_friction": 0.2, "twisting_friction": 0.1, "gravity": 9.81}, \
        sorted(attributes)
