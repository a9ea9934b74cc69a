"""Grips (pendular.dem.grips.Grip) on the GPU against the CPU, under Numba's CUDA simulator in a
process of its own (this file run as a script, as tests/gpu/simulated.py is): the 64-sphere
scene of simulated.py, wet (bridges at contact at 30 kPa, so that the sample holds in
tension), its lateral walls held, its z walls pulled apart at a constant strain rate (5 %
over the run: the grips push, then the sample comes apart from them), two
layers of spheres gripped by the bottom wall and one by the top (members in chunks of
pendular.gpu.grips.GRIP_CHUNK: two chunks and one), as a direct tension's pull in miniature.
A recorder reads the grips' pulls and the walls every RECORD_PERIOD steps: the walls alone
come back (a pull is a force on its wall's body), the particles stay on the device.

Measured (simulator, 64 spheres, 300 steps, 11 rebuilds, 93 contacts at the end): largest
relative differences from the CPU: positions 1.2e-14, velocities 7.0e-13, forces 2.3e-12,
wall forces 3.2e-14, the pulls (16 records) 2.9e-14; the gripped spheres' velocities are
equal (the walls' own). The CPU adds a grip's forces pairwise (np.sum), the device in chunks:
the pulls are the same terms in another order, on forces that differ by round-off (the
simulator does not contract multiply-adds).
"""

import json
import os

import pytest

from simulator import simulated

try:
    import numba_cuda  # noqa: F401
except ImportError:
    pytest.skip("numba-cuda is not installed (pip install -e '.[gpu]')", allow_module_level=True)

STEPS = 300
RECORD_PERIOD = 20
#: Extension of the pull over the run [-].
EXTENSION = 0.05


@pytest.fixture(scope="module")
def grips():
    return simulated(os.path.basename(__file__))


def test_grips_on_the_gpu_agree_with_the_cpu_to_round_off(grips):
    agreement = grips["agreement"]
    assert agreement["touching_cpu"] == agreement["touching_gpu"] == agreement["touching_both"]
    assert agreement["position"] < 1e-13 and agreement["wall_position"] < 1e-13
    assert agreement["wall_force"] < 1e-12
    for name in ("velocity", "angular_velocity", "force", "torque", "springs"):
        assert agreement[name] < 1e-10, name
    assert grips["gripped_velocity"] == 0.0       # the walls' velocities, on both devices


def test_the_pulls_are_the_cpus_at_every_record(grips):
    history = grips["history"]
    assert history["records"] == [STEPS // RECORD_PERIOD + 1] * 2
    assert history["pull"] < 1e-12 and history["wall_force"] < 1e-12
    # the grips first push (compression), then the sample comes apart from them
    smallest, largest = grips["pull_magnitude"]
    assert grips["pull_range"][0] < -1.0 and smallest < 1e-6 * largest
    assert grips["members"] == [32, 16] and grips["chunks"] == [2, 1]


def test_a_record_of_the_pulls_brings_back_the_walls_alone(grips):
    """The recorder reads the walls and the pulls every RECORD_PERIOD steps: walls only, and
    everything once at the end of the run (Simulation.run)."""
    assert grips["copies"] == ["walls"] * (STEPS // RECORD_PERIOD) + ["all"]


def test_what_the_device_cannot_hold_is_refused_by_name(grips):
    before, shared = grips["refusals"]
    assert "after every wall control" in before and "ConstantStrainRate" in before
    assert "in two grips" in shared


# ---------------------------------------------------------------- the script, in the simulator

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


def main():
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
    print(json.dumps({
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
        "refusals": refusals()}))


if __name__ == "__main__":
    main()
