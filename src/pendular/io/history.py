"""Histories and summaries that describe themselves: writing them, and reading them back.

``write_history`` stores a run's columns in HDF5 group ``history``, each dataset with its
``units``, ``description`` and thesis ``equation`` (pendular.io.schema), HDF5 dimension scales
(``record``, ``axis``, ``component``, ``grip``), integers as integers, and file attributes
``pendular_version``, ``schema_version`` and ``config`` (the run's configuration, JSON), written
atomically. ``read_history`` returns an ``xarray.Dataset`` with coordinates and units;
``read_summary`` a ``pandas.DataFrame`` (one row per run) with the units of its columns.
"""

from __future__ import annotations

import json
import os

import h5py
import numpy as np

from pendular.utils.version import software_version

from pendular.utils.atomic import replacing

from pendular.io.columns import DIMENSION_LABELS, DIMENSIONS, HISTORY_COLUMNS
from pendular.io.schema import SCHEMA_VERSION, SUMMARY_UNITS

#: File attributes written by write_history itself (not overridable by ``attributes``).
RESERVED_ATTRIBUTES = ("pendular_version", "schema_version", "config")
#: Coordinates of the ``record`` dimension in read_history's Dataset.
RECORD_COORDINATES = ("axial_strain", "shear_strain", "step", "time")
#: Files read_summary looks for in a folder, in this order.
SUMMARY_FILES = ("summary.json", "campaign.json", "campaign.csv", "tension.json")




def _checked(name, values, column, rows):
    """``values`` of column ``name`` as an array of the declared dtype; ValueError naming the
    column when it is not declared, its shape differs from the declaration or from ``rows``,
    or an integer column holds a non-integral value."""
    if column is None:
        raise ValueError(f"history column {name!r} is not declared in pendular.io.schema "
                         "(HISTORY_COLUMNS: units and description are required)")
    array = np.asarray(values)
    expected = ("record", *column.dims)
    if array.ndim != len(expected) or array.shape[1:] != column.shape:
        raise ValueError(f"history column {name!r} has shape {array.shape}; declared dims "
                         f"{expected} of shape (records, {', '.join(map(str, column.shape))})")
    if rows is not None and len(array) != rows:
        raise ValueError(f"history column {name!r} has {len(array)} records; the other "
                         f"columns have {rows}")
    if column.is_integer and array.dtype.kind not in "iu":
        if array.dtype.kind not in "fb" or not np.all(np.isfinite(array)) \
                or np.any(array != np.round(array)):
            raise ValueError(f"history column {name!r} is declared {column.dtype} but holds "
                             "non-integral values")
    return array.astype(column.dtype, copy=False)


def write_history(path, columns, config, *, attributes=None, schema=HISTORY_COLUMNS):
    """Write ``columns`` (name -> array, first axis the record) to ``path`` atomically.

    Group ``history``: one dataset per column with attributes ``units``, ``description`` and
    (where the thesis has one) ``equation``, in the dtype ``schema`` declares, its dimensions
    attached to the dimension scales ``record`` (0, 1, ...) and ``axis``/``component``/``grip``
    (their labels). File attributes: ``pendular_version``, ``schema_version``, ``config`` (JSON
    of ``config``, the run's configuration, e.g. pendular.procedures.config.config_to_dict) and
    ``attributes`` (further flat name -> number or text; other values stored as text).
    ValueError naming a column that ``schema`` does not declare, whose shape does not match
    its declaration or whose record count differs from the others.
    """
    checked, rows = {}, None
    for name, values in columns.items():
        checked[name] = _checked(name, values, schema.get(name), rows)
        rows = len(checked[name])
    text = json.dumps(config, sort_keys=True, default=str)
    with replacing(path) as temporary, h5py.File(temporary, "w") as handle:
        for key, value in (attributes or {}).items():
            if key in RESERVED_ATTRIBUTES:
                raise ValueError(f"attributes[{key!r}] is reserved (written by write_history)")
            handle.attrs[key] = (value if isinstance(value, (int, float, str, bool, np.generic))
                                 else str(value))
        handle.attrs["pendular_version"] = software_version()
        handle.attrs["schema_version"] = SCHEMA_VERSION
        handle.attrs["config"] = text
        group = handle.create_group("history")
        used = {dim for name in checked for dim in schema[name].dims}
        scales = {"record": group.create_dataset("record", data=np.arange(rows or 0))}
        scales["record"].attrs["description"] = "record number (row of the history)"
        for dim in DIMENSION_LABELS:
            if dim in used:
                labels = np.array(DIMENSION_LABELS[dim], dtype=h5py.string_dtype())
                scales[dim] = group.create_dataset(dim, data=labels)
                scales[dim].attrs["description"] = f"labels of dimension {dim!r}"
        for dim, scale in scales.items():
            scale.make_scale(dim)
        for name, values in checked.items():
            column = schema[name]
            data = group.create_dataset(name, data=values)
            data.attrs["units"] = column.units
            data.attrs["description"] = column.description
            if column.equation:
                data.attrs["equation"] = column.equation
            for index, dim in enumerate(("record", *column.dims)):
                data.dims[index].attach_scale(scales[dim])
                data.dims[index].label = dim


