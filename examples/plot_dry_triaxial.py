"""
A whole triaxial test from a configuration
==========================================

:class:`pendular.TriaxialTest` runs the test of ``pendular triaxial`` from a typed configuration:
:class:`pendular.TriaxialConfig` holds the sample (:class:`pendular.PrepareConfig`, thesis Table
5.2 defaults), the shear (:class:`pendular.ShearConfig`) and, for a wet test, the bridges
(:class:`pendular.BridgeConfig`). Configurations are validated when they are made (an error names
the parameter, its value and the valid range) and saved as JSON in every file the run writes.

Two dry tests at two confining stresses, 200 spheres to 4 % strain, and their friction angle.
"""

import dataclasses
import shutil

import matplotlib.pyplot as plt
import numpy as np

import pendular
from pendular import PrepareConfig, ShearConfig, TriaxialConfig, TriaxialTest

base = TriaxialConfig(sample=PrepareConfig(particles=200, seed=2),
                      shear=ShearConfig(max_strain=0.04), vtk_frames=0)
figure, axes = plt.subplots(figsize=(6, 4))
peaks = []
for confining in (500.0, 1000.0):
    config = dataclasses.replace(base, sample=dataclasses.replace(base.sample,
                                                                  confining=confining))
    out = f"runs/dry_{confining:g}"
    shutil.rmtree(out, ignore_errors=True)
    summary = TriaxialTest(config).run(out, progress=False, plots=False)
    history = pendular.read_history(out)
    q = history.sigma_wall.sel(axis="z") - history.sigma_wall.sel(axis=["x", "y"]).mean("axis")
    axes.plot(100 * history.axial_strain, q, label=f"σ3 = {confining:g} Pa")
    peaks.append((summary["p_at_peak"], summary["peak_q"]))
    print(f"σ3 = {confining:6g} Pa: peak q = {summary['peak_q']:.1f} Pa at "
          f"εa = {100 * summary['axial_strain_at_peak']:.2f} %, "
          f"initial porosity {summary['initial_porosity']:.3f}")
axes.set_xlabel("axial strain εa [%]")
axes.set_ylabel("deviator stress q [Pa]")
axes.set_title("dry triaxial tests, 200 spheres")
axes.legend()
figure.tight_layout()
plt.show()

# %%
# Through the origin, the peak stress ratio M = q/p gives the friction angle of a triaxial
# compression test, sin φ = 3M / (6 + M):

ratio = np.mean([q / p for p, q in peaks])
print(f"M = {ratio:.3f}, φ = {np.degrees(np.arcsin(3 * ratio / (6 + ratio))):.1f}° "
      "(thesis, 10,000 spheres: 25°)")

# %%
# A 200-sphere sample is looser than the thesis's 10,000 spheres (porosity about 0.44 against
# 0.38: its wall layers weigh more) and weaker; :doc:`/dry_triaxial` gives the full-size tests.
