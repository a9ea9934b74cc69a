"""A CPU Simulation's scene run on the GPU: ``GpuSimulation(sim).run(steps)``.

The state is copied to the device once; each step is a fixed sequence of kernel launches, the
CPU pipeline (pendular.dem.simulation) on the device::

    bin_particles, find_pairs, finish_rebuild   neighbour list (only when a rebuild is due)
    pair_forces                                 contact law (+ bridges, wet)
    gather                                      forces and torques per particle (+ walls)
    pair_moments, gather_moments                rolling resistance (its moments on torques)
    add_weight                                  gravity
    wall_partials, wall_sums, wall_controls     walls' force, stiffness, moment; controls
    grip_partials, grip_hold                    grips: their pulls, members on their walls
    leapfrog                                    integrator (+ the rebuild test)

The host reads nothing per step. It reads the device's flags at its checks (every
``check_every`` steps, as Simulation.run checks ``until``: the loop is Simulation.run_chunks).
After each step the Simulation's state is held by the device (Simulation.hold) and the writers
are called as on the CPU: one that reads the state (a HistoryRecorder at its recording steps,
a checkpoint at its period) fetches it first (Simulation.fetch, which calls ``copy_back``; the
walls alone when only they are read, as a stress ``until`` does every step), one that is not
due reads nothing and costs no copy. Simulation.run brings the state back as it returns; a
GpuSimulation driven directly leaves it held until fetched (or ``to_host``), so that runs in a
row copy nothing between them (a run's set-up reads what the scene is made of with
Simulation.peek).

A mixed stress condition (MixedStress) sets its servos' targets on the device from the walls'
stresses, as the CPU does. When a target falls below zero the device records it and the host
raises the CPU's StageFailed at its next check or, earlier, when anything fetches the state
(``copy_back``), so that no writer records a state past the failure.

What runs on the device so far: walled scenes (``Walls``) with ContactForces (or the damped
and Hertz–Mindlin laws of pendular.dem.hertz_mindlin), WallForces or a wall law with springs
(ViscoelasticWallForces, FrictionalWallForces: pendular.gpu.wall_friction), RollingResistance
(pendular.gpu.rolling), Gravity (pendular.gpu.gravity) and, wet, SuctionBridges at contact or
across gaps (``persist``; a new suction between runs, as the CPU: GpuSimulation._follow_suction);
controls StressServo, ConstantStrainRate, MixedStress (its servos among the controls),
RadiusGrowth and GrowthTimeStep (pendular.gpu.growth), Grip after them (pendular.gpu.grips);
the Integrator. A periodic cell (``PeriodicCell``, sheared or not) with ContactForces (or a
damped or Hertz–Mindlin law), RollingResistance and, wet, SuctionBridges at contact or across
gaps or VolumeBridges, under StressServo, ConstantStrainRate, ConstantShearRate (simple
shear, Lees–Edwards) and MixedStress (pendular.gpu.cell): its step wraps the particles and finds the pairs through the
cell's faces at a rebuild (as far as the bridges' rupture range), reduces the cell's stress
(with the face terms of the forces of bridges across gaps), runs its controls and a leapfrog
carried by its stretching and shear, or grows the radii (RadiusGrowth, GrowthTimeStep) in a
cell whose faces no control moves. Anything else (a radius growth in a moving cell) is refused by
name (ValueError), so that a scene never runs with part of its physics missing.
"""

import numpy as np

from pendular.capillary.bridges import CapillaryBridges, SuctionBridges, VolumeBridges
from pendular.dem.cell import ConstantShearRate, PeriodicCell
from pendular.dem.contact_law import ContactForces
from pendular.dem.gravity import Gravity
from pendular.dem.hertz_mindlin import (DampedLinearForces, HertzMindlinForces,
    ViscoelasticWallForces)
from pendular.dem.grips import Grip
from pendular.dem.growth import GrowthTimeStep, RadiusGrowth
from pendular.dem.integrate import Integrator
from pendular.dem.mixed_stress import MixedStress
from pendular.dem.neighbors import NeighborList, carry_pair_array, previous_pair_index
from pendular.dem.rolling import RollingResistance
from pendular.dem.state import Walls
from pendular.dem.wall_friction import FrictionalWallForces
from pendular.dem.walls import ConstantStrainRate, StressServo, WallForces
from pendular.gpu import (cell as device_cell, forces, gravity as device_gravity, integrate,
    neighbors, rolling as device_rolling, walls as device_walls)
from pendular.gpu.cuda import configured, cuda, simulated
from pendular.gpu.grips import DeviceGrips, check_grips
from pendular.gpu.growth import DeviceGrowth
from pendular.gpu.homogenize import device_homogenization
from pendular.gpu.state import DeviceState
from pendular.gpu.wall_friction import DeviceSpringWalls
from pendular.utils.validate import check_int