def history_path(path_or_dir):
    """DIR/history.h5 for a folder, else the path itself."""
    path = os.fspath(path_or_dir)
    return os.path.join(path, "history.h5") if os.path.isdir(path) else path


def _plain(value):
    """An HDF5 attribute value as a Python value (text decoded, NumPy scalars unwrapped)."""
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.generic):
        return value.item()
    return value


def _variable(name, data):
    """(dims, values, attrs) of one history dataset: dimension names from the file's labels,
    else the schema's, else ``name_dim1``...; attributes missing in the file (files written
    before schema 1) filled from the schema, and declared integers stored as floats cast."""
    column = HISTORY_COLUMNS.get(name)
    values = data[()]
    labels = tuple(dim.label for dim in data.dims)
    if values.ndim and all(labels) and labels[0] == "record":
        dims = labels
    elif column is not None and values.ndim == 1 + len(column.dims):
        dims = ("record", *column.dims)
    else:
        dims = ("record", *(f"{name}_dim{i}" for i in range(1, values.ndim)))
    attrs = {key: _plain(data.attrs[key]) for key in ("units", "description", "equation")
             if key in data.attrs}
    if column is not None:
        attrs.setdefault("units", column.units)
        attrs.setdefault("description", column.description)
        if column.equation:
            attrs.setdefault("equation", column.equation)
        if column.is_integer and values.dtype.kind == "f" and np.all(np.isfinite(values)) \
                and np.all(values == np.round(values)):
            values = values.astype(column.dtype)
    return dims, values, attrs


def read_history(path_or_dir, index="auto"):
    """The history of a run (its folder or its history.h5) as an ``xarray.Dataset``.

    One variable per column, each with attributes ``units``, ``description`` (and
    ``equation``); dimensions: the records, ``axis`` and ``component`` (coordinates x, y, z),
    ``grip`` (z-, z+); coordinates ``axial_strain``, ``step`` and ``time`` on the records.
    ``index`` names the records' dimension: "auto" (default) the strain a test drives, when
    it rises or falls strictly over the records: ``shear_strain`` gamma in a simple shear,
    else ``axial_strain`` (a shear: ``history.peak_q.plot()`` plots against the strain,
    ``history.sel(axial_strain=0.01, method="nearest")`` picks a record), else ``record`` (a
    simple shear after a consolidation, whose gamma stays 0 there); or one of "record",
    "axial_strain", "shear_strain", "step", "time". Dataset attributes:
    ``config`` (the run configuration as JSON text: ``json.loads(history.attrs["config"])``),
    ``pendular_version``, ``schema_version`` (0 for files written before the schema, whose
    attributes are filled from pendular.io.schema), the file's other attributes (run
    parameters) and ``source`` (the path). ValueError naming the path for a missing or
    unreadable file.
    """
    import xarray

    if index not in ("auto", "record", *RECORD_COORDINATES):
        raise ValueError(f"index = {index!r} is not one of 'auto', 'record', "
                         + ", ".join(repr(name) for name in RECORD_COORDINATES))
    path = history_path(path_or_dir)
    if not os.path.isfile(path):
        raise ValueError(f"history = {path!r}: no such file")
    try:
        with h5py.File(path, "r") as handle:
            if not isinstance(handle.get("history"), h5py.Group):
                raise ValueError("no group 'history'")
            group = handle["history"]
            variables = {name: _variable(name, group[name]) for name in group
                         if isinstance(group[name], h5py.Dataset) and name not in DIMENSIONS}
            file_attrs = {key: _plain(value) for key, value in handle.attrs.items()}
        coords = {dim: list(labels) for dim, labels in DIMENSION_LABELS.items()
                  if any(dim in dims for dims, _, _ in variables.values())}
        for name in RECORD_COORDINATES:
            if name in variables:
                coords[name] = variables.pop(name)
        dataset = xarray.Dataset(variables, coords=coords)
        config = file_attrs.pop("config", None)
        if config is not None:
            json.loads(config)
    except (OSError, KeyError, TypeError, ValueError) as error:
        raise ValueError(f"history = {path!r} is not a readable pendular history: "
                         f"{error}") from None
    dataset.attrs.update(file_attrs)
    dataset.attrs.update({
        "config": config if config is not None else "{}",
        "pendular_version": str(file_attrs.get("pendular_version", "unknown")),
        "schema_version": int(file_attrs.get("schema_version", 0)),
        "source": path})
    if index == "auto":
        driven = "shear_strain" if "shear_strain" in dataset else "axial_strain"
        strain = np.diff(dataset[driven].values) if driven in dataset else []
        rises_or_falls = len(strain) > 0 and (np.all(strain > 0) or np.all(strain < 0))
        index = driven if rises_or_falls else "record"
    if index != "record":
        if index not in dataset.coords:
            raise ValueError(f"history = {path!r} has no {index!r} to index its records by")
        dataset = dataset.swap_dims(record=index)
    return dataset


