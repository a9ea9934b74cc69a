"""Volume-controlled bridges (VolumeBridges) on the GPU against the CPU under Numba's CUDA
simulator: the scene of test_gpu_persist.py (27 spheres in six walls pulled apart along z under
a stress servo on x and y) with bridges of constant volume formed at contact at 30 kPa from a
reservoir, then a closed amount of liquid (close_liquid between two runs of the same
GpuSimulation, the state back on the host between them, with a film put on every other grain
there): "shared" (a ruptured bridge's liquid goes to its grains' other bridges or stays on a
grain as film) and "lost"; new contacts form bridges from the films. The simulator runs in a process of its own (this file as a script:
``NUMBA_ENABLE_CUDASIM=1 python test_gpu_volume.py LIQUID`` prints one JSON object of
measurements), so that no other test meets it.

Measured (simulator, 27 spheres, 100 steps open, 200 closed; 4 then 10 bridges across gaps,
bridges ruptured and 2 formed from films): the same pairs hold bridges in the same states as
on the CPU, the bridges' volumes, the films and the liquid lost equal the CPU's exactly (the
same sums in the same order), and the largest relative differences are 1.7e-14 in positions,
1.7e-12 in velocities, 5.8e-14 in wall stresses, 6.5e-12 in bridge forces, 5.9e-12 in their
suctions; bridges + films + lost equal the liquid closed to 2e-16 on both. The tests hold 1e-12
(positions) and 1e-10 (the rest).

The command (``pendular triaxial --sample S --particles 60 --water-content 5 --max-strain
0.002 --inertial-number 1e-3 --device gpu``, 162 steps of shear) records the CPU's rows,
bridge and contact counts; the other columns differ by up to 4.1e-5 of their largest value
(volumetric strain; the unbalanced force 3.7e-3). That is the sensitivity of the wetting to a
water content, not an error of the device: on the CPU alone one coordinate of the sample moved
by one ulp changes them by 5.0e-5 and 4.2e-3. The test holds 2e-4 and 2e-2.
"""

import json
import os
import sys

import numpy as np
import pytest

from simulator import assert_same_records, histories_on_both, relative, simulated
from test_gpu_persist import scene as persist_scene, snapshot as persist_snapshot

#: Steps with the reservoir, then with the closed liquid.
OPEN_STEPS = 100
CLOSED_STEPS = 200
#: Film [m^3] put on every other grain before the liquid is closed (about a bridge's volume),
#: so that new contacts form bridges from films.
FILM = 3e-14


def scene():
    """The module docstring's scene on the CPU, and its bridges."""
    from pendular.capillary.bridges import CapillaryBridges

    sim, _ = persist_scene()
    bridges = CapillaryBridges(30000.0, control="volume")
    sim.forces[-1] = bridges
    return sim, bridges


def snapshot(sim, bridges):
    """test_gpu_persist.py's snapshot (particles, walls, each bridge per pair (i, j)) and the
    liquid's account."""
    sim.fetch()                         # a device run's state, all of it
    in_bridges, film, lost, error = bridges.liquid_balance(sim)
    return {**persist_snapshot(sim, bridges), "film": bridges.film.copy(),
            "liquid": [in_bridges, film, lost], "balance_error": error}


def compare(cpu, gpu):
    """Largest relative difference of each array of two snapshots; whether the bridges are
    the same pairs in the same states."""
    same = cpu["pairs"] == gpu["pairs"] and cpu["state"] == gpu["state"]
    out = {"same_bridges": same, "bridges": len(cpu["pairs"]),
           "across_gaps": int(sum(s == 2 for s in cpu["state"])),
           "liquid": cpu["liquid"], "balance_error": [cpu["balance_error"],
                                                      gpu["balance_error"]]}
    for name in ("position", "velocity", "stress", "film"):
        out[name] = relative(cpu[name], gpu[name])
    out["lost"] = relative(cpu["liquid"][2], gpu["liquid"][2])
    for name in ("volume", "bridge_force", "suction", "pair_force"):
        out[name] = relative(cpu[name], gpu[name]) if same else None
    return out


def agreement(liquid):
    """The open then closed (``liquid``) runs on the CPU and on the GPU, compared after each."""
    from pendular.gpu import GpuSimulation

    cpu, cpu_bridges = scene()
    gpu_sim, gpu_bridges = scene()
    gpu = GpuSimulation(gpu_sim)
    cpu.run(OPEN_STEPS)
    gpu.run(OPEN_STEPS)
    out = {"open": compare(snapshot(cpu, cpu_bridges), snapshot(gpu_sim, gpu_bridges))}
    for sim, bridges in ((cpu, cpu_bridges), (gpu_sim, gpu_bridges)):
        bridges.film[::2] = FILM
        bridges.close_liquid(sim, liquid)
    formed = 0                      # bridges formed from films on the CPU
    for _ in range(CLOSED_STEPS):
        film = float(np.sum(cpu_bridges.film))
        cpu.run(1)
        formed += float(np.sum(cpu_bridges.film)) < film
    out["formed_from_films"] = formed
    gpu.run(CLOSED_STEPS)
    out["closed"] = compare(snapshot(cpu, cpu_bridges), snapshot(gpu_sim, gpu_bridges))
    return out


# ---------------------------------------------------------------- the tests (pytest)
def measured(liquid):
    pytest.importorskip("numba_cuda")
    return simulated(os.path.basename(__file__), liquid)


def assert_agrees(stage):
    assert stage["same_bridges"], stage
    assert stage["bridges"] > 20
    assert stage["position"] < 1e-12
    for name in ("velocity", "stress", "volume", "bridge_force", "suction", "pair_force",
                 "film", "lost"):
        assert stage[name] < 1e-10, name


@pytest.mark.parametrize("liquid", ["shared", "lost"])
def test_volume_controlled_bridges_agree_with_the_cpu(liquid):
    result = measured(liquid)
    assert_agrees(result["open"])
    closed = result["closed"]
    assert_agrees(closed)
    assert closed["across_gaps"] > 0 and result["formed_from_films"] > 0
    if liquid == "shared":
        assert closed["liquid"][2] == 0.0
    else:
        assert closed["liquid"][2] > 0.0              # bridges ruptured and lost their liquid
    assert max(closed["balance_error"]) < 1e-12      # bridges + films + lost: the liquid closed


#: The wet triaxial of test_gpu_command.py at a water content (its sample added).
TRIAXIAL = ["--particles", "60", "--water-content", "5", "--max-strain", "0.002",
            "--inertial-number", "1e-3", "--quiet"]


def test_the_triaxial_command_at_a_water_content_records_the_cpu_history(tmp_path):
    """``pendular triaxial --sample S --water-content 5 --device gpu`` (S prepared on the CPU)
    records the CPU's rows, bridge and contact counts, and columns within the sensitivity of
    that wetting (module docstring)."""
    pytest.importorskip("numba_cuda")
    cpu, gpu = histories_on_both("triaxial", ["--particles", 60, "--max-strain", 1e-4,
                                              "--quiet"], TRIAXIAL, tmp_path)
    assert_same_records(cpu, gpu, 100, ("bridges", "coordination"))
    for name, values in cpu.items():
        if values.dtype == object:
            continue
        bound = 2e-2 if name == "unbalanced_force" else 2e-4
        assert np.max(np.abs(gpu[name] - values)) <= bound * np.max(np.abs(values)), name


if __name__ == "__main__":
    print(json.dumps(agreement(sys.argv[1])))
