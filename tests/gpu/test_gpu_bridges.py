"""Suction-controlled bridges at contact on the GPU path against the CPU path under Numba's
CUDA simulator (tests/gpu/simulated.py in a process of its own): the 27-sphere scene of
test_gpu_dem.py wet at 30 kPa over 200 steps, and the device's table lookup against the CPU's.

The device's lookup is the CPU's lookup_suction compiled for the device
(pendular.gpu.cuda.device_twin). Measured: it equals the CPU's exactly at 64 random
(r, u*, d*) points; the bridges' states, volumes, forces and filling angles equal the CPU's;
largest relative differences 2.4e-15 in positions, 1.3e-12 in forces.
"""

import pytest

from simulator import simulated


@pytest.fixture(scope="module")
def wet():
    return simulated("simulated.py", "wet")


def test_the_device_reads_the_table_as_the_cpu(wet):
    assert wet["lookups_existing"] > 16
    assert wet["lookup"] < 1e-14


def test_bridges_form_and_pull_as_on_the_cpu(wet):
    count_cpu, count_gpu = wet["bridges"]
    assert count_cpu == count_gpu == wet["agreement"]["touching_both"] > 20
    for name, difference in wet["bridge_fields"].items():
        assert difference < 1e-12, name
    agreement = wet["agreement"]
    assert agreement["position"] < 1e-13 and agreement["wall_stress"] < 1e-12
    for name in ("velocity", "angular_velocity", "force", "torque", "springs"):
        assert agreement[name] < 1e-10, name
    assert wet["history"]["records"] == [4, 4] and wet["history"]["stress"] < 1e-12
