"""An operation's device side: how a force or a control of the CPU's pipeline is uploaded to
the device and stepped there (LAMMPS's Kokkos styles beside the plain ones), so that
GpuSimulation (pendular.gpu.simulation) builds a step from what each operation declares and
tests no operation's type.

The device module of an operation (pendular.gpu.forces for the contact laws, pendular.gpu.walls
for the wall controls, ...) declares its side with ``@device_side(CpuClass, ...)`` on a
subclass of DeviceSide. The CPU's layers never import pendular.gpu
(docs/architecture.md): the device names the CPU class, not the other way. ``side_of(op)``
finds the side of ``op``'s class or of the nearest base class that has one, provided ``op``
keeps that class's ``apply`` (a subclass with a step of its own needs a side of its own), and
refuses, by name, an operation without one: a scene never runs with part of its physics
missing.

A side is made once per GpuSimulation with its operation (``side.op``) and reads the
operation's parameters at every run. It declares:

- ``family``: "box", "neighbor list", "force", "control" or "integrator"; ``role``: what the
  step does with it (a force's: FORCE_ROLES; a control's: its row kind in the controls'
  program, pendular.gpu.walls);
- ``single``: at most one of its role in a scene; ``in_walls``, ``in_cell``: the boxes it runs
  in (a walled scene, a periodic cell);
- ``check(scene)``: ValueError naming what of ``scene`` (a Scene: the simulation and every
  side) it does not run, called before anything is uploaded and at every run;
- a box (BoxSide): its step's launches, its own state up and back; a force: what its role's
  launches read (pendular.gpu.simulation), and ``changed_on_host()``, whether the host changed
  its operation during a run (the launches laid again); a control (ControlSide):
  ``upload(row, program, scene)``, its row of the controls' program and memory;
  ``parameters(values)``, its row of parameters now; ``to_host(row, program)``, the memory it
  keeps back into the operation; ``driven(scene)``, the rows of the servos whose targets it
  sets.
"""

from dataclasses import dataclass

import numpy as np

#: The roles of forces the step reads by name (pendular.gpu.simulation): the one contact law
#: (the pair forces' kernel and its gather), the walls' springs, the capillary bridges (joining
#: the pair forces' kernel). Any other force runs by its own ``launches`` after the gather
#: (a rolling resistance, gravity), its role its own name.
FORCE_ROLES = ("contact law", "walls", "bridges")

#: CPU operation class -> its DeviceSide class (``device_side``).
_SIDES = {}


class DeviceSide:
    """The device side of one operation ``op`` (module docstring); a subclass declares its
    family, role and boxes, and overrides what its role needs."""

    family = None
    role = None
    single = True
    in_walls = True
    in_cell = True

    def __init__(self, op):
        self.op = op

    @property
    def name(self):
        """The operation's class name, for messages."""
        return type(self.op).__name__

    def check(self, scene):
        """ValueError naming what of ``scene`` this side does not run (nothing by default)."""

    def launches(self, state, dt):
        """A force's (kernel, items, arguments) after the pairs' gather, in the scene's order
        (``state`` a DeviceState, ``dt`` [s]); none by default (the contact law, the walls'
        springs and the bridges run in the pair forces' kernel and the gather)."""
        return []

    def wall_launches(self, state):
        """A force's (kernel, items, arguments) after the walls' sums and before their
        controls, its own share of the walls' sums (``state`` a DeviceState, inside walls);
        none by default."""
        return []

    def changed_on_host(self):
        """A force's: whether the host changed what the step's launches read of its operation
        since they were laid (a model stepped on the host between two of the device's steps,
        the state fetched: a new suction, new cluster forces), so that they are laid again
        before the next step (GpuSimulation.advance); False by default."""
        return False

    def pairs_to_host(self, sim, state, index):
        """A force's own state from ``state`` (a DeviceState) into its operation when the
        state comes back to ``sim``: per pair, carried to the host list's pairs (``index``:
        pendular.dem.neighbors.previous_pair_index), or per particle (the walls' springs);
        nothing by default."""


class ControlSide(DeviceSide):
    """A control's side: a row of the controls' program (pendular.gpu.walls), ``role`` its
    kind. By default the row holds no walls, parameters nor memory."""

    family = "control"
    single = False
    #: Whether it grows the radii (pendular.gpu.growth).
    grows_radii = False

    def upload(self, row, program, scene):
        """Row ``row`` of ``program`` (ControlProgram: host arrays) from the operation."""
        program.kinds[row] = self.role

    def parameters(self, values):
        """``values`` (6,), the row's parameters now, from the operation."""

    def to_host(self, row, program):
        """The memory the device kept in row ``row`` of ``program`` (host copies) back into
        the operation."""

    def driven(self, scene):
        """The rows of the servos whose targets this control sets on the device (their
        targets come back with the state); none by default."""
        return []


class BoxSide(DeviceSide):
    """A box's side (Walls, PeriodicCell): the step's launches in it, and what of the box
    beyond the walls' arrays (pendular.gpu.state) goes to the device and back."""

    family = "box"

    def upload(self, state, scene):
        """The box's own state into ``state`` (a DeviceState), with ``scene``'s controls."""

    def to_host(self, state, box):
        """The box's own state from ``state`` into the host's ``box``."""

    def steps(self, gpu):
        """(kernel, items, arguments) of a step of ``gpu`` (a GpuSimulation) in this box."""
        raise NotImplementedError


