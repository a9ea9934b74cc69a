"""
A graded sample from a sieve curve
==================================

A grading curve as from a sieve analysis — diameters and the percentage passing by mass — gives
the radii of a sample (:func:`pendular.dem.grading.sample_radii`): pendular draws the sizes so
that the sample's mass-based curve follows the sieve curve, and reports the usual descriptors
D10 … D60, the uniformity Cu = D60/D10 and the curvature Cc = D30²/(D10 D60)
(:func:`pendular.dem.grading.grading`). ``pendular triaxial --psd FILE`` (or
``PrepareConfig(psd=curve)``) prepares such a sample.
"""

import matplotlib.pyplot as plt
import numpy as np

from pendular.dem.grading import grading, sample_radii

# a sand: (diameter [m], percent passing by mass), linear in log d between sieves
curve = ((0.10e-3, 0.0), (0.15e-3, 10.0), (0.25e-3, 50.0), (0.40e-3, 90.0), (0.60e-3, 100.0))
radii = sample_radii(400, radius=None, curve=curve, seed=1)
descriptors = grading(radii)
for key in ("D10", "D30", "D50", "D60"):
    print(f"{key} = {descriptors[key] * 1e3:.3f} mm")
print(f"Cu = {descriptors['Cu']:.2f}, Cc = {descriptors['Cc']:.2f}, "
      f"radius ratio {descriptors['radius_max'] / descriptors['radius_min']:.2f}")

# %%
# The sample's curve (by mass) against the sieve curve:

diameters = np.sort(2 * radii)
mass = diameters ** 3
passing = 100 * np.cumsum(mass) / mass.sum()
figure, axes = plt.subplots(figsize=(6, 4))
axes.semilogx(np.array([d for d, _ in curve]) * 1e3, [p for _, p in curve], "o-",
              label="sieve curve")
axes.semilogx(diameters * 1e3, passing, drawstyle="steps-post", label="400 spheres")
axes.set_xlabel("diameter [mm]")
axes.set_ylabel("passing by mass [%]")
axes.set_title(f"graded sample: Cu = {descriptors['Cu']:.2f}")
axes.legend()
figure.tight_layout()
plt.show()
