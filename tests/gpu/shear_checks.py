"""The periodic cell's controls on the GPU path (pendular.gpu.cell) against the CPU path, the
checks of tests/gpu/test_gpu_shear.py run under Numba's CUDA simulator in a process of their own
(``NUMBA_ENABLE_CUDASIM=1 python shear_checks.py dry wet mixed growth`` prints one JSON object
of measurements, simulator.run_checks):

- simple shear (Lees–Edwards), "dry" and "wet" (suction-controlled bridges at contact):
  periodic_checks.py's 64 spheres in a cell whose image above in z starts offset by
  START_OFFSET of its width along x, sheared x with z at SHEAR_RATE under the cell's stress
  servo on z; friction 30 deg, damping 0.2. The particles cross the x and the z faces (those
  through a z face shifted by the offset), the offset passes half the cell's width and loses
  a whole width at a rebuild, and the pairs are found through the sheared faces at every
  rebuild;
- mixed stress conditions in a cell, "mixed": periodic_checks.py's scene at a constant p and
  at a constant b, and a condition that cannot hold;
- radius growth in a cell, "growth": 64 spheres grown in a fixed cell with the time step set
  at every rebuild, as a periodic preparation's growth; a preparation cut short.
"""

import math

import numpy as np

from growth_checks import prepare_run
from periodic_checks import (RADIUS, SIDE, agreement as periodic_agreement, compare,
    scene as periodic_scene, snapshot)
from simulator import relative, run_checks

#: Shear rate gamma_dot [1/s]: a shear strain of about 0.31 in SHEAR_STEPS.
SHEAR_RATE = 500.0
#: Steps of the dry and the wet comparison (twenty rebuilds).
SHEAR_STEPS = 200
#: The offset the cell starts from, as a fraction of its width (half: brought back).
START_OFFSET = 0.49


def sheared(length):
    """The scene's controls in a cell of edge ``length`` [m]: the stress servo on z, the
    shear of x with z at SHEAR_RATE."""
    from pendular.dem.cell import ConstantShearRate
    from pendular.dem.walls import StressServo

    return [StressServo("z", 2e4, 0.02), ConstantShearRate(SHEAR_RATE)]


def scene(wet=False):
    """A CPU Simulation of the module docstring's scene: periodic_checks.py's, sheared."""
    return periodic_scene(wet, seed=5, controls=sheared, offset=START_OFFSET)


def agreement(wet):
    """periodic_checks.py's comparison of the CPU's and the GPU's runs, of the sheared
    scene."""
    return periodic_agreement(wet, scene, SHEAR_STEPS)



# ---------------------------------------------------------------- mixed stress in a cell
#: Steps of a mixed condition's comparison (seven rebuilds; past the failing run's first
#: check on the device, at step 100); the mean stress held [Pa] (the cell's stresses are
#: 1e5-1.6e5 Pa); that of the failing run and its strain rate on z [1/s], under which
#: sigma_z passes 3 p after about 80 steps.
MIXED_STEPS = 120
MEAN_STRESS = 1.2e5
FAILING_MEAN_STRESS = 5.5e4
FAILING_RATE = 10.0


def mixed_scene(condition, mean_stress=MEAN_STRESS, axial_rate=None):
    """periodic_checks.py's cell under a mixed condition and its strain rate on z (or one
    of ``axial_rate`` [1/s]): "constant_p" (one servo for x and y, at ``mean_stress`` [Pa])
    or "constant_b" (b = 0.5, sigma_3 given on x, y set), the servos' targets recorded every
    25 steps."""
    from pendular.dem.mixed_stress import MixedStress
    from pendular.dem.record import HistoryRecorder
    from pendular.dem.walls import ConstantStrainRate, StressServo

    sim = periodic_scene()
    axial = sim.controls[1]
    if axial_rate is not None:
        axial = ConstantStrainRate("z", axial_rate, axial.reference_length)
    if condition == "constant_p":
        servos = [StressServo("xy", 2e4, 0.02)]
        control = MixedStress({0: servos[0], 1: servos[0]}, "xy", mean_stress=mean_stress)
    else:
        servos = [StressServo("x", 2e4, 0.02), StressServo("y", 2e4, 0.02)]
        control = MixedStress({0: servos[0], 1: servos[1]}, "y", b=0.5, stress={"x": 2e4})
    sim.controls = [control, *servos, axial]
    sim.writers = [HistoryRecorder(25, {
        "step": lambda s: s.step,
        "targets": lambda s: [op.target for op in s.controls if hasattr(op, "target")]})]
    return sim


def failed(sim, steps):
    """{error, message, step} of ``sim.run(steps)`` expected to fail."""
    try:
        sim.run(steps)
    except Exception as error:   # the class is what is compared
        return {"error": type(error).__name__, "message": str(error), "step": sim.step}
    return {"error": None, "message": None, "step": sim.step}