@dataclass
class ControlProgram:
    """The controls' program on the host (pendular.gpu.walls's module docstring): per row its
    ``kinds``, ``control_walls`` (C, 6), ``wall_counts``, and a servo's memory ``previous``
    (C, 6), ``stiffness`` (C, 6), ``calls``."""

    kinds: np.ndarray
    control_walls: np.ndarray
    wall_counts: np.ndarray
    previous: np.ndarray
    stiffness: np.ndarray
    calls: np.ndarray

    @classmethod
    def fetch(cls, state):
        """The program as the device holds it now (``state``: a DeviceState), copied back."""
        return cls(*(getattr(state, name).copy_to_host() for name in
                     ("kinds", "control_walls", "wall_counts", "previous", "stiffness",
                      "calls")))

    @classmethod
    def empty(cls, controls):
        """Zeros for ``controls`` rows (at least one row for the arrays other than kinds)."""
        count = max(1, controls)
        return cls(np.zeros(controls, np.int64), np.zeros((count, 6), np.int64),
                   np.zeros(count, np.int64), np.zeros((count, 6)), np.zeros((count, 6)),
                   np.zeros(count, np.int64))


class Scene:
    """The device sides of a simulation ``sim``'s scene (what it is made of: Simulation.peek):
    ``box``, ``neighbors``, ``forces`` and ``controls`` (in the scene's order),
    ``integrator``; ``periodic``: whether the box is a periodic cell."""

    def __init__(self, sim):
        self.sim = sim
        self.box = side_of(sim.peek("walls"), "box")
        self.periodic = bool(self.box.op.periodic)
        self.neighbors = side_of(sim.neighbors, "neighbor list")
        self.forces = tuple(side_of(op, "force") for op in sim.forces)
        self.controls = tuple(side_of(op, "control") for op in sim.peek("controls"))
        self.integrator = side_of(sim.integrator, "integrator")

    def forces_of(self, role):
        """The force sides of ``role`` (FORCE_ROLES), in order."""
        return [side for side in self.forces if side.role == role]

    def force(self, role, required=False):
        """The one force side of ``role`` (None if absent and not ``required``)."""
        found = self.forces_of(role)
        if required and not found:
            raise ValueError(f"device='gpu' needs one {role} among the forces; found none")
        return found[0] if found else None

    def changeable_on_host(self):
        """The force sides whose operation the host may change during a run: those whose
        class has a ``changed_on_host`` of its own (GpuSimulation.advance asks only them)."""
        return [side for side in self.forces
                if type(side).changed_on_host is not DeviceSide.changed_on_host]

    def index(self, side):
        """The place of ``side`` among the forces' sides."""
        return next(i for i, other in enumerate(self.forces) if other is side)

    def controls_of(self, role):
        """The control sides of ``role`` (a row kind), in order."""
        return [side for side in self.controls if side.role == role]

    def row(self, control):
        """The row of ``control`` (one of the scene's operations, by identity) in the
        controls' program."""
        return next(c for c, side in enumerate(self.controls) if side.op is control)

    def check(self):
        """ValueError naming what of the scene the device does not run: an operation outside
        its boxes, two of a single role, then each side's own check."""
        where = "a periodic cell" if self.periodic else "walls"
        for side in (*self.forces, *self.controls):
            if not (side.in_cell if self.periodic else side.in_walls):
                if side.family == "force":
                    raise ValueError(f"device='gpu' runs a periodic cell without {side.name} "
                                     "(it has no walls)")
                valid = ", ".join(runnable("control", self.periodic))
                raise ValueError(f"device='gpu' does not run the control {side.name} in "
                                 f"{where} (valid: {valid})")
        for family, sides in (("force", self.forces), ("control", self.controls)):
            for side in sides:
                twins = [other for other in sides if other.role == side.role]
                if side.single and len(twins) > 1:
                    if family == "force":
                        raise ValueError(f"device='gpu' runs at most one {side.role} "
                                         f"operation among the forces; found {len(twins)}")
                    raise ValueError(f"device='gpu' runs at most one {side.name} among the "
                                     "controls")
        for side in (self.box, self.neighbors, *self.forces, *self.controls, self.integrator):
            side.check(self)


def device_side(*classes):
    """Class decorator: the decorated DeviceSide is the device side of the CPU operation
    classes ``classes`` (module docstring)."""
    def register(side):
        for cpu_class in classes:
            _SIDES[cpu_class] = side
        return side
    return register


def runnable(family, periodic=None):
    """Names of the CPU classes with a device side of ``family`` (in the box: inside walls,
    ``periodic``, or either when None), in the order they were declared."""
    return [cpu_class.__name__ for cpu_class, side in _SIDES.items()
            if side.family == family and (periodic is None or
                                          (side.in_cell if periodic else side.in_walls))]


def side_of(op, family):
    """The device side of ``op`` (a force or a control: ``family``), made now; ValueError
    naming its class when it has none (module docstring)."""
    for cpu_class in type(op).__mro__:
        side = _SIDES.get(cpu_class)
        if side is None:
            continue
        if side.family == family and (getattr(type(op), "apply", None)
                                      is getattr(cpu_class, "apply", None)):
            return side(op)
        break
    raise ValueError(f"device='gpu' does not run the {family} {type(op).__name__} yet "
                     f"(valid: {', '.join(runnable(family))})")