#: The first launches of a step, the neighbour list's: in the simulator, where the host reads
#: the device's memory for free, they are skipped when no rebuild is due (the kernels would
#: return at once), which saves a third of a simulated step.
REBUILD_LAUNCHES = 3


def _one(sim, kind, required=True):
    """The one operation of class ``kind`` among sim's forces (None if absent and not
    ``required``)."""
    found = [op for op in sim.forces if type(op) is kind]
    if len(found) > 1 or (required and not found):
        raise ValueError(f"device='gpu' needs {'one' if required else 'at most one'} "
                         f"{kind.__name__} among the forces; found {len(found)}")
    return found[0] if found else None


def _contact_law(sim):
    """The one contact law among sim's forces: a ContactForces, or a damped or Hertz–Mindlin
    law (pendular.dem.hertz_mindlin), which the device runs with the same gather."""
    found = [op for op in sim.forces if isinstance(op, ContactForces)]
    if len(found) != 1:
        raise ValueError(f"device='gpu' needs one contact law among the forces; found "
                         f"{len(found)}")
    return found[0]


def check_scene(sim):
    """ValueError naming what of ``sim`` the GPU path does not run yet (module docstring).
    Reads what the scene is made of, not its state (Simulation.peek)."""
    box = sim.peek("walls")
    if not isinstance(box, (Walls, PeriodicCell)):
        raise ValueError(f"device='gpu' runs walled scenes and periodic cells only; the box "
                         f"is a {type(box).__name__}")
    if isinstance(box, PeriodicCell):
        _check_periodic(sim, box)
    if type(sim.neighbors) is not NeighborList or type(sim.integrator) is not Integrator:
        raise ValueError("device='gpu' needs pendular's NeighborList and Integrator")
    for op in sim.forces:
        if type(op) not in (ContactForces, HertzMindlinForces, DampedLinearForces, WallForces,
                            ViscoelasticWallForces, FrictionalWallForces,   # wall_friction
                            SuctionBridges, VolumeBridges, RollingResistance, Gravity):
            raise ValueError(f"device='gpu' does not run the force {type(op).__name__} yet "
                             "(valid: ContactForces, HertzMindlinForces, DampedLinearForces, "
                             "WallForces, ViscoelasticWallForces, FrictionalWallForces, "
                             "SuctionBridges, VolumeBridges, RollingResistance, Gravity)")
    _one(sim, Gravity, required=False)             # at most one of each
    resistance = _one(sim, RollingResistance, required=False)
    if resistance is not None and sim.forces.index(resistance) < sim.forces.index(
            _contact_law(sim)):
        raise ValueError("device='gpu' runs a RollingResistance listed after the contact law "
                         "only (it reads the contact law's pairs of the same step)")
    bridges = _bridges_of(sim)
    if bridges is not None and bridges.walls is not None:     # wall_bridges: no device side
        raise ValueError("device='gpu' does not run sphere-wall bridges (--wall-bridges) yet: "
                         "run them with --device cpu")
    if bridges is not None and bridges.persist:
        _check_persist(sim, bridges)
    controls = sim.peek("controls")
    for op in controls:
        if type(op) not in (StressServo, ConstantStrainRate, RadiusGrowth, Grip) \
                and not isinstance(op, (MixedStress, GrowthTimeStep)) \
                and not (type(op) is ConstantShearRate and box.periodic):
            raise ValueError(f"device='gpu' does not run the control {type(op).__name__} yet "
                             "(valid: StressServo, ConstantStrainRate, MixedStress, "
                             "RadiusGrowth, GrowthTimeStep, Grip; ConstantShearRate in a "
                             "periodic cell)")
        if isinstance(op, MixedStress) and not all(
                any(op.servos[axis] is other for other in controls) for axis in op.free):
            raise ValueError("device='gpu' runs a MixedStress whose servos are among the "
                             "scene's controls only")
    for kind in (RadiusGrowth, GrowthTimeStep):
        if sum(isinstance(op, kind) for op in controls) > 1:
            raise ValueError(f"device='gpu' runs at most one {kind.__name__} among the controls")
    check_grips(list(controls), len(sim.peek("particles")))


def _bridges_of(sim):
    """The one CapillaryBridges (SuctionBridges or VolumeBridges) among sim's forces, or None;
    ValueError when there are several."""
    found = [op for op in sim.forces if isinstance(op, CapillaryBridges)]
    if len(found) > 1:
        raise ValueError(f"device='gpu' runs at most one bridge operation among the forces; "
                         f"found {len(found)}")
    return found[0] if found else None


def _check_persist(sim, bridges):
    """ValueError naming what of bridges across gaps (SuctionBridges ``persist``,
    VolumeBridges) the GPU path does not run: gathered before the contact law or the walls
    (the device adds their forces last, as the CPU's gather_pair_forces after both), or with
    radii that grow."""
    what = f"bridges across gaps ({type(bridges).__name__} with persist = True)"
    if sim.forces[-1] is not bridges:
        raise ValueError(f"device='gpu' runs {what} listed after the contact law and the wall "
                         "forces only")
    if any(isinstance(op, RadiusGrowth) for op in sim.peek("controls")):
        raise ValueError(f"device='gpu' does not run {what} while radii grow (RadiusGrowth)")


