"""Histories and summaries that describe themselves: writing them, and reading them back.

``write_history`` stores a run's columns in HDF5 group ``history``, each dataset with its
``units``, ``description`` and thesis ``equation`` (pendular.schema), HDF5 dimension scales
(``record``, ``axis``, ``component``, ``grip``), integers as integers, and file attributes
``pendular_version``, ``schema_version`` and ``config`` (the run's configuration, JSON), written
atomically. ``read_history`` returns an ``xarray.Dataset`` with coordinates and units;
``read_summary`` a ``pandas.DataFrame`` (one row per run).
"""

from __future__ import annotations

import json
import os

import h5py
import numpy as np

from dem.atomic import replacing

from .schema import DIMENSION_LABELS, HISTORY_COLUMNS, SCHEMA_VERSION, SUMMARY_UNITS


def _version():
    from . import __version__
    return __version__


def write_history(path, columns, config, *, attributes=None, schema=HISTORY_COLUMNS):
    """Write ``columns`` (name -> array, first axis the record) to ``path`` atomically.

    config: the run's configuration (a dict, e.g. pendular.config.config_to_dict) stored as
    JSON; attributes: further file attributes (flat name -> number or text). ValueError naming
    a column that ``schema`` does not declare or whose shape does not match it.
    """
    for name, values in columns.items():
        if name not in schema:
            raise ValueError(f"history column {name!r} is not declared in pendular.schema "
                             "(units and description are required)")
        expected = 1 + len(schema[name].dims)
        if np.ndim(values) != expected:
            raise ValueError(f"history column {name!r} has shape {np.shape(values)}; "
                             f"declared dims ('record', {', '.join(schema[name].dims)})")
    with replacing(path) as temporary, h5py.File(temporary, "w") as handle:
        for key, value in (attributes or {}).items():
            handle.attrs[key] = (value if isinstance(value, (int, float, str, bool, np.generic))
                                 else str(value))
        handle.attrs["pendular_version"] = _version()
        handle.attrs["schema_version"] = SCHEMA_VERSION
        handle.attrs["config"] = json.dumps(config, sort_keys=True, default=str)
        group = handle.create_group("history")
        rows = len(next(iter(columns.values()), ()))
        scales = {"record": group.create_dataset("record", data=np.arange(rows, dtype=np.int64))}
        scales["record"].make_scale("record")
        for dim, labels in DIMENSION_LABELS.items():
            scale = group.create_dataset(dim, data=np.array(labels, dtype=h5py.string_dtype()))
            scale.make_scale(dim)
            scales[dim] = scale
        for name, values in columns.items():
            column = schema[name]
            data = group.create_dataset(name, data=np.asarray(values, dtype=column.dtype))
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


def read_history(path_or_dir):
    """The history of a run (its folder or its history.h5) as an ``xarray.Dataset``: one
    variable per column with ``units`` and ``description`` attributes, dimensions ``record``,
    ``axis``/``component`` (labelled x, y, z) and ``grip``, coordinates ``axial_strain``,
    ``step`` and ``time`` on ``record``; dataset attributes ``config`` (dict),
    ``pendular_version``, ``schema_version``. Files of pendular 0.1 (no attributes) get the
    declared ones. ValueError naming the path for a missing or unreadable file."""
    import xarray

    path = history_path(path_or_dir)
    if not os.path.isfile(path):
        raise ValueError(f"history = {path!r}: no such file")
    try:
        with h5py.File(path, "r") as handle:
            group = handle["history"]
            names = [n for n in group if n not in ("record", *DIMENSION_LABELS)]
            variables = {}
            for name in names:
                column = HISTORY_COLUMNS.get(name)
                values = group[name][()]
                dims = ("record", *(column.dims if column else
                                    [f"dim_{name}_{i}" for i in range(1, values.ndim)]))
                attrs = {k: (v.decode() if isinstance(v, bytes) else v)
                         for k, v in group[name].attrs.items()
                         if k in ("units", "description", "equation")}
                if column is not None:
                    attrs.setdefault("units", column.units)
                    attrs.setdefault("description", column.description)
                variables[name] = (dims, values, attrs)
            file_attrs = dict(handle.attrs)
    except (OSError, KeyError) as error:
        raise ValueError(f"history = {path!r} is not a readable pendular history: "
                         f"{error}") from None
    coords = {dim: list(labels) for dim, labels in DIMENSION_LABELS.items()
              if any(dim in v[0] for v in variables.values())}
    for name in ("axial_strain", "step", "time"):
        if name in variables:
            coords[name] = variables.pop(name)
    dataset = xarray.Dataset(variables, coords=coords)
    config = file_attrs.get("config")
    dataset.attrs.update({
        "config": json.loads(config) if isinstance(config, str) else {},
        "pendular_version": str(file_attrs.get("pendular_version", "0.1")),
        "schema_version": int(file_attrs.get("schema_version", 0)),
        "source": path})
    return dataset


def read_summary(path_or_dir):
    """Summaries as a ``pandas.DataFrame``: a summary.json (one row), a run folder (its
    summary.json), or a campaign (folder or campaign.json / campaign.csv: one row per run).
    Units of the columns in ``DataFrame.attrs["units"]``."""
    import pandas

    path = os.fspath(path_or_dir)
    if os.path.isdir(path):
        for name in ("summary.json", "campaign.json", "campaign.csv"):
            if os.path.isfile(os.path.join(path, name)):
                path = os.path.join(path, name)
                break
        else:
            raise ValueError(f"summary = {path!r}: no summary.json, campaign.json or "
                             "campaign.csv in this folder")
    if not os.path.isfile(path):
        raise ValueError(f"summary = {path!r}: no such file")
    try:
        if path.endswith(".csv"):
            frame = pandas.read_csv(path)
        else:
            with open(path) as handle:
                data = json.load(handle)
            rows = data["runs"] if isinstance(data, dict) and "runs" in data else [data]
            frame = pandas.DataFrame([{k: v for k, v in row.items()
                                       if not isinstance(v, (dict, list))} for row in rows])
    except (OSError, ValueError, KeyError) as error:
        raise ValueError(f"summary = {path!r} is not a readable pendular summary: "
                         f"{error}") from None
    frame.attrs["units"] = {k: v for k, v in SUMMARY_UNITS.items() if k in frame.columns}
    frame.attrs["source"] = path
    return frame
