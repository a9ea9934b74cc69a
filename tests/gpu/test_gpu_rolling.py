"""Rolling and twisting resistance (pendular.dem.rolling) and gravity (pendular.dem.gravity) on
the GPU against the CPU, under Numba's CUDA simulator in a process of its own (this file run as
a script, as tests/gpu/simulated.py is): the 27-sphere scene of simulated.py (a triaxial's
shear in miniature, several rebuilds) with RollingResistance(0.3, 0.2, damping_ratio=0.3)
and Gravity(9.81) after the walls, as a loaded sample lists them; the rolling resistance in
the periodic cell of test_gpu_periodic.py too.

Measured (simulator, 27 spheres, 200 steps, 6 rebuilds, 49 touching pairs): largest relative
differences from the CPU 1.3e-15 in positions, 1.0e-12 in angular velocities, 1.5e-12 in
torques, 1.5e-13 in the rolling springs, 1.6e-13 in the twisting springs, 1.8e-13 in the
pairs' moments (the simulator does not contract multiply-adds as the CPU's hot kernels do).
In the cell (64 spheres, 100 steps, 185 touching pairs): 5.8e-16 in unwrapped positions,
2.6e-13 in angular velocities, 7.3e-14 and 1.2e-13 in the rolling and twisting springs.
"""

import json
import os

import pytest

from simulator import simulated

try:
    import numba_cuda  # noqa: F401
except ImportError:
    pytest.skip("numba-cuda is not installed (pip install -e '.[gpu]')", allow_module_level=True)

STEPS = 200
PERIODIC_STEPS = 100
ROLLING = 0.3
TWISTING = 0.2


@pytest.fixture(scope="module")
def resisting():
    return simulated(os.path.basename(__file__))


def test_rolling_resistance_and_gravity_on_the_gpu_agree_with_the_cpu_to_round_off(resisting):
    agreement = resisting["agreement"]
    assert agreement["touching_cpu"] == agreement["touching_gpu"] == agreement["touching_both"]
    assert agreement["touching_both"] > 20
    assert resisting["rebuilds"] == resisting["rebuilds_cpu"] >= 3
    assert agreement["position"] < 1e-13 and agreement["wall_position"] < 1e-13
    for name in ("velocity", "angular_velocity", "force", "torque", "springs",
                 "rolling_moment", "twisting_moment", "moment"):
        assert agreement[name] < 1e-10, name


def test_the_moments_and_the_weight_matter(resisting):
    """What the comparison would miss if the device left them out: springs on their limits
    and off them, and a trajectory that neither force leaves unchanged by far more than
    round-off."""
    on_limit, below = resisting["rolling_on_limit"]
    assert on_limit > 0 and below > 0
    assert resisting["without"]["moments"]["angular_velocity"] > 1e-3
    assert resisting["without"]["weight"]["position"] > 1e-6


def test_the_springs_are_carried_across_the_devices_rebuilds(resisting):
    """A run forced to rebuild its list every 10 steps equals the plain run bit for bit."""
    assert resisting["rebuilds_forced"] >= 2 * resisting["rebuilds"]
    assert resisting["forced_equals_plain"]


def test_the_springs_go_to_the_device_and_come_back(resisting):
    """Half the run on the CPU, the other half on the device from the host's springs: the
    CPU's whole run, to round-off."""
    handed = resisting["handed_over"]
    assert handed["touching_cpu"] == handed["touching_gpu"] == handed["touching_both"]
    assert handed["position"] < 1e-13
    for name in ("angular_velocity", "rolling_moment", "twisting_moment", "moment"):
        assert handed[name] < 1e-10, name


def test_the_rolling_resistance_in_a_periodic_cell_agrees_with_the_cpu(resisting):
    periodic = resisting["periodic"]
    assert periodic["touching_cpu"] == periodic["touching_gpu"] == periodic["touching_both"]
    assert periodic["position"] < 1e-13 and periodic["cell"] < 1e-13
    for name in ("angular_velocity", "torque", "rolling_moment", "twisting_moment", "moment"):
        assert periodic[name] < 1e-10, name


def test_a_rolling_resistance_before_the_contact_law_is_refused(resisting):
    assert "RollingResistance listed after the contact law only" in resisting["refusal"]


# ---------------------------------------------------------------- the script, in the simulator

def scene(moments=True, weight=True, periodic=False):
    """simulated.py's scene with the rolling resistance and the weight (module docstring), or
    test_gpu_periodic.py's cell with the rolling resistance (``periodic``: no weight)."""
    from pendular.dem.gravity import Gravity
    from pendular.dem.rolling import RollingResistance
    from simulated import scene as plain
    from test_gpu_periodic import scene as cell

    sim = cell() if periodic else plain()
    weight = weight and not periodic
    if weight:
        sim.forces.append(Gravity(9.81))
    if moments:
        sim.forces.append(RollingResistance(ROLLING, TWISTING, damping_ratio=0.3))
    return sim


