"""Radius growth, the controls of a sample's preparation (thesis Ch. 5.2.2: spheres grown in a
fixed box until the mean wall stress reaches a target; pendular.procedures.preparation runs
them; the GPU runs the same law, pendular.gpu.growth).

- ``RadiusGrowth``: every radius grows by (1 + g) each step, g = max_rate clip(1 - sigma_mean /
  target, -1, 1), sigma_mean the mean of the three axes' wall stresses of this step's forces;
  masses and inertias follow at constant density (Particles.update_mass).
- ``GrowthTimeStep``: dt = safety times the P-wave estimate of the current radii
  (pendular.dem.timestep.pwave_timestep), set at every neighbour-list rebuild.
"""

import numpy as np

from pendular.dem.timestep import pwave_timestep
from pendular.utils.validate import check_positive


class RadiusGrowth:
    """Grow all radii by (1 + g) per step, g = max_rate * clip(1 - sigma_mean / target, -1, 1).

    A control (it reads the wall stress of this step's forces); masses follow the radii
    (constant density). target_stress [Pa].
    """

    def __init__(self, target_stress, max_rate):
        self.target_stress = check_positive("prep_stress", target_stress, "Pa")
        self.max_rate = check_positive("growth max_rate", max_rate)

    def apply(self, sim):
        mean_stress = float(np.mean(sim.walls.stress()))
        rate = self.max_rate * float(np.clip(1.0 - mean_stress / self.target_stress, -1.0, 1.0))
        sim.particles.radius *= 1.0 + rate
        sim.particles.update_mass()


class GrowthTimeStep:
    """A control of the radius growth: dt = ``safety`` times the P-wave estimate of the current
    radii (young [Pa], density [kg/m^3]), at every neighbour-list rebuild (the spheres grow
    and the step with them; a cloud whose contacts are still forming has no contact network
    to read a critical step from)."""

    def __init__(self, safety, young, density):
        self.safety = check_positive("timestep_safety", safety)
        self.young = check_positive("young", young, "Pa")
        self.density = check_positive("density", density, "kg/m^3")
        #: the neighbour list's rebuild count when dt was last set (None: not yet)
        self.seen_rebuilds = None

    def step_for(self, radius):
        """dt [s] for spheres of ``radius`` [m]."""
        return self.safety * pwave_timestep(radius, self.young, self.density)

    def apply(self, sim):
        if sim.neighbors.rebuilds != self.seen_rebuilds:
            self.seen_rebuilds = sim.neighbors.rebuilds
            sim.dt = self.step_for(sim.particles.radius)
