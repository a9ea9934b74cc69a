"""
Capillary stress of regular packings (thesis Chapter 4)
=======================================================

For regular packings — simple cubic (SCP), isotropic body-centred (BCC) and face-centred (FCP) —
with one identical bridge at every contact, the degree of saturation, the effective stress
parameter χ (Eq. 3.44) and the capillary stress ψ (Eq. 3.46) follow from the suction alone
(:func:`pendular.homogenize.packing_state`, thesis Tables 4.2–4.4). Spheres of R = 0.1 mm, water
(γ = 0.074 N/m, the Chapter 4 value), contact angle 0.
"""

import matplotlib.pyplot as plt
import numpy as np

from pendular.homogenize import packing_state, regular_packing

suctions = np.logspace(3.3, 6, 30)                            # Pa
figure, (left, right) = plt.subplots(1, 2, figsize=(9, 3.8))
for kind in ("scp", "bcc", "fcp"):
    packing = regular_packing(kind)
    states = []
    for suction in suctions:
        try:
            states.append(packing_state(packing, radius=1e-4, contact_angle=0.0,
                                        surface_tension=0.074, suction=suction))
        except ValueError:           # beyond the pendular limit: menisci would merge
            states.append(None)
    kept = [(s, state) for s, state in zip(suctions, states) if state is not None]
    label = f"{kind.upper()} (n = {packing.porosity:.3f})"
    left.semilogx([s / 1e3 for s, _ in kept], [100 * state.saturation for _, state in kept],
                  label=label)
    right.semilogx([s / 1e3 for s, _ in kept], [np.trace(state.psi) / 3e3 for _, state in kept],
                   label=label)
    state = kept[-1][1]
    print(f"{kind}: at {kept[-1][0] / 1e3:.0f} kPa Sr = {100 * state.saturation:.4f} %, "
          f"tr(chi)/3 = {np.trace(state.chi) / 3:.2e}, tr(psi)/3 = {np.trace(state.psi) / 3:.1f} Pa")
left.set_xlabel("suction s [kPa]")
left.set_ylabel("degree of saturation Sr [%]")
left.set_title("SWCC")
right.set_xlabel("suction s [kPa]")
right.set_ylabel("mean capillary stress tr ψ / 3 [kPa]")
right.set_title("capillary stress, Eq. 3.46")
right.legend()
figure.tight_layout()
plt.show()

# %%
# Curves stop at low suction where the menisci of neighbouring contacts would merge: the pendular
# limit of each packing. The thesis's tables and figures of Chapter 4, computed beside the printed
# values: :doc:`/chapter4`.
