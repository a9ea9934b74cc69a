"""``pendular tension --device gpu`` (pendular.procedures.tension on the GPU path): the
wetting to a water content (volume-controlled bridges at contacts and across gaps, the
formation suction found on the host) and the pull (two grips, the z walls apart at the strain
rate of the inertial number, the history the test records) run on the device and record the
CPU's results (in a periodic cell: tests/gpu/test_gpu_persist_cell.py).

Checked under Numba's CUDA simulator in a process of its own (this file run as a script, as
tests/gpu/simulated.py is), from tests/gpu/simulated.py's 27 spheres (dry, slightly
overlapping, servoed at 10 kPa) standing for a prepared sample (a whole preparation is out of
the simulator's reach): ``wet`` at w = 1 % (WET_STEPS steps of settling), then ``Pull`` (one
grip layer at each z wall, 1 % of extension, a record every step).

The wetting's formation suction, water content and saturation equal the CPU's, the pull's
rows and counts too, its columns within round-off (docs/gpu.md). Each record brings back the
walls with the pulls alone: the contacts' and the bridges' columns read the device's
homogenisation (GpuSimulation.homogenized), bridges across gaps included; the whole state
comes back once, as the run returns.
"""

import json
import os

import numpy as np
import pytest

from conftest import requires
from simulator import simulated

#: Largest difference of a history column from the CPU's over its largest magnitude [-].
TOLERANCE = 1e-11
#: The same for the unbalanced force, a ratio of a residual to the mean force [-].
UNBALANCED_TOLERANCE = 1e-10
#: Steps of the wetting's settling (the tension's WET_STEPS, a bound on its run).
WET_STEPS = 200


@pytest.fixture(scope="module")
def tension():
    return simulated(os.path.basename(__file__))


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


# ---------------------------------------------------------------- the script, in the simulator

def wetted_and_pulled(device, folder):
    """(wetting report, wetted positions, pull steps, history, Pull) of the tension's phases
    (module docstring) on ``device``; the copies back of the pull (counted_copies)."""
    from dataclasses import replace

    from pendular.dem.walls import StressServo
    from pendular.procedures import tension_pull
    from pendular.procedures.tension import TensionConfig, tension_sample
    from simulated import RADIUS, scene
    from simulator import counted_copies

    tension_pull.WET_STEPS = WET_STEPS
    dry = scene(side=3)
    dry.writers.clear()
    dry.controls = [StressServo("xyz", 1e4, 0.01)]
    dry.evaluate_forces()           # the contacts of the state the wetting starts from
    dry.device = device
    sample = replace(tension_sample(), radius=RADIUS, density=2650.0, confining=1e4)
    config = TensionConfig(sample=sample, cases=[(0.7, 0.01)], inertial_number=1e-2,
                           max_strain=0.01, grip_depth=0.1, vtk_frames=0)
    sim, bridges, report = tension_pull.wet(dry, config, 0.01, progress=False)
    position = sim.particles.position.copy()
    with counted_copies() as copies:
        pull = tension_pull.Pull(sim, bridges, config, folder, progress=False)
        steps, history = pull.run(None)
    return report, position, steps, history, pull, copies


def main():
    import tempfile

    from simulator import relative

    with tempfile.TemporaryDirectory() as folder:
        cpu_report, cpu_position, steps, cpu, _, _ = wetted_and_pulled("cpu", folder)
        gpu_report, gpu_position, _, gpu, pull, copies = wetted_and_pulled("gpu", folder)
    wetting = {"position": relative(cpu_position, gpu_position)}
    for name, report in (("cpu", cpu_report), ("gpu", gpu_report)):
        wetting[name] = {"tries": len(report["wetting_attempts"]),
                         **{key: report[key] for key in ("formation_suction_pa",
                                                         "water_content", "saturation",
                                                         "bridges")}}
    counts = ("step", "bridges", "coordination")
    print(json.dumps({"wetting": wetting, "pull": {
        "steps": steps, "rows": [len(cpu["step"]), len(gpu["step"])],
        "equal": [name for name in counts if np.array_equal(cpu[name], gpu[name])],
        "differences": {name: relative(cpu[name], gpu[name]) for name in cpu
                        if name not in counts},
        "copies": copies, "members": [len(grip.members) for grip in pull.grips]}},
        default=float))


if __name__ == "__main__":
    main()
