"""What every resume checks before it goes on: the run folder's files, then its stored run.

A laboratory test (pendular.procedures.laboratory.LaboratoryTest.resume) and the SWCC
(pendular.procedures.swcc.SwccTest.resume) resume from the sample.h5 and checkpoint.h5 of
their folder, the direct tension (pendular.procedures.tension.TensionTest.resume) from its
checkpoint.h5 alone; each refuses a folder without them (``resume_files``) and a stored run of
another test, or a device that cannot run here (``stored_run``), in one line naming the
folder and what to do.
"""

from __future__ import annotations

import os

from pendular.dem.simulation import check_device

#: Why a run has no checkpoint, where its configuration does not say.
NO_CHECKPOINT = ("the run stopped before its first checkpoint, or was started with "
                 "--checkpoint-every 0, which writes none")


def resume_files(out, before_sample=None, no_checkpoint=None):
    """(sample.h5, checkpoint.h5) of the run folder ``out``. ValueError naming ``out`` when
    the sample of a run that has one is missing (``before_sample``: the phases that come
    before it, None for a run without) or the checkpoint is (``no_checkpoint(sample.h5)``:
    why, from the stored run; NO_CHECKPOINT by default)."""
    sample = os.path.join(out, "sample.h5")
    checkpoint = os.path.join(out, "checkpoint.h5")
    if before_sample is not None and not os.path.exists(sample):
        raise ValueError(f"resume = {out!r}: {sample} is missing: the run stopped before its "
                         f"sample existed ({before_sample}), so nothing can be resumed; run it "
                         "again")
    if not os.path.exists(checkpoint):
        why = NO_CHECKPOINT if no_checkpoint is None else no_checkpoint(sample)
        raise ValueError(f"resume = {out!r}: {checkpoint} is missing: {why}; run it again")
    return sample, checkpoint


def stored_run(config, out, test, name, device):
    """``config``, the configuration stored in the run folder ``out``, once checked to be of
    ``test`` (its ``CONFIG``; ValueError naming ``out`` and the command ``name`` otherwise)
    and ``device`` to run here (check_device)."""
    if not isinstance(config, test.CONFIG):
        raise ValueError(f"resume = {out!r} holds a run of another test "
                         f"({type(config).__name__}), not of pendular {name}")
    check_device(device)
    return config
