"""``pendular tension --device gpu`` (pendular.procedures.tension on the GPU path): the
wetting to a water content (volume-controlled bridges at contacts and across gaps, the
formation suction found on the host) and the pull (two grips, the z walls apart at the strain
rate of the inertial number, the history the test records) run on the device and record the
CPU's results (in a periodic cell: tests/gpu/test_gpu_persist_cell.py).

Checked under Numba's CUDA simulator in a process of its own (tests/gpu/tension_checks.py),
from tests/gpu/simulated.py's 27 spheres (dry, slightly
overlapping, servoed at 10 kPa) standing for a prepared sample (a whole preparation is out of
the simulator's reach): ``wet`` at w = 1 % (WET_STEPS steps of settling), then ``Pull`` (one
grip layer at each z wall, PULL_STRAIN of extension, a record every step).

The wetting's formation suction, water content and saturation equal the CPU's, the pull's
rows and counts too, its columns within round-off (docs/gpu.md). Each record brings back the
walls with the pulls alone: the contacts' and the bridges' columns read the device's
homogenisation (GpuSimulation.homogenized), bridges across gaps included; the whole state
comes back once, as the run returns.
"""

import pytest

from conftest import requires
from simulator import simulated

#: Largest difference of a history column from the CPU's over its largest magnitude [-].
TOLERANCE = 1e-11
#: The same for the unbalanced force, a ratio of a residual to the mean force [-].
UNBALANCED_TOLERANCE = 1e-10


@pytest.fixture(scope="module")
def tension():
    return simulated("tension_checks.py", "pull")["pull"]


@requires("numba_cuda")
def test_the_wetting_on_the_gpu_holds_the_cpus_water(tension):
    cpu, gpu = tension["wetting"]["cpu"], tension["wetting"]["gpu"]
    assert cpu["tries"] == gpu["tries"] == 1
    assert cpu["bridges"] == gpu["bridges"] > 27        # across gaps too
    for name in ("formation_suction_pa", "water_content", "saturation"):
        assert gpu[name] == pytest.approx(cpu[name], rel=1e-12, abs=0.0), name
    assert tension["wetting"]["position"] < 1e-13


@requires("numba_cuda")
def test_the_pull_on_the_gpu_records_the_cpu_history(tension):
    pull = tension["pull"]
    assert pull["rows"][0] == pull["rows"][1] == pull["steps"] + 1
    assert pull["equal"] == ["step", "bridges", "coordination"]
    for name, difference in pull["differences"].items():
        bound = UNBALANCED_TOLERANCE if name == "unbalanced_force" else TOLERANCE
        assert difference <= bound, (name, difference)
    assert pull["members"] == [9, 9]


@requires("numba_cuda")
def test_a_record_of_the_pull_brings_back_the_walls_with_the_pulls(tension):
    """Each record reads the walls alone (the pulls come with them; module docstring), and
    the run's end the whole state once."""
    copies, steps = tension["pull"]["copies"], tension["pull"]["steps"]
    assert copies.count("walls") == steps and copies.count("all") == 1
    assert copies[0] == "walls" and copies[-1] == "all"
