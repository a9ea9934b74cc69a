"""The bridge operations by control (pendular.capillary.bridges), their declared per-pair state
(pendular.capillary.bridge_state) and the kernels' bundled arguments
(pendular.capillary.bridge_kernels): every parallel kernel's writes land, with the values of
the tables' own lookups scaled by hand."""

import math

import numpy as np
import pytest

from pendular import capillary
from pendular.capillary import (BridgeState, CapillaryBridges, SuctionBridges, VolumeBridges,
    bridge_kernels)
from pendular.capillary.bridge_state import ACROSS_GAP, AT_CONTACT, FIELDS, NO_BRIDGE
from pendular.capillary.volume_table import lookup_volume_interface
from pendular.dem.neighbors import build_contacts
from pendular.dem.state import period_layout

GAMMA = capillary.SURFACE_TENSION
RADIUS = 1e-3


def test_capillary_bridges_builds_the_operation_of_its_control():
    at_contact = CapillaryBridges(1000.0, GAMMA)
    persisting = CapillaryBridges(1000.0, GAMMA, persist=True)
    volume = CapillaryBridges(1000.0, GAMMA, control="volume", roughness=0.01, liquid="lost")
    assert type(at_contact) is SuctionBridges and type(persisting) is SuctionBridges
    assert type(volume) is VolumeBridges
    assert all(isinstance(op, CapillaryBridges) for op in (at_contact, persisting, volume))
    assert (at_contact.control, at_contact.persist, at_contact.joins_contact_gather,
            at_contact.liquid, at_contact.roughness) == ("suction", False, True, "reservoir", 0.0)
    assert (persisting.persist, persisting.joins_contact_gather) == (True, False)
    assert (volume.control, volume.persist, volume.joins_contact_gather, volume.liquid,
            volume.roughness, volume.model) == ("volume", True, False, "lost", 0.01, "exact")
    assert at_contact.pair_state == volume.pair_state == FIELDS
    # the classes themselves take only their own control's options
    assert type(SuctionBridges(1000.0, GAMMA, persist=True)) is SuctionBridges
    with pytest.raises(TypeError, match="roughness"):
        SuctionBridges(1000.0, GAMMA, roughness=0.1)
    with pytest.raises(ValueError, match="volume-controlled bridges need model='exact'"):
        CapillaryBridges(1000.0, GAMMA, control="volume", model="toroidal")
    with pytest.raises(ValueError, match="liquid = 'shared' needs control='volume'"):
        CapillaryBridges(1000.0, GAMMA, liquid="shared")


def test_bridge_state_is_declared_and_kept_under_the_bridge_keys():
    contacts = build_contacts(np.array([[0.0, 0, 0], [2.1, 0, 0], [0, 2.1, 0]]), np.ones(3), 0.2)
    state = BridgeState.of(contacts)
    assert BridgeState._fields == tuple(field.name for field in FIELDS)
    assert {field.name: (np.dtype(field.dtype).name, field.unit) for field in FIELDS} == {
        "state": ("int8", "1"), "volume": ("float64", "m^3"), "force": ("float64", "N"),
        "filling_i": ("float64", "deg"), "filling_j": ("float64", "deg"),
        "suction": ("float64", "Pa")}
    assert sorted(contacts.extra) == sorted(f"bridge.{field.name}" for field in FIELDS)
    assert state.volume is contacts.extra["bridge.volume"]      # a view, not a copy
    assert state.volume.shape == (len(contacts),) and not state.volume.any()
    assert BridgeState.present(contacts) and state.count() == 0
    contacts.extra["bridge.volume"] = np.zeros(len(contacts), np.float32)
    with pytest.raises(ValueError, match=r"bridge.volume holds float32 .* declared float64"):
        BridgeState.of(contacts)


@pytest.fixture(scope="module")
def tables():
    suction = capillary.BridgeTable.cached(0.0, radius_ratios=(1.0,))
    return suction, capillary.VolumeBridgeTable.cached(0.0, radius_ratios=(1.0,))


def three_pairs(gap_star):
    """Equal spheres of radius RADIUS on the x axis: pair 0 touching (overlap 1e-9 m), pair 1
    apart by gap_star R, pair 2 apart by 2 R (beyond any rupture)."""
    position = np.array([[0.0, 0, 0], [2 * RADIUS - 1e-9, 0, 0], [10 * RADIUS, 0, 0],
                         [12 * RADIUS + gap_star * RADIUS, 0, 0], [20 * RADIUS, 0, 0],
                         [24 * RADIUS, 0, 0]])
    pair_i, pair_j = np.array([0, 2, 4]), np.array([1, 3, 5])
    branch = position[pair_j] - position[pair_i]
    distance = np.linalg.norm(branch, axis=1)
    return (position, np.full(6, RADIUS), pair_i, pair_j, np.zeros((3, 3), np.int8),
            period_layout(np.zeros(3)), 2 * RADIUS - distance, branch / distance[:, None])


