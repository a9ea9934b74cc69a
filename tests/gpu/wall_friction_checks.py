"""Walls with tangential springs (pendular.gpu.wall_friction) on the GPU against the CPU, the
checks of tests/gpu/test_gpu_wall_friction.py run under Numba's CUDA simulator in a process of
their own (``NUMBA_ENABLE_CUDASIM=1 python wall_friction_checks.py linear hertz wet rolling
refusal`` prints one JSON object of measurements, simulator.run_checks):

- "linear": the 27-sphere scene of simulated.py (a triaxial's shear in miniature) with its
  walls frictional (FrictionalWallForces, FRICTION) and the weight: the plain run, one handed
  from the CPU to the device halfway (the springs go up and come back), and the CPU's run
  with frictionless walls (what the comparison would miss);
- "hertz": the same on Hertz–Mindlin contacts damped to e = 0.5 with Hertz–Mindlin walls of
  a material of their own (ViscoelasticWallForces on WALL at FRICTION: the unlike pair's E*,
  G* and restitution, pendular.dem.material), over periodic_checks.HERTZ_STEPS (a damped
  scene's runs part from round-off within a hundred steps on the CPU alone);
- "wet": the linear scene with bridges at contact, which gather the pairs after the walls;
- "rolling": the linear scene with rolling and twisting resistance on its walls
  (WallRollingResistance of WALL_ROLLING, pendular.gpu.wall_rolling), and the CPU's run
  without it;
- "refusal": a scene with two wall operations (one role "walls" at most).
"""

from periodic_checks import HERTZ_STEPS
from simulator import run_checks

STEPS = 200
FRICTION = 25.0
#: Hertz–Mindlin material of the "hertz" scene: E [Pa], nu, e.
HERTZ = (1e7, 0.3, 0.5)
#: Its walls' material: E [Pa], nu, e (the contacts' e the mean with the grains', 0.7).
WALL = (3e7, 0.25, 0.9)
#: The walls' rolling and twisting friction of the "rolling" scene: mu_r, mu_t.
WALL_ROLLING = (0.2, 0.1)


def scene(friction=FRICTION, hertz=False, wet=False, wall=WALL, rolling=False):
    """simulated.py's scene (module docstring) with frictional walls and the weight; with
    ``hertz`` the walls of ``wall`` (E [Pa], nu, e; None: rigid, of the grains' e); with
    ``rolling`` the walls' rolling resistance (WALL_ROLLING) after their springs."""
    from pendular.dem.gravity import Gravity
    import math

    from pendular.dem.hertz_mindlin import HertzMindlinForces, ViscoelasticWallForces
    from pendular.dem.material import Material
    from pendular.dem.wall_friction import FrictionalWallForces
    from simulated import YOUNG, scene as plain

    sim = plain(wet=wet)
    if hertz:
        contact = HertzMindlinForces(*HERTZ, friction_deg=30.0)
        sim.forces[0] = contact
        young, poisson, restitution = (math.inf, 0.0, HERTZ[2]) if wall is None else wall
        sim.forces[1] = ViscoelasticWallForces(
            contact, Material(young, poisson, math.inf, friction, 0.0, restitution))
    else:
        sim.forces[1] = FrictionalWallForces(YOUNG, 0.3, friction)
    sim.forces.insert(2, Gravity(9.81))
    if rolling:
        from pendular.dem.wall_rolling import WallRollingResistance

        walls = Material(math.inf, rolling_friction=WALL_ROLLING[0],
                         twisting_friction=WALL_ROLLING[1])
        sim.forces.insert(2, WallRollingResistance(sim.forces[0], walls))
    return sim


def snapshot(sim):
    """simulated.py's snapshot with the walls' moments, stiffnesses and the wall springs."""
    from pendular.dem.hertz_mindlin import ViscoelasticWallForces
    from simulated import snapshot as plain

    out = plain(sim)
    out["wall_moment"] = sim.walls.moment.copy()
    out["wall_stiffness"] = sim.walls.stiffness.copy()
    out["wall_shear"] = sim.operation(ViscoelasticWallForces).wall_shear.copy()
    resistance = [op for op in sim.forces if type(op).__name__ == "WallRollingResistance"]
    if resistance:
        out["wall_rolling_moment"] = resistance[0].wall_rolling_moment.copy()
        out["wall_twisting_moment"] = resistance[0].wall_twisting_moment.copy()
    return out


def compare(cpu, gpu):
    """simulated.py's comparison and the count of springs on the walls (CPU, GPU)."""
    import numpy as np

    from simulated import compare as plain
    from simulator import relative

    out = plain(cpu, gpu)
    out["springs_on_walls"] = [int(np.count_nonzero(np.any(s["wall_shear"] != 0, axis=2)))
                               for s in (cpu, gpu)]
    if "wall_rolling_moment" in cpu:
        out["rolling_on_walls"] = [
            int(np.count_nonzero(np.any(s["wall_rolling_moment"] != 0, axis=2)))
            for s in (cpu, gpu)]
        for name in ("wall_rolling_moment", "wall_twisting_moment"):
            out[name] = relative(cpu[name], gpu[name])
    return out


def agreement(hertz=False, wet=False, steps=STEPS, rolling=False):
    """The scene on both devices over ``steps``: plain, handed over halfway, and the CPU
    without friction (and, ``hertz``, on rigid walls of the grains' restitution; ``rolling``,
    with the walls' rolling resistance, and the CPU without it)."""
    from pendular.gpu import GpuSimulation
    from simulated import compare as plain_compare, snapshot as plain_snapshot

    given = {"hertz": hertz, "wet": wet, "rolling": rolling}
    cpu = scene(**given)
    cpu.run(steps)
    gpu = GpuSimulation(scene(**given))
    gpu.run(steps)
    gpu.to_host()
    handed = scene(**given)
    handed.run(steps // 2)
    handed_gpu = GpuSimulation(handed)
    handed_gpu.run(steps - steps // 2)
    handed_gpu.to_host()
    other = scene(hertz=hertz, wet=wet) if rolling else scene(friction=0.0, **given)
    other.run(steps)
    out = {"agreement": compare(snapshot(cpu), snapshot(gpu.sim)),
           "handed_over": compare(snapshot(cpu), snapshot(handed_gpu.sim)),
           "without_rolling" if rolling else "without_friction":
               plain_compare(plain_snapshot(cpu), plain_snapshot(other))}
    if hertz:
        rigid = scene(hertz=True, wall=None)
        rigid.run(steps)
        out["rigid_wall"] = plain_compare(plain_snapshot(cpu), plain_snapshot(rigid))
    return out


def refusal():
    """The error of a scene with a frictionless and a frictional wall operation."""
    from pendular.dem.walls import WallForces
    from pendular.gpu import GpuSimulation
    from simulated import YOUNG

    twice = scene()
    twice.forces.insert(1, WallForces(YOUNG))
    try:
        GpuSimulation(twice)
    except ValueError as error:
        return str(error)
    return None


if __name__ == "__main__":
    run_checks({"linear": agreement, "hertz": lambda: agreement(hertz=True, steps=HERTZ_STEPS),
                "wet": lambda: agreement(wet=True), "rolling": lambda: agreement(rolling=True),
                "refusal": refusal})
