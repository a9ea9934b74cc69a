"""Capillary bridges' device side (pendular.capillary.bridges: SuctionBridges, VolumeBridges):
their tables in device memory, the suction the pair forces' lookups read, the liquid of volume
control, the sphere–wall bridges (pendular.gpu.wall_bridges), and what comes back to the
host. Their kernels are pendular.gpu.forces's
(pair_forces, exchange_liquid, refresh_bridges); their per-pair state is
pendular.gpu.state's ``bridges``.

A dry scene has ``NoBridges`` in their place: the stand-ins of the arrays the kernels take and
do not read (a kernel takes no None).
"""

import numpy as np

from pendular.capillary.bridges import SuctionBridges, VolumeBridges
from pendular.dem.neighbors import carry_pair_array
from pendular.gpu import forces
from pendular.gpu.cuda import configured, cuda
from pendular.gpu.operations import DeviceSide, device_side
from pendular.gpu.wall_bridges import DeviceWallBridges

#: Shapes of the stand-ins of a BridgeTable's and a VolumeBridgeTable's arrays().
TABLE_SHAPES = ((1,), (3,), (1, 1), (1, 1), (1, 1, 1, 1))
VOLUME_TABLE_SHAPES = ((1,), (1, 2), (1, 1), (1, 1), (1, 1, 1, 1))


def _on_device(arrays):
    return tuple(cuda.to_device(np.ascontiguousarray(a)) for a in arrays)


class NoBridges:
    """A dry scene's bridges: no operation, zero suction, stand-in tables."""

    op = None
    wet = False
    persist = False
    volume_control = False
    surface_tension = 1.0
    roughness = 0.0
    closed = False

    def __init__(self):
        self.suction = 0.0
        self.table = _on_device(np.zeros(shape) for shape in TABLE_SHAPES)
        self.volume_table = _on_device(np.zeros(shape) for shape in VOLUME_TABLE_SHAPES)

    def upload(self, sim):
        """(reach [m], film) of the device's state: none."""
        return 0.0, None

    def follow_suction(self, state, holding):
        """Nothing to follow."""

    def pairs_to_host(self, sim, state, index):
        """Nothing to bring back."""

    def reach_changed(self, state):
        """Whether the bridges' reach differs from the one ``state`` was sized for: never."""
        return False


@device_side(SuctionBridges)
class SuctionBridgesOnDevice(DeviceSide, NoBridges):
    """Suction-controlled bridges, at contact (joined to the contact law's gather) or across
    gaps (``persist``: their forces on j from i gathered last)."""

    family = "force"
    role = "bridges"
    wet = True

    def __init__(self, op):
        DeviceSide.__init__(self, op)
        NoBridges.__init__(self)
        self.walls = None if op.walls is None else DeviceWallBridges(op.walls)

    @property
    def persist(self):
        """Whether the bridges persist across gaps (the operation's option)."""
        return self.op.persist

    @property
    def surface_tension(self):
        """gamma [N/m] now."""
        return self.op.surface_tension

    def check(self, scene):
        """Bridges across gaps (``persist``) run listed after the contact law and the wall
        forces (the device adds their forces last, as the CPU's gather_pair_forces after
        both), with radii that do not grow; sphere–wall bridges (``walls``) inside walls,
        listed after the wall forces (the CPU's pulls enter the walls' sums the wall forces
        have set), with radii that do not grow (their table is checked for the radii at each
        run)."""
        if self.walls is not None:
            if scene.periodic:
                raise ValueError("device='gpu' runs sphere-wall bridges (--wall-bridges) "
                                 "inside walls only, not in a periodic cell")
            if scene.index(self) < scene.index(scene.force("walls", required=True)):
                raise ValueError("device='gpu' runs sphere-wall bridges (--wall-bridges) "
                                 "listed after the wall forces only")
            if any(side.grows_radii for side in scene.controls):
                raise ValueError("device='gpu' does not run sphere-wall bridges "
                                 "(--wall-bridges) while radii grow (RadiusGrowth)")
        if not self.persist:
            return
        what = f"bridges across gaps ({self.name} with persist = True)"
        after = scene.forces[scene.index(self) + 1:]
        if any(side.role in ("contact law", "walls") for side in after):
            raise ValueError(f"device='gpu' runs {what} listed after the contact law and the "
                             "wall forces only")
        if any(side.grows_radii for side in scene.controls):
            raise ValueError(f"device='gpu' does not run {what} while radii grow "
                             "(RadiusGrowth)")

    def upload(self, sim):
        """The tables into device memory (loaded, the suction checked: the bridges'
        ``reach``) and the neighbour list's reach beyond touching (the CPU's
        NeighborList.interaction_range: the rupture range of persisting bridges); returns
        (reach [m], film (N,) [m^3] or None)."""
        op = self.op
        reach = op.reach(sim)
        sim.neighbors.interaction_range = reach
        self.table = _on_device(op.suction_table.arrays())
        self.suction = op.suction
        return reach, None

    def follow_suction(self, state, holding):
        """The bridges at the suction imposed now (a suction path: SuctionBridges.set_suction
        between runs), as the CPU's next step: the bridges at contact looked up again at a
        new suction (forces.refresh_bridges, the CPU's refresh_contact_bridges), the suction
        of the next steps' lookups. The list's reach (the rupture range, which never
        shrinks) must be the one the device's grid and rows were sized for (``state``: a
        DeviceState; ``holding``: whether the device holds the scene's state now)."""
        self._check_reach(state)
        self.suction = self.op.suction
        if self.op.take_new_suction():
            kernel, items, args = self.refresh_step(state)
            configured(kernel, items)(*args)

    def launches(self, state, dt):
        """The sphere–wall bridges' step (pendular.gpu.wall_bridges), none without them."""
        return [] if self.walls is None else self.walls.launches(state, self.op)

    def wall_launches(self, state):
        """The sphere–wall bridges' pulls on the walls, after the walls' own sums."""
        return [] if self.walls is None else self.walls.wall_launches(state)

    def changed_on_host(self):
        """Whether the host imposed a new suction during a run (LiquidClusters.hold_volume
        between two steps)."""
        return self.op.suction != self.suction

    def reach_changed(self, state):
        """Whether the bridges' reach (the rupture range, which grows as the suction falls)
        differs from the one ``state`` (a DeviceState) was sized for."""
        return self.op.required_range != state.reach

    def _check_reach(self, state):
        if self.reach_changed(state):
            raise ValueError(f"the bridges' reach {self.op.required_range:g} m changed since "
                             f"the GPU copy was made ({state.reach:g} m; a lower suction "
                             "of persisting bridges): call to_host() and build a new "
                             "GpuSimulation")

    def refresh_step(self, state):
        """(kernel, items, arguments) of the bridges at contact looked up again at the
        suction now (forces.refresh_bridges)."""
        s = state
        return (forces.refresh_bridges, s.count,
                (s.radius, s.pair_count, s.pair_j, s.bridge_columns()[:5], self.op.suction,
                 self.op.surface_tension, self.table))

    def pairs_to_host(self, sim, state, index):
        """Persisting bridges' host state for the CPU's list (``index``: its pairs in the
        device's, previous_pair_index): their count, which the CPU's next list must carry
        (CapillaryBridges._attach), and their forces on j from i at the last step, carried to
        the same pairs (CapillaryBridges.pair_forces reads them). Nothing for bridges at
        contact (the list's per-pair state holds them). The sphere–wall bridges' state and
        moments per sphere and wall (``walls``)."""
        if self.walls is not None:
            self.walls.to_host()
        if not self.persist:
            return
        self.op.adopt(sim)
        self.op.pair_force[:] = carry_pair_array(state.bridge_pair_forces(), index)


