"""The radius growth of a preparation on the device (pendular.dem.growth on the CPU).

- RadiusGrowth: its row of the controls' program sets this step's rate g from the box's
  stresses, the walls' or a periodic cell's (pendular.gpu.walls.growth_rate,
  pendular.gpu.cell); ``grow`` then multiplies every radius by (1 + g)
  and sets mass and inertia at constant density (Particles.update_mass), before the
  integrator.
- The neighbour list's rebuild test with growing radii (pendular.dem.neighbors.moved_beyond):
  a particle's displacement plus its radius's growth since the last rebuild against half the
  skin (``grown_beyond``, after the integrator), the radii at each rebuild kept by
  ``mark_rebuild`` (between the rebuild's launches and the pair forces, while the rebuild flag
  is still set).
- GrowthTimeStep: at a rebuild step the host reads the flag before the step, runs the step up
  to the integrator, reads the radii back and sets dt (the CPU's GrowthTimeStep.step_for on
  the same radii), so that the integrator of that step and the next steps use it, as on the
  CPU. Every other step reads nothing back but the flag.

The device's grid and rows are sized for the radii the growth may reach (``grown_state``):
the spheres of the box's volume at the densest packing.
"""

import math
import types

import numpy as np

from pendular.dem.state import Particles
from pendular.gpu.cuda import cuda
from pendular.gpu.state import DENSEST, DeviceState
from pendular.gpu.walls import GROWTH_TIMESTEP, RADIUS_GROWTH


@cuda.jit
def grow(radius, mass, inertia, density, parameters, row):
    """Radius of particle p times (1 + g), g = ``parameters[row, 2]`` (this step's rate);
    mass rho 4/3 pi R^3 and inertia 2/5 m R^2 (Particles.update_mass)."""
    p = cuda.grid(1)
    if p >= radius.shape[0]:
        return
    grown = radius[p] * (1.0 + parameters[row, 2])
    radius[p] = grown
    mass[p] = density * 4.0 / 3.0 * math.pi * grown ** 3.0
    inertia[p] = 0.4 * mass[p] * (grown * grown)


@cuda.jit
def mark_rebuild(radius, reference_radius, flags):
    """At a rebuild (``flags[0]`` set), keep particle p's radius as the list's reference."""
    p = cuda.grid(1)
    if flags[0] == 0 or p >= radius.shape[0]:
        return
    reference_radius[p] = radius[p]


@cuda.jit
def grown_beyond(position, reference_position, radius, reference_radius, limit, flags):
    """Set flags[0] when particle p's displacement plus radius growth since the last rebuild
    exceeds ``limit`` [m] (pendular.dem.neighbors.moved_beyond inside walls, or in a periodic
    cell whose faces do not move: no stretching, s = 1)."""
    p = cuda.grid(1)
    if p >= position.shape[0]:
        return
    growth = max(radius[p] - reference_radius[p], 0.0)
    if growth == 0.0:
        return              # the integrator's test is the whole test
    d0 = position[p, 0] - reference_position[p, 0]
    d1 = position[p, 1] - reference_position[p, 1]
    d2 = position[p, 2] - reference_position[p, 2]
    if math.sqrt(d0 * d0 + d1 * d1 + d2 * d2) + growth > limit:
        flags[0] = 1


def growth_factor_bound(particles, walls):
    """Largest factor [-] the radii can grow by in the walls' box: until the spheres fill
    DENSEST of its volume."""
    box = float(np.prod(walls.lengths()))
    return max(1.0, (DENSEST * box / particles.solid_volume()) ** (1.0 / 3.0))


