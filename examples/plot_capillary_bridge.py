"""
The force of a liquid bridge against the gap
============================================

The exact Young–Laplace bridge between two equal spheres at a fixed suction
(:func:`pendular.capillary.bridge_at_distance`), in YADE's dimensionless units: suction
u* = s R/γ, gap d* = D/R, force F* = F/(2πγR) (:doc:`/units`). The force is largest at contact
and falls as the spheres separate, until the rupture distance, beyond which no bridge exists at
that suction (:func:`pendular.capillary.rupture_distance`). Beside it, the toroidal
approximation of thesis Appendix A (:func:`pendular.capillary.toroidal_bridge`) at the same
filling angles.
"""

import matplotlib.pyplot as plt
import numpy as np

from pendular import capillary

figure, axes = plt.subplots(figsize=(6, 4))
for suction_star in (10.0, 100.0, 1000.0):
    rupture = capillary.rupture_distance(1.0, 0.0, suction_star)
    gaps = np.linspace(0.0, rupture, 40)[:-1]
    bridges = [capillary.bridge_at_distance(1.0, 0.0, suction_star, gap) for gap in gaps]
    line, = axes.plot(gaps, [bridge.force for bridge in bridges],
                      label=f"u* = {suction_star:g}, rupture at d* = {rupture:.3f}")
    print(f"u* = {suction_star:6g}: F* at contact {bridges[0].force:.4f}, "
          f"V* {bridges[0].volume:.3e}, filling angle {bridges[0].delta1:.2f} deg, "
          f"rupture d* {rupture:.4f}")
    toroidal = [capillary.toroidal_bridge(bridge.delta1, 0.0, gap)
                for bridge, gap in zip(bridges, gaps)]
    axes.plot(gaps, [bridge.force for bridge in toroidal], ":", color=line.get_color())
axes.set_xlabel("gap d* = D / R")
axes.set_ylabel("force F* = F / (2π γ R)")
axes.set_title("equal spheres, θ = 0 (dotted: toroidal approximation)")
axes.legend()
figure.tight_layout()
plt.show()

# %%
# For water (γ = 0.073 N/m) on spheres of R = 0.024 mm (thesis Table 5.2), u* = 10 is a suction of
# about 30 kPa — the thesis's wet tests — and F* = 1 a force of 2πγR = 11 µN.
print(f"u* = 10 is s = {10 * 0.073 / 0.024e-3 / 1e3:.1f} kPa; "
      f"2 pi gamma R = {2 * np.pi * 0.073 * 0.024e-3 * 1e6:.2f} µN")