def snapshot(sim):
    """simulated.py's snapshot (test_gpu_periodic.py's in a cell: positions unwrapped) with
    the torques and, keyed by pair (i, j) for the touching pairs, the tangential springs, the
    rolling and twisting springs and the pairs' moments."""
    sim.fetch()                         # a device run's state, all of it
    from pendular.dem.protocols import pair_key
    from pendular.dem.rolling import FIELDS, OWNER, RollingResistance
    from simulated import snapshot as walled
    from test_gpu_periodic import snapshot as periodic

    out = periodic(sim) if sim.walls.periodic else walled(sim)
    out["torque"] = sim.particles.torque.copy()
    c = sim.contacts
    pairs = [(int(i), int(j)) for i, j in zip(c.pair_i, c.pair_j)]
    touching = [k for k in range(len(c)) if c.overlap[k] > 0]
    per_pair = {"springs": c.shear_force, "moment": sim.operation(RollingResistance).moment}
    per_pair.update({field.name: c.extra[pair_key(OWNER, field)] for field in FIELDS[:2]})
    for name, values in per_pair.items():
        out[name] = {pairs[k]: values[k].copy() for k in touching}
    return out


PER_PAIR = ("springs", "rolling_moment", "twisting_moment", "moment")


def compare(cpu, gpu):
    """Largest relative difference of each quantity of two snapshots, the per-pair ones
    matched by pair identity; the touching pairs of each and of both."""
    from simulator import relative

    out = {name: relative(cpu[name], gpu[name]) for name in cpu if name not in PER_PAIR}
    for name in PER_PAIR:
        shared = sorted(set(cpu[name]) & set(gpu[name]))
        out[name] = relative([cpu[name][key] for key in shared],
                             [gpu[name][key] for key in shared])
    out["touching_cpu"] = len(cpu["springs"])
    out["touching_gpu"] = len(gpu["springs"])
    out["touching_both"] = len(set(cpu["springs"]) & set(gpu["springs"]))
    return out


def identical(a, b):
    """Whether two snapshots are equal bit for bit."""
    import numpy as np

    per_pair = all(a[name].keys() == b[name].keys()
                   and all(np.array_equal(a[name][key], b[name][key]) for key in a[name])
                   for name in PER_PAIR)
    return per_pair and all(np.array_equal(a[name], b[name]) for name in a
                            if name not in PER_PAIR)


def on_limit(sim):
    """(touching pairs whose rolling spring sits on its limit mu_r R* F_n, those below it)."""
    import numpy as np

    from pendular.dem.protocols import pair_key
    from pendular.dem.rolling import FIELDS, OWNER

    c = sim.contacts
    radius = sim.particles.radius
    touching = c.overlap > 0
    reduced = radius[c.pair_i] * radius[c.pair_j] / (radius[c.pair_i] + radius[c.pair_j])
    size = np.linalg.norm(c.extra[pair_key(OWNER, FIELDS[0])], axis=1)
    limited = np.isclose(size, ROLLING * reduced * c.normal_force, rtol=1e-12) & touching
    return [int(np.count_nonzero(limited)), int(np.count_nonzero(touching & ~limited))]


def main():
    import numpy as np

    from pendular.gpu import GpuSimulation
    from simulated import compare as plain_compare, snapshot as plain_snapshot

    cpu = scene()
    cpu.run(STEPS)
    gpu = GpuSimulation(scene())
    gpu.run(STEPS)
    gpu.to_host()
    forced = GpuSimulation(scene())
    for _ in range(STEPS // 10):
        forced.run(10)
        forced.state.flags[0:1].copy_to_device(np.ones(1, np.int32))
    forced.to_host()
    handed = scene()
    handed.run(STEPS // 2)
    handed_gpu = GpuSimulation(handed)
    handed_gpu.run(STEPS - STEPS // 2)
    handed_gpu.to_host()
    without = {}
    for name, options in (("moments", {"moments": False}), ("weight", {"weight": False})):
        other = scene(**options)
        other.run(STEPS)
        without[name] = plain_compare(plain_snapshot(cpu), plain_snapshot(other))
    cpu_cell = scene(periodic=True)
    cpu_cell.run(PERIODIC_STEPS)
    gpu_cell = GpuSimulation(scene(periodic=True))
    gpu_cell.run(PERIODIC_STEPS)
    gpu_cell.to_host()
    misplaced = scene()
    misplaced.forces.insert(0, misplaced.forces.pop())
    try:
        GpuSimulation(misplaced)
        refusal = None
    except ValueError as error:
        refusal = str(error)
    print(json.dumps({
        "steps": STEPS, "agreement": compare(snapshot(cpu), snapshot(gpu.sim)),
        "rebuilds": gpu.rebuilds, "rebuilds_cpu": cpu.neighbors.rebuilds,
        "rebuilds_forced": forced.rebuilds,
        "forced_equals_plain": identical(snapshot(gpu.sim), snapshot(forced.sim)),
        "handed_over": compare(snapshot(cpu), snapshot(handed_gpu.sim)),
        "rolling_on_limit": on_limit(cpu), "without": without,
        "periodic": compare(snapshot(cpu_cell), snapshot(gpu_cell.sim)), "refusal": refusal}))


if __name__ == "__main__":
    main()
