"""Walls with tangential springs (pendular.gpu.wall_friction) on the GPU against the CPU, the
checks of tests/gpu/test_gpu_wall_friction.py run under Numba's CUDA simulator in a process of
their own (``NUMBA_ENABLE_CUDASIM=1 python wall_friction_checks.py linear hertz wet refusal`` prints one JSON object of measurements, simulator.run_checks):

- "linear": the 27-sphere scene of simulated.py (a triaxial's shear in miniature) with its
  walls frictional (FrictionalWallForces, FRICTION) and the weight: the plain run, one handed
  from the CPU to the device halfway (the springs go up and come back), and the CPU's run
  with frictionless walls (what the comparison would miss);
- "hertz": the same on Hertz–Mindlin contacts damped to e = 0.5 with Hertz–Mindlin walls of
  a material of their own (ViscoelasticWallForces on WALL at FRICTION: the unlike pair's E*,
  G* and restitution, pendular.dem.material), over periodic_checks.HERTZ_STEPS (a damped
  scene's runs part from round-off within a hundred steps on the CPU alone);
- "wet": the linear scene with bridges at contact, which gather the pairs after the walls;
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


def scene(friction=FRICTION, hertz=False, wet=False, wall=WALL):
    """simulated.py's scene (module docstring) with frictional walls and the weight; with
    ``hertz`` the walls of ``wall`` (E [Pa], nu, e; None: rigid, of the grains' e)."""
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
    return sim


def snapshot(sim):
    """simulated.py's snapshot with the walls' moments, stiffnesses and the wall springs."""
    from pendular.dem.hertz_mindlin import ViscoelasticWallForces
    from simulated import snapshot as plain

    out = plain(sim)
    out["wall_moment"] = sim.walls.moment.copy()
    out["wall_stiffness"] = sim.walls.stiffness.copy()
    out["wall_shear"] = sim.operation(ViscoelasticWallForces).wall_shear.copy()
    return out


def compare(cpu, gpu):
    """simulated.py's comparison and the count of springs on the walls (CPU, GPU)."""
    import numpy as np

    from simulated import compare as plain

    out = plain(cpu, gpu)
    out["springs_on_walls"] = [int(np.count_nonzero(np.any(s["wall_shear"] != 0, axis=2)))
                               for s in (cpu, gpu)]
    return out


def agreement(hertz=False, wet=False, steps=STEPS):
    """The scene on both devices over ``steps``: plain, handed over halfway, and the CPU
    without friction (and, ``hertz``, on rigid walls of the grains' restitution)."""
    from pendular.gpu import GpuSimulation
    from simulated import compare as plain_compare, snapshot as plain_snapshot

    cpu = scene(hertz=hertz, wet=wet)
    cpu.run(steps)
    gpu = GpuSimulation(scene(hertz=hertz, wet=wet))
    gpu.run(steps)
    gpu.to_host()
    handed = scene(hertz=hertz, wet=wet)
    handed.run(steps // 2)
    handed_gpu = GpuSimulation(handed)
    handed_gpu.run(steps - steps // 2)
    handed_gpu.to_host()
    frictionless = scene(friction=0.0, hertz=hertz, wet=wet)
    frictionless.run(steps)
    out = {"agreement": compare(snapshot(cpu), snapshot(gpu.sim)),
           "handed_over": compare(snapshot(cpu), snapshot(handed_gpu.sim)),
           "without_friction": plain_compare(plain_snapshot(cpu), plain_snapshot(frictionless))}
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
                "wet": lambda: agreement(wet=True), "refusal": refusal})
