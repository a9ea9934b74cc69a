"""
A custom loading path in Python
===============================

The command line runs the thesis's procedure. In Python the same building blocks compose any
other path. Here: a sample prepared and compressed isotropically to 2 kPa, unloaded to 500 Pa
(an overconsolidated sample), wetted at 30 kPa suction, then sheared at 500 Pa.

A scene is a :class:`pendular.Simulation` that declares its step pipeline in one call — forces,
controls (what drives the boundaries), the integrator and writers — in the order a step runs
them; a phase of a test changes its controls. :func:`pendular.prepare_sample` builds such a scene
(thesis Ch. 5.2.2) and returns it static at its confining stress.
"""

import matplotlib.pyplot as plt
import numpy as np

from pendular import (BridgeConfig, PrepareConfig, ShearConfig, StressServo, TriaxialShear,
                      equilibrate, prepare_sample, summarize, wet)

# %%
# Prepare at 2 kPa
# ----------------
#
# 300 spheres of the thesis's radius (0.024 mm) and material (Table 5.2); ``seed`` fixes the
# random cloud, so the run is the same at every build.

sample = PrepareConfig(particles=300, confining=2000.0, seed=3)
sim, report = prepare_sample(sample, progress=False)
print(f"porosity {report['porosity']:.4f}, coordination {report['coordination']:.2f}, "
      f"wall stresses {np.round(report['sigma_wall'], 1)} Pa")

# %%
# Unload to 500 Pa
# ----------------
#
# The walls are servoed by a :class:`pendular.StressServo` (YADE's TriaxialStressController law):
# lowering its target in stages, each followed by a few hundred steps, unloads the sample
# slowly. :func:`pendular.equilibrate` then runs until the sample is static (unbalanced force
# below 0.01 and wall stresses at the target), or raises an error if it cannot settle.

servo = sim.operation(StressServo)
for target in np.linspace(2000.0, 500.0, 11)[1:]:
    servo.target = target
    sim.run(500)
equilibrate(sim)
print(f"wall stresses {np.round(sim.walls.stress(), 1)} Pa (x, y, z)")

# %%
# Wet it
# ------
#
# :func:`pendular.wet` appends the capillary bridges to the scene's forces — here exact
# Young–Laplace bridges at every contact at 30 kPa suction — and equilibrates again.

wet(sim, BridgeConfig(suction=30000.0).build())

# %%
# Shear at 500 Pa
# ---------------
#
# :class:`pendular.TriaxialShear` replaces the controls by the lateral walls servoed at the
# confining stress and the axial walls at a constant strain rate (inertial number 3e-4), and
# records the history.

shear = TriaxialShear(sim, ShearConfig(max_strain=0.05), confining=500.0,
                      radius=sample.radius, density=sample.density)
sim.run(shear.steps)
history = shear.recorder.arrays()
peak = summarize(history)
for key in ("peak_q", "p_at_peak", "axial_strain_at_peak", "peak_q_effective",
            "p_effective_at_peak", "saturation_at_peak"):
    print(f"{key:22s} {peak[key]:.4g}")

# %%
# The recorded arrays are plain NumPy (``sigma_wall`` is (records, 3), compression positive):

wall = history["sigma_wall"]
q = wall[:, 2] - wall[:, :2].mean(axis=1)
figure, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(6, 5))
top.plot(100 * history["axial_strain"], q / 1e3)
top.set_ylabel("q [kPa]")
top.set_title("unloaded from 2 kPa to 500 Pa, then wet (s = 30 kPa) and sheared")
bottom.plot(100 * history["axial_strain"], 100 * history["volumetric_strain"])
bottom.set_ylabel("volumetric strain εv [%]\n(contraction positive)")
bottom.set_xlabel("axial strain εa [%]")
figure.tight_layout()

# %%
# The whole test of the command line, with its files, is
# ``TriaxialTest(TriaxialConfig(sample=..., shear=..., bridges=...)).run("runs/mine")``
# (:class:`pendular.TriaxialTest`); the configurations are typed dataclasses, validated once,
# and ``dataclasses.replace(config, ...)`` makes variants.

# %%
# Any path from a table
# ---------------------
#
# The same stages run from the command line: ``pendular path PATH.toml`` reads a TOML list of
# ``[[stage]]`` tables whose keys are those of :class:`pendular.Stage` — ``stress``
# (servoed walls, {axis: Pa}), ``strain_rate`` (driven walls, {axis: 1/s}; 0 holds them),
# ``mean_stress``, ``b``, ``max_strain_rate`` — and its end ``until``: ``{strain = 0.05,
# axis = "z"}``, ``{stress = 5000, axis = "z"}`` or ``"static"``. A stress may be written
# ``"confining"`` (the ``--confining`` the path starts from), a strain rate ``"quasi-static"``
# or ``"-quasi-static"`` (the inertial-number rule, ``--inertial-number``). An entry with
# ``repeat = N`` and ``stages = [...]`` runs its stages N times: cycles. The sample and its
# wetting are the command's options, as for ``pendular triaxial``; a mistyped key is refused
# with the file, the stage and the valid keys, before anything runs.
#
# Here a K0 loading to 5 kPa and two unload–reload cycles, on a wet sample of 150 spheres:

table = """\
[[stage]]                                   # K0 loading: x and y held, z pushed in
strain_rate = {x = 0, y = 0, z = "quasi-static"}
until = {stress = 5000, axis = "z"}

[[stage]]                                   # two unload-reload cycles
repeat = 2
stages = [
  {strain_rate = {x = 0, y = 0, z = "-quasi-static"}, until = {stress = 1500, axis = "z"}},
  {strain_rate = {x = 0, y = 0, z = "quasi-static"}, until = {stress = 5000, axis = "z"}},
]
"""
with open("k0_cycles.toml", "w") as handle:
    handle.write(table)

# sphinx_gallery_start_ignore
import shutil

shutil.rmtree("runs/k0_cycles", ignore_errors=True)     # a fresh folder at every build
# sphinx_gallery_end_ignore
import subprocess
import sys

command = ("pendular path k0_cycles.toml --particles 150 --confining 750 --suction 30000 "
           "--inertial-number 1e-3 --vtk-every 0 --out runs/k0_cycles")
done = subprocess.run([sys.executable, "-m", *command.split()], capture_output=True,
                      text=True, check=True)
print(done.stdout)

# %%
# ``summary.json`` lists the end of each stage (stresses, p and q, strains, void ratio and,
# wet, p′ and q′ of the effective stress, Eq. 3.43); ``path.png`` draws the stress paths and
# the stresses and strains against the history row:

figure, axes = plt.subplots(figsize=(9, 5.5))
axes.imshow(plt.imread("runs/k0_cycles/path.png"))
axes.set_axis_off()
figure.tight_layout()

# %%
# ``examples/paths/`` holds three tables: ``triaxial.toml``, the triaxial of thesis Ch. 5
# (with ``--records 500`` its history is, row for row and bit for bit, that of ``pendular
# triaxial`` with the same options), ``oedometer_unload.toml`` and ``cyclic.toml``.
#
# A change of suction is not a table's stage yet; in Python it is one call,
# ``pendular.procedures.path.change_suction``, between stages run by ``run_path``:
# the example :doc:`/auto_examples/loading_path_api` wets a sample at 30 kPa, loads it
# oedometrically to 10 kPa, dries it to 300 kPa at constant σv and unloads it, in six lines.
