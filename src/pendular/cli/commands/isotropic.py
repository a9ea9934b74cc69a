"""Isotropic loading and unloading in stages, dry or wet: prepare (or load) a sample at
--confining, wet it, then servo the six walls to each stress of --stresses in turn, each stage
until static, the walls moving at most at the quasi-static rate
(pendular.procedures.isotropic.isotropic_stages).

Writes into --out: history.h5 (with void_ratio and stage at every row), summary.json (each
stage's end: p, e, and wet p' of the effective stress; the compression and swelling indices,
Delta e per log10 p over the loading and the unloading steps, net and effective),
isotropic.png (e-log p), vtk/, sample.h5, with --checkpoint-every checkpoint.h5; --resume DIR
continues an interrupted run. The sample, wetting and output options are those of ``pendular
triaxial``. Stresses compression positive [Pa].
"""

from __future__ import annotations

from pendular.cli.commands.triaxial import loading_command

add_arguments, config_from, run, EXAMPLE = loading_command("isotropic")
