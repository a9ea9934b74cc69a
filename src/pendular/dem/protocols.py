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
  ``sim.contacts.extra`` under ``pair_key(owner, field)``, carried to the same pair across
  rebuilds (new pairs start at zero) and saved by checkpoints;
- ``joins_contact_gather``: its pair forces are central along the contact normals and are
  added in the contact law's gather, one pass over the pairs instead of two
  (pendular.dem.contact_law.ContactForces.joined_by).
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