def mixed_agreement():
    """Each mixed condition on the CPU and the GPU (Simulation.run on each device) compared,
    the targets' records too; a condition that cannot hold, failing on both."""
    out = {}
    for condition in ("constant_p", "constant_b"):
        cpu, gpu = mixed_scene(condition), mixed_scene(condition)
        first = [op.target for op in cpu.controls if hasattr(op, "target")]
        cpu.run(MIXED_STEPS)
        gpu.device = "gpu"
        gpu.run(MIXED_STEPS)
        last = [op.target for op in cpu.controls if hasattr(op, "target")]
        out[condition] = compare(snapshot(cpu), snapshot(gpu))
        out[condition]["targets"] = relative(cpu.writers[0].arrays()["targets"],
                                             gpu.writers[0].arrays()["targets"])
        out[condition]["final_targets"] = relative(
            last, [op.target for op in gpu.controls if hasattr(op, "target")])
        out[condition]["target_change"] = float(np.max(np.abs(np.subtract(last, first)))
                                                / np.max(np.abs(first)))
    cpu = mixed_scene("constant_p", FAILING_MEAN_STRESS, FAILING_RATE)
    gpu = mixed_scene("constant_p", FAILING_MEAN_STRESS, FAILING_RATE)
    gpu.device = "gpu"
    out["failing"] = {"cpu": failed(cpu, MIXED_STEPS), "gpu": failed(gpu, MIXED_STEPS)}
    return out


# ---------------------------------------------------------------- radius growth in a cell
#: Steps of the growth's comparison; the mean stress it grows to [Pa].
GROWTH_STEPS = 200
GROWTH_TARGET = 3000.0


def growth_scene(timestep=True, seed=3):
    """test_gpu_growth.py's growth in a periodic cell: 64 spheres of radii within 5 % of 1 mm
    on a jittered cubic lattice 2.2 mm apart (solid fraction 0.39) with random velocities,
    friction 0.5 deg, radii grown at up to 1e-3 per step towards a mean stress of the cell of
    GROWTH_TARGET, with ``timestep`` the time step set at every rebuild (GrowthTimeStep),
    skin 0.1 mm; the cell holds still (the preparation's growth)."""
    from pendular.dem.cell import PeriodicCell
    from pendular.dem.contact_law import ContactForces
    from pendular.dem.growth import GrowthTimeStep, RadiusGrowth
    from pendular.dem.integrate import Integrator
    from pendular.dem.neighbors import NeighborList
    from pendular.dem.simulation import Simulation
    from pendular.dem.state import Particles

    rng = np.random.default_rng(seed)
    spacing = 2.2 * RADIUS
    nodes = np.arange(SIDE) * spacing + 0.01 * RADIUS      # the first layers across faces
    position = np.array(np.meshgrid(nodes, nodes, nodes, indexing="ij")).reshape(3, -1).T
    position += rng.uniform(-0.05, 0.05, position.shape) * RADIUS
    radius = RADIUS * rng.uniform(0.95, 1.05, len(position))
    particles = Particles(position, radius, 2650.0, velocity=rng.normal(0, 0.005,
                                                                          position.shape))
    young = 1e6
    dt = 0.7 * float(radius.min()) / math.sqrt(young / 2650.0)
    controls = [RadiusGrowth(GROWTH_TARGET, 1e-3)]
    if timestep:
        controls.append(GrowthTimeStep(0.7, young, 2650.0))
    return Simulation(particles, PeriodicCell.box([0.0] * 3, [SIDE * spacing] * 3), dt,
                      neighbors=NeighborList(0.1 * RADIUS),
                      forces=[ContactForces(young, 0.3, 0.5)], controls=controls,
                      integrator=Integrator(0.2))


def growth_agreement():
    """The growth on the CPU and the GPU (GpuSimulation driven directly) compared, with the
    radii's and the step's growth, the largest mean stress on the CPU and the rebuilds; the
    same steps at a fixed time step in two device runs (the state back on the host between
    them) against the CPU's. (With GrowthTimeStep a second run's first step rebuilds the
    device's new list where the CPU would not, which moves the next rebuilds and the steps
    set at them: pendular.gpu.growth.)"""
    from pendular.gpu import GpuSimulation

    cpu = growth_scene()
    start_radius, start_dt = cpu.particles.radius.copy(), cpu.dt
    peak = 0.0
    for _ in range(GROWTH_STEPS // 10):
        cpu.run(10)
        peak = max(peak, float(np.mean(cpu.walls.stress())))
    sim = growth_scene()
    gpu = GpuSimulation(sim)
    gpu.run(GROWTH_STEPS)
    rebuilds = gpu.fetch_rebuilds()
    gpu.to_host()
    fixed, split = growth_scene(timestep=False), growth_scene(timestep=False)
    fixed.run(GROWTH_STEPS)
    for _ in range(2):
        half = GpuSimulation(split)
        half.run(GROWTH_STEPS // 2)
        half.to_host()
    out = compare(snapshot(cpu), snapshot(sim))
    p, q = sim.particles, cpu.particles
    out.update({name: relative(getattr(q, name), getattr(p, name))
                for name in ("radius", "mass", "inertia")})
    out["dt"] = abs(sim.dt - cpu.dt) / cpu.dt
    out["split"] = {"position": relative(snapshot(fixed)["position"],
                                         snapshot(split)["position"]),
                    "radius": relative(fixed.particles.radius, split.particles.radius)}
    out["rebuilds"] = [cpu.neighbors.rebuilds, rebuilds]
    out["radius_growth"] = float(np.min(q.radius / start_radius))
    out["dt_change"] = abs(cpu.dt / start_dt - 1.0)
    out["peak_stress"] = peak
    out["wrapped"] = int(np.count_nonzero(sim.walls.wraps))
    out["prepare"] = prepare_run(particles=60, periodic=True)
    return out


if __name__ == "__main__":
    run_checks({"dry": lambda: agreement(False), "wet": lambda: agreement(True),
                "mixed": mixed_agreement, "growth": growth_agreement})
