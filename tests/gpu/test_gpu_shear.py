"""The periodic cell's controls on the GPU path (pendular.gpu.cell) against the CPU path under
Numba's CUDA simulator, each check in a process of its own (this file as a script:
``NUMBA_ENABLE_CUDASIM=1 python test_gpu_shear.py CHECK`` prints one JSON object of
measurements), so that no other test meets the simulator.

- Simple shear (Lees–Edwards), "dry" and "wet" (suction-controlled bridges at contact):
  test_gpu_periodic.py's 64 spheres (radii within 5 % of 1 mm on a jittered cubic lattice,
  slightly overlapping, random velocities) in a cell whose image above in z starts offset by
  START_OFFSET of its width along x, sheared x with z at SHEAR_RATE under the cell's stress
  servo on z; friction 30 deg, damping 0.2. The particles cross the x and the z faces (those
  through a z face shifted by the offset), the offset passes half the cell's width and loses
  a whole width at a rebuild, and the pairs are found through the sheared faces at every
  rebuild. Then ``pendular simple-shear --sample S --device gpu`` against ``--device cpu``.
- Mixed stress conditions in a cell, "mixed": test_gpu_periodic.py's scene at a constant p
  and at a constant b, and a condition that cannot hold.
- Radius growth in a cell, "growth": 64 spheres grown in a fixed cell with the time step set
  at every rebuild, as a periodic preparation's growth; a preparation cut short.

Measured (simulator; largest relative differences from the CPU):

- simple shear, 300 dry (200 wet) steps, 30 (20) rebuilds on both devices: unwrapped
  positions 1.8e-14 (6.3e-15), velocities 9.1e-13 (5.7e-13), angular velocities 1.1e-12
  (4.5e-13), the cell's stress tensor 3.8e-14 (7.6e-15), the shear stress tau 9.8e-14
  (1.1e-13), stiffness 9.9e-16 (5.9e-16); faces, rates, offset and shear strain equal. A GPU
  run of 150 steps continued 100 on the CPU: positions 7.2e-15 (1.3e-14), velocities 4.3e-13
  (5.5e-13), tau 1.1e-12 (1.7e-12).
- the command (60 spheres, 338 steps): the same rows, contact counts and shear strains;
  1.1e-10 of the largest volumetric strain, 2.7e-11 of tau, 1.2e-11 of sigma_contact, 4.9e-9
  in the unbalanced force (a residual ratio). TOLERANCE and UNBALANCED_TOLERANCE hold them
  with a margin of about 20.
- mixed, 200 steps: constant p (constant b) positions 2.2e-15 (1.6e-15), velocities 1.1e-12
  (1.4e-12), the cell's faces 2.2e-16 (equal) and rates 1.1e-11 (equal), stress tensor
  3.1e-15 (2.1e-15), the servos' targets 7.0e-16 (8.2e-16); the failing condition's message
  and step are the CPU's.
- growth, 200 steps, 34 rebuilds on both devices, radii grown by 13 %: radii 2.0e-15, masses
  5.7e-15, dt 3.2e-15, positions 2.6e-13, velocities 2.4e-11, the cell's stress 2.7e-12 (88
  contacts of a dense packing, round-off grown over the rebuilds); the same steps at a fixed
  time step split between two device runs: 9.9e-14 in positions.

The CPU's hot kernels contract multiply-adds and take reciprocals; the simulator computes
each operation as written.
"""

import json
import math
import os
import sys

import numpy as np
import pytest

from simulator import histories_on_both, relative
from test_gpu_growth import prepare_run
from test_gpu_periodic import (RADIUS, SIDE, agreement as periodic_agreement, compare,
    measured as periodic_measured, scene as periodic_scene, snapshot)

#: Shear rate gamma_dot [1/s]: a shear strain of about 0.46 in the dry run's steps.
SHEAR_RATE = 500.0
#: The offset the cell starts from, as a fraction of its width (half: brought back).
START_OFFSET = 0.49


