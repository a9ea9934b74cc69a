"""Per-pair liquid-bridge state, declared once and read by attribute.

The arrays live in the neighbour list's ``Contacts.extra`` (so that dem carries them across
rebuilds and checkpoints them without knowing what they hold) under the keys
``"bridge." + field``; ``BridgeState.of(contacts)`` is the view every reader uses (the bridge
operation, homogenisation, ParaView writer, tests).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

#: Values of ``BridgeState.state``.
NO_BRIDGE = 0
AT_CONTACT = 1
ACROSS_GAP = 2

#: Key prefix of the bridge arrays in ``Contacts.extra``.
PREFIX = "bridge."


@dataclass
class BridgeState:
    """Liquid bridges of the K candidate pairs (one row per pair of ``sim.contacts``).

    state: int8, NO_BRIDGE, AT_CONTACT (values cached at contact) or ACROSS_GAP;
    volume [m^3]; force [N] magnitude of the attractive capillary force (> 0);
    filling_i, filling_j [deg] filling angles on particles pair_i and pair_j (delta1 on the
    smaller sphere); suction [Pa] the bridge's own suction (volume control; 0 under suction
    control, where the imposed suction holds).
    """

    state: np.ndarray
    volume: np.ndarray
    force: np.ndarray
    filling_i: np.ndarray
    filling_j: np.ndarray
    suction: np.ndarray

    @classmethod
    def of(cls, contacts):
        """The bridge arrays of ``contacts`` (created as zeros, no bridge, when absent)."""
        extra = contacts.extra
        arrays = {}
        for field in fields(cls):
            key = PREFIX + field.name
            if key not in extra:
                extra[key] = np.zeros(len(contacts), np.int8 if field.name == "state"
                                      else np.float64)
            arrays[field.name] = extra[key]
        return cls(**arrays)

    @staticmethod
    def present(contacts):
        """Whether ``contacts`` holds bridge arrays (a wet scene ran)."""
        return PREFIX + "state" in contacts.extra

    def mask(self):
        """(K,) bool: the pairs holding a bridge."""
        return self.state != NO_BRIDGE

    def count(self):
        """Number of bridges."""
        return int(np.count_nonzero(self.state))
