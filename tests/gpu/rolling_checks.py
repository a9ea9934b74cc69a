"""Rolling and twisting resistance (pendular.dem.rolling) and gravity (pendular.dem.gravity) on
the GPU against the CPU, the checks of tests/gpu/test_gpu_rolling.py run under Numba's CUDA
simulator in a process of their own (``NUMBA_ENABLE_CUDASIM=1 python rolling_checks.py walls
periodic hertz refusal`` prints one JSON object of measurements, simulator.run_checks):

- "walls": the 27-sphere scene of simulated.py (a triaxial's shear in miniature, several
  rebuilds) with RollingResistance(ROLLING, TWISTING, damping_ratio=0.3) and Gravity(9.81)
  after the walls, as a loaded sample lists them: the plain run, one forced to rebuild every
  10 steps, one handed from the CPU to the device halfway, and the CPU's runs without the
  moments and without the weight;
- "periodic": the rolling resistance in the periodic cell of periodic_checks.py;
- "hertz": the same with that cell's contacts Hertz–Mindlin's damped to e = 0.5, over
  periodic_checks.HERTZ_STEPS;
- "refusal": a rolling resistance listed before the contact law.
"""

from periodic_checks import HERTZ_STEPS
from simulator import relative, run_checks

STEPS = 200
PERIODIC_STEPS = 100
ROLLING = 0.3
TWISTING = 0.2


def scene(moments=True, weight=True, periodic=False, hertz=False):
    """simulated.py's scene with the rolling resistance and the weight (module docstring), or
    periodic_checks.py's cell with the rolling resistance (``periodic``: no weight), its
    contacts Hertz–Mindlin's damped to e = 0.5 with ``hertz`` (periodic_checks.hertz_scene)."""
    from pendular.dem.gravity import Gravity
    from pendular.dem.rolling import RollingResistance
    from simulated import scene as plain
    from periodic_checks import hertz_scene, scene as cell

    sim = (hertz_scene() if hertz else cell()) if periodic else plain()
    weight = weight and not periodic
    if weight:
        sim.forces.append(Gravity(9.81))
    if moments:
        sim.forces.append(RollingResistance(ROLLING, TWISTING, damping_ratio=0.3))
    return sim


def snapshot(sim):
    """simulated.py's snapshot (periodic_checks.py's in a cell: positions unwrapped) with
    the torques and, keyed by pair (i, j) for the touching pairs, the tangential springs, the
    rolling and twisting springs and the pairs' moments."""
    sim.fetch()                         # a device run's state, all of it
    from pendular.dem.protocols import pair_key
    from pendular.dem.rolling import FIELDS, OWNER, RollingResistance
    from simulated import snapshot as walled
    from periodic_checks import snapshot as periodic

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


def walls():
    """The walled scene on both devices (the module docstring's "walls")."""
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
    return {"steps": STEPS, "agreement": compare(snapshot(cpu), snapshot(gpu.sim)),
            "rebuilds": gpu.fetch_rebuilds(), "rebuilds_cpu": cpu.neighbors.rebuilds,
            "rebuilds_forced": forced.fetch_rebuilds(),
            "forced_equals_plain": identical(snapshot(gpu.sim), snapshot(forced.sim)),
            "handed_over": compare(snapshot(cpu), snapshot(handed_gpu.sim)),
            "rolling_on_limit": on_limit(cpu), "without": without}


def periodic(hertz=False, steps=PERIODIC_STEPS):
    """The cell's scene on both devices (the module docstring's "periodic" and "hertz"): the
    comparison and the CPU's pairs on and below their rolling limit."""
    from pendular.gpu import GpuSimulation

    cpu = scene(periodic=True, hertz=hertz)
    cpu.run(steps)
    gpu = GpuSimulation(scene(periodic=True, hertz=hertz))
    gpu.run(steps)
    gpu.to_host()
    return {**compare(snapshot(cpu), snapshot(gpu.sim)), "on_limit": on_limit(cpu)}


def refusal():
    """The error of a scene whose rolling resistance comes before the contact law (None when
    the device takes it)."""
    from pendular.gpu import GpuSimulation

    misplaced = scene()
    misplaced.forces.insert(0, misplaced.forces.pop())
    try:
        GpuSimulation(misplaced)
    except ValueError as error:
        return str(error)
    return None


if __name__ == "__main__":
    run_checks({"walls": walls, "periodic": periodic,
                "hertz": lambda: periodic(hertz=True, steps=HERTZ_STEPS), "refusal": refusal})