def _summary_path(path):
    """The summary file of ``path`` (a file, or a folder holding one of SUMMARY_FILES)."""
    if os.path.isdir(path):
        for name in SUMMARY_FILES:
            if os.path.isfile(os.path.join(path, name)):
                return os.path.join(path, name)
        raise ValueError(f"summary = {path!r}: no {', '.join(SUMMARY_FILES)} in this folder")
    if not os.path.isfile(path):
        raise ValueError(f"summary = {path!r}: no such file")
    return path


def _rows(data):
    """The rows of a loaded JSON summary: ``runs`` (campaign.json), ``cases`` (tension.json)
    or the object itself (summary.json)."""
    if not isinstance(data, dict):
        raise ValueError(f"expected a JSON object, found {type(data).__name__}")
    for key in ("runs", "cases"):
        if key in data:
            if not isinstance(data[key], list) or not all(isinstance(r, dict) for r in data[key]):
                raise ValueError(f"{key!r} is not a list of objects")
            return data[key]
    return [data]


def read_summary(path_or_dir):
    """Summaries as a ``pandas.DataFrame``: a summary.json (one row), a run folder (its
    summary.json), a campaign (its folder, campaign.json: one row per entry of ``runs``, or
    campaign.csv: one row per run) or a tension.json (one row per case).

    Scalar keys become columns (nested records such as ``units`` or lists are left out);
    ``DataFrame.attrs["units"]``: units of the numeric columns (pendular.io.schema.SUMMARY_UNITS
    and the file's own ``units`` blocks), ``attrs["source"]``: the file read. ValueError naming
    the path for a missing, empty or unreadable file.
    """
    import pandas

    path = _summary_path(os.fspath(path_or_dir))
    units = {}
    try:
        if path.endswith(".csv"):
            frame = pandas.read_csv(path)
        else:
            with open(path) as handle:
                rows = _rows(json.load(handle))
            for row in rows:
                if isinstance(row.get("units"), dict):
                    units.update(row["units"])
            frame = pandas.DataFrame([{k: v for k, v in row.items()
                                       if not isinstance(v, (dict, list))} for row in rows])
    except (OSError, ValueError) as error:
        raise ValueError(f"summary = {path!r} is not a readable pendular summary: "
                         f"{error}") from None
    numeric = [name for name in frame.columns if frame[name].dtype.kind in "iuf"]
    frame.attrs["units"] = {name: units.get(name, SUMMARY_UNITS.get(name)) for name in numeric
                            if name in units or name in SUMMARY_UNITS}
    frame.attrs["source"] = path
    return frame
