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

--device gpu prepares and shears on the GPU (docs/gpu.md, "The periodic cell on the GPU").
"""

from __future__ import annotations

from pendular.procedures.simple_shear import SimpleShearTest

from pendular.cli.commands.triaxial import loading_command

#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular simple-shear --particles 1000 --normal-stress 1000 "
           "--constant-volume --max-strain 0.2 --out runs/simple_shear",
           "a constant-volume simple shear to gamma 20 %: the peak of tau, the peak of "
           "tau/sigma_n with its friction angle, each with its own record; simple_shear.png with "
           "the tau-sigma_n stress path")

#: Summary keys printed at the end.
SHOWN = ("peak_shear_stress", "shear_strain_at_peak_stress", "normal_stress_at_peak_stress",
         "peak_stress_ratio", "phi_peak_deg", "shear_strain_at_peak", "normal_stress_at_peak",
         "shear_stress_at_peak", "peak_reached", "residual_stress_ratio", "phi_residual_deg",
         "phi_peak_effective_deg", "phi_residual_effective_deg", "normal_stress_final",
         "max_dilatancy", "dilatancy_angle_deg", "max_volume_change", "liquid_balance_error",
         "initial_porosity", "wall_time_s", "particle_steps_per_s")

add_arguments, config_from, run = loading_command("simple-shear", SimpleShearTest, SHOWN)
