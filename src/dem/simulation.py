"""The Simulation: state plus an ordered list of operations run once per step.

A dry triaxial step reads, as in YADE's engine list::

    ForceReset(), NeighborList(skin), ContactForces(E, 0.3, 18), WallForces(E),
    StressServo("xy", 750, ...), ConstantStrainRate("z", rate, L0), Integrator(0.2), recorder

Each operation has ``apply(sim)``; a scene runs only the operations it lists.
"""

import time

import numba
from tqdm import tqdm

from .state import Particles, Walls
from .validate import check_int, check_positive


class ForceReset:
    """Zero the particles' forces and torques (first operation of every step)."""

    def apply(self, sim):
        sim.particles.force[:] = 0.0
        sim.particles.torque[:] = 0.0


#: Below this many particles a step is too short to pay for waking a second thread.
SERIAL_BELOW = 2000


class Simulation:
    """Holds particles, walls, contacts, time step and the operations that advance them.

    dt [s]; ``step`` and ``time`` [s] count from the start; ``contacts`` is filled by
    ``NeighborList``. ``writers`` (recorders) run after each step, seeing the advanced
    state, step and time, as HOOMD's writers do. ``threads``: Numba threads used by ``run`` (default: all of Numba's for
    SERIAL_BELOW particles or more, else 1). Results do not depend on the thread count.
    """

    def __init__(self, particles, walls, dt, operations=(), writers=(), threads=None):
        for name, value, kind in (("particles", particles, Particles), ("walls", walls, Walls)):
            if not isinstance(value, kind):
                raise TypeError(f"{name} must be a dem.state.{kind.__name__}, got "
                                f"{type(value).__name__}")
        for op in (*operations, *writers):
            if not callable(getattr(op, "apply", None)):
                raise TypeError(f"operation {op!r} has no apply(sim) method")
        self.particles = particles
        self.walls = walls
        self.dt = check_positive("dt", dt, "s")
        self.operations = list(operations)
        self.writers = list(writers)
        self.contacts = None
        self.step = 0
        self.time = 0.0
        if threads is None:
            threads = numba.get_num_threads() if len(particles) >= SERIAL_BELOW else 1
        self.threads = check_int("threads", threads, low=1, high=numba.config.NUMBA_NUM_THREADS)

    def operation(self, kind):
        """The first operation or writer of class ``kind`` (KeyError if absent)."""
        for op in self.operations + self.writers:
            if isinstance(op, kind):
                return op
        raise KeyError(f"no {kind.__name__} operation in this simulation")

    def advance(self):
        """One step: every operation in order, then the writers (which see the new step)."""
        for op in self.operations:
            op.apply(self)
        self.step += 1
        self.time += self.dt
        for writer in self.writers:
            writer.apply(self)

    def run(self, steps, *, until=None, check_every=100, progress=None, status=None):
        """Advance ``steps`` steps, or fewer if ``until(sim)`` becomes true (checked every
        ``check_every`` steps). ``progress`` is a label for a progress bar; ``status(sim)``
        returns a dict shown beside it. Returns the number of steps taken."""
        steps = check_int("steps", steps)
        check_every = check_int("check_every", check_every, low=1)
        bar = tqdm(total=steps, desc=progress, unit="step", mininterval=1.0, smoothing=0.05,
                   disable=progress is None)
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