def _check_periodic(sim, cell):
    """ValueError naming what of a periodic scene the GPU path does not run yet (a sheared
    cell, ConstantShearRate, MixedStress and a radius growth in a fixed cell run:
    pendular.gpu.cell)."""
    for op in sim.forces:
        if isinstance(op, (WallForces, ViscoelasticWallForces, Gravity)):
            raise ValueError(f"device='gpu' runs a periodic cell without {type(op).__name__} "
                             "(it has no walls)")
    controls = sim.peek("controls")
    for op in controls:
        if type(op) not in (StressServo, ConstantStrainRate, ConstantShearRate, RadiusGrowth) \
                and not isinstance(op, (MixedStress, GrowthTimeStep)):
            raise ValueError(f"device='gpu' does not run the control {type(op).__name__} in a "
                             "periodic cell yet (valid: StressServo, ConstantStrainRate, "
                             "ConstantShearRate, MixedStress, RadiusGrowth, GrowthTimeStep)")
    moving = [type(op).__name__ for op in controls
              if type(op) is not RadiusGrowth and not isinstance(op, GrowthTimeStep)]
    if any(type(op) is RadiusGrowth for op in controls) and (moving or cell.sheared):
        raise ValueError("device='gpu' runs a RadiusGrowth in a periodic cell whose faces no "
                         f"control moves only (its rebuild test: pendular.gpu.growth); found "
                         f"{', '.join(moving) or 'a sheared cell'}")


