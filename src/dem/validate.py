"""Input checks shared by every entry point: each error names the parameter, its value and the valid range."""

import math

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
    if isinstance(value, bool) or not float(value).is_integer():
        raise ValueError(f"{name} must be an integer, got {value!r}")
    number = int(value)
    if number < low or (high is not None and number > high):
        upper = "inf" if high is None else str(high)
        raise ValueError(f"{name} = {value!r} is outside the valid range [{low}, {upper}]")
    return number


def check_array(name, array, shape_tail=(), positive=False):
    """Return a contiguous float64 copy of ``array`` after checking shape, finiteness and sign."""
    data = np.ascontiguousarray(array, dtype=np.float64)
    if data.shape[1:] != tuple(shape_tail):
        raise ValueError(f"{name} must have shape (N, {', '.join(map(str, shape_tail))}), got {data.shape}"
                         if shape_tail else f"{name} must be one-dimensional, got shape {data.shape}")
    bad = ~np.isfinite(data)
    if bad.any():
        index = np.argwhere(bad)[0]
        raise ValueError(f"{name}{list(index)} = {data[tuple(index)]} is not finite")
    if positive and (data <= 0).any():
        index = int(np.argmax(data <= 0))
        raise ValueError(f"{name}[{index}] = {data.flat[index]:g} is outside the valid range (0, inf)")
    return data
