"""Simple shear, dry or wet, in a periodic cell (Lees–Edwards images: the cell's image above in
z displaced along x as it shears): prepare (or load) a sample at --confining, always in a
periodic cell (--periodic is implied), wet it, bring z to --normal-stress with x and y held,
then shear x with z at the quasi-static rate to the shear strain --max-strain, the normal
stress held (drained) or, with --constant-volume, the cell's lengths held
(pendular.procedures.simple_shear).

Writes into --out: history.h5 (with shear_strain gamma, shear_stress tau and normal_stress
sigma_zz at every row), summary.json (the peak and residual tau / sigma_n and their friction
angles, the dilatancy, or at constant volume the volume change), simple_shear.png (tau,
sigma_n and the volumetric strain against gamma), vtk/, sample.h5, with --checkpoint-every
checkpoint.h5; --resume DIR continues an interrupted run. The sample, wetting and output
options are those of ``pendular triaxial``. Stresses compression positive [Pa].
"""

from __future__ import annotations

from pendular.procedures.config import SimpleShearConfig
from pendular.procedures.simple_shear import SimpleShearTest
from pendular.utils.parameters import add_options, fields_from

from pendular.cli.commands.triaxial import (add_output_options, add_sample_options,
    add_wetting_options, laboratory_fields, run_test)

#: The path's own fields, each set by its option (the strain rate by --shear-rate).
OWN = ("normal_stress", "constant_volume", "max_strain", "inertial_number", "strain_rate",
       "record_strain", "stage_steps")
#: Summary keys printed at the end.
SHOWN = ("peak_shear_stress", "peak_stress_ratio", "phi_peak_deg", "shear_strain_at_peak",
         "normal_stress_at_peak", "residual_stress_ratio", "phi_residual_deg",
         "phi_peak_effective_deg", "phi_residual_effective_deg", "normal_stress_final",
         "max_dilatancy", "dilatancy_angle_deg", "max_volume_change", "liquid_balance_error",
         "initial_porosity", "wall_time_s", "particle_steps_per_s")


def add_arguments(parser):
    add_sample_options(parser)
    parser.set_defaults(periodic=True)          # walls cannot shear a sample
    add_wetting_options(parser)
    add_options(parser, SimpleShearConfig, OWN)
    add_output_options(parser, "runs/simple_shear", frames=False)


def config_from(args):
    """The SimpleShearConfig of parsed options (ValueError / UsageError naming the option)."""
    return SimpleShearConfig(**laboratory_fields(args, add_arguments, lambda: fields_from(
        args, SimpleShearConfig, OWN)))


def run(args):
    return run_test(args, SimpleShearTest, config_from, SHOWN, add_arguments)
