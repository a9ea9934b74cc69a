"""Oedometric (K0) compression, dry or wet: prepare (or load) a sample at --confining, wet it,
hold the lateral walls and push the axial ones in at the quasi-static rate until the axial
stress is --axial-stress, then with --unload-to pull them back until it is that
(pendular.procedures.oedometer.oedometer_stages).

Writes into --out: history.h5 (with void_ratio and k0 = sigma_lateral / sigma_axial at every
row), summary.json (k0 at the axial stress, the constrained modulus, the compression and
swelling indices, net and wet effective), oedometer.png (e-log sigma_v and K0), plots/,
vtk/, sample.h5, with --checkpoint-every checkpoint.h5; --resume DIR continues an interrupted
run. The sample, wetting and output options are those of ``pendular triaxial``. Stresses
compression positive [Pa].
"""

from __future__ import annotations

from pendular.cli.commands.triaxial import loading_command

add_arguments, config_from, run, EXAMPLE = loading_command("oedometer")