def sheared(length):
    """The scene's controls in a cell of edge ``length`` [m]: the stress servo on z, the
    shear of x with z at SHEAR_RATE."""
    from pendular.dem.cell import ConstantShearRate
    from pendular.dem.walls import StressServo

    return [StressServo("z", 2e4, 0.02), ConstantShearRate(SHEAR_RATE)]


def scene(wet=False):
    """A CPU Simulation of the module docstring's scene: test_gpu_periodic.py's, sheared."""
    return periodic_scene(wet, seed=5, controls=sheared, offset=START_OFFSET)


def agreement(wet):
    """test_gpu_periodic.py's comparison of the CPU's and the GPU's runs, of the sheared
    scene."""
    return periodic_agreement(wet, scene)


# ---------------------------------------------------------------- the tests (pytest)
def measured(check):
    """The measurements of this file's ``check``, run under the simulator."""
    return periodic_measured(check, os.path.basename(__file__))


@pytest.fixture(scope="module")
def dry():
    return measured("dry")


@pytest.fixture(scope="module")
def wet():
    return measured("wet")


def assert_agrees(measured):
    assert measured["touching"][0] == measured["touching"][1] > 80     # a packing, not a gas
    assert measured["position"] < 1e-13
    assert measured["cell"] < 1e-13
    assert measured["rate"] < 1e-10             # a servo's rate: a velocity
    assert measured["stress"] < 1e-12 and measured["shear_stress"] < 1e-11
    assert measured["stiffness"] < 1e-12
    assert measured["offset"] < 1e-12 and measured["shear_strain"] < 1e-14
    assert measured["shear_rate"] == 0.0
    for name in ("velocity", "angular_velocity"):
        assert measured[name] < 1e-10, name


def test_simple_shear_agrees_with_the_cpu_to_round_off_dry(dry):
    x, _, z = dry["wrapped"]
    assert x > 0 and z > 0                      # through the x faces and the sheared z faces
    assert dry["rebuilds"][0] == dry["rebuilds"][1] > 3
    # the offset passed half the width and lost a whole width at a rebuild
    assert START_OFFSET + dry["gamma"] > 0.5 and abs(dry["offset_fraction"]) < 0.5
    assert dry["gamma"] > 0.2 and dry["tau"] > 0.0
    assert_agrees(dry)


def test_simple_shear_agrees_with_the_cpu_to_round_off_wet(wet):
    assert wet["rebuilds"][0] == wet["rebuilds"][1] > 2
    assert_agrees(wet)


def test_a_sheared_gpu_run_continued_on_the_cpu_equals_the_cpu_run(dry, wet):
    assert_agrees(dry["continued"])
    assert_agrees(wet["continued"])


# ---------------------------------------------------------------- mixed stress in a cell
#: Steps of a mixed condition's comparison; the mean stress held [Pa] (the cell's stresses
#: are 1e5-1.6e5 Pa); that of the failing run and its strain rate on z [1/s], under which
#: sigma_z passes 3 p after about 80 steps.
MIXED_STEPS = 200
MEAN_STRESS = 1.2e5
FAILING_MEAN_STRESS = 5.5e4
FAILING_RATE = 10.0


