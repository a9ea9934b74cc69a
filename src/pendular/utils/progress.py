"""Progress bars with a total and a time left, for phases of known and of unknown length, and
one bar for the whole run.

A phase of known length (a shear to a strain at a constant rate, an unload in stages) counts
steps. A phase that ends when a quantity reaches a value (a radius growth until a stress, an
equilibrium until the unbalanced force is small) cannot count steps honestly: it counts the
quantity that ends it, through a gauge given with its label, ``Phase(label, gauge)``:

- ``Approach(quantity, target, unit)``: a quantity moving from where it starts toward a target
  (the walls' mean stress during the radius growth, a wall's stress toward a loading stage's
  target). Total |target - start| in the quantity's unit; position how far the quantity has
  come toward the target, never going back.
- ``Decades(quantity, threshold)``: a quantity falling roughly geometrically to a threshold
  (the unbalanced force of an equilibrium). Total log10(first / threshold) decades, position
  log10(first / lowest so far).

A bar's time left is tqdm's: its position's recent rate of advance, so it is as good as the
phase's progress is steady. A gauge is read after a chunk of steps, at most once every
READ_INTERVAL seconds, from quantities that the phase's end test reads anyway (a device run
brings back what its status fields bring back); reading it changes no result.

``whole_run(plan)``: while it is open, one more bar (above the phases') shows the run's
percentage and its time left. ``plan`` lists the phases expected, in order, as (label prefix
or a tuple of them, estimated steps); a phase bar whose label starts with a prefix belongs to
that entry (several phases may: the stages of a path, the repeated preparations of a tuning),
and an entry passed over is a phase that did not run. The
run counts steps: those the ended phases took, the running phase's against its estimate (its
length, or from its gauge: steps so far over the fraction of the total reached, once that is
5 % or more) and the plan's estimates of the phases to come, an entry never taking fewer than
its plan says until it ends. So the run's share of each phase is refined as the run goes, and
at each phase's end its estimate gives way to the steps it took.
"""

import contextlib
import math
import time

from tqdm import tqdm

#: Least time between two readings of a phase's gauge [s].
READ_INTERVAL = 1.0


class Approach:
    """Progress of ``quantity(sim)`` from its first reading toward ``target`` (module
    docstring), in ``unit``."""

    def __init__(self, quantity, target, unit):
        self.quantity, self.target, self.unit = quantity, float(target), unit
        self.start = None
        self.position = 0.0

    @property
    def total(self):
        return None if self.start is None else abs(self.target - self.start)

    def read(self, sim):
        """Read the quantity; returns the position [unit], never lower than before."""
        value = float(self.quantity(sim))
        if not math.isfinite(value):          # nothing to measure yet (no contact)
            return self.position
        if self.start is None:
            self.start = value
        span = self.target - self.start
        if span != 0.0:
            done = min(max((value - self.start) / span, 0.0), 1.0) * abs(span)
            self.position = max(self.position, done)
        return self.position


class Decades:
    """Progress of ``quantity(sim)`` falling from its first reading to ``threshold``, in
    decades (module docstring)."""

    unit = "decade"

    def __init__(self, quantity, threshold):
        self.quantity, self.threshold = quantity, float(threshold)
        self.first = None
        self.position = 0.0

    @property
    def total(self):
        if self.first is None:
            return None
        return max(math.log10(self.first / self.threshold), 0.01)

    def read(self, sim):
        """Read the quantity; returns the position [decade], never lower than before."""
        value = float(self.quantity(sim))
        if not math.isfinite(value):          # nothing to measure yet (no contact)
            return self.position
        if self.first is None:
            self.first = max(value, self.threshold)
        if value > 0.0:
            self.position = max(self.position,
                                min(math.log10(self.first / value), self.total))
        else:
            self.position = self.total
        return self.position


class Phase:
    """A progress bar's label with the ``gauge`` (Approach, Decades) that measures how far
    its open-ended phase has come."""

    def __init__(self, label, gauge):
        self.label, self.gauge = label, gauge

    def __str__(self):
        return self.label


