"""Liquid clusters (pendular.capillary.liquid_clusters) on the GPU against the CPU, the checks of
tests/gpu/test_gpu_clusters.py run under Numba's CUDA simulator in a process of their own
(``NUMBA_ENABLE_CUDASIM=1 python clusters_checks.py clusters refusal`` prints one JSON object of
measurements, simulator.run_checks):

- "clusters": the 27-sphere scene of simulated.py with suction-controlled bridges across gaps
  and LiquidClusters drying from saturation at SUCTION, run STEPS steps with the host's model
  stepped between two steps by a writer (pendular.procedures.loading_clusters.ClusterUpdates:
  the forces following the grains every FOLLOW steps, the model at the packing as it stands
  every UPDATES of them, which drains most units as the packing settles), then dried to DRIER
  between two runs (fewer filled units), run STEPS more: the grains' forces after each run,
  the positions and the clusters' forces against the CPU's, the filled units of each, and
  the largest of the clusters' own forces and of the bridges' forces they absorb (the
  comparison's sensitivity to them);
- "wetter": the same scene, its model stepped by a writer at a lower suction WETTER halfway
  through a run of STEPS steps (the bridges' reach grows: the device's state uploaded again
  from the host), against the CPU's;
- "refusal": clusters listed before their bridges, and in a periodic cell.
"""

from simulator import relative, run_checks

#: The suction [Pa] of the first run (27 spheres of 1 mm, water: some units drained) and of
#: the second (drier: fewer filled units).
SUCTION = 350.0
DRIER = 360.0
WETTER = 300.0
STEPS = 40
FOLLOW = 10
UPDATES = 2


def scene():
    """simulated.py's scene with bridges across gaps and liquid clusters drying from
    saturation at SUCTION (the model's first step taken)."""
    from pendular.capillary.bridges import CapillaryBridges
    from pendular.capillary.liquid_clusters import LiquidClusters
    from pendular.procedures.loading_clusters import ClusterUpdates
    from simulated import scene as plain

    sim = plain()
    bridges = CapillaryBridges(SUCTION, persist=True)
    clusters = LiquidClusters(bridges, saturated=True)
    sim.forces += [bridges, clusters]
    sim.evaluate_forces()
    clusters.set_suction(sim, SUCTION)
    sim.writers.append(ClusterUpdates(clusters, FOLLOW, UPDATES, sim.step))
    return sim, bridges, clusters


def snapshot(sim, clusters):
    """The positions, the grains' forces of the last step and the clusters' own forces."""
    sim.fetch()                         # a device run's state, all of it
    return {"position": sim.particles.position.copy(), "force": sim.particles.force.copy(),
            "cluster_force": clusters.cluster_force.copy()}


def absorbed(sim, clusters):
    """The largest of the bridges' forces [N] that the filled units absorb now."""
    import numpy as np

    share = clusters.pair_share(sim.contacts)
    return float(np.max(np.abs(share[:, None] * clusters.bridges.pair_force), initial=0.0))


def compare(cpu, gpu):
    return {name: relative(cpu[name], gpu[name]) for name in cpu}


def clusters():
    """The module docstring's "clusters"."""
    import numpy as np

    from pendular.gpu import GpuSimulation

    runs = {}
    for device in ("cpu", "gpu"):
        sim, bridges, held = scene()
        filled = [int(np.count_nonzero(held.filled))]
        runner = sim if device == "cpu" else GpuSimulation(sim)
        runner.run(STEPS)
        first = snapshot(sim, held)
        largest = [absorbed(sim, held)]
        filled.append(int(np.count_nonzero(held.filled)))
        bridges.set_suction(DRIER)
        held.set_suction(sim, DRIER)
        filled.append(int(np.count_nonzero(held.filled)))
        runner = sim if device == "cpu" else GpuSimulation(sim)
        runner.run(STEPS)
        largest.append(absorbed(sim, held))
        filled.append(int(np.count_nonzero(held.filled)))
        runs[device] = (first, snapshot(sim, held), filled, held.version,
                        sim.writers[-1].updates, largest)
    (cpu_first, cpu_second, filled, version, updates, largest), gpu = runs["cpu"], runs["gpu"]
    scale = [float(np.max(np.abs(run["force"]))) for run in (cpu_first, cpu_second)]
    return {"first": compare(cpu_first, gpu[0]), "second": compare(cpu_second, gpu[1]),
            "filled": [filled, gpu[2]], "versions": [version, gpu[3]],
            "updates": [updates, gpu[4]],
            "clusters_force": [float(np.max(np.abs(run["cluster_force"]))) / size
                               for run, size in zip((cpu_first, cpu_second), scale)],
            "absorbed_force": [value / size for value, size in zip(largest, scale)]}


class Wetting:
    """Writer: at step ``at`` the bridges and the clusters of ``sim`` at WETTER (the state
    fetched first, as the model's steps do)."""

    def __init__(self, bridges, clusters, at):
        self.bridges, self.clusters, self.at = bridges, clusters, at

    def apply(self, sim):
        if sim.step == self.at:
            self.bridges.set_suction(WETTER)
            self.clusters.set_suction(sim, WETTER)


def wetter():
    """The module docstring's "wetter"."""
    import numpy as np

    from pendular.gpu import GpuSimulation

    runs = {}
    for device in ("cpu", "gpu"):
        sim, bridges, held = scene()
        reach = bridges.required_range
        sim.writers.append(Wetting(bridges, held, sim.step + STEPS // 2))
        runner = sim if device == "cpu" else GpuSimulation(sim)
        uploaded = None if device == "cpu" else runner.state
        runner.run(STEPS)
        runs[device] = snapshot(sim, held)
        if device == "gpu":
            replaced = runner.state is not uploaded
        filled = int(np.count_nonzero(held.filled))
    return {"agreement": compare(runs["cpu"], runs["gpu"]), "replaced": replaced,
            "reach": [reach, bridges.required_range], "filled": filled}


def refusal():
    """The messages of the scenes the device refuses: clusters before their bridges, and in
    a periodic cell."""
    from pendular.capillary.bridges import CapillaryBridges
    from pendular.capillary.liquid_clusters import LiquidClusters
    from pendular.gpu import GpuSimulation
    from periodic_checks import scene as cell
    from simulated import scene as plain

    messages = []
    for sim in (plain(), cell()):
        bridges = CapillaryBridges(SUCTION, persist=True)
        clusters = LiquidClusters(bridges, saturated=True)
        sim.forces += [clusters, bridges] if not sim.walls.periodic else [bridges, clusters]
        try:
            GpuSimulation(sim)
        except ValueError as error:
            messages.append(str(error))
    return messages


if __name__ == "__main__":
    run_checks({"clusters": clusters, "wetter": wetter, "refusal": refusal})