def no_bridges():
    return BridgeState(np.zeros(3, np.int8), *(np.zeros(3) for _ in range(5)))


def scaled(table_row):
    """(F [N], V [m^3], delta1, delta2 [deg]) of a suction table's row (exists, F*, V*, delta1,
    delta2) between spheres of radius RADIUS, in the kernels' order of operations."""
    _, force_star, volume_star, delta1, delta2 = table_row
    return (force_star * 2.0 * math.pi * GAMMA * RADIUS, volume_star * RADIUS * RADIUS * RADIUS,
            delta1, delta2)


def test_parallel_kernels_write_the_tables_bridges(tables):
    """Each parallel kernel (and the serial twin of contact_bridges) writes the bridge arrays
    and pair forces it computes: F = F* 2 pi gamma R, V = V* R^3 from the table's lookup."""
    suction_table, volume_table = tables
    suction, gap_star = 2000.0, 0.02
    u_star = suction * RADIUS / GAMMA
    pairs = three_pairs(gap_star)
    lookup = suction_table.arrays()
    contact = scaled(suction_table.lookup(1.0, u_star, 0.0))
    for kernel in (bridge_kernels.contact_bridges, bridge_kernels.serial_contact_bridges):
        state = no_bridges()
        kernel(pairs, state, suction, GAMMA, lookup)
        assert state.state.tolist() == [AT_CONTACT, NO_BRIDGE, NO_BRIDGE], kernel
        assert (state.force[0], state.volume[0], state.filling_i[0],
                state.filling_j[0]) == contact
    interfaces = bridge_kernels.suction_interfaces(pairs, state, np.array([0]), suction, GAMMA,
                                                   lookup)
    _, nn11, nn33 = suction_table.lookup_interface(1.0, u_star, 0.0)
    np.testing.assert_array_equal(interfaces, [[nn11 * RADIUS * RADIUS, nn33 * RADIUS * RADIUS]])
    later = scaled(suction_table.lookup(1.0, 3 * u_star, 0.0))
    bridge_kernels.refresh_contact_bridges(pairs, state, 3 * suction, GAMMA, lookup)
    assert (state.force[0], state.volume[0]) == later[:2]

    state, pair_force = no_bridges(), np.full((3, 3), 7.0)
    state.state[1] = ACROSS_GAP                      # a bridge that formed before
    bridge_kernels.suction_bridges(pairs, state, pair_force, suction, GAMMA, lookup)
    across = scaled(suction_table.lookup(1.0, u_star, -pairs[6][1] / RADIUS))   # d* = gap / R
    assert state.state.tolist() == [AT_CONTACT, ACROSS_GAP, NO_BRIDGE]
    assert state.force.tolist() == [contact[0], across[0], 0.0]
    assert state.volume[1] == across[1]
    np.testing.assert_array_equal(pair_force[:, 0], [-contact[0], -across[0], 0.0])
    assert not pair_force[:, 1:].any()

    state, pair_force = no_bridges(), np.zeros((3, 3))
    liquid = bridge_kernels.LiquidExchange(np.zeros(6), np.zeros(3), np.zeros(3, np.int8))
    marked = bridge_kernels.volume_bridges(pairs, state, pair_force, suction, GAMMA, 0.0,
                                           lookup, volume_table.arrays(), liquid, False)
    cube = RADIUS * RADIUS * RADIUS
    held = suction_table.lookup(1.0, u_star, 0.0)[2] * cube          # formed at contact
    row = volume_table.lookup(1.0, held / cube, 0.0)
    assert marked == 0 and state.state.tolist() == [AT_CONTACT, NO_BRIDGE, NO_BRIDGE]
    assert (state.volume[0], state.force[0]) == (held, scaled(row)[0])
    assert state.suction[0] == row[2] * GAMMA / RADIUS
    assert pair_force[0, 0] == -state.force[0]
    interfaces = bridge_kernels.volume_interfaces(pairs, state, np.array([0]), 0.0,
                                                  volume_table.arrays())
    _, nn11, nn33 = lookup_volume_interface(*volume_table.arrays(), 1.0, held / cube, 0.0)
    np.testing.assert_array_equal(interfaces, [[nn11 * RADIUS * RADIUS, nn33 * RADIUS * RADIUS]])
