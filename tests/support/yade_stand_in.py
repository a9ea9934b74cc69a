"""A stand-in for YADE in the cross-check's tests (pendular.studies.crosscheck): pendular on
the CPU shears the driver's packing and writes YADE's history layout, so that the pendular
half of a cross-check runs where YADE is not installed and every difference is zero."""

import numpy as np

from pendular.studies import crosscheck


def pendular_as_yade(config):
    """A stand-in for pendular.interop.yade.runner.run_yade_triaxial: pendular shears the driver's packing
    and writes the driver's history layout (box lengths chosen to give the same volume)."""

    def run(settings, threads=1, env=None):
        sim, shear = crosscheck.pendular_shear(config, settings["spheres"], threads)
        box_volume = sim.walls.volume()
        sim.run(shear.steps)
        history = shear.recorder.arrays()
        sigma = history["sigma_wall"]
        columns = {"i": history["step"], "t": history["time"],
                   "eps_axial": history["axial_strain"],
                   "sx": sigma[:, 0], "sy": sigma[:, 1], "sz": sigma[:, 2],
                   "lx": np.ones(len(sigma)), "ly": np.ones(len(sigma)),
                   "lz": (1.0 - history["volumetric_strain"]) * box_volume,
                   "porosity": history["porosity"],
                   "unbalanced": history["unbalanced_force"]}
        if "saturation" in history:
            columns.update(saturation=history["saturation"], menisci=history["bridges"])
        lines = ["# " + "\t\t".join(columns)]
        lines += ["\t".join(repr(float(v)) for v in row) for row in zip(*columns.values())]
        with open(settings["history"], "w") as handle:
            handle.write("\n".join(lines) + "\n")
        return {"steps": shear.steps, "wall_time_s": 1.0, "yade_version": "stand-in"}

    return run
