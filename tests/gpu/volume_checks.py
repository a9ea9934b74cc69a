"""Volume-controlled bridges (VolumeBridges) on the GPU against the CPU, the checks of
tests/gpu/test_gpu_volume.py run under Numba's CUDA simulator in a process of their own
(``NUMBA_ENABLE_CUDASIM=1 python volume_checks.py shared lost`` prints one JSON object of
measurements, simulator.run_checks): the scene of persist_checks.py (27 spheres in six walls
pulled apart along z under a stress servo on x and y) with bridges of constant volume formed
at contact at 30 kPa from a reservoir, then a closed amount of liquid (close_liquid between two
runs of the same GpuSimulation, the state back on the host between them, with a film put on
every other grain there): "shared" (a ruptured bridge's liquid goes to its grains' other
bridges or stays on a grain as film) and "lost"; new contacts form bridges from the films.
"""

import numpy as np

from persist_checks import scene as persist_scene, snapshot as persist_snapshot
from simulator import relative, run_checks

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
    """persist_checks.py's snapshot (particles, walls, each bridge per pair (i, j)) and the
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


if __name__ == "__main__":
    run_checks({"shared": lambda: agreement("shared"), "lost": lambda: agreement("lost")})
