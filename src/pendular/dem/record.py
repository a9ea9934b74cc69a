"""Recorders: operations that sample the state every ``period`` steps into named columns."""

import numpy as np

from pendular.dem.protocols import state_array
from pendular.dem.simulation import DEVICE_HELD
from pendular.utils.validate import check_int


class HistoryRecorder:
    """Every ``period`` steps counted from step ``origin`` (and at step ``end`` when given, so a
    phase of any length records its final state), evaluate each ``quantities[name](sim)`` and
    append it as a row.

    Quantities are only computed on recording steps, so costly measures (homogenisation) do not
    run every step. ``rows`` maps name -> list of values; ``arrays()`` stacks them. ``reads``:
    the parts of the state the quantities read, fetched before each record (Simulation.fetch:
    a device run brings those back alone; the default, all of it).
    """

    def __init__(self, period, quantities, origin=0, end=None, reads=DEVICE_HELD):
        self.period = check_int("record period", period, low=1)
        self.origin = check_int("record origin", origin)
        self.end = None if end is None else check_int("record end", end, low=self.origin)
        self.quantities = dict(quantities)
        for name, quantity in self.quantities.items():
            if not callable(quantity):
                raise TypeError(f"quantities[{name!r}] = {quantity!r} is not a function of sim")
        self.rows = {name: [] for name in self.quantities}
        self.reads = tuple(reads)

    def state_dict(self):
        """``origin`` and ``end`` (the steps its records count from and end at, None: no
        end; a resumed run builds its recorder at another step) and ``rows``: each
        quantity's values so far, stacked (records, ...) float64 (a column may hold one more
        row than another: a row cut short by an interrupt)."""
        rows = {}
        for name, values in self.rows.items():
            try:
                rows[name] = np.stack(values) if values else np.zeros(0)
            except ValueError:
                raise ValueError(f"cannot checkpoint {name!r} of the HistoryRecorder: its "
                                 "values are not all of one shape") from None
        return {"origin": self.origin, "end": self.end, "rows": rows}

    def load_state(self, state):
        origin = check_int("origin", state["origin"])
        end = None if state["end"] is None else check_int("end", state["end"], low=origin)
        rows = state["rows"]
        if not isinstance(rows, dict) or set(rows) != set(self.quantities):
            found = sorted(rows) if isinstance(rows, dict) else type(rows).__name__
            raise ValueError(f"rows holds {found}; valid: the quantities "
                             f"{sorted(self.quantities)}")
        columns = {}
        for name in self.quantities:
            column = rows[name]
            axes = max(1, column.ndim) if isinstance(column, np.ndarray) else 1
            try:                # NaN is a value (e.g. k0 while the axial stress is 0)
                columns[name] = state_array(rows, name, np.float64, (None,) * axes,
                                            finite=False)
            except ValueError as error:
                raise ValueError(f"rows/{error}") from None
        lengths = {name: len(column) for name, column in columns.items()}
        if len(set(lengths.values())) > 1:
            shortest = min(lengths, key=lengths.get)
            longest = max(lengths, key=lengths.get)
            raise ValueError(f"rows/{shortest} holds {lengths[shortest]} rows and rows/{longest} "
                             f"{lengths[longest]}; valid: one row per record in every quantity")
        self.origin, self.end = origin, end
        self.rows = {name: [np.array(row) for row in column]
                     for name, column in columns.items()}

    def apply(self, sim):
        if (sim.step - self.origin) % self.period == 0 or sim.step == self.end:
            self.record(sim)

    def record(self, sim):
        """Sample every quantity now. The row is computed whole before any column grows, so an
        interrupt (Ctrl-C) while the quantities are computed leaves no partial row."""
        sim.fetch(*self.reads)
        row = {name: np.asarray(quantity(sim), dtype=np.float64)
               for name, quantity in self.quantities.items()}
        for name, value in row.items():
            self.rows[name].append(value)

    def __len__(self):
        """Complete records (a row cut short by an interrupt while appending is not one)."""
        return min((len(values) for values in self.rows.values()), default=0)

    def arrays(self):
        """Columns of the complete records as stacked arrays (first axis: record)."""
        complete = len(self)
        return {name: np.array(values[:complete]) for name, values in self.rows.items()}

    def last(self, name):
        return self.rows[name][-1]

