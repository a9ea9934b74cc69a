"""Any loading path from a table, dry or wet: prepare (or load) a sample at --confining, wet
it, then run the stages of PATH.toml in turn (pendular.procedures.path).

PATH.toml holds the path, a list of [[stage]] tables with the keys of the Python API's Stage:

    [[stage]]                                 # K0 loading to 10 kPa
    strain_rate = {x = 0, y = 0, z = "quasi-static"}
    until = {stress = 10000, axis = "z"}

    [[stage]]                                 # three unload-reload cycles
    repeat = 3
    stages = [
      {strain_rate = {x = 0, y = 0, z = "-quasi-static"}, until = {stress = 2000}},
      {strain_rate = {x = 0, y = 0, z = "quasi-static"}, until = {stress = 10000}},
    ]

Keys of a stage: stress = {axis = Pa} (servoed walls), strain_rate = {axis = 1/s} (driven
walls, 0 holds them), mean_stress [Pa], b, max_strain_rate [1/s], volume = "constant" (x and y
hold the volume as z is driven: undrained), suction = Pa (a sample at --suction; stepped, or
ramped at suction_rate = Pa/s), water_content = % (a sample at --water-content), until =
{strain = X, axis = "z"} | {stress = Pa, axis = "z", strain_limit = X} | "static" (the
default) | {static = true, max_steps = N}; a stress may be "confining" (--confining), a strain
rate "quasi-static" or
"-quasi-static" (--inertial-number at the lowest stress of the path, or --strain-rate). A
group {repeat = N, stages = [...]} runs its stages N times (they may follow instead as
[[stage.stages]] tables). examples/paths/ holds the triaxial of thesis Ch. 5 (with --records
500, row for row the history of ``pendular triaxial``), an oedometric loading, unloading and
reloading, a cyclic loading and a collapse on wetting (wetting_collapse.toml: summary
collapse_strain). The sample, wetting and output options are those of
``pendular triaxial``.

Writes into --out: history.h5 (with void_ratio, k0 and stage at every row), summary.json (the
end of each stage: stresses, p, q, strains, void ratio, and wet p', q'; the peak of q where the
path has one), path.png (q-p and q'-p' stress paths, stresses and strains against the row),
vtk/, sample.h5, with --checkpoint-every checkpoint.h5; --resume DIR continues an interrupted
run without its table. Stresses compression positive [Pa].
"""

from __future__ import annotations

from pendular.cli.commands.triaxial import loading_command

add_arguments, config_from, run, EXAMPLE = loading_command("path")