class PhaseBar:
    """The bar of one phase (Simulation.run_chunks): ``progress`` a label (``steps`` counted)
    or a Phase (its gauge read; module docstring); None: no bar. ``update(sim, steps)``
    after each chunk, ``close()`` at the end."""

    def __init__(self, progress, steps):
        self.gauge = getattr(progress, "gauge", None)
        label = None if progress is None else str(progress)
        self.bar = tqdm(total=steps if self.gauge is None else None, desc=label,
                        unit="step" if self.gauge is None else self.gauge.unit,
                        mininterval=READ_INTERVAL, smoothing=0.05, disable=progress is None)
        self.steps, self.taken = steps, 0
        self.read_at = -math.inf
        self.planned = label is not None and _RUN.enter(label)

    def update(self, sim, steps, *, last=False):
        """Count ``steps`` more steps taken; read the gauge if it is time, or if this is the
        ``last`` update of the phase."""
        self.taken += steps
        if self.bar.disable:
            return
        if self.gauge is None:
            self.bar.update(steps)
            estimate = self.steps
        else:
            now = time.perf_counter()
            if now - self.read_at < READ_INTERVAL and not last:
                return
            self.read_at = now
            position = self.gauge.read(sim)
            total = self.gauge.total
            if total is None:
                return
            if self.bar.total is None:
                self.bar.total = _shown(total)
            self.bar.update(_shown(position) - self.bar.n)
            # the steps this phase will take, once its gauge has moved enough to tell
            estimate = self.taken * total / position if position >= 0.05 * total else None
        if self.planned:
            _RUN.show(self.taken, estimate)

    def set_postfix(self, fields):
        self.bar.set_postfix(fields, refresh=False)

    def close(self):
        if self.planned:
            _RUN.finish(self.taken)
        self.bar.close()


def _shown(value):
    """``value`` to 4 significant digits, as a bar shows it."""
    return float(f"{value:.4g}")


class _Run:
    """The whole run's bar (whole_run), counting steps: the steps taken by the phases that
    have ended, the running phase's steps against its estimate (PhaseBar), and the estimates
    of the phases to come. Inactive (no bar, nothing counted) when no run is open."""

    def __init__(self):
        self.bar = None
        self.plan, self.current = [], None
        self.ended, self.in_entry = 0, 0

    def enter(self, label):
        """Whether the phase ``label`` starting now is in the plan: the entry of its prefix,
        from the current one on (a phase of the current entry's prefix stays in it)."""
        if self.bar is None:
            return False
        first = 0 if self.current is None else self.current
        for index in range(first, len(self.plan)):
            if label.startswith(self.plan[index][0]):
                if index != self.current:
                    self.ended += self.in_entry
                    self.current, self.in_entry = index, 0
                return True
        return False

    def show(self, taken=0, estimate=None):
        """Show the run's percentage, the running phase having taken ``taken`` steps of an
        ``estimate`` (None: its entry's estimate of the plan)."""
        phase = taken if estimate is None else max(estimate, taken)
        entry = max(self.plan[self.current][1], self.in_entry + phase)
        later = sum(steps for _, steps in self.plan[self.current + 1:])
        done = self.ended + self.in_entry + taken
        percent = 100.0 * done / max(self.ended + entry + later, 1)
        self.bar.update(max(round(percent, 1) - self.bar.n, 0.0))

    def finish(self, taken):
        """The running phase has ended after ``taken`` steps."""
        self.in_entry += taken
        self.show()


_RUN = _Run()


@contextlib.contextmanager
def whole_run(plan, *, enabled=True, label="run"):
    """Show one bar for the whole run while the block runs (module docstring): ``plan`` a list
    of (label prefix or a tuple of them, estimated steps); nothing shown when not ``enabled``
    or when a run is open already."""
    if not enabled or not plan or _RUN.bar is not None:
        yield
        return
    _RUN.plan = [(prefix, max(int(steps), 1)) for prefix, steps in plan]
    _RUN.current, _RUN.ended, _RUN.in_entry = None, 0, 0
    _RUN.bar = tqdm(total=100.0, desc=label, unit="%", mininterval=READ_INTERVAL,
                    bar_format="{desc}: {n:.0f}%|{bar}| [{elapsed}<{remaining}]")
    try:
        yield
        _RUN.bar.update(_RUN.bar.total - _RUN.bar.n)         # the run has ended: 100 %
    finally:
        _RUN.bar.close()
        _RUN.bar = None
