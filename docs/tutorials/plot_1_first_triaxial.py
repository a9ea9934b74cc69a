"""
A first triaxial test, from the command line to the plots
=========================================================

A drained triaxial test of thesis Chapter 5 on a wet sample: spheres prepared dry (thesis
Ch. 5.2.2), capillary bridges placed at every contact at a matric suction of 30 kPa, the lateral
stress held at 750 Pa while the sample is compressed axially. One command runs all of it and
draws the plots.

Here the sample is small (200 spheres) and the test short (5 % axial strain) so that it runs in
seconds; the thesis's test is ``--particles 10000`` to 25 % strain (about a minute and a half on
two cores).
"""

# %%
# Run the test
# ------------
#
# In a shell this is one line::
#
#     pendular triaxial --particles 200 --suction 30000 --max-strain 0.05 --out runs/first
#
# (``python scenarios/triaxial.py`` takes the same options). Here we run it from Python, as a
# shell would, and print what it prints on its standard output (the progress bars go to the
# standard error; ``--quiet`` leaves them out and prints the summary as JSON, for scripts).

# sphinx_gallery_parallel = False
# sphinx_gallery_start_ignore
import shutil

shutil.rmtree("runs/first", ignore_errors=True)     # a fresh folder at every build
# sphinx_gallery_end_ignore
import subprocess
import sys

command = ("pendular triaxial --particles 200 --suction 30000 --max-strain 0.05 "
           "--out runs/first")
done = subprocess.run([sys.executable, "-m", *command.split()], capture_output=True,
                      text=True, check=True)
print(done.stdout)

# %%
# The terminal summary gives, one a line with its unit and to 4 significant figures, the peak of
# the deviator stress q = σ₁ − σ₃, the mean stress p = (σ₁ + 2σ₃)/3 there, the same for the
# effective stress of thesis Eq. 3.43 (q′, p′), the degree of saturation Sr and the timings.
# Stresses are in Pa, compression positive; strains are fractions, compression positive
# (:doc:`/units`). A note follows when q still rises at the end of the test (``peak_reached``
# false in ``summary.json``): the "peak" is then the highest record, not a peak. The critical
# state (``phi_cs_deg``, ``M_cs``, ``void_ratio_cs``) is given when the test reaches it; a test
# to 5 % does not, and ``critical_state_note`` says why (:doc:`/outputs`).
#
# What the run left
# -----------------

import os

for name in sorted(os.listdir("runs/first")):
    if not name.startswith("."):
        print(name)

# %%
# ``history.h5`` holds one row per record of the shear, ``summary.json`` the peak values and
# settings, ``triaxial.png`` and ``plots/`` the figures, ``vtk/`` the ParaView series and
# ``sample.h5`` the wetted sample the shear started from. :doc:`/outputs` lists every dataset and
# key with its units.
#
# The figures
# -----------
#
# ``triaxial.png`` is the counterpart of thesis Fig. 5.3: q and the volumetric strain against
# the axial strain, the peak marked.

import matplotlib.pyplot as plt


def show(path):
    """Show a PNG the run drew."""
    figure, axes = plt.subplots(figsize=(8, 6))
    axes.imshow(plt.imread(path))
    axes.set_axis_off()
    figure.tight_layout()


show("runs/first/triaxial.png")

# %%
# ``plots/`` holds the stress ratio of the net stress, q/p, beside that of the effective stress
# of Eq. 3.43, q′/p′ (thesis Fig. 5.7), the degree of saturation against the strain, the
# capillary stress ψ (Eq. 3.46) with the interface term and σ_cap, and the stress paths.

for name in sorted(os.listdir("runs/first/plots")):
    print(name)
show("runs/first/plots/q_p.png")

# %%
# ``stress_path.png`` draws the path of the net stress, q against p, and beside it that of the
# effective stress, q′ against p′: the capillary stress ψ shifts the wet sample's path to
# higher mean stress.

show("runs/first/plots/stress_path.png")

# %%
# Next: :doc:`plot_2_results_in_python` reads the same folder in Python, and
# :doc:`/commands` lists every option of the command.
