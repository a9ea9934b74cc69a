"""The Simulation: state plus the step pipeline, declared in one place.

A scene names what it needs, in the order a step runs it (YADE's engine list, HOOMD-blue's
shape)::

    Simulation(particles, walls, dt,
               neighbors=NeighborList(skin),
               forces=[ContactForces(E, 0.3, 18), WallForces(E)],      # + CapillaryBridges
               controls=[StressServo("xy", 750, v), ConstantStrainRate("z", rate, L0)],
               integrator=Integrator(0.2),
               writers=[recorder])

One step (``advance``): zero forces and torques (and a periodic cell's virial sums, which the
pair forces' gathers fill, pendular.dem.virial), the neighbour list, every force, what the box
measures of them (a periodic cell: its stress), every control, the integrator; then step and
time advance and the writers see the new state. The box is ``Walls`` (with ``WallForces``
among the forces) or a ``pendular.dem.cell.PeriodicCell``.
``forces``, ``controls`` and ``writers`` are plain lists: a phase change replaces
``sim.controls``, wetting appends a force. An operation has ``apply(sim)``; a force that
needs pairs beyond contact says so with ``reach(sim)`` [m] (pendular.dem.neighbors.NeighborList asks).

``device`` chooses where ``run`` advances: "cpu" (here) or another device, whose module
(DEVICE_MODULES) is imported by name when first asked for and registers its run
(``register_device``): the one plug-in point of the layers (docs/architecture.md). During a
device run the state (DEVICE_HELD) is the device's: whatever reads it during the run (a writer
at its step, ``until``, ``status``) brings it back first with an explicit
``sim.fetch(...)`` ("walls" alone: a cheap copy), and reading a held attribute that was not
fetched raises StaleState, so that nothing reads a stale host copy. After ``run`` the host
holds the state; pendular.homogenize.on_the_fly.homogenized measures it where it is held (on
the device without bringing it back).
"""

import importlib
import time

import numba

from pendular.dem.protocols import Operation
from pendular.dem.state import Box, Particles
from pendular.utils.progress import PhaseBar
from pendular.utils.validate import check_int, check_positive
from pendular.utils.threads import configure as configure_threading

#: Below this many particles a step is too short to pay for waking a second thread
#: (docs/performance.md, "Threads by sample size").
SERIAL_BELOW = 500
#: The devices a Simulation runs on, with the module that provides each one's run (None: this
#: module's); pendular.dem never imports them statically (module docstring).
DEVICE_MODULES = {"cpu": None, "gpu": "pendular.gpu"}
DEVICES = tuple(DEVICE_MODULES)
#: What a device run holds between its syncs (module docstring).
DEVICE_HELD = ("particles", "walls", "contacts", "controls")
#: The part of the held state that ``fetch`` brings back alone (the rest comes back together).
FETCHED_ALONE = "walls"
#: Registered devices: name -> (start(sim), unavailable()) (``register_device``).
_DEVICES = {}


def register_device(name, start, unavailable):
    """Declare how device ``name`` (a key of DEVICE_MODULES; its module calls this when
    imported) runs a Simulation: ``start(sim)`` returns a run with ``run(steps, until=,
    check_every=, progress=, status=)`` as Simulation.run (its loop ``run_chunks``, with the
    device's step and checks), which holds the state (``hold``) after each of its steps, and
    ``copy_back(part)``, which writes the device's state into sim (``part`` "walls": those
    alone; Simulation.fetch calls it); ``unavailable()`` says why the device cannot run here
    (text), or None."""
    if name not in DEVICE_MODULES or DEVICE_MODULES[name] is None:
        raise ValueError(f"device = {name!r} is not one of the plug-in devices "
                         f"{', '.join(repr(n) for n, m in DEVICE_MODULES.items() if m)}")
    _DEVICES[name] = (start, unavailable)


def device_start(device, label=None):
    """The ``start`` of ``device`` (None for "cpu"), its module imported on first use;
    ValueError naming ``label`` (default "device = '<device>'") when the device is unknown or
    cannot run here (its extra not installed, no GPU), with how to install it."""
    label = label or f"device = {device!r}"
    if device not in DEVICE_MODULES:
        raise ValueError(f"{label} is not one of {', '.join(map(repr, DEVICE_MODULES))}")
    module = DEVICE_MODULES[device]
    if module is None:
        return None
    install = f"pip install -e '.[{device}]'"
    try:
        importlib.import_module(module)
    except ImportError as error:
        raise ValueError(f"{label} cannot run here: {module} does not import ({error}); "
                         f"install its extra: {install}") from None
    start, unavailable = _DEVICES[device]
    reason = unavailable()
    if reason is not None:
        raise ValueError(f"{label} cannot run here: {reason}")
    return start


