"""A CPU Simulation's scene run on the GPU: ``GpuSimulation(sim).run(steps)``.

The state is copied to the device once; each step is a fixed sequence of kernel launches, the
CPU pipeline (pendular.dem.simulation) on the device::

    bin_particles, find_pairs, finish_rebuild   neighbour list (only when a rebuild is due)
    pair_forces                                 contact law (+ bridges, wet)
    gather                                      forces and torques per particle (+ walls)
    pair_moments, gather_moments                rolling resistance (its moments on torques)
    absorbed_forces, add_clusters               liquid clusters (their forces, absorbed shares)
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

Each operation of the scene carries its device side (pendular.gpu.operations, declared by
the operation's device module): the box's side lays out the step's launches (WallBox in
pendular.gpu.walls, CellBox in pendular.gpu.cell), the forces' sides give what their roles'
launches read, the controls' sides their rows of the controls' program. Nothing here tests an
operation's type.

What runs on the device so far: walled scenes (``Walls``) with ContactForces (or the damped
and Hertz–Mindlin laws of pendular.dem.hertz_mindlin), WallForces or a wall law with springs
(ViscoelasticWallForces, FrictionalWallForces: pendular.gpu.wall_friction), RollingResistance
(pendular.gpu.rolling), WallRollingResistance (pendular.gpu.wall_rolling), Gravity
(pendular.gpu.gravity) and, wet, SuctionBridges at contact or across gaps (``persist``; a
new suction between runs, as the CPU: pendular.gpu.bridges), LiquidClusters beside bridges
across gaps (their model on the host: pendular.gpu.clusters); controls StressServo,
ConstantStrainRate, MixedStress (its servos among the controls), RadiusGrowth and
GrowthTimeStep (pendular.gpu.growth), Grip after them (pendular.gpu.grips); the Integrator. A periodic cell (``PeriodicCell``, sheared or not) with ContactForces (or a
damped or Hertz–Mindlin law), RollingResistance and, wet, SuctionBridges at contact or across
gaps or VolumeBridges, under StressServo, ConstantStrainRate, ConstantShearRate (simple
shear, Lees–Edwards) and MixedStress (pendular.gpu.cell): its step wraps the particles and
finds the pairs through the cell's faces at a rebuild (as far as the bridges' rupture range),
reduces the cell's stress (with the face terms of the forces of bridges across gaps), runs its
controls and a leapfrog carried by its stretching and shear, or grows the radii
(RadiusGrowth, GrowthTimeStep) in a cell whose faces no control moves. Anything else (an
operation without a device side, a radius growth in a moving cell) is refused by name
(ValueError), so that a scene never runs with part of its physics missing.
"""

import numpy as np

from pendular.dem.neighbors import carry_pair_array, previous_pair_index
# the modules that declare the operations' device sides (pendular.gpu.operations)
from pendular.gpu import (cell, clusters, gravity, grips, integrate, rolling,  # noqa: F401
    wall_friction, wall_rolling)
from pendular.gpu import bridges as device_bridges, forces, neighbors, walls as device_walls
from pendular.gpu.cuda import configured, cuda, simulated
from pendular.gpu.grips import DeviceGrips
from pendular.gpu.growth import DeviceGrowth
from pendular.gpu.homogenize import device_homogenization
from pendular.gpu.operations import ControlProgram, Scene
from pendular.gpu.state import DeviceState
from pendular.utils.validate import check_int

#: The first launches of a step, the neighbour list's: in the simulator, where the host reads
#: the device's memory for free, they are skipped when no rebuild is due (the kernels would
#: return at once), which saves a third of a simulated step.
REBUILD_LAUNCHES = 3


def check_scene(sim):
    """ValueError naming what of ``sim`` the GPU path does not run yet (module docstring):
    an operation without a device side (pendular.gpu.operations), or one whose side refuses
    the scene. Reads what the scene is made of, not its state (Simulation.peek). Returns the
    scene's sides (pendular.gpu.operations.Scene)."""
    scene = Scene(sim)
    scene.force("contact law", required=True)
    scene.check()
    return scene


