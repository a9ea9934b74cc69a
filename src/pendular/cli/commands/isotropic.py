"""Isotropic loading and unloading in stages, dry or wet: prepare (or load) a sample at
--confining, wet it, then servo the six walls to each stress of --stresses in turn, each stage
until static, the walls moving at most at the quasi-static rate
(pendular.procedures.loading.isotropic_stages).

Writes into --out: history.h5 (with void_ratio and stage at every row), summary.json (each
stage's end: p, e, and wet p' of the effective stress; the compression and swelling indices,
Delta e per log10 p over the loading and the unloading steps, net and effective),
isotropic.png (e-log p), vtk/, sample.h5, with --checkpoint-every checkpoint.h5; --resume DIR
continues an interrupted run. The sample, wetting and output options are those of ``pendular
triaxial``. Stresses compression positive [Pa].
"""

from __future__ import annotations

from pendular.procedures.triaxial import IsotropicTest

from pendular.cli.commands.triaxial import loading_command

#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular isotropic --particles 1000 --stresses 1000,2000,4000,2000,1000 "
           "--out runs/isotropic",
           "e against log p at the end of each stage, with the compression and swelling indices; "
           "isotropic.png")

#: Summary keys printed at the end.
SHOWN = ("stages", "initial_void_ratio", "final_void_ratio", "compression_index",
         "swelling_index", "compression_index_effective", "swelling_index_effective",
         "initial_porosity", "wall_time_s", "particle_steps_per_s")

add_arguments, config_from, run = loading_command("isotropic", IsotropicTest, SHOWN)
