"""The pieces the exact bridges and their tables share: one Bridge record from the kernel, one
file layout and build checks for both kinds of table."""

import dataclasses
import math

import h5py
import numpy as np
import pytest

from pendular import capillary
from pendular.capillary.meniscus import bridge_from_kernel, bridge_kernel
from pendular.capillary.table import BridgeTable, check_node_count, check_radius_ratios
from pendular.capillary.volume_table import VolumeBridgeTable


def test_a_bridge_record_keeps_the_filling_angle_it_was_asked_for():
    filling_angle = 3.0  # math.degrees(math.radians(3.0)) != 3.0
    assert math.degrees(math.radians(filling_angle)) != filling_angle
    bridge = capillary.solve_bridge(1.5, 20.0, 40.0, filling_angle)
    assert bridge.delta1 == filling_angle
    kernel = bridge_kernel(1.5, math.radians(20.0), 40.0, math.radians(filling_angle))
    assert (bridge.distance, bridge.volume, bridge.force, bridge.nn11, bridge.nn33) == (
        kernel[0], kernel[1], kernel[2], kernel[4], kernel[5])
    assert bridge.delta2 == math.degrees(kernel[3])
    assert bridge_from_kernel(1.5, 20.0, 40.0, math.radians(filling_angle)).delta1 == math.degrees(
        math.radians(filling_angle))


def test_suction_and_volume_controlled_bridges_are_kernel_records_at_their_state():
    held = capillary.bridge_at_distance(2.0, 10, 50.0, 0.01)
    kept = capillary.bridge_with_volume(2.0, 10, 1e-3, 0.01)
    assert kept.volume == pytest.approx(1e-3, rel=1e-10)
    for bridge in (held, kept):
        assert bridge.contact_angle == 10.0 and isinstance(bridge.contact_angle, float)
        assert bridge.distance == pytest.approx(0.01, abs=1e-12)
        again = bridge_from_kernel(2.0, 10.0, bridge.suction, math.radians(bridge.delta1))
        assert dataclasses.astuple(again) == pytest.approx(dataclasses.astuple(bridge), rel=1e-9, abs=1e-12)


def _volume_table():
    values = np.arange(1.0, 1.0 + 2 * 3 * 4 * 6).reshape(2, 3, 4, 6)
    values[..., 1] *= -1.0  # the suction column may be negative
    axes = np.log([[1e-4, 1e-2], [2e-4, 2e-2]])
    return VolumeBridgeTable(15.0, [1.0, 2.0], axes, np.zeros((2, 3)), np.full((2, 3), 0.3), values)


def _suction_table():
    values = np.arange(1.0, 1.0 + 1 * 5 * 3 * 6).reshape(1, 5, 3, 6)
    return BridgeTable(5.0, [1.0], 0.1, 200.0, np.zeros((1, 5)), np.linspace(0.1, 0.5, 5)[None, :], values)


@pytest.mark.parametrize("make, other, attributes", [
    (_suction_table, VolumeBridgeTable,
     ["kind", "format", "contact_angle_deg", "suction_scale", "suction_max", "fields"]),
    (_volume_table, BridgeTable, ["kind", "format", "contact_angle_deg", "fields"]),
])
def test_both_tables_round_trip_through_one_file_layout(tmp_path, make, other, attributes):
    table = make()
    path = tmp_path / "table.h5"
    table.save(path)
    with h5py.File(path, "r") as handle:
        assert sorted(handle.attrs) == sorted(attributes)
        assert handle.attrs["fields"] == ",".join(table.fields)
        assert list(handle) == sorted(table.file_arrays)
    loaded = type(table).load(path)
    for name in ("contact_angle", *table.file_scalars, *table.file_arrays):
        assert np.array_equal(getattr(loaded, name), getattr(table, name)), name
    for mine, theirs in zip(table.arrays(), loaded.arrays()):
        assert np.array_equal(mine, theirs)
    with pytest.raises(ValueError, match=f"is not a {other.description} of format 1"):
        other.load(path)


def test_the_volume_table_cache_expects_its_volume_axes():
    parameters = {"radius_ratios": [1.0, 2.0], "n_volume": 3, "n_distance": 4}
    assert VolumeBridgeTable.array_shapes(parameters) == {
        "values": (2, 3, 4, 6), "distance_low": (2, 3), "distance_rupture": (2, 3), "volume_axes": (2, 2)}
    parameters = {"radius_ratios": [1.0], "n_suction": 5, "n_distance": 3}
    assert BridgeTable.array_shapes(parameters) == {
        "values": (1, 5, 3, 6), "distance_low": (1, 5), "distance_rupture": (1, 5)}


def test_table_builds_check_radius_ratios_and_node_counts():
    assert check_radius_ratios((1, 2.5)).tolist() == [1.0, 2.5]
    with pytest.raises(ValueError, match=r"radius_ratios = \[2.0, 1.0\] must be non-empty and strictly increasing"):
        check_radius_ratios((2.0, 1.0))
    with pytest.raises(ValueError, match="radius_ratio = 0.5 is outside the valid range"):
        check_radius_ratios((0.5,))
    assert check_node_count("n_volume", 3.0) == 3 and isinstance(check_node_count("n_volume", 3.0), int)
    for bad in (1, 2.5):
        with pytest.raises(ValueError, match=f"n_volume = {bad} is outside the valid range: an integer >= 2"):
            check_node_count("n_volume", bad)
    with pytest.raises(ValueError, match="radius_ratios = \\[\\] must be non-empty"):
        VolumeBridgeTable.build(0.0, radius_ratios=())
