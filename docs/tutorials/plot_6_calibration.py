"""
Calibrating the contact friction to a curve
===========================================

``pendular calibrate`` fits a test's options to a measured curve by Bayesian inference
(GrainLearning's iterative Bayesian filter, :doc:`/calibration`), and says how well the curve
pins each of them. Here the "measured" curve is one pendular made itself, at a contact friction
we know (15°); the calibration should find 15° within the uncertainty it reports.

The sizes are tiny so that the page builds in seconds: 100 spheres to 4 % axial strain, two
iterations of six runs. The measured recoveries at real sizes, and a calibration to a
laboratory curve of a sand, are on :doc:`/calibration`.
"""

# sphinx_gallery_start_ignore
import shutil

shutil.rmtree("runs/calibration", ignore_errors=True)    # a fresh calibration at every build
# sphinx_gallery_end_ignore

# %%
# The "measured" curve
# --------------------
#
# A dry drained triaxial at 750 Pa (the default confining stress) with a contact friction of
# 15°, on the sample of the default seed (0); :func:`pendular.studies.calibration.write_curve`
# writes its deviator stress and volumetric strain at 16 axial strains as the CSV a
# calibration reads (a header naming the columns, SI units, strains as fractions, compression
# positive).

import subprocess
import sys

import numpy as np

from pendular.studies.calibration import write_curve

TEST = ["--particles", "100", "--max-strain", "0.04", "--inertial-number", "0.01",
        "--records", "40"]
subprocess.run([sys.executable, "-m", "pendular", "triaxial", *TEST, "--friction", "15",
                "--quiet", "--out", "runs/calibration/truth"],
               check=True, capture_output=True)
strains = np.linspace(0.0025, 0.04, 16)
write_curve("runs/calibration/friction15.csv", "runs/calibration/truth", "triaxial", strains)
print(open("runs/calibration/friction15.csv").read()[:300])

# %%
# The calibration
# ---------------
#
# The test's own options fix everything but the fitted one, the same as the data's;
# ``--fit friction=5:40`` fits the contact friction in degrees with a uniform prior over 5–40°.
# In a shell::
#
#     pendular calibrate --data friction15.csv --test triaxial --particles 100 \
#         --max-strain 0.04 --inertial-number 0.01 --records 40 \
#         --fit friction=5:40 --iterations 2 --samples 6 --out runs/calibration/fit
#
# After its runs, the first iteration runs its best sample again at seven other seeds: the
# scatter between those eight specimens is the least uncertainty the filter may give a curve,
# so the posterior is no narrower than the difference between two specimens allows, although
# here the data and the runs share their specimen.

import json

subprocess.run([sys.executable, "-m", "pendular", "calibrate",
                "--data", "runs/calibration/friction15.csv", "--test", "triaxial", *TEST,
                "--fit", "friction=5:40", "--iterations", "2", "--samples", "6", "--quiet",
                "--out", "runs/calibration/fit"], check=True, capture_output=True)
with open("runs/calibration/fit/summary.json") as handle:
    summary = json.load(handle)
friction = summary["parameters"]["friction"]
print(f"{summary['runs']} runs; friction {friction['mean']:.1f} ± {friction['std']:.1f}° "
      f"(prior 5–40°, its std {friction['prior_std']:.1f}°), "
      f"best run {friction['best']:.1f}°, constrained: {friction['constrained']}")
print(f"the truth, 15°, is {abs(friction['mean'] - 15.0) / friction['std']:.2f} reported "
      "standard deviations from the posterior mean")

# %%
# ``posterior.csv`` holds every run: its friction, its weight in the posterior and its error to
# the data (the RMS difference, each column in units of its range in the data). The weights are
# those of every iteration's samples together: each sample's likelihood at the seed noise,
# divided by the mixture of the densities the iterations drew from; where the seed noise makes
# the likelihood nearly flat, as here, a sample drawn where the samples are sparse weighs most:

import matplotlib.pyplot as plt
import pandas as pd

posterior = pd.read_csv("runs/calibration/fit/posterior.csv")
figure, left = plt.subplots(figsize=(6, 4))
for iteration, runs in posterior.groupby("iteration"):
    left.scatter(runs["friction"], runs["error"], s=20 + 300 * runs["weight"],
                 label=f"iteration {iteration + 1}")
left.axvline(15.0, color="k", ls=":", label="truth (15°)")
left.axvspan(friction["mean"] - friction["std"], friction["mean"] + friction["std"],
             color="C3", alpha=0.15, label="posterior mean ± std")
left.set(xlabel="contact friction [deg]", ylabel="error to the data [-]",
         title="runs (size: weight)")
left.legend(fontsize=8)
figure.tight_layout()

# %%
# The data against the best run (its folder is ``best_run``):

from pendular.studies.calibration import DATA_COLUMNS, read_curve

data = read_curve("runs/calibration/friction15.csv", "triaxial")
best = DATA_COLUMNS["triaxial"].read("runs/calibration/fit/" + summary["best_run"])
figure, right = plt.subplots(figsize=(6, 4))
right.plot(100 * data.control, data.observed["q"], "ko", label="data (15°)")
right.plot(100 * best["axial_strain"], best["q"], "C3",
           label=f"best run ({friction['best']:.1f}°)")
right.set(xlabel="axial strain [%]", ylabel="deviator stress q [Pa]")
right.legend()
figure.tight_layout()

# %%
# ``pendular calibrate`` draws the same figures into its folder (``calibration.png``,
# ``posterior.png``, ``errors.png``).
#
# The best runs lie near 15°, but at 100 spheres two specimens of one material differ by as much
# as runs many degrees of friction apart (their porosities alone spread over a few hundredths),
# so the posterior stays wide, and is reported unconstrained when its standard deviation is
# above 70 % of the prior's: the data of one 100-sphere specimen cannot say more. Calibrate on
# samples large enough for that scatter to be small: the recoveries at 1,000 spheres, and a
# calibration to a laboratory curve of a sand, are on :doc:`/calibration`.
