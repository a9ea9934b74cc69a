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
"""

import time

import numba
from tqdm import tqdm

from pendular.dem.protocols import Operation
from pendular.dem.state import Box, Particles
from pendular.utils.validate import check_int, check_positive
from pendular.utils.threads import configure as configure_threading

#: Below this many particles a step is too short to pay for waking a second thread
#: (docs/performance.md, "Threads by sample size").
SERIAL_BELOW = 500


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
    """

    def __init__(self, particles, walls, dt, *, neighbors, forces=(), controls=(),
                 integrator, writers=(), threads=None):
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
        ``check_every`` steps). ``progress`` is a label for a progress bar; ``status(sim)``
        returns a dict shown beside it (an open-ended run, with ``until``, shows the steps
        taken and its status, not a fraction of the step limit). Returns the steps taken."""
        steps = check_int("steps", steps)
        check_every = check_int("check_every", check_every, low=1)
        bar = tqdm(total=None if until is not None else steps, desc=progress, unit="step",
                   mininterval=1.0, smoothing=0.05, disable=progress is None)
        taken = 0
        started = time.perf_counter()
        caller_threads = numba.get_num_threads()
        numba.set_num_threads(self.threads)
        try:
            while taken < steps:
                chunk = min(check_every, steps - taken)
                for _ in range(chunk):
                    self.advance()
                taken += chunk
                bar.update(chunk)
                if status is not None and time.perf_counter() - started > 1.0:
                    bar.set_postfix(status(self), refresh=False)
                if until is not None and until(self):
                    break
        finally:
            numba.set_num_threads(caller_threads)
            bar.close()
        return taken
