"""The contracts of what a ``Simulation`` runs (pendular.dem.simulation): one small interface
per kind of operation, as LAMMPS's pair styles and fixes, so that a new force, control or
writer plugs in by implementing it and touches nothing else (docs/architecture.md, "Adding a
force").

Every operation has ``apply(sim)``, called once a step at its place in the pipeline: the
neighbour list, the forces in order, the controls in order, the integrator, then the writers
(read-only). A force may also declare what it needs from the neighbour list:

- ``reach(sim)`` [m]: how far beyond touching it needs pairs (the list rebuilds when the
  largest reach of the scene's forces changes); none: touching pairs and the skin;
- ``pair_state``: the per-pair quantities it keeps (``PairField``\\ s), held in
  ``sim.contacts.extra`` under ``pair_key(pair_owner, field)`` (``pair_owner``: its name
  there), carried to the same pair across rebuilds (new pairs start at zero) and saved by
  checkpoints, which store only declared fields and check each against its declaration;
- ``joins_contact_gather``: its pair forces are central along the contact normals and are
  added in the contact law's gather, one pass over the pairs instead of two
  (pendular.dem.contact_law.ContactForces.joined_by).

Every operation says what a checkpoint (pendular.dem.checkpoint) must keep of it:

- one that keeps something across steps (a servo's memory, a recorder's rows, a counter) or
  whose settings its procedure changes after building it (a stage's target or strain rate)
  is ``Stateful``: ``state_dict()`` returns that, as plain values only (no object, no
  function), and ``load_state(state)`` takes it back from a dict of the same keys, checking every value
  before changing anything (ValueError naming the key; ``state_array`` checks an array).
  What the scene builds (parameters of its configuration, functions, references to other
  objects) is not state: the scene that loads a checkpoint builds it again;
- one that keeps nothing declares ``stateless = True`` (class attribute).

A checkpoint refuses an operation that does neither, so that nothing is skipped silently.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Operation(Protocol):
    """Anything in the step pipeline: forces, controls, the integrator, the neighbour list,
    writers (which only read)."""

    def apply(self, sim) -> None:
        """Do this operation's part of one step on ``sim``."""


@runtime_checkable
class ReachingForce(Operation, Protocol):
    """A force that needs pairs beyond touching (e.g. liquid bridges across gaps)."""

    def reach(self, sim) -> float:
        """Largest distance [m] between two surfaces at which this force still acts."""


@runtime_checkable
class Stateful(Protocol):
    """An operation that keeps something across steps (module docstring)."""

    def state_dict(self) -> dict:
        """What a checkpoint must keep of this operation, by name, as copies (the dict does
        not change as the operation runs) of plain values: None (an optional value not
        set), bool, int, float, str, NumPy arrays of numbers or booleans, lists of numbers
        or of strings, and dicts of these by name."""

    def load_state(self, state: dict) -> None:
        """Take back ``state`` (a ``state_dict`` of an operation of this type, the same
        keys): every value checked before anything changes, ValueError naming the key."""


def state_array(state, key, dtype, shape, finite=True):
    """A copy of the array ``state[key]`` after checking that it holds ``dtype``, has
    ``shape`` (None: any length on that axis) and, if ``finite``, finite numbers only;
    ValueError naming ``key`` otherwise."""
    value = state[key]
    if not isinstance(value, np.ndarray) or value.dtype != np.dtype(dtype):
        found = value.dtype if isinstance(value, np.ndarray) else type(value).__name__
        raise ValueError(f"{key} holds {found}; valid: an array of {np.dtype(dtype)}")
    if value.ndim != len(shape) or any(want is not None and got != want
                                       for got, want in zip(value.shape, shape)):
        wanted = ", ".join("any" if n is None else str(n) for n in shape)
        raise ValueError(f"{key} has shape {value.shape}; valid: ({wanted}"
                         f"{',' if len(shape) == 1 else ''})")
    if finite and value.dtype.kind == "f" and not np.isfinite(value).all():
        index = [int(i) for i in np.argwhere(~np.isfinite(value))[0]]
        raise ValueError(f"{key}{index} = {value[tuple(index)]} is not finite")
    return np.array(value, dtype=dtype)


@dataclass(frozen=True)
class PairField:
    """One per-pair quantity an operation keeps across neighbour-list rebuilds: its ``name``,
    NumPy ``dtype``, ``unit`` (SI; "1" for a number or a code), ``description`` and trailing
    ``shape`` (one row per pair)."""

    name: str
    dtype: type
    unit: str
    description: str
    shape: tuple = ()


def pair_key(owner, field):
    """The ``Contacts.extra`` key of ``field`` (a PairField) kept by ``owner`` (a name)."""
    return f"{owner}.{field.name}"


def pair_arrays(contacts, owner, fields):
    """name -> the per-pair array of each PairField of ``fields`` kept by ``owner`` in
    ``contacts.extra``, created as zeros of its declared dtype and shape when absent (a pair
    without state); ValueError naming the field when an array held there does not match its
    declaration (a damaged or foreign checkpoint)."""
    arrays = {}
    for field in fields:
        key = pair_key(owner, field)
        shape = (len(contacts), *field.shape)
        array = contacts.extra.get(key)
        if array is None:
            array = contacts.extra[key] = np.zeros(shape, field.dtype)
        elif array.dtype != np.dtype(field.dtype) or array.shape != shape:
            raise ValueError(f"per-pair {key} holds {array.dtype} {array.shape}; declared "
                             f"{np.dtype(field.dtype)} {shape} [{field.unit}]")
        arrays[field.name] = array
    return arrays
