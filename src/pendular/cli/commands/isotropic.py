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

from pendular.procedures.config import IsotropicConfig, PathConfig
from pendular.procedures.triaxial import IsotropicTest
from pendular.utils.parameters import add_options, fields_from, spec_of

from pendular.cli import UsageError
from pendular.cli.commands.triaxial import (add_output_options, add_rate_options,
    add_sample_options, add_wetting_options, laboratory_fields, run_test)

#: The path's own fields set by their options as they are (--stresses, a comma list, by hand).
OWN = ("stage_steps", "inertial_number", "strain_rate", "record_strain")
#: Summary keys printed at the end.
SHOWN = ("stages", "initial_void_ratio", "final_void_ratio", "compression_index",
         "swelling_index", "compression_index_effective", "swelling_index_effective",
         "initial_porosity", "wall_time_s", "particle_steps_per_s")


def add_arguments(parser):
    add_sample_options(parser)
    add_wetting_options(parser)
    stresses = spec_of(IsotropicConfig, "stresses")       # a comma list: by hand
    parser.add_argument(stresses.flag, metavar=stresses.metavar,
                        default=",".join(f"{v:g}" for v in IsotropicConfig().stresses),
                        help=f"{stresses.help} [{stresses.unit}]")
    add_options(parser, IsotropicConfig, ("stage_steps",))
    add_rate_options(parser)
    add_options(parser, PathConfig, ("record_strain",))
    add_output_options(parser, "runs/isotropic", frames=False)


def stresses(text):
    """The stresses [Pa] of --stresses 'P1,P2,...'."""
    try:
        return [float(value) for value in text.split(",")]
    except ValueError:
        raise UsageError(f"--stresses {text!r}: numbers [Pa] separated by commas expected, "
                         "e.g. 500,1000,2000,1000") from None


def config_from(args):
    """The IsotropicConfig of parsed options (ValueError / UsageError naming the option)."""
    return IsotropicConfig(**laboratory_fields(args, add_arguments, lambda: {
        "stresses": stresses(args.stresses), **fields_from(args, IsotropicConfig, OWN)}))


def run(args):
    return run_test(args, IsotropicTest, config_from, SHOWN, add_arguments)
