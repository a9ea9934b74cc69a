"""Grips (pendular.dem.grips.Grip) on the GPU against the CPU, the check of
tests/gpu/test_gpu_grips.py run under Numba's CUDA simulator in a process of its own
(``NUMBA_ENABLE_CUDASIM=1 python grips_checks.py pull`` prints one JSON object of measurements,
simulator.run_checks): the 64-sphere scene of simulated.py, wet (bridges at contact at 30 kPa,
so that the sample holds in tension), its lateral walls held, its z walls pulled apart at a
constant strain rate (EXTENSION over the run: the grips push, then the sample comes apart from
them), two layers of spheres gripped by the bottom wall and one by the top (members in chunks
of pendular.gpu.grips.GRIP_CHUNK: two chunks and one), as a direct tension's pull in
miniature. A recorder reads the grips' pulls and the walls every RECORD_PERIOD steps: the walls
alone come back (a pull is a force on its wall's body), the particles stay on the device.
"""

from simulator import run_checks

STEPS = 300
RECORD_PERIOD = 20
#: Extension of the pull over the run [-].
EXTENSION = 0.05


def scene(wet=True):
    """The pull (module docstring) of simulated.py's 64-sphere scene, with a recorder of the
    pulls and wall forces; the grips: the Grip controls, bottom then top."""
    import numpy as np

    from pendular.dem.grips import Grip
    from pendular.dem.record import HistoryRecorder
    from pendular.dem.walls import ConstantStrainRate
    from pendular.procedures.grips import grip_members
    from simulated import RADIUS, scene as base

    sim = base(wet=wet, side=4)
    length = sim.walls.lengths()[2]
    rate = EXTENSION / (STEPS * sim.dt)
    grips = [Grip(wall, grip_members(sim.particles.position, sim.particles.radius, sim.walls,
                                     wall, depth * RADIUS))
             for wall, depth in ((4, 3.2), (5, 1.2))]
    sim.controls = [ConstantStrainRate("z", -rate, length), *grips]

    def pulls(s):
        walls = s.walls            # fetched by the recorder: the pulls come with the walls
        return [walls.force[4], walls.force[5], *(grip.pull for grip in grips)]

    sim.writers = [HistoryRecorder(RECORD_PERIOD, {"pulls": pulls}, origin=sim.step,
                                   reads=("walls",))]
    sim.writers[0].record(sim)
    return sim, np.concatenate([grip.members for grip in grips])


def refusals():
    """The messages of a grip before the wall control and of a particle in two grips."""
    from pendular.dem.grips import Grip
    from pendular.gpu import GpuSimulation

    messages = []
    before, _ = scene(wet=False)
    before.controls = before.controls[1:] + before.controls[:1]
    shared, _ = scene(wet=False)
    shared.controls.append(Grip(4, shared.controls[1].members[:3]))
    for sim in (before, shared):
        try:
            GpuSimulation(sim)
        except ValueError as error:
            messages.append(str(error))
    return messages


def pull():
    """Every measurement the tests judge."""
    import numpy as np

    from pendular.gpu.grips import GRIP_CHUNK
    from simulated import compare, relative, snapshot
    from simulator import counted_copies

    (cpu, members), (gpu, _) = scene(), scene()
    cpu.run(STEPS)
    gpu.device = "gpu"
    with counted_copies() as copies:
        gpu.run(STEPS)
    cpu_pulls = cpu.writers[0].arrays()["pulls"]
    gpu_pulls = gpu.writers[0].arrays()["pulls"]
    grips = cpu.controls[1:]
    return {
        "agreement": compare(snapshot(cpu), snapshot(gpu)),
        "gripped_velocity": float(np.max(np.abs(cpu.particles.velocity[members]
                                                - gpu.particles.velocity[members]))),
        "history": {"records": [len(cpu_pulls), len(gpu_pulls)],
                    "wall_force": relative(cpu_pulls[:, :2], gpu_pulls[:, :2]),
                    "pull": relative(cpu_pulls[:, 2:], gpu_pulls[:, 2:])},
        "pull_range": [float(cpu_pulls[1:, 2:].min()), float(cpu_pulls[1:, 2:].max())],
        "pull_magnitude": [float(np.abs(cpu_pulls[1:, 2:]).min()),
                           float(np.abs(cpu_pulls[1:, 2:]).max())],
        "members": [len(grip.members) for grip in grips],
        "chunks": [-(-len(grip.members) // GRIP_CHUNK) for grip in grips],
        "copies": copies,
        "refusals": refusals()}


if __name__ == "__main__":
    run_checks({"pull": pull})
