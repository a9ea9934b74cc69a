"""Oedometric (K0) compression, dry or wet: prepare (or load) a sample at --confining, wet it,
hold the lateral walls and push the axial ones in at the quasi-static rate until the axial
stress is --axial-stress, then with --unload-to pull them back until it is that
(pendular.procedures.loading.oedometer_stages).

Writes into --out: history.h5 (with void_ratio and k0 = sigma_lateral / sigma_axial at every
row), summary.json (k0 at the axial stress, the constrained modulus, the compression and
swelling indices, net and wet effective), oedometer.png (e-log sigma_v and K0), plots/,
vtk/, sample.h5, with --checkpoint-every checkpoint.h5; --resume DIR continues an interrupted
run. The sample, wetting and output options are those of ``pendular triaxial``. Stresses
compression positive [Pa].
"""

from __future__ import annotations

from pendular.procedures.triaxial import OedometerTest

from pendular.cli.commands.triaxial import loading_command

#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular oedometer --particles 1000 --axial-stress 10000 --unload-to 2000 "
           "--out runs/oedometer",
           "K0, the constrained modulus and the compression and swelling indices of a loading to "
           "10 kPa and an unloading to 2 kPa; e-log sigma_v in oedometer.png")

#: Summary keys printed at the end.
SHOWN = ("k0", "k0_effective", "axial_stress_at_load", "lateral_stress_at_load",
         "axial_strain_at_load", "initial_void_ratio", "void_ratio_at_load",
         "constrained_modulus", "constrained_modulus_tangent", "compression_index",
         "compression_index_effective", "k0_final", "void_ratio_final",
         "constrained_modulus_unloading", "swelling_index", "swelling_index_effective",
         "initial_porosity", "wall_time_s", "particle_steps_per_s")

add_arguments, config_from, run = loading_command("oedometer", OedometerTest, SHOWN)