class DeviceGrowth:
    """A scene's radius growth on the device (module docstring): ``of(scene)`` (None without
    a RadiusGrowth among the controls), ``grown_state`` for the device's arrays, ``launches``
    for the step's, ``advance`` for a step that sets the time step."""

    def __init__(self, scene):
        controls = scene.controls
        self.row = next(c for c, side in enumerate(controls) if side.role == RADIUS_GROWTH)
        timestep = next((c for c, side in enumerate(controls)
                         if side.role == GROWTH_TIMESTEP), None)
        if timestep is not None and timestep < self.row:
            raise ValueError("device='gpu' runs a GrowthTimeStep after the RadiusGrowth only "
                             "(it reads the grown radii)")
        self.timestep = None if timestep is None else controls[timestep].op
        self.reference_radius = None
        self._first = True

    @classmethod
    def of(cls, scene):
        """The growth of ``scene``'s controls (sides, pendular.gpu.operations.Scene), or
        None."""
        if not scene.controls_of(RADIUS_GROWTH):
            return None
        return cls(scene)

    def grown_state(self, sim, skin, wet, resisting=False):
        """DeviceState of ``sim`` whose grid cells and rows hold the neighbours of the
        largest radii the growth may reach (growth_factor_bound), with the radii, masses and
        inertias of now and the host's list (its per-pair state) in those rows; ``wet``,
        ``resisting`` as DeviceState's."""
        p = sim.particles
        bound = growth_factor_bound(p, sim.walls)
        grown = Particles(p.position, p.radius * bound, p.density, velocity=p.velocity,
                          angular_velocity=p.angular_velocity)
        state = DeviceState(types.SimpleNamespace(particles=grown, walls=sim.walls,
                                                  contacts=None), skin, wet,
                            resisting=resisting)
        for name in ("radius", "mass", "inertia"):
            setattr(state, name, cuda.to_device(np.ascontiguousarray(getattr(p, name))))
        if sim.contacts is not None and len(sim.contacts):
            rows = state.host_rows(sim.contacts, state.count)
            for name in ("pair_count", "pair_j", "shear_force", "normal", "overlap", "bridges",
                         "rolling"):
                setattr(state, name, cuda.to_device(rows[name]))
        self.reference_radius = cuda.to_device(np.ascontiguousarray(p.radius))
        return state

    def launches(self, steps, state, sim, limit):
        """The step's (kernel, items, arguments) ``steps`` with the growth's kernels in:
        mark_rebuild after the rebuild's three, grow after the controls (the walls' or a
        periodic cell's), grown_beyond after the integrator (the last)."""
        n = state.count
        steps = list(steps)
        controls = next(i for i, step in enumerate(steps) if step[0].py_func.__name__
                        in ("wall_controls", "cell_controls"))
        steps.insert(controls + 1, (grow, n, (state.radius, state.mass, state.inertia,
                                              float(sim.peek("particles").density),
                                              state.parameters,
                                              self.row)))
        steps.insert(3, (mark_rebuild, n, (state.radius, self.reference_radius, state.flags)))
        steps.append((grown_beyond, n, (state.position, state.reference_position, state.radius,
                                        self.reference_radius, limit, state.flags)))
        return steps

    def sets_timestep(self, sim, state):
        """Whether this step rebuilds the list and so sets dt (GrowthTimeStep): the device's
        rebuild flag, read now; the first step of a run rebuilds on the device, but sets dt
        only where the CPU would (its GrowthTimeStep has not seen the host's last rebuild)."""
        if self.timestep is None:
            return False
        first, self._first = self._first, False
        if first:
            return self.timestep.seen_rebuilds != sim.neighbors.rebuilds
        return bool(state.flags[0:1].copy_to_host()[0])

    def advance(self, gpu, launches):
        """One step of ``gpu`` (a GpuSimulation) by its ``launches``; at a step that sets the
        time step, dt set from the grown radii before the integrator's launches (the last
        two) and the step's launches configured again with it."""
        sim, state = gpu.sim, gpu.state
        if not self.sets_timestep(sim, state):
            for kernel, args in launches:
                kernel(*args)
            return
        for kernel, args in launches[:-2]:
            kernel(*args)
        sim.dt = self.timestep.step_for(state.radius.copy_to_host())
        gpu.configure()
        state.control_step.copy_to_device(np.array([sim.step + 1], np.int64))
        for kernel, args in gpu.launches[-2:]:
            kernel(*args)

    def to_host(self, sim, state):
        """The device's radii, masses and inertias into ``sim``'s particles."""
        p = sim.particles
        for name in ("radius", "mass", "inertia"):
            getattr(state, name).copy_to_host(getattr(p, name))

    def after_copy_back(self, sim):
        """The time step's memory of the host's rebuilds (copy_back rebuilt the host's list:
        the CPU going on from here sets dt at its own next rebuild, as the device would)."""
        if self.timestep is not None:
            self.timestep.seen_rebuilds = sim.neighbors.rebuilds