@device_side(VolumeBridges)
class VolumeBridgesOnDevice(SuctionBridgesOnDevice):
    """Volume-controlled bridges (always across gaps) and their liquid: the film on each
    grain and the liquid lost, exchanged on the device (forces.exchange_liquid)."""

    volume_control = True

    @property
    def persist(self):
        """Volume-controlled bridges always persist across gaps."""
        return True

    def changed_on_host(self):
        """Never during a run: the formation suction changes between runs (a wetting's try),
        which a run's set-up reads."""
        return False

    @property
    def roughness(self):
        """The liquid model's roughness now."""
        return self.op.roughness

    @property
    def closed(self):
        """Whether the liquid is a closed amount."""
        return self.op.closed

    def upload(self, sim):
        """As the suction's, with the volume table and the film on each grain (zeros when the
        host has none for these particles)."""
        reach, _ = super().upload(sim)
        self.volume_table = _on_device(self.op.volume_table.arrays())
        count = len(sim.particles)
        film = self.op.film
        return reach, (film if film is not None and len(film) == count else np.zeros(count))

    def follow_suction(self, state, holding):
        """Volume control's film and lost liquid from the host's bridges when the host holds
        the state (its close_liquid may have changed them since the device's last copy)."""
        self._check_reach(state)
        if holding:
            return
        if self.op.film is not None:      # None: no step yet, no film (the device's zeros)
            state.film.copy_to_device(np.ascontiguousarray(self.op.film, dtype=np.float64))
        state.liquid_lost.copy_to_device(np.array([self.op.liquid_lost]))

    def exchange_step(self, state):
        """(kernel, items, arguments) of the liquid exchange (forces.exchange_liquid: the
        liquid model's sharing and the volume table's range now)."""
        s = state
        smallest, largest = self.op.volume_table.volume_star_bounds()
        return (forces.exchange_liquid, 1,
                (s.radius, s.pairs(), s.transposed(), *s.bridge_columns()[:2],
                 forces.Liquid(self.roughness, self.closed, s.film, s.released, s.events,
                               s.marked),
                 self.op.shares, smallest, largest, s.liquid_lost))

    def pairs_to_host(self, sim, state, index):
        """As the suction's across gaps, with the film on each grain and the liquid lost."""
        super().pairs_to_host(sim, state, index)
        self.op.film = state.film.copy_to_host()
        self.op.liquid_lost = float(state.liquid_lost.copy_to_host()[0])