class GpuSimulation:
    """Runs ``sim`` (a pendular.dem.simulation.Simulation whose scene the GPU path supports,
    ``check_scene``) on the GPU: ``run(steps)`` as Simulation.run (its loop,
    Simulation.run_chunks, with the device's steps and checks), ``to_host()`` to bring the
    state back into ``sim`` (done whenever anything reads it from sim: module docstring).
    ``sim.step`` and ``sim.time`` advance with the device. Parameters of the operations
    (friction, servo target, dt, ...) are read at every ``run`` (the targets a MixedStress
    sets are the device's); a scene whose operations change (a new control list) needs
    ``to_host()`` and a new GpuSimulation.

    What the other device modules read of it: ``sim``, ``scene`` (the operations' device
    sides), ``state`` (DeviceState), ``bridges`` (the bridges' side, or
    pendular.gpu.bridges.NoBridges), ``grips`` (DeviceGrips or None), ``steps`` and
    ``launches`` (the step's, ``configure``).
    """

    def __init__(self, sim):
        scene = check_scene(sim)
        self.sim = sim
        self.scene = scene
        self.bridges = scene.force("bridges") or device_bridges.NoBridges()
        self._host_changes = scene.changeable_on_host()
        self._upload()
        self.steps = []
        self.launches = []

    # ---------------------------------------------------------------- set-up
    def _upload(self):
        """The host's state onto the device: particles, the neighbour list with its per-pair
        state (sized for the bridges' reach now), the controls' program and memory."""
        sim, scene = self.sim, self.scene
        reach, film = self.bridges.upload(sim)
        self._growth = DeviceGrowth.of(scene)
        resisting = scene.force("rolling") is not None
        wet = self.bridges.wet
        skin = scene.neighbors.skin
        self.state = (DeviceState(sim, skin, wet, reach, self.bridges.persist, film, resisting)
                      if self._growth is None else
                      self._growth.grown_state(sim, skin, wet, resisting))
        self._controls = tuple(side.op for side in scene.controls)
        # the rows of the servos whose targets a MixedStress sets on the device
        self._driven = tuple(sorted({row for side in scene.controls
                                     for row in side.driven(scene)}))
        self._holding = False
        self._upload_controls()

    def _upload_controls(self):
        """The controls' program and memory (pendular.gpu.walls), each row from its control's
        side, and the box's own state."""
        scene = self.scene
        program = ControlProgram.empty(len(scene.controls))
        for row, side in enumerate(scene.controls):
            side.upload(row, program, scene)
        s = self.state
        s.kinds = cuda.to_device(program.kinds)
        s.control_walls = cuda.to_device(program.control_walls)
        s.wall_counts = cuda.to_device(program.wall_counts)
        s.previous = cuda.to_device(program.previous)
        s.stiffness = cuda.to_device(program.stiffness)
        s.calls = cuda.to_device(program.calls)
        s.parameters = cuda.to_device(self._control_parameters())
        s.control_step = cuda.to_device(np.zeros(1, np.int64))
        s.failure = cuda.to_device(np.zeros(len(device_walls.FAILURE_FIELDS)))
        self.grips = DeviceGrips.of(scene)
        scene.box.upload(s, scene)

    def _control_parameters(self):
        """(controls, 6) parameters of the controls now (pendular.gpu.walls's fields)."""
        parameters = np.zeros((max(1, len(self.scene.controls)), 6))
        for row, side in enumerate(self.scene.controls):
            side.parameters(parameters[row])
        return parameters

    def _targets_to_host(self):
        """The targets the device's MixedStress controls set, into their servos on the host."""
        if self._driven:
            targets = self.state.parameters.copy_to_host()[:, 0]
            for c in self._driven:
                self._controls[c].target = float(targets[c])

    def configure(self):
        """The step's launches (``launches``: configured kernel, arguments; ``steps``:
        kernel, items, arguments) with the operations' parameters now."""
        sim = self.sim
        for family, ops, sides in (("controls", sim.peek("controls"), self.scene.controls),
                                   ("forces", sim.forces, self.scene.forces)):
            if len(ops) != len(sides) or any(op is not side.op for op, side in zip(ops, sides)):
                raise ValueError(f"the scene's {family} changed since the GPU copy was made: "
                                 "call to_host() and build a new GpuSimulation")
        self.scene.check()
        self.bridges.follow_suction(self.state, self._holding)
        if self._holding:           # the host's targets of a MixedStress's servos are stale
            self._targets_to_host()
        self.state.parameters.copy_to_device(self._control_parameters())
        self.state.control_step.copy_to_device(np.array([sim.step], np.int64))
        self.steps = self.scene.box.steps(self)
        if self._growth is not None:
            self.steps = self._growth.launches(self.steps, self.state, sim,
                                               0.5 * self.state.skin)
        self.launches = [(configured(kernel, items), args)
                         for kernel, items, args in self.steps]

    def force_steps(self, walls_first, wall_young):
        """(kernel, items, arguments) of the pair forces and their gather (walls' springs of
        stiffness ``wall_young`` [Pa] E R, 0: none, added before the pairs' terms when
        ``walls_first``; a periodic cell's images and stretching: DeviceState.images), then
        every force's own launches (a rolling resistance, the weight: their sides'
        ``launches``) in the scene's order."""
        sim = self.sim
        s = self.state
        n = s.count
        columns = s.bridge_columns()
        # bridges at contact join the contact law's gather; persisting ones are added last
        joined = s.wet and not s.persist
        bridges = self.bridges
        return [
            (forces.pair_forces, n,
             (forces.Particles(s.position, s.velocity, s.angular_velocity, s.radius, s.mass),
              s.pairs(), s.images(),
              self.scene.force("contact law").law(sim.dt),
              forces.Bridges(s.wet, s.persist, bridges.volume_control, *columns,
                             s.bridge_pair_force, bridges.suction, bridges.surface_tension),
              bridges.table,
              forces.Liquid(bridges.roughness, bridges.closed, s.film, s.released, s.events,
                            s.marked),
              bridges.volume_table, s.flags)),
            *((bridges.exchange_step(s),) if bridges.volume_control else ()),
            (forces.gather, n, (s.position, s.radius, s.pairs(), s.transposed(),
                                forces.Gathered(joined, columns[2], s.persist,
                                                s.bridge_pair_force),
                                walls_first, s.wall_position, wall_young, s.force, s.torque)),
            *(launch for side in self.scene.forces for launch in side.launches(s, sim.dt)),
        ]

    def finish_step(self):
        """(kernel, items, arguments) of finish_rebuild."""
        s = self.state
        return (neighbors.finish_rebuild, s.count,
                (s.position, s.rows(), s.new_carried(), s.second_count, s.second_pair,
                 s.carried(), s.normal_force, s.pair_force, s.reference_position,
                 s.wall_position, s.reference_walls, s.grid(), s.flags, s.rebuilds))

    # ---------------------------------------------------------------- running
    def advance(self):
        """One step on the device (launches only); sim.step and sim.time advance, the rest of
        sim's state is held by the device (Simulation.hold) until read. When the host changed
        an operation since the last step (a model stepped by a writer on the state it fetched:
        a force side's ``changed_on_host``), the launches are laid again first, and the state
        uploaded again from the host if the bridges' reach grew (the host holds it then)."""
        if self._host_changes and any(side.changed_on_host() for side in self._host_changes):
            if not self._holding and self.bridges.reach_changed(self.state):
                self._upload()
            self.configure()
        idle = simulated() and self.state.flags[0] == 0
        launches = self.launches[REBUILD_LAUNCHES if idle else 0:]
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
        if not self.scene.controls_of(device_walls.MIXED_STRESS):
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
        self.configure()
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
        if self.grips is not None:      # a grip's pull is a force on its wall's body
            self.grips.to_host()
        box = self.scene.box
        if part == "walls":
            self.state.walls_to_host(sim.walls)
            box.to_host(self.state, sim.walls)
            self._report_failure()
            return
        self._holding = False
        self.state.to_host(sim)
        box.to_host(self.state, sim.walls)
        if self._growth is not None:
            self._growth.to_host(sim, self.state)
        self._targets_to_host()
        program = ControlProgram.fetch(self.state)
        for row, side in enumerate(self.scene.controls):
            side.to_host(row, program)
        # the CPU's own list from the device's, so that its rebuild test holds if the CPU goes
        # on; a rebuilt list holds no pair forces (pendular.dem.neighbors.build_contacts): the
        # device's are carried to the same pairs (every touching pair is in both lists)
        listed = sim.contacts
        sim.neighbors.rebuild(sim)
        index = previous_pair_index(listed.row_start, listed.pair_j, sim.contacts.row_start,
                                    sim.contacts.pair_j)
        sim.contacts.force = carry_pair_array(listed.force, index)
        sim.contacts.normal_force = carry_pair_array(listed.normal_force, index)
        for side in self.scene.forces:
            side.pairs_to_host(sim, self.state, index)
        if self._growth is not None:
            self._growth.after_copy_back(sim)
        self._report_failure()

    def fetch_rebuilds(self):
        """Neighbour-list rebuilds on the device so far (one number copied back)."""
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
