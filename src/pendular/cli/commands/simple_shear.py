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
options are those of ``pendular triaxial``. Stresses compression positive [Pa]. --liquid
clusters (at a suction or a water content; on the CPU, the GPU's cell stress holding no
clusters): liquid clusters of filled pore units
cut from the sheared cell's images, their stress in the cell's (docs/liquid_clusters.md).

--device gpu prepares and shears on the GPU (docs/gpu.md, "The periodic cell on the GPU").
"""

from __future__ import annotations

from pendular.cli.commands.triaxial import loading_command

add_arguments, config_from, run, EXAMPLE = loading_command("simple-shear")