def mixed_scene(condition, mean_stress=MEAN_STRESS, axial_rate=None):
    """test_gpu_periodic.py's cell under a mixed condition and its strain rate on z (or one
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


@pytest.fixture(scope="module")
def mixed():
    return measured("mixed")


@pytest.mark.parametrize("condition", ["constant_p", "constant_b"])
def test_a_mixed_condition_in_a_cell_agrees_with_the_cpu_to_round_off(mixed, condition):
    run = mixed[condition]
    assert_agrees(run)
    assert run["targets"] < 1e-12 and run["final_targets"] < 1e-12
    assert run["target_change"] > 0.05      # the condition moved the servos' targets


def test_a_mixed_condition_that_cannot_hold_in_a_cell_fails_as_on_the_cpu(mixed):
    """The CPU's StageFailed, its message (the step of the failure included), raised on the
    GPU at the run's next check (every 100 steps: nothing reads the device's state before)."""
    cpu, gpu = mixed["failing"]["cpu"], mixed["failing"]["gpu"]
    assert cpu["error"] == gpu["error"] == "StageFailed"
    assert gpu["message"] == cpu["message"] and "walls cannot pull" in cpu["message"]
    assert 0 < cpu["step"] < MIXED_STEPS and gpu["step"] == 100 * (cpu["step"] // 100 + 1)


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
    rebuilds = gpu.rebuilds
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


@pytest.fixture(scope="module")
def growth():
    return measured("growth")


def test_a_radius_growth_in_a_cell_agrees_with_the_cpu_to_round_off(growth):
    assert growth["touching"][0] == growth["touching"][1] > 0
    for name in ("radius", "mass", "inertia", "position", "dt"):
        assert growth[name] < 1e-12, name
    assert growth["stress"] < 1e-11                 # a dense packing's contact forces
    assert growth["velocity"] < 1e-9                # a residual of the damped motion
    assert growth["cell"] == 0.0                    # the cell holds still
    assert growth["rebuilds"][0] == growth["rebuilds"][1] >= 4
    # the run the docstring describes: grown by more than 10 %, the cell's stress near its
    # target (the rate falls as it nears it), dt followed
    assert growth["radius_growth"] > 1.1 and growth["peak_stress"] > 0.8 * GROWTH_TARGET
    assert growth["dt_change"] > 0.05
    for name, difference in growth["split"].items():
        assert difference < 1e-12, name


def test_a_periodic_preparation_runs_its_growth_on_the_gpu(growth):
    """prepare_sample(device="gpu") of a periodic sample runs the growth there: cut short at a
    step limit, it stops with the CPU's message."""
    prepared = growth["prepare"]
    assert prepared["device_steps"] == prepared["max_steps"]
    assert prepared["gpu"] == prepared["cpu"]
    assert "radius growth not reached" in prepared["gpu"]


#: The simple shear command on both devices (its sample, prepared on the CPU, added).
COMMAND = ["--particles", "60", "--max-strain", "0.002", "--inertial-number", "1e-3",
           "--quiet"]
#: Largest difference of a history column from the CPU's over its largest magnitude [-], and
#: the same for the unbalanced force (a ratio of a residual to the mean force).
TOLERANCE = 2e-9
UNBALANCED_TOLERANCE = 1e-7


def test_the_simple_shear_command_records_the_cpu_history(tmp_path):
    """``pendular simple-shear --sample S --device gpu`` (S a sample prepared by the command on
    the CPU) shears on the device and records the CPU's history: the same rows, contact
    counts and shear strains, the other columns to round-off grown over the steps (module
    docstring's MEASURED)."""
    pytest.importorskip("numba_cuda")
    cpu, gpu = histories_on_both("simple-shear", ["--particles", 60, "--max-strain", 1e-3,
                                                  "--quiet"], COMMAND, tmp_path)
    assert cpu.keys() == gpu.keys() and len(cpu["step"]) > 5
    for name in ("step", "coordination", "shear_strain"):
        assert np.array_equal(cpu[name], gpu[name]), name
    assert cpu["shear_strain"][-1] >= 0.002
    for name, values in cpu.items():
        if values.dtype == object:
            assert np.array_equal(values, gpu[name]), name
            continue
        bound = UNBALANCED_TOLERANCE if name == "unbalanced_force" else TOLERANCE
        assert np.max(np.abs(gpu[name] - values)) <= bound * np.max(np.abs(values)), name


if __name__ == "__main__":
    CHECKS = {"dry": lambda: agreement(False), "wet": lambda: agreement(True),
              "mixed": mixed_agreement, "growth": growth_agreement}
    print(json.dumps(CHECKS[sys.argv[1]]()))
