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

from pendular.procedures.config import OedometerConfig, PathConfig
from pendular.procedures.triaxial import OedometerTest
from pendular.utils.parameters import add_options, fields_from

from pendular.cli.commands.triaxial import (add_output_options, add_rate_options,
    add_sample_options, add_wetting_options, laboratory_fields, run_test)

#: The path's own fields, each set by its option.
OWN = ("axial_stress", "unload_to", "inertial_number", "strain_rate", "record_strain")
#: Summary keys printed at the end.
SHOWN = ("k0", "k0_effective", "axial_stress_at_load", "lateral_stress_at_load",
         "axial_strain_at_load", "initial_void_ratio", "void_ratio_at_load",
         "constrained_modulus", "constrained_modulus_tangent", "compression_index",
         "compression_index_effective", "k0_final", "void_ratio_final",
         "constrained_modulus_unloading", "swelling_index", "swelling_index_effective",
         "initial_porosity", "wall_time_s", "particle_steps_per_s")


def add_arguments(parser):
    add_sample_options(parser)
    add_wetting_options(parser)
    add_options(parser, OedometerConfig, ("axial_stress", "unload_to"))
    add_rate_options(parser)
    add_options(parser, PathConfig, ("record_strain",))
    add_output_options(parser, "runs/oedometer", frames=False)


def config_from(args):
    """The OedometerConfig of parsed options (ValueError / UsageError naming the option)."""
    return OedometerConfig(**laboratory_fields(args, add_arguments, lambda: fields_from(
        args, OedometerConfig, OWN)))


def run(args):
    return run_test(args, OedometerTest, config_from, SHOWN, add_arguments)
