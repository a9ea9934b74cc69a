"""
A hydro-mechanical loading path in a few lines
==============================================

Wet a sample at 30 kPa suction, load it oedometrically to σv = 10 kPa, dry it to 300 kPa
at constant σv, then unload it: each phase is one call on the same scene, so stress and
suction paths compose in any order.

- :func:`pendular.wet` adds the capillary bridges and equilibrates;
- ``run_path`` (pendular.procedures.path) runs :class:`pendular.Stage` objects, the
  same stages a path table (``pendular path PATH.toml``) holds, and returns their history;
- ``change_suction`` brings suction-controlled bridges to a new suction at a held stress, in
  steps of equal ratio, each until static.

150 spheres, so that it runs in seconds.
"""

import matplotlib.pyplot as plt

from pendular import BridgeConfig, PrepareConfig, Stage, Stress, prepare_sample, wet
from pendular.procedures.config import quasi_static_rate
from pendular.procedures.oedometer import oedometer_stages
from pendular.procedures.path import change_suction, run_path

sample = PrepareConfig(particles=150, confining=1000.0, seed=1)
sim, _ = prepare_sample(sample, progress=False)
# inertial number 1e-3 at the lowest stress of the path, 1 kPa
rate = quasi_static_rate(1e-3, None, sample.radius, sample.density, 1000.0)

bridges = BridgeConfig(suction=30e3).build()
wet(sim, bridges)                                                    # 30 kPa, at 1 kPa
loading = run_path(sim, oedometer_stages(10e3, rate), record_every=200)      # K0 to 10 kPa
drying = change_suction(sim, bridges, 300e3, stress={"z": 10e3})     # σv held, x, y fixed
held = {"x": 0.0, "y": 0.0}
unloading = run_path(sim, [Stage(strain_rate={**held, "z": -rate}, until=Stress(1000.0))],
                     record_every=200)

# %%
# Each phase returns its history, a dict of NumPy arrays (``sigma_wall`` (rows, 3) [Pa],
# compression positive; ``void_ratio``; wet, ``suction`` [Pa] and ``saturation``). The state
# at the end of each phase:

phases = {"wet, K0 loaded": loading, "dried": drying, "unloaded": unloading}
print(f"{'phase':>15} {'σx':>8} {'σy':>8} {'σz [Pa]':>8} {'e':>7} {'s [kPa]':>8} "
      f"{'Sr [%]':>7}")
for name, history in phases.items():
    sx, sy, sz = history["sigma_wall"][-1]
    print(f"{name:>15} {sx:8.0f} {sy:8.0f} {sz:8.0f} {history['void_ratio'][-1]:7.4f} "
          f"{history['suction'][-1] / 1e3:8.0f} {100 * history['saturation'][-1]:7.3f}")

# %%
# The void ratio against the vertical stress: the drying is the vertical step at σv = 10 kPa,
# where the volume changes at constant stress as the bridges thin (less liquid at a higher
# suction).

figure, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
for name, history in phases.items():
    left.semilogx(history["sigma_wall"][:, 2] / 1e3, history["void_ratio"], ".-", ms=3,
                  label=name)
left.set_xlabel("vertical stress σv [kPa] (log scale)")
left.set_ylabel("void ratio e [-]")
left.legend()
right.semilogx(drying["suction"] / 1e3, drying["void_ratio"], "o-", label="void ratio e")
right.set_xlabel("suction s [kPa] (log scale), at σv = 10 kPa")
right.set_ylabel("void ratio e [-]")
twin = right.twinx()
twin.semilogx(drying["suction"] / 1e3, 100 * drying["saturation"], "s--", color="C1")
twin.set_ylabel("degree of saturation Sr [%] (squares)")
for axes, ticks in ((left, (1, 2, 5, 10)), (right, (30, 50, 100, 200, 300))):
    axes.set_xticks(ticks, [f"{tick:g}" for tick in ticks])       # kPa as plain numbers
    axes.minorticks_off()
figure.suptitle("wet at 30 kPa, K0 loading to 10 kPa, drying to 300 kPa, unloading "
                f"({len(sim.particles)} spheres)", fontsize=10)
figure.tight_layout()
plt.show()

# %%
# The same path of stresses alone, as a table for ``pendular path`` (the sample and its
# wetting are the command's options, ``--suction 30000``), is two ``[[stage]]`` entries::
#
#     [[stage]]
#     strain_rate = {x = 0, y = 0, z = "quasi-static"}
#     until = {stress = 10000, axis = "z"}
#
#     [[stage]]
#     strain_rate = {x = 0, y = 0, z = "-quasi-static"}
#     until = {stress = 1000, axis = "z"}
#
# A change of suction within a table's path needs a stage that sets the bridges' suction,
# which loading.Stage does not have yet; in Python, ``change_suction`` is that step.
