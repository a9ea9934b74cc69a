"""Recorders: operations that sample the state every ``period`` steps into named columns."""

import h5py
import numpy as np

from pendular.utils.atomic import replacing
from pendular.utils.validate import check_int


class HistoryRecorder:
    """Every ``period`` steps counted from step ``origin`` (and at step ``end`` when given, so a
    phase of any length records its final state), evaluate each ``quantities[name](sim)`` and
    append it as a row.

    Quantities are only computed on recording steps, so costly measures (homogenisation) do not
    run every step. ``rows`` maps name -> list of values; ``arrays()`` stacks them.
    """

    def __init__(self, period, quantities, origin=0, end=None):
        self.period = check_int("record period", period, low=1)
        self.origin = check_int("record origin", origin)
        self.end = None if end is None else check_int("record end", end, low=self.origin)
        self.quantities = dict(quantities)
        for name, quantity in self.quantities.items():
            if not callable(quantity):
                raise TypeError(f"quantities[{name!r}] = {quantity!r} is not a function of sim")
        self.rows = {name: [] for name in self.quantities}

    def apply(self, sim):
        if (sim.step - self.origin) % self.period == 0 or sim.step == self.end:
            self.record(sim)

    def record(self, sim):
        """Sample every quantity now. The row is computed whole before any column grows, so an
        interrupt (Ctrl-C) while the quantities are computed leaves no partial row."""
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


def write_history(path, columns, attributes, group="history"):
    """Write ``columns`` as datasets of ``group`` and ``attributes`` on the file, atomically.

    The file is written under a temporary name then renamed, so a killed run never leaves a
    truncated HDF5 file at ``path``. Attribute values that HDF5 cannot hold are stored as text.
    """
    with replacing(path) as temporary, h5py.File(temporary, "w") as handle:
        for key, value in attributes.items():
            handle.attrs[key] = value if isinstance(value, (int, float, str, bool)) else str(value)
        data = handle.create_group(group)
        for name, values in columns.items():
            data.create_dataset(name, data=values)
