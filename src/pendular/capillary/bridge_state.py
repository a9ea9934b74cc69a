"""Per-pair liquid-bridge state, declared once and read by attribute.

``FIELDS`` declares each per-pair quantity of a bridge (name, dtype, unit; pendular.dem.protocols
.PairField); the bridge operations declare them as their ``pair_state``. The arrays live in the
neighbour list's ``Contacts.extra`` under ``pair_key(OWNER, field)`` = ``"bridge.<field>"`` (so
that dem carries them across rebuilds and checkpoints them without knowing what they hold);
``BridgeState.of(contacts)`` is the view every reader uses (the bridge operations and kernels,
homogenisation, the ParaView writer, tests). A BridgeState is a named tuple of those arrays, so
that the Numba kernels take it as one argument (pendular.capillary.bridge_kernels).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from pendular.dem.protocols import PairField, pair_arrays, pair_key

#: Values of ``BridgeState.state``.
NO_BRIDGE = 0
AT_CONTACT = 1
ACROSS_GAP = 2

#: Owner name of the bridge arrays in ``Contacts.extra`` (keys ``"bridge.<field>"``).
OWNER = "bridge"

#: The per-pair quantities of a liquid bridge, in BridgeState's order.
FIELDS = (
    PairField("state", np.int8, "1", "NO_BRIDGE (0), AT_CONTACT (1: values cached at contact) "
              "or ACROSS_GAP (2)"),
    PairField("volume", np.float64, "m^3", "liquid volume of the bridge"),
    PairField("force", np.float64, "N", "magnitude of the attractive capillary force (> 0)"),
    PairField("filling_i", np.float64, "deg", "filling angle on particle pair_i (delta1 on the "
              "smaller sphere)"),
    PairField("filling_j", np.float64, "deg", "filling angle on particle pair_j"),
    PairField("suction", np.float64, "Pa", "the bridge's own suction (volume control; 0 under "
              "suction control, where the imposed suction holds)"),
)


class BridgeState(NamedTuple):
    """Liquid bridges of the K candidate pairs (one row per pair of ``sim.contacts``): the
    arrays of ``FIELDS``, by name."""

    state: np.ndarray
    volume: np.ndarray
    force: np.ndarray
    filling_i: np.ndarray
    filling_j: np.ndarray
    suction: np.ndarray

    @classmethod
    def of(cls, contacts):
        """The bridge arrays of ``contacts`` (created as zeros, no bridge, when absent;
        ValueError when one held there does not match its declaration)."""
        return cls(**pair_arrays(contacts, OWNER, FIELDS))

    @staticmethod
    def present(contacts):
        """Whether ``contacts`` holds bridge arrays (a wet scene ran)."""
        return pair_key(OWNER, FIELDS[0]) in contacts.extra

    def mask(self):
        """(K,) bool: the pairs holding a bridge."""
        return self.state != NO_BRIDGE

    def count(self):
        """Number of bridges."""
        return int(np.count_nonzero(self.state))
