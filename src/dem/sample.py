"""Save and load a prepared sample (positions, radii, walls, velocities) as HDF5."""

import json

import h5py
import numpy as np

from .atomic import replacing
from .state import Particles, Walls
from .validate import reading


def save_sample(path, sim, report=None, config=None):
    """Write the particles and walls of ``sim`` (and the preparation report/config) atomically."""
    with replacing(path) as temporary, h5py.File(temporary, "w") as handle:
        p = sim.particles
        for name in ("position", "radius", "velocity", "angular_velocity"):
            handle.create_dataset(name, data=getattr(p, name))
        handle.create_dataset("walls", data=sim.walls.position)
        handle.attrs["density"] = p.density
        handle.attrs["report"] = json.dumps(report or {})
        handle.attrs["config"] = json.dumps(config or {})


def load_sample(path):
    """Read a sample written by ``save_sample``: (Particles, Walls, report dict, config dict).

    ValueError naming the path for a corrupt or foreign file or invalid contents."""
    with reading(path, "pendular sample (dem.sample.save_sample)"), h5py.File(path, "r") as handle:
        particles = Particles(handle["position"][:], handle["radius"][:],
                              float(handle.attrs["density"]), velocity=handle["velocity"][:],
                              angular_velocity=handle["angular_velocity"][:])
        walls = Walls(position=handle["walls"][:].astype(np.float64))
        report = json.loads(handle.attrs["report"])
        config = json.loads(handle.attrs["config"])
    return particles, walls, report, config