class GpuSimulation:
    """Runs ``sim`` (a pendular.dem.simulation.Simulation whose scene the GPU path supports,
    ``check_scene``) on the GPU: ``run(steps)`` as Simulation.run (its loop,
    Simulation.run_chunks, with the device's steps and checks), ``to_host()`` to bring the
    state back into ``sim`` (done whenever anything reads it from sim: module docstring).
    ``sim.step`` and ``sim.time`` advance with the device. Parameters of the operations
    (friction, servo target, dt, ...) are read at every ``run`` (the targets a MixedStress
    sets are the device's); a scene whose operations change (a new control list) needs
    ``to_host()`` and a new GpuSimulation.
    """

    def __init__(self, sim):
        check_scene(sim)
        self.sim = sim
        bridges = _bridges_of(sim)
        self._bridges = bridges
        self._volume_control = isinstance(bridges, VolumeBridges)
        reach = 0.0
        # the tables' arrays (BridgeTable, VolumeBridgeTable: arrays()), stand-ins when unread
        self._table = tuple(cuda.to_device(np.zeros(shape)) for shape in
                            ((1,), (3,), (1, 1), (1, 1), (1, 1, 1, 1)))
        self._volume_table = tuple(cuda.to_device(np.zeros(shape)) for shape in
                                   ((1,), (1, 2), (1, 1), (1, 1), (1, 1, 1, 1)))
        self._suction = 0.0
        if bridges is not None:
            # loads the tables, checks the suction; the list's reach beyond touching (the
            # CPU's NeighborList.interaction_range: the rupture range of persisting bridges)
            reach = bridges.reach(sim)
            sim.neighbors.interaction_range = reach
            self._table = tuple(cuda.to_device(np.ascontiguousarray(a))
                                for a in bridges.suction_table.arrays())
            self._suction = bridges.suction
        film = None
        if self._volume_control:
            self._volume_table = tuple(cuda.to_device(np.ascontiguousarray(a))
                                       for a in bridges.volume_table.arrays())
            count = len(sim.particles)
            film = (bridges.film if bridges.film is not None and len(bridges.film) == count
                    else np.zeros(count))
        self._growth = DeviceGrowth.of(tuple(sim.controls))
        persist = bridges is not None and bridges.persist
        self._resistance = _one(sim, RollingResistance, required=False)
        resisting = self._resistance is not None
        # wall_friction: a wall law with springs runs its own launches (pendular.gpu.wall_friction)
        self._spring_walls = DeviceSpringWalls.of(sim.forces, len(sim.particles))
        self.state = (DeviceState(sim, sim.neighbors.skin, bridges is not None, reach, persist,
                                  film, resisting)
                      if self._growth is None else
                      self._growth.grown_state(sim, sim.neighbors.skin, bridges is not None,
                                               resisting))
        self._controls = tuple(sim.controls)
        self._mixed = tuple(c for c, op in enumerate(self._controls)
                            if isinstance(op, MixedStress))
        # the rows of the servos whose targets a MixedStress sets on the device
        driven = set()
        for c in self._mixed:
            mixed = self._controls[c]
            driven.update(self._row(mixed.servos[axis]) for axis in mixed.free)
        self._driven = tuple(sorted(driven))
        self._holding = False
        self._upload_controls()
        self._steps = []
        self._launches = []

    # ---------------------------------------------------------------- set-up
    def _row(self, control):
        """The row of ``control`` (one of the scene's, by identity) in the controls' program."""
        return next(c for c, op in enumerate(self._controls) if op is control)

    def _upload_controls(self):
        """The controls' program and memory (pendular.gpu.walls) from the host's operations."""
        count = max(1, len(self._controls))
        kinds = np.zeros(len(self._controls), np.int64)
        control_walls = np.zeros((count, 6), np.int64)
        wall_counts = np.zeros(count, np.int64)
        previous = np.zeros((count, 6))
        stiffness = np.zeros((count, 6))
        calls = np.zeros(count, np.int64)
        for c, op in enumerate(self._controls):
            if type(op) is StressServo:
                kinds[c] = device_walls.STRESS_SERVO
                # a periodic cell's servo reads its axes (pendular.gpu.cell)
                walls = op.axes if self.state.periodic else op.walls
                previous[c, :len(op.walls)] = op.previous
                stiffness[c, :len(op.walls)] = op.stiffness
                calls[c] = op.calls
            elif type(op) is ConstantStrainRate:
                kinds[c] = device_walls.STRAIN_RATE
                walls = ((op.axis,) if self.state.periodic else
                         (2 * op.axis, 2 * op.axis + 1))
            elif type(op) is RadiusGrowth:
                kinds[c] = device_walls.RADIUS_GROWTH
                continue
            elif isinstance(op, GrowthTimeStep):
                kinds[c] = device_walls.GROWTH_TIMESTEP
                continue
            elif type(op) is Grip:          # held after the walls' controls (pendular.gpu.grips)
                kinds[c] = device_walls.GRIP
                continue
            elif type(op) is ConstantShearRate:     # a periodic cell's (pendular.gpu.cell)
                kinds[c] = device_walls.SHEAR_RATE
                continue
            else:
                kinds[c] = device_walls.MIXED_STRESS
                control_walls[c, :3] = [self._row(op.servos[axis]) if axis in op.free else -1
                                        for axis in range(3)]
                control_walls[c, 3:3 + len(op.free)] = op.free
                wall_counts[c] = len(op.free)
                continue
            control_walls[c, :len(walls)] = walls
            wall_counts[c] = len(walls)
        s = self.state
        s.kinds = cuda.to_device(kinds)
        s.control_walls = cuda.to_device(control_walls)
        s.wall_counts = cuda.to_device(wall_counts)
        s.previous = cuda.to_device(previous)
        s.stiffness = cuda.to_device(stiffness)
        s.calls = cuda.to_device(calls)
        s.parameters = cuda.to_device(self._control_parameters())
        s.control_step = cuda.to_device(np.zeros(1, np.int64))
        s.failure = cuda.to_device(np.zeros(len(device_walls.FAILURE_FIELDS)))
        self._grips = DeviceGrips.of(self._controls)
        if s.periodic:          # the shear's layout and state (pendular.gpu.cell)
            cell = self.sim.walls
            device_cell.upload_shear(s, cell, device_cell.sheared_layout(cell, self._controls))

    def _control_parameters(self):
        """(controls, 6) parameters of the controls now (pendular.gpu.walls's fields)."""
        parameters = np.zeros((max(1, len(self._controls)), 6))
        for c, op in enumerate(self._controls):
            if type(op) is StressServo:
                parameters[c] = (op.target, op.gain, op.memory, op.max_velocity,
                                 float(op.scale_max_velocity), float(op.stiffness_every))
            elif type(op) is ConstantStrainRate:
                parameters[c, :3] = (op.rate, op.reference_length, float(op.on_current_length))
            elif type(op) is ConstantShearRate:
                parameters[c, 0] = op.rate
            elif type(op) is RadiusGrowth:
                parameters[c, :2] = (op.target_stress, op.max_rate)
            elif isinstance(op, MixedStress):
                parameters[c, :5] = (np.nan if op.mean_stress is None else op.mean_stress,
                                     np.nan if op.b is None else op.b,
                                     *(op.stress.get(axis, np.nan) for axis in range(3)))
        return parameters

    def _targets_to_host(self):
        """The targets the device's MixedStress controls set, into their servos on the host."""
        if self._driven:
            targets = self.state.parameters.copy_to_host()[:, 0]
            for c in self._driven:
                self._controls[c].target = float(targets[c])

    def _configure(self):
        """The step's launches (``_launches``: configured kernel, arguments) with the
        operations' parameters now."""
        sim = self.sim
        if tuple(sim.peek("controls")) != self._controls:
            raise ValueError("the scene's controls changed since the GPU copy was made: call "
                             "to_host() and build a new GpuSimulation")
        check_scene(sim)
        self._follow_suction()
        if self._holding:           # the host's targets of a MixedStress's servos are stale
            self._targets_to_host()
        self.state.parameters.copy_to_device(self._control_parameters())
        self.state.control_step.copy_to_device(np.array([sim.step], np.int64))
        if self.state.periodic:
            self._steps = self._cell_steps()
        else:
            self._steps = self._walled_steps()
        if self._growth is not None:
            self._steps = self._growth.launches(self._steps, self.state, sim,
                                                0.5 * self.state.skin)
        self._launches = [(configured(kernel, items), args)
                          for kernel, items, args in self._steps]

    def _follow_suction(self):
        """The bridges at the suction imposed now (a suction path: SuctionBridges.set_suction
        between runs), as the CPU's next step: the bridges at contact looked up again at a new
        suction on the device (forces.refresh_bridges, the CPU's refresh_contact_bridges),
        the suction of the next steps' lookups. The list's reach (the rupture range, which
        never shrinks) must be the one the device's grid and rows were sized for: a farther
        one needs a new GpuSimulation (Simulation.run makes one for each run)."""
        bridges = self._bridges
        if bridges is None:
            return
        if bridges.required_range != self.state.reach:
            raise ValueError(f"the bridges' reach {bridges.required_range:g} m changed since "
                             f"the GPU copy was made ({self.state.reach:g} m; a lower suction "
                             "of persisting bridges): call to_host() and build a new "
                             "GpuSimulation")
        if self._volume_control:
            self._liquid_from_host()
            return
        self._suction = bridges.suction
        if bridges.take_new_suction():
            kernel, items, args = self._refresh_step()
            configured(kernel, items)(*args)

    def _liquid_from_host(self):
        """Volume control's film and lost liquid from the host's bridges when the host holds
        the state (its close_liquid may have changed them since the device's last copy)."""
        if self._holding:
            return
        bridges = self._bridges
        if bridges.film is not None:        # None: no step yet, no film (the device's zeros)
            self.state.film.copy_to_device(np.ascontiguousarray(bridges.film,
                                                                dtype=np.float64))
        self.state.liquid_lost.copy_to_device(np.array([bridges.liquid_lost]))

    def _refresh_step(self):
        """(kernel, items, arguments) of the bridges at contact looked up again at the
        suction now (forces.refresh_bridges)."""
        s = self.state
        return (forces.refresh_bridges, s.count,
                (s.radius, s.pair_count, s.pair_j, *self._bridge_columns()[:5],
                 self._bridges.suction, self._bridges.surface_tension, *self._table))

    def _bridge_columns(self):
        """The device's bridge columns (pendular.gpu.state.BRIDGE_COLUMNS) as the law's
        arrays."""
        bridges = self.state.bridges
        return tuple(bridges[:, c] for c in range(bridges.shape[1]))

    def _force_steps(self, image, period, affine_rate, walls_first, wall_young):
        """(kernel, items, arguments) of the pair forces and their gather (walls' springs of
        stiffness ``wall_young`` [Pa] E R, 0: none; images ``image``, ``period`` and
        stretching ``affine_rate``: pendular.gpu.forces.pair_forces), then the rolling
        resistance and the weight, if the scene has them."""
        sim = self.sim
        s = self.state
        n = s.count
        contact = _contact_law(sim)
        tan_friction = float(np.tan(np.radians(contact.friction_deg)))
        damped = type(contact) is not ContactForces
        stiffness = (contact.modulus, contact.tangential) if damped else (contact.young,
                                                                           contact.shear_ratio)
        columns = self._bridge_columns()
        # bridges at contact join the contact law's gather; persisting ones are added last
        joined = s.wet and not s.persist
        bridges = self._bridges
        volume = self._volume_control
        liquid = (bridges.roughness, bridges.closed) if volume else (0.0, False)
        gravity = _one(sim, Gravity, required=False)
        return [
            (forces.pair_forces, n, (s.position, s.velocity, s.angular_velocity, s.radius,
                                     s.pair_count, s.pair_i, s.pair_j, image, period,
                                     affine_rate, s.shear_force, s.normal,
                                     s.overlap, s.normal_force, s.pair_force, *stiffness,
                                     tan_friction, sim.dt, s.mass, damped,
                                     damped and contact.hertz,
                                     contact.damping if damped else 0.0, s.flags,
                                     s.wet, s.persist, volume, *columns,
                                     s.bridge_pair_force, self._suction,
                                     bridges.surface_tension if s.wet else 1.0,
                                     *self._table, *liquid, s.film, s.released, s.events,
                                     s.marked, *self._volume_table)),
            *((self._exchange_step(),) if volume else ()),
            (forces.gather, n, (s.position, s.radius, s.pair_count, s.second_count,
                                s.second_pair, s.pair_force, s.normal, s.overlap, joined,
                                columns[2], walls_first, s.wall_position, wall_young,
                                s.persist, s.bridge_pair_force, s.force, s.torque)),
            # wall_friction: the walls' springs right after the gather, as the CPU's walls
            *(self._spring_walls.launches(s, sim.dt) if self._spring_walls is not None
              else ()),
            *(device_rolling.launches(self._resistance, s, sim.dt)
              if self._resistance is not None else ()),
            *(device_gravity.launches(gravity, s) if gravity is not None else ()),
        ]

    def _exchange_step(self):
        """(kernel, items, arguments) of volume control's liquid exchange
        (forces.exchange_liquid: the liquid model's sharing and the volume table's range
        now)."""
        s = self.state
        smallest, largest = self._bridges.volume_table.volume_star_bounds()
        return (forces.exchange_liquid, 1,
                (s.radius, s.pair_count, s.pair_i, s.pair_j, s.second_count, s.second_pair,
                 *self._bridge_columns()[:2], s.film, s.released, s.events, s.marked,
                 self._bridges.shares, smallest, largest, s.liquid_lost))

    def _finish_step(self):
        """(kernel, items, arguments) of finish_rebuild."""
        s = self.state
        return (neighbors.finish_rebuild, s.count,
                (s.position, s.new_count, s.new_pair_j, s.lower_count, s.lower,
                 s.new_shear_force, s.new_normal, s.new_overlap, s.new_bridges, s.new_rolling,
                 s.pair_count, s.pair_j, s.second_count, s.second_pair, s.shear_force,
                 s.normal, s.overlap, s.bridges, s.rolling, s.normal_force, s.pair_force,
                 s.reference_position,
                 s.wall_position, s.reference_walls, s.cell_count, s.cell_of, s.flags,
                 s.rebuilds))

    def _cell_steps(self):
        """(kernel, items, arguments) of a step in a periodic cell (pendular.gpu.cell): the
        rebuild (wrap and bin, pairs through the faces, finish; in a sheared cell the offset
        it took stored), the forces (no walls), the cell's stress and controls, the leapfrog
        carried by the cell's stretching and shear."""
        sim = self.sim
        s = self.state
        n = s.count
        # bridges at contact join the contact law's gather (their attraction in the face
        # terms); persisting ones add their own forces' face terms (the CPU's
        # gather_pair_forces_virial)
        joined = s.wet and not s.persist
        bridges = s.bridges
        sheared = s.period.shape[0] > 3
        return [
            (neighbors.bin_periodic, n, (s.position, s.wall_position, s.period, s.wraps,
                                         s.cell_size, s.max_dims, s.cell_count,
                                         s.cell_members, s.cell_width, s.cell_of, s.flags)),
            (neighbors.find_periodic_pairs, n,
             (s.position, s.radius, s.skin + s.reach, s.wall_position, s.period, s.cell_size,
              s.max_dims, s.cell_count, s.cell_members, s.cell_width, s.cell_of, s.width,
              s.pair_count, s.pair_j, s.new_count, s.new_pair_j, s.image, s.lower_count,
              s.lower, s.shear_force, s.normal, s.overlap, bridges, s.rolling,
              s.new_shear_force, s.new_normal, s.new_overlap, s.new_bridges, s.new_rolling,
              s.flags)),
            self._finish_step(),
            *([(neighbors.shear_rebuilt, 1, (s.period, s.shear, s.flags))] if sheared else []),
            *self._force_steps(s.image, s.period, s.affine_rate, False, 0.0),
            (device_cell.cell_partials, s.cell_partial.shape[0],
             (s.position, s.force, s.radius, s.pair_count, s.pair_j, s.image, s.period,
              s.pair_force, s.normal, s.overlap, s.normal_force, joined, bridges[:, 2],
              s.persist, s.bridge_pair_force, s.kinds, s.parameters, s.calls,
              s.cell_partial)),
            (device_cell.cell_controls, 1,
             (s.cell_partial, s.wall_position, s.cell_rate, s.stress_tensor, s.cell_stiffness,
              s.period, s.affine_rate, s.shear, s.kinds, s.control_walls, s.wall_counts,
              s.parameters, s.previous, s.stiffness, s.calls, sim.dt, s.control_step,
              s.failure)),
            (integrate.cell_leapfrog, n,
             (s.position, s.velocity, s.angular_velocity, s.force, s.torque, s.mass,
              s.inertia, sim.integrator.damping, s.affine_rate, sim.dt, s.reference_position,
              s.wall_position, s.reference_walls, s.period, s.shear, 0.5 * s.skin,
              2.0 * float(sim.peek("particles").radius.max()) + s.skin + s.reach,
              s.flags)),
        ]

    def _walled_steps(self):
        """(kernel, items, arguments) of a step inside walls (module docstring)."""
        sim = self.sim
        springs = self._spring_walls        # wall_friction: a wall law with springs, or None
        wall_law = _one(sim, WallForces) if springs is None else springs.wall
        s = self.state
        n = s.count
        order = [type(op) for op in sim.forces]
        gatherer = (order.index(SuctionBridges) if s.wet and not s.persist
                    else sim.forces.index(_contact_law(sim)))
        walls_first = order.index(type(wall_law)) < gatherer
        limit = 0.5 * s.skin
        bridges = s.bridges
        return [
            (neighbors.bin_particles, n, (s.position, s.wall_position, s.cell_size, s.max_dims,
                                          s.cell_count, s.cell_members, s.cell_width,
                                          s.cell_of, s.flags)),
            (neighbors.find_pairs, n, (s.position, s.radius, s.skin + s.reach,
                                       s.wall_position, s.cell_size, s.max_dims, s.cell_count,
                                       s.cell_members, s.cell_width, s.cell_of, s.width,
                                       s.pair_count, s.pair_j, s.new_count, s.new_pair_j,
                                       s.lower_count, s.lower, s.shear_force, s.normal,
                                       s.overlap, bridges, s.rolling, s.new_shear_force,
                                       s.new_normal, s.new_overlap, s.new_bridges,
                                       s.new_rolling, s.flags)),
            self._finish_step(),
            *self._force_steps(s.no_image, s.no_period, s.no_period, walls_first,
                               wall_law.young if springs is None else 0.0),
            *(() if springs is not None else       # wall_friction: its own partial sums
              ((device_walls.wall_partials, s.partial.shape[0],
                (s.position, s.radius, s.wall_position, wall_law.young, s.partial)),)),
            (device_walls.wall_sums, 6 * device_walls.WALL_SUMS,
             (s.partial, s.wall_force, s.wall_stiffness, s.wall_moment)),
            (device_walls.wall_controls, 1,
             (s.wall_force, s.wall_stiffness, s.kinds, s.control_walls, s.wall_counts,
              s.parameters, s.previous, s.stiffness, s.calls, s.wall_position,
              s.wall_velocity, s.reference_walls, limit, sim.dt, s.control_step, s.failure,
              s.flags)),
            *(self._grips.launches(s) if self._grips is not None else ()),
            (integrate.leapfrog, n, (s.position, s.velocity, s.angular_velocity, s.force,
                                     s.torque, s.mass, s.inertia, sim.integrator.damping,
                                     s.no_period, sim.dt, s.reference_position, limit,
                                     s.flags)),
        ]

    # ---------------------------------------------------------------- running
    def advance(self):
        """One step on the device (launches only); sim.step and sim.time advance, the rest of
        sim's state is held by the device (Simulation.hold) until read."""
        idle = simulated() and self.state.flags[0] == 0
        launches = self._launches[REBUILD_LAUNCHES if idle else 0:]
        if self._growth is not None:        # sets dt mid-step at a rebuild
            self._growth.advance(self, launches)
        else:
            for kernel, args in launches:
                kernel(*args)
        self.sim.step += 1
        self.sim.time += self.sim.dt
        self.sim.hold(self)
        self._holding = True

    def _advance_and_write(self):
        """One step on the device, then the writers (Simulation.advance's order)."""
        self.advance()
        for writer in self.sim.writers:
            writer.apply(self.sim)

    def _report_failure(self):
        """StageFailed (MixedStress.failure) of a mixed condition the device could not hold,
        the first since the last report; nothing when none."""
        if not self._mixed:
            return
        record = self.state.failure.copy_to_host()
        if record[0] == 0.0:
            return
        self.state.failure.copy_to_device(np.zeros_like(record))
        _, row, step, axis, target, axial = record
        raise self._controls[int(row)].failure(int(step), int(axis), float(target),
                                               float(axial))

    def check(self):
        """Read the device's flags: StageFailed when a mixed condition could not be held,
        RuntimeError when a cell or a row overflowed (the list would miss pairs),
        FloatingPointError when a position is not finite."""
        self._report_failure()
        _, overflow, not_finite = self.state.flags_now()
        if not_finite:
            raise FloatingPointError("a particle's position is not finite on the GPU: the "
                                     "simulation diverged (lower the time step, e.g. "
                                     "timestep_safety, or check the forces)")
        if overflow & neighbors.CELL_OVERFLOW:
            raise RuntimeError(f"a cell of the GPU's neighbour grid holds more than "
                               f"{self.state.cell_width} particles (the box grew past the grid "
                               "allocated, or spheres overlap deeply): results after it are "
                               "not valid")
        if overflow & neighbors.NARROW_CELL:
            raise RuntimeError("the periodic cell is narrower than 3 cells of 2 max(radius) + "
                               "skin on an axis on the GPU: results after it are not valid "
                               "(use more particles)")
        if overflow & neighbors.ROW_OVERFLOW:
            raise RuntimeError(f"a particle has more than {self.state.width} neighbours on "
                               "one side in the GPU's neighbour list: results after it are "
                               "not valid")

    def run(self, steps, *, until=None, check_every=100, progress=None, status=None):
        """Advance ``steps`` steps on the device, or fewer if ``until(sim)`` becomes true
        (checked every ``check_every`` steps); the writers after every step, as on the CPU
        (module docstring), and ``check`` after every ``check_every`` steps. Arguments and
        result as Simulation.run; the state stays held by the device until read
        (``to_host``; Simulation.run brings it back as it returns)."""
        steps = check_int("steps", steps)
        check_every = check_int("check_every", check_every, low=1)
        self._configure()
        return self.sim.run_chunks(steps, self._advance_and_write, check=self.check,
                                   until=until, check_every=check_every, progress=progress,
                                   status=status)

    def to_host(self):
        """Bring the device's state into ``sim`` now (Simulation.fetch; nothing to do when
        sim holds it already)."""
        self.sim.fetch()

    def copy_back(self, part=None):
        """Copy the device's state into ``sim`` (called by Simulation.fetch): particles,
        walls, the neighbour list with its per-pair state (rebuilt by the CPU's NeighborList
        from it, so that the CPU can go on from here) and the servos' memory; with ``part``
        "walls", the walls alone. Then StageFailed if a mixed condition could not be held
        (``check``), so that nothing reads a state past the failure."""
        sim = self.sim
        if self._grips is not None:     # a grip's pull is a force on its wall's body
            self._grips.to_host()
        if part == "walls":
            self.state.walls_to_host(sim.walls)
            if self.state.periodic:     # a cell's shear is the box's too
                device_cell.shear_to_host(self.state, sim.walls)
            self._report_failure()
            return
        self._holding = False
        self.state.to_host(sim)
        if self._spring_walls is not None:      # wall_friction: the walls' springs
            self._spring_walls.to_host()
        if self.state.periodic:
            device_cell.shear_to_host(self.state, sim.walls)
        if self._growth is not None:
            self._growth.to_host(sim, self.state)
        self._targets_to_host()
        s = self.state
        previous = s.previous.copy_to_host()
        stiffness = s.stiffness.copy_to_host()
        calls = s.calls.copy_to_host()
        for c, op in enumerate(self._controls):
            if type(op) is StressServo:
                op.previous[:] = previous[c, :len(op.walls)]
                op.stiffness[:] = stiffness[c, :len(op.walls)]
                op.calls = int(calls[c])
        # the CPU's own list from the device's, so that its rebuild test holds if the CPU goes
        # on; a rebuilt list holds no pair forces (pendular.dem.neighbors.build_contacts): the
        # device's are carried to the same pairs (every touching pair is in both lists)
        listed = sim.contacts
        sim.neighbors.rebuild(sim)
        index = previous_pair_index(listed.row_start, listed.pair_j, sim.contacts.row_start,
                                    sim.contacts.pair_j)
        sim.contacts.force = carry_pair_array(listed.force, index)
        sim.contacts.normal_force = carry_pair_array(listed.normal_force, index)
        if self._resistance is not None:
            self._resistance.moment = carry_pair_array(self.state.pair_moments(), index)
        if self.state.persist:
            self._persisting_to_host(sim, index)
        if self._growth is not None:
            self._growth.after_copy_back(sim)
        self._report_failure()

    def _persisting_to_host(self, sim, index):
        """The persisting bridges' host state for the CPU's list (``index``: its pairs in the
        device's, previous_pair_index): their count, which the CPU's next list must carry
        (CapillaryBridges._attach), and their forces on j from i at the last step, carried
        to the same pairs (CapillaryBridges.pair_forces reads them); volume control's film on
        each grain and liquid lost."""
        bridges = self._bridges
        bridges.adopt(sim)
        bridges.pair_force[:] = carry_pair_array(self.state.bridge_pair_forces(), index)
        if self._volume_control:
            bridges.film = self.state.film.copy_to_host()
            bridges.liquid_lost = float(self.state.liquid_lost.copy_to_host()[0])

    @property
    def rebuilds(self):
        """Neighbour-list rebuilds on the device so far."""
        return int(self.state.rebuilds.copy_to_host()[0])

    #: (step, time, volume) of the last homogenisation and its quantities (``homogenized``).
    _homogenized = (None, None)

    def homogenized(self, volume=None):
        """The homogenised quantities of the state the device holds, reduced on the device
        (pendular.gpu.homogenize.device_homogenization: small arrays named as the history's
        columns, computed once per step, so that a record's columns share one reduction);
        ``volume`` [m^3], None: the box inside the walls, or the periodic cell's. No particle
        state comes back, bridges across gaps (``persist``, volume control) included.
        StageFailed first if a mixed condition could not be held (as ``copy_back``);
        RuntimeError when the device holds no state (it came back to the host, whose copy may
        have changed since: homogenise it there)."""
        if not self._holding:
            raise RuntimeError("the GPU holds no state now (it came back to the host): "
                               "homogenise the host's state")
        self._report_failure()
        key = (self.sim.step, self.sim.time, volume)
        if self._homogenized[0] != key:
            self._homogenized = (key, device_homogenization(self, volume))
        return self._homogenized[1]
