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

from pendular.procedures.config import (MAX_RECORD_STRAIN, MAX_SHEAR_STRAIN, MIN_AXIAL_STRAIN,
    MIN_RECORD_STRAIN, SimpleShearConfig)
from pendular.procedures.simple_shear import SimpleShearTest
from pendular.utils.validate import check_positive

from pendular.cli import UsageError
from pendular.cli.commands.triaxial import (add_output_options, add_sample_options,
    add_wetting_options, laboratory_fields, run_test)

#: Summary keys printed at the end.
SHOWN = ("peak_shear_stress", "peak_stress_ratio", "phi_peak_deg", "shear_strain_at_peak",
         "normal_stress_at_peak", "residual_stress_ratio", "phi_residual_deg",
         "normal_stress_final", "max_dilatancy", "dilatancy_angle_deg", "max_volume_change",
         "initial_porosity", "wall_time_s", "particle_steps_per_s")


def add_arguments(parser):
    add_sample_options(parser)
    parser.set_defaults(periodic=True)          # walls cannot shear a sample
    add_wetting_options(parser)
    parser.add_argument("--normal-stress", type=float, default=None,
                        help="normal stress sigma_zz of the shear [Pa], (0, 1e7] (default: "
                             "--confining)")
    parser.add_argument("--constant-volume", action="store_true",
                        help="shear at constant volume (the cell's lengths held; the normal "
                             "stress an output) instead of at --normal-stress")
    parser.add_argument("--max-strain", type=float, default=SimpleShearConfig.max_strain,
                        help=f"final shear strain gamma [-], in [{MIN_AXIAL_STRAIN:g}, "
                             f"{MAX_SHEAR_STRAIN:g}]")
    parser.add_argument("--inertial-number", type=float,
                        default=SimpleShearConfig.inertial_number,
                        help="target inertial number setting the shear rate [-]")
    parser.add_argument("--shear-rate", type=float, default=None,
                        help="shear rate gamma_dot [1/s] (overrides --inertial-number)")
    parser.add_argument("--record-strain", type=float,
                        default=SimpleShearConfig.record_strain,
                        help="shear strain between history rows [-] "
                             f"({MIN_RECORD_STRAIN:g}-{MAX_RECORD_STRAIN:g})")
    parser.add_argument("--stage-steps", type=int, default=SimpleShearConfig.stage_steps,
                        help="most steps of the consolidation to --normal-stress [-]")
    add_output_options(parser, "runs/simple_shear", frames=False)


def config_from(args):
    """The SimpleShearConfig of parsed options (ValueError / UsageError naming the option)."""
    if not MIN_AXIAL_STRAIN <= args.max_strain <= MAX_SHEAR_STRAIN:      # NaN included
        raise UsageError(f"--max-strain = {args.max_strain:g} is outside the valid range "
                         f"[{MIN_AXIAL_STRAIN:g}, {MAX_SHEAR_STRAIN:g}]: the final shear strain "
                         "gamma of a simple shear")
    if args.shear_rate is not None:
        check_positive("--shear-rate", args.shear_rate, "1/s")
    return SimpleShearConfig(**laboratory_fields(args, add_arguments, lambda: {
        "normal_stress": args.normal_stress, "constant_volume": args.constant_volume,
        "max_strain": args.max_strain, "inertial_number": args.inertial_number,
        "strain_rate": args.shear_rate, "record_strain": args.record_strain,
        "stage_steps": args.stage_steps}))


def run(args):
    return run_test(args, SimpleShearTest, config_from, SHOWN, add_arguments)
