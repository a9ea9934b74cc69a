"""
A campaign from a parameter table
=================================

A study is usually many runs that differ by a few options: suctions, confining stresses, seeds.
``pendular campaign TABLE.toml`` runs every row of a table, side by side, and collects their
summaries in one CSV file; started again, it reuses the runs that finished with the same
configuration, so an interrupted campaign goes on where it stopped.

Here: dry and wet (30 kPa) samples of 150 spheres at two confining stresses, sheared to 3 %.
"""

# %%
# The table
# ---------
#
# TOML: the command, the options every run shares under ``[fixed]``, and lists to sweep under
# ``[sweep]`` (every combination; or explicit ``[[runs]]`` rows). Keys are the command's options
# with underscores for dashes (``pendular triaxial --help`` lists them).

table = """\
command = "triaxial"
[fixed]
particles = 150
max_strain = 0.03
vtk_frames = 0          # no ParaView output
[sweep]
suction = [0, 30000]
confining = [250, 750]
"""
with open("campaign.toml", "w") as handle:
    handle.write(table)

# %%
# Run it
# ------
#
# ``--jobs 2`` runs two at a time (one Numba thread each); ``--scheduler tcp://HOST:8786`` would
# send them to a Dask cluster instead (:doc:`/howto/dask_campaigns`). In a shell::
#
#     pendular campaign campaign.toml --out runs/campaign --jobs 2
#
# With ``--quiet`` its standard output is JSON alone (the counts of runs and the folder), which
# a script reads with ``json.loads``:

# sphinx_gallery_start_ignore
import shutil

shutil.rmtree("runs/campaign", ignore_errors=True)     # a fresh campaign at every build
# sphinx_gallery_end_ignore
import json
import subprocess
import sys

done = subprocess.run([sys.executable, "-m", "pendular", "campaign", "campaign.toml",
                       "--out", "runs/campaign", "--jobs", "2", "--quiet"],
                      capture_output=True, text=True, check=True)
print(json.loads(done.stdout))

# %%
# Each run has its folder ``runs/campaign/runs/<name>/`` (its outputs and ``log.txt``), named
# after the options it varies.
#
# The results
# -----------
#
# ``runs/campaign/campaign.csv`` has one row per run: its options and its summary.
# :func:`pendular.read_summary` reads it as a :class:`pandas.DataFrame`:

import pendular

runs = pendular.read_summary("runs/campaign")
print(runs[["run", "suction", "confining", "peak_q", "p_at_peak", "saturation_at_peak"]]
      .to_string(index=False))

# %%
# The capillary bridges add strength: at each confining stress the wet sample's peak deviator
# stress is several times the dry one's. Against the mean stress at peak, the failure points give
# each suction's Mohr–Coulomb line (thesis Fig. 5.4):

import matplotlib.pyplot as plt

figure, axes = plt.subplots(figsize=(6, 4))
for suction, rows in runs.groupby("suction"):
    label = "dry" if suction == 0 else f"s = {suction / 1e3:g} kPa"
    axes.plot(rows.p_at_peak / 1e3, rows.peak_q / 1e3, "o-", label=label)
axes.set_xlabel("p at peak [kPa]")
axes.set_ylabel("peak q [kPa]")
axes.set_title("failure points, 150 spheres, 3 % strain")
axes.legend()
figure.tight_layout()

# %%
# The thesis's whole Table 5.3 is such a table, shipped with pendular and run by
# ``pendular chapter5`` (16 runs of 10,000 spheres: :doc:`/chapter5_campaign`).
