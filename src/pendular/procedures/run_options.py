"""How a run is watched and where it runs: ``RunOptions``, passed once to every command's run.

Every laboratory test runs as ``test.run(out, options) -> summary`` and resumes as
``Test.resume(out, options) -> summary`` (pendular.procedures.laboratory.LaboratoryTest, the
direct tension's TensionTest, the SWCC's SwccTest), a RunOptions holding what is not part of
the configuration: the device, the Numba threads, the progress bars, the checkpoints of a
run whose configuration does not hold them (tension, swcc), a stop after some steps (as an
interruption would), the expert override of the feasibility checks, the ParaView frames of
the preparation and the figures. The commands that run many tests or another code run so
too, with the same options and their own: a campaign (pendular.studies.campaign.Campaign,
``pendular campaign``), the Chapter 5 campaign (pendular.studies.chapter5.Chapter5Campaign)
with their local processes or Dask cluster, the YADE cross-check
(pendular.studies.crosscheck.CrossCheck) with YADE run beside pendular's shear. The results
depend on none of them: a run on 1 or 2 threads, with or without bars or frames, in one
process or several, is the same bit for bit; a checkpoint resumes on either device. A run's
keyword arguments, e.g. ``run(out, progress=False, threads=1)``, are the same options given
one by one (``RunOptions.of``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass


@dataclass(frozen=True)
class RunOptions:
    """device: "cpu" or "gpu" (pendular.dem.simulation.check_device); threads: Numba threads
    (None: the run chooses); progress: progress bars; checkpoint_every: steps between
    checkpoints of a run whose configuration has no such field (tension, swcc; 0: none);
    stop_after: stop the loading after this many steps as an interruption would (raises
    pendular.procedures.laboratory.Interrupted; tests of resume); force: run settings refused
    as not quasi-static or too long (experts; checked when the test is made); vtk_prep:
    ParaView frames of the preparation and wetting (True, a period in steps, or False);
    plots: write the figures; arguments: the command line's options, recorded by a direct
    tension in its tension.json; jobs: local processes of a campaign's runs
    (pendular.studies.campaign.check_jobs); scheduler: the address of the Dask cluster that
    runs them instead (None: local processes); concurrent: a cross-check runs YADE while
    pendular shears (each code's timing then shares the machine with the other)."""

    device: str = "cpu"
    threads: int | None = None
    progress: bool = True
    checkpoint_every: int = 0
    stop_after: int | None = None
    force: bool = False
    vtk_prep: bool | int = False
    plots: bool = True
    arguments: dict | None = None
    jobs: int = 1
    scheduler: str | None = None
    concurrent: bool = False

    @classmethod
    def of(cls, options=None, **settings):
        """``options`` (a RunOptions, None for the defaults) with ``settings`` (its fields by
        name) over it; TypeError naming a setting that is not a field."""
        unknown = set(settings) - {f.name for f in dataclasses.fields(cls)}
        if unknown:
            raise TypeError(f"run options {sorted(unknown)} are not RunOptions fields")
        return dataclasses.replace(options if options is not None else cls(), **settings)
