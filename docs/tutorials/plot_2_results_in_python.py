"""
Reading the results in Python: histories, summaries, ParaView series
====================================================================

Every run folder describes itself: datasets carry their units and descriptions, the history its
configuration. Three functions read it:

- :func:`pendular.read_history` — the history as an :class:`xarray.Dataset`;
- :func:`pendular.read_summary` — summaries as a :class:`pandas.DataFrame` (a run, a campaign);
- :func:`pendular.read_vtk` — a ParaView series as ``meshio`` meshes.

This tutorial reads the folder of :doc:`plot_1_first_triaxial`.
"""

# sphinx_gallery_start_ignore
import os
import subprocess
import sys

if not os.path.exists("runs/first/summary.json"):     # the first tutorial's run
    subprocess.run([sys.executable, "-m", "pendular", "triaxial", "--particles", "200",
                    "--suction", "30000", "--max-strain", "0.05", "--out", "runs/first",
                    "--quiet"], check=True, capture_output=True)
# sphinx_gallery_end_ignore

# %%
# The history
# -----------
#
# One variable per recorded column; the records are indexed by the axial strain (a fraction),
# with the step and the simulated time beside it; tensors have the dimensions ``axis`` and
# ``component`` (x, y, z; z is the axial direction).

import pendular

history = pendular.read_history("runs/first")
print(history.sigma_wall)

# %%
# Each variable carries its units, its description and, where it implements one, the thesis
# equation:

for name in ("sigma_wall", "saturation", "psi", "sigma_effective"):
    print(f"{name:16s} [{history[name].attrs['units']}]  {history[name].attrs.get('equation', '')}"
          f"  {history[name].attrs['description']}")

# %%
# q and p of the net stress, and of the effective stress of Eq. 3.43, are one line each
# (compression positive; σ₁ is z, σ₃ the mean of x and y):

import matplotlib.pyplot as plt

wall = history.sigma_wall
q = wall.sel(axis="z") - wall.sel(axis=["x", "y"]).mean("axis")
effective = history.sigma_effective
q_effective = (effective.sel(axis="z", component="z")
               - (effective.sel(axis="x", component="x")
                  + effective.sel(axis="y", component="y")) / 2)

figure, axes = plt.subplots(figsize=(6, 4))
axes.plot(100 * history.axial_strain, q / 1e3, label="net stress, q")
axes.plot(100 * history.axial_strain, q_effective / 1e3, "--", label="effective stress, q′")
axes.set_xlabel("axial strain εa [%]")
axes.set_ylabel("deviator stress [kPa]")
axes.set_title("200 spheres, σ3 = 750 Pa, s = 30 kPa")
axes.legend()
figure.tight_layout()

# %%
# ``sel`` picks records by strain, e.g. the state at 2 % (the nearest record):

print(history.saturation.sel(axial_strain=0.02, method="nearest").item())

# %%
# The configuration the run used is stored as JSON in the file's attributes:

import json

config = json.loads(history.attrs["config"])
print(json.dumps(config, indent=1)[:600], "...")

# %%
# The summary
# -----------
#
# ``read_summary`` gives one row per run (a campaign folder gives one row per run of it), the
# units of its numeric columns in ``attrs["units"]``:

summary = pendular.read_summary("runs/first")
for key in ("peak_q", "p_at_peak", "axial_strain_at_peak", "peak_q_effective",
            "saturation_at_peak"):
    print(f"{key:22s} {summary[key].iloc[0]:10.4g} {summary.attrs['units'].get(key, '')}")

# %%
# The ParaView series
# -------------------
#
# ``vtk/particles.pvd`` (spheres), ``walls.pvd``, ``bridges.pvd`` and ``contacts.pvd`` are
# ParaView collections of ``.vtu`` frames. In ParaView: *File → Open* ``particles.pvd``, then a
# *Glyph* filter (sphere, *Scale Array* = ``radius``, scale factor 1); ``bridges.pvd`` and
# ``contacts.pvd`` draw as lines, coloured by their ``force`` or ``normal_force``. Each frame's
# time value (ParaView's time axis) is the axial strain of the triaxial test in %; its field data
# hold the step, the simulated time and the axial strain both as a fraction (``axial_strain``)
# and in % (``axial_strain_percent``, the time value).
#
# In Python, :func:`pendular.read_vtk` reads a series with ``meshio`` (a dependency of
# pendular): a list of (time value, mesh) pairs.

frames = pendular.read_vtk("runs/first/vtk/particles.pvd")
time_value, mesh = frames[-1]
print(len(frames), "frames; the last:", time_value)
print(mesh)
print(mesh.field_data)

# %%
# The point data are NumPy arrays, one row per sphere, e.g. the distribution of the contact
# force magnitudes at the end of the test:

figure, axes = plt.subplots(figsize=(6, 3.5))
axes.hist(mesh.point_data["contact_force"] * 1e6, bins=30)
axes.set_xlabel("sum of contact force magnitudes on a sphere [µN]")
axes.set_ylabel("spheres")
axes.set_title(f"last frame, {len(mesh.points)} spheres")
figure.tight_layout()

# %%
# With `pyvista <https://pyvista.org>`_ (not a dependency: ``pip install pyvista``) the same
# series reads as ``pyvista.PVDReader("runs/first/vtk/particles.pvd")``, with
# ``reader.set_active_time_value(t)`` and ``reader.read()`` for a frame, and
# ``mesh.glyph(scale="radius", geom=pyvista.Sphere(radius=1))`` draws the spheres at their size.