def check_device(device):
    """A run's device option (a test's ``device``, a command's --device) checked before
    anything is made: ValueError naming ``--device <device>`` when it is unknown or cannot run
    here (device_start)."""
    device_start(device, f"--device {device}")


class StaleState(RuntimeError):
    """A read of state that a device run holds, not brought back first (Simulation.fetch)."""


def _check_operation(op):
    """``op`` if it meets the Operation contract (pendular.dem.protocols), else TypeError."""
    if not isinstance(op, Operation) or not callable(op.apply):
        raise TypeError(f"operation {op!r} has no apply(sim) method (pendular.dem.protocols)")
    return op


class Simulation:
    """Holds particles, the box (``walls``: Walls or a PeriodicCell), contacts, time step and
    the step pipeline.

    dt [s]; ``step`` and ``time`` [s] count from the start; ``contacts`` is filled by the
    neighbour list. ``threads``: Numba threads used by ``run`` (default: all of Numba's for
    SERIAL_BELOW particles or more, else 1). Results do not depend on the thread count.
    ``device``: where ``run`` advances, "cpu" or "gpu" (module docstring; docs/gpu.md).
    While a device run holds the state, read it after ``fetch("walls")`` (the box alone) or
    ``fetch()`` (all of it); an unfetched read raises StaleState.
    """

    def __init__(self, particles, walls, dt, *, neighbors, forces=(), controls=(),
                 integrator, writers=(), threads=None, device="cpu"):
        for name, value, kind in (("particles", particles, Particles), ("walls", walls, Box)):
            if not isinstance(value, kind):
                raise TypeError(f"{name} must be a pendular.dem.state.{kind.__name__}, got "
                                f"{type(value).__name__}")
        self.particles = particles
        self.walls = walls
        self.dt = check_positive("dt", dt, "s")
        self.neighbors = _check_operation(neighbors)
        self.forces = [_check_operation(op) for op in forces]
        self.controls = [_check_operation(op) for op in controls]
        self.integrator = _check_operation(integrator)
        self.writers = [_check_operation(op) for op in writers]
        self.contacts = None
        self.step = 0
        self.time = 0.0
        configure_threading()
        if threads is None:
            threads = numba.get_num_threads() if len(particles) >= SERIAL_BELOW else 1
        self.threads = check_int("threads", threads, low=1, high=numba.config.NUMBA_NUM_THREADS)
        self.device = device

    @property
    def device(self):
        """Where ``run`` advances: "cpu" or "gpu" (set it to move the next runs there)."""
        return self._device

    @device.setter
    def device(self, device):
        self._device_start = device_start(device)
        self._device = device

    def __getattr__(self, name):
        # reached only for an attribute that is not there: the state a device run holds
        if name in DEVICE_HELD and "_holder" in self.__dict__:
            raise StaleState(f"sim.{name} is held by a device run: bring it back first with "
                             f"sim.fetch({name!r})")
        raise AttributeError(f"'Simulation' object has no attribute {name!r}")

    def hold(self, run):
        """The device run ``run`` changed the state (DEVICE_HELD): until fetched, reading it
        raises StaleState. Called by a device run after a step."""
        state = self.__dict__
        held = state.setdefault("_held", {})
        for name in DEVICE_HELD:
            if name in state:
                held[name] = state.pop(name)
        state["_holder"] = run

    def fetch(self, *parts):
        """Bring the state a device run holds back to the host before reading it: with
        ``parts`` "walls" alone, the box (its walls' positions, forces and stresses, a cell's
        shear, the grips' pulls: a copy cheap enough for every step), the rest left on the
        device; with any other of DEVICE_HELD, or none named, all of it (``run.copy_back``),
        which ends the hold. Nothing to do for what the host holds already. Returns sim."""
        unknown = [part for part in parts if part not in DEVICE_HELD]
        if unknown:
            raise ValueError(f"cannot fetch {', '.join(map(repr, unknown))}: the held state is "
                             f"{', '.join(map(repr, DEVICE_HELD))}")
        state = self.__dict__
        run = state.get("_holder")
        if run is None:
            return self
        if set(parts) == {FETCHED_ALONE}:
            if FETCHED_ALONE not in state:
                state[FETCHED_ALONE] = state["_held"].pop(FETCHED_ALONE)
                run.copy_back(FETCHED_ALONE)
            return self
        state.update(state.pop("_held"))
        del state["_holder"]
        run.copy_back(None)
        return self

    @property
    def holder(self):
        """The device run holding the state (``hold``; its ``homogenized()`` measures it
        there, pendular.homogenize.on_the_fly.homogenized), None when the host holds it."""
        return self.__dict__.get("_holder")

    def peek(self, name):
        """The host's ``name`` (one of DEVICE_HELD) without bringing a device run's state back:
        what the scene is made of (the box's type, the control list), whose values may be
        stale while a device run holds them."""
        state = self.__dict__
        return state[name] if name in state else state["_held"][name]

    @property
    def operations(self):
        """The step's operations in order (read-only tuple): neighbour list, forces, controls,
        integrator. Change the scene through ``forces``, ``controls`` and ``writers``."""
        return (self.neighbors, *self.forces, *self.controls, self.integrator)

    def operation(self, kind):
        """The first operation or writer of class ``kind`` (KeyError if absent)."""
        for op in (*self.operations, *self.writers):
            if isinstance(op, kind):
                return op
        raise KeyError(f"no {kind.__name__} operation in this simulation")

    def evaluate_forces(self):
        """Forces and torques of the current state (neighbour list, every force, the box's
        measure of them), without moving anything: the first part of a step."""
        self.particles.force[:] = 0.0
        self.particles.torque[:] = 0.0
        self.walls.virial_blocks.fill(0.0)
        self.neighbors.apply(self)
        for op in self.forces:
            op.apply(self)
        self.walls.after_forces(self)

    def advance(self):
        """One step: forces, controls, integrator, then the writers (which see the new step)."""
        self.evaluate_forces()
        for op in self.controls:
            op.apply(self)
        self.integrator.apply(self)
        self.step += 1
        self.time += self.dt
        for writer in self.writers:
            writer.apply(self)

    def run(self, steps, *, until=None, check_every=100, progress=None, status=None):
        """Advance ``steps`` steps, or fewer if ``until(sim)`` becomes true (checked every
        ``check_every`` steps). ``progress`` is a label for a progress bar counting steps, or
        for an open-ended run (with ``until``) a ``pendular.utils.progress.Phase``, whose
        gauge counts the quantity that ends it; ``status(sim)`` returns a dict shown beside
        it. Returns the steps taken.
        On another ``device`` the steps run there, the writers, ``until`` and ``status``
        reading the state they fetch (module docstring)."""
        steps = check_int("steps", steps)
        check_every = check_int("check_every", check_every, low=1)
        self.fetch()                        # a run starts from the host's state
        caller_threads = numba.get_num_threads()
        numba.set_num_threads(self.threads)
        try:
            if self._device_start is None:
                return self.run_chunks(steps, self.advance, until=until,
                                       check_every=check_every, progress=progress,
                                       status=status)
            try:
                return self._device_start(self).run(steps, until=until, check_every=check_every,
                                                    progress=progress, status=status)
            finally:
                self.fetch()                # after a run, the host holds the state
        finally:
            numba.set_num_threads(caller_threads)

    def run_chunks(self, steps, advance, *, check=None, until=None, check_every=100,
                   progress=None, status=None):
        """The loop of ``run`` on every device: ``advance()`` (one step, its writers
        included) ``steps`` times, in chunks of ``check_every``; after each chunk ``check()``
        (a device's own checks, which raise; None: none), the progress bar and ``status``,
        then ``until``. Arguments otherwise as ``run``, which checks them; returns the steps
        taken."""
        bar = PhaseBar(progress, steps)
        taken = 0
        started = time.perf_counter()
        try:
            while taken < steps:
                chunk = min(check_every, steps - taken)
                for _ in range(chunk):
                    advance()
                taken += chunk
                if check is not None:
                    check()
                bar.update(self, chunk)
                if status is not None and time.perf_counter() - started > 1.0:
                    bar.set_postfix(status(self))
                if until is not None and until(self):
                    break
            bar.update(self, 0, last=True)
        finally:
            bar.close()
        return taken
