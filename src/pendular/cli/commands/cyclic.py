"""Cyclic triaxial loading, dry or wet, stress- or strain-controlled: prepare (or load) a sample
at --confining, wet it, servo the lateral walls at --confining and drive the axial ones at the
quasi-static rate: a first loading to the amplitude, then --cycles cycles of unloading to minus
the amplitude and reloading (pendular.procedures.cyclic.cyclic_stages). Give one amplitude:
--amplitude-q A (stress control: q = sigma_axial - sigma_lateral between +A and -A, A below
--confining since the walls cannot pull) or --amplitude-strain X (strain control: the axial
strain between +X and -X; a run whose axial stress falls to 0 stops with an error).

Writes into --out: history.h5 (with void_ratio, stage and cycle at every row), summary.json
(per cycle the secant modulus (q_max - q_min) / (eps_max - eps_min), the damping ratio
W_D / (4 pi W_S) of its loop (Kramer 1996), its strain range and the accumulated axial and
volumetric strains; net and, wet, effective), cyclic.png (the q-eps_a loops, the modulus and
damping ratio against the cycle), vtk/, sample.h5, with --checkpoint-every checkpoint.h5;
--resume DIR continues an interrupted run. The history has a row every --record-strain and,
under strain control, at least pendular.procedures.cyclic.MIN_BRANCH_RECORDS a half-cycle;
under stress control choose --record-strain well below the strain a half-cycle travels (a
loop's area needs its shape). The sample, wetting
and output options are those of ``pendular triaxial``. Stresses compression positive [Pa].
"""

from __future__ import annotations

from pendular.cli.commands.triaxial import loading_command

add_arguments, config_from, run, EXAMPLE = loading_command("cyclic")
