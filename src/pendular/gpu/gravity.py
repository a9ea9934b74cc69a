"""Gravity on the device: the CPU's own per-particle body (pendular.dem.gravity
._add_particle_weight, compiled by device_twin), one thread per particle, after the gather of
the pair forces and the walls (pendular.gpu.forces.gather). The CPU subtracts the weight where
Gravity stands among the forces; the device after every force it gathers, the same sum in
another order (round-off) when Gravity precedes one of them (the bridges, listed last)."""

from pendular.dem.gravity import Gravity, _add_particle_weight
from pendular.gpu.cuda import cuda, device_twin
from pendular.gpu.operations import DeviceSide, device_side

add_particle_weight = device_twin(_add_particle_weight)


@cuda.jit
def add_weight(force, mass, gravity):
    """Subtract particle p's weight m g [N] from its ``force`` (N, 3) along z (pendular.dem
    .gravity.add_weight); ``gravity`` [m/s^2]."""
    p = cuda.grid(1)
    if p >= mass.shape[0]:
        return
    add_particle_weight(p, force, mass, gravity)


@device_side(Gravity)
class Weight(DeviceSide):
    """Gravity's side: its launch after the gather; inside walls only."""

    family = "force"
    role = "gravity"
    in_cell = False

    def launches(self, state, dt):
        """(kernel, items, arguments) of a step's weight (its acceleration now; ``state`` a
        DeviceState), to run after the gather."""
        return [(add_weight, state.count, (state.force, state.mass, self.op.acceleration))]
