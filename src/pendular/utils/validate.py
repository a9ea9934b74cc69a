"""Input checks shared by every entry point: each error names the parameter, its value and the valid range."""

import math
import os
from contextlib import contextmanager

import numpy as np


def finite_number(name, value, valid_range):
    """``value`` as a float; ValueError naming the parameter, value and ``valid_range`` (text)
    unless it is a finite number."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {value!r} is not a number; valid range {valid_range}") from None
    if not math.isfinite(number):
        raise ValueError(f"{name} = {number} is not finite; valid range {valid_range}")
    return number


def check_range(name, value, low=-math.inf, high=math.inf, *, low_inclusive=True,
                high_inclusive=True, unit=""):
    """Return ``value`` as float after checking it lies in [low, high] (bounds open or closed)."""
    left = "[" if low_inclusive else "("
    right = "]" if high_inclusive else ")"
    suffix = f" {unit}" if unit else ""
    valid_range = f"{left}{low:g}, {high:g}{right}{suffix}"
    number = finite_number(name, value, valid_range)
    too_low = number < low if low_inclusive else number <= low
    too_high = number > high if high_inclusive else number >= high
    if too_low or too_high:
        raise ValueError(f"{name} = {value!r}{suffix} is outside the valid range {valid_range}")
    return number


def check_positive(name, value, unit=""):
    """Return ``value`` as float after checking it is finite and > 0."""
    return check_range(name, value, 0.0, math.inf, low_inclusive=False, unit=unit)


def check_int(name, value, low=0, high=None):
    """Return ``value`` as int after checking it is an integer in [low, high]."""
    valid_range = f"[{low}, {'inf' if high is None else high}]"
    if isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)):
        number = int(value)                   # exact, also beyond float's 2**53
    else:
        number = finite_number(name, value, f"integers in {valid_range}")
        if isinstance(value, bool) or not number.is_integer():
            raise ValueError(f"{name} = {value!r} is not an integer; valid range integers in "
                             f"{valid_range}")
        number = int(number)
    if number < low or (high is not None and number > high):
        raise ValueError(f"{name} = {value!r} is outside the valid range {valid_range}")
    return number


def check_array(name, array, shape_tail=(), positive=False, length=None):
    """Return ``array`` as contiguous, writable float64 (a copy unless it already is one)
    after checking its shape (``length`` rows if given, then ``shape_tail``), finiteness and
    sign. Always writable: a read-only view (``np.broadcast_to``) would both refuse in-place
    updates and make every compiled kernel it reaches compile a second, read-only version."""
    try:
        data = np.ascontiguousarray(array, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {array!r} is not an array of numbers") from None
    if not data.flags.writeable:
        data = data.copy()
    if data.ndim != 1 + len(shape_tail) or data.shape[1:] != tuple(shape_tail):
        raise ValueError(f"{name} must have shape (N, {', '.join(map(str, shape_tail))}), got {data.shape}"
                         if shape_tail else f"{name} must be one-dimensional, got shape {data.shape}")
    if length is not None and len(data) != length:
        raise ValueError(f"{name} has {len(data)} entries; valid: exactly {length}")
    bad = ~np.isfinite(data)
    if bad.any():
        index = [int(i) for i in np.argwhere(bad)[0]]
        raise ValueError(f"{name}{index} = {data[tuple(index)]} is not finite")
    if positive and (data <= 0).any():
        index = int(np.argmax(data <= 0))
        raise ValueError(f"{name}[{index}] = {data.flat[index]:g} is outside the valid range (0, inf)")
    return data


def check_values(name, values, low=-math.inf, high=math.inf, *, low_inclusive=True,
                 high_inclusive=True, unit=""):
    """Return ``values`` (scalar or array of any shape) as float64 after checking every entry
    as ``check_range`` does; the error names the first offending entry."""
    try:
        data = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {values!r} is not a number or an array of numbers") from None
    with np.errstate(invalid="ignore"):
        good = np.isfinite(data) & (data >= low if low_inclusive else data > low) \
            & (data <= high if high_inclusive else data < high)
    if not good.all():
        index = tuple(int(i) for i in np.argwhere(~good)[0])
        check_range(f"{name}{list(index) if index else ''}", data[index], low, high,
                    low_inclusive=low_inclusive, high_inclusive=high_inclusive, unit=unit)
    return data


@contextmanager
def reading(path, kind):
    """Block that reads the file ``path`` holding a ``kind`` (e.g. "pendular sample"): a missing
    file raises FileNotFoundError, and a corrupt, truncated or foreign one ValueError naming
    the path and the kind expected (instead of the reader's KeyError, OSError ...)."""
    if not os.path.isfile(path):
        raise FileNotFoundError(f"path = {os.fspath(path)!r}: no such file (expected a {kind})")
    try:
        yield
    except (OSError, KeyError, IndexError, TypeError, EOFError, UnicodeDecodeError,
            AttributeError) as error:
        raise ValueError(f"path = {os.fspath(path)!r} is not a readable {kind}: "
                         f"{type(error).__name__}: {error}") from None
