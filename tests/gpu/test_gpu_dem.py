"""The GPU path (pendular.gpu) against the CPU path under Numba's CUDA simulator: the 27-sphere
triaxial step pipeline of tests/gpu/simulated.py (contacts with friction, walls, stress servo,
strain rate, leapfrog, neighbour list rebuilt on the device) over 200 steps, dry and wet
(suction-controlled bridges at contact at 30 kPa, and the device's table lookup, the CPU's
lookup_suction compiled for the device by pendular.gpu.cuda.device_twin, against the CPU's).
Both scenes run in one process of their own, so that no other test meets the simulator. The
CPU's hot kernels contract multiply-adds and take reciprocals; the simulator computes each
operation as written, hence round-off bounds (docs/gpu.md gives the differences measured).
"""

import json
import os
import subprocess
import sys

import pytest

from conftest import requires
from simulator import ROOT, simulated

pytestmark = requires("numba_cuda")


@pytest.fixture(scope="module")
def measured():
    """The dry and the wet scene's measurements, in one process."""
    return simulated("simulated.py", "dry", "wet")


@pytest.fixture(scope="module")
def dry(measured):
    return measured["dry"]


@pytest.fixture(scope="module")
def wet(measured):
    return measured["wet"]


def test_every_kernel_agrees_with_the_cpu_to_round_off(dry):
    agreement = dry["agreement"]
    assert agreement["touching_cpu"] == agreement["touching_gpu"] == agreement["touching_both"]
    assert agreement["touching_both"] > 20          # a packing, not a gas
    assert agreement["position"] < 1e-13
    assert agreement["wall_position"] < 1e-13
    assert agreement["wall_stress"] < 1e-12
    for name in ("velocity", "angular_velocity", "force", "torque", "springs", "wall_force"):
        assert agreement[name] < 1e-10, name


def test_writers_record_the_cpu_history_at_the_same_steps(dry):
    history = dry["history"]
    assert history["records"] == [4, 4]
    assert history["stress"] < 1e-12 and history["mean_height"] < 1e-13
    assert history["touching"] == 0.0
    assert dry["step"] == [200, 200] and dry["time"][0] == dry["time"][1]


def test_a_gpu_simulation_runs_until_as_the_cpu_and_copies_back_what_is_read(dry):
    """Simulation(device="gpu").run(until=, check_every=25), until 110 steps of the axial
    strain rate: the CPU's steps (125) and state. The until fetches the walls' lengths: the
    walls alone come back at each check; the recorder (every 50 steps, before the check)
    fetches everything, which the check then reads; the end of the run brings back the rest."""
    run = dry["device"]
    assert run["taken"] == run["step"] == [125, 125]
    expected = ["all" if step % 50 == 0 else "walls" for step in range(25, 126, 25)]
    assert run["copies"] == expected + ["all"]
    assert run["released"] == ["contacts", "controls", "particles", "walls"]
    assert run["agreement"]["position"] < 1e-13 and run["agreement"]["wall_stress"] < 1e-12
    assert run["history"]["records"] == [2, 2] and run["history"]["stress"] < 1e-12


def test_two_runs_are_equal_bit_for_bit(dry):
    assert dry["deterministic"]


def test_per_pair_state_is_carried_across_rebuilds(dry):
    """A run forced to rebuild its list every 10 steps (three times the rebuilds) equals the
    plain run bit for bit: every tangential spring follows its pair through each rebuild."""
    assert dry["rebuilds_gpu"] == dry["rebuilds_cpu"] >= 3
    assert dry["rebuilds_forced"] >= 2 * dry["rebuilds_gpu"]
    assert dry["forced_equals_plain"]


def test_what_the_gpu_does_not_run_is_refused_by_name(dry):
    persisting, unknown = dry["refusals"]
    assert "listed after the contact law and the wall forces only" in persisting
    assert "control Integrator" in unknown and "StressServo, ConstantStrainRate" in unknown


def test_a_diverged_run_stops_with_an_error(dry):
    assert "not finite" in dry["diverged"]


def test_the_device_reads_the_table_as_the_cpu(wet):
    assert wet["lookups_existing"] > 16
    assert wet["lookup"] < 1e-14


def test_bridges_form_and_pull_as_on_the_cpu(wet):
    count_cpu, count_gpu = wet["bridges"]
    assert count_cpu == count_gpu == wet["agreement"]["touching_both"] > 20
    for name, difference in wet["bridge_fields"].items():
        assert difference < 1e-12, name
    agreement = wet["agreement"]
    assert agreement["position"] < 1e-13 and agreement["wall_stress"] < 1e-12
    for name in ("velocity", "angular_velocity", "force", "torque", "springs"):
        assert agreement[name] < 1e-10, name
    assert wet["history"]["records"] == [4, 4] and wet["history"]["stress"] < 1e-12


def compile_ptx(*arguments):
    """tests/gpu/compile_ptx.py run in a process of its own (CompletedProcess)."""
    return subprocess.run([sys.executable, os.path.join(ROOT, "tests", "gpu", "compile_ptx.py"),
                           *arguments], capture_output=True, text=True,
                          cwd=os.path.join(ROOT, "tests", "gpu"), timeout=600)


@requires("cuda compiler")
def test_every_kernel_compiles_for_a_gpu():
    """PTX for an H100 of every kernel of a dry and a wet step, walled and periodic, with
    the rolling resistance, gravity, the sphere-wall bridges, the walls' springs and rolling
    resistance, the liquid clusters (tests/gpu/compile_ptx.py),
    where the gpu extra's CUDA compiler is installed: the simulator would run code that the
    CUDA target rejects."""
    done = compile_ptx()
    assert done.returncode == 0, done.stderr[-3000:]
    compiled = json.loads(done.stdout.strip().splitlines()[-1])
    kernels = ("bin_particles", "find_pairs", "finish_rebuild", "pair_forces", "gather",
               "wall_partials", "wall_sums", "wall_controls", "leapfrog",
               "homogenize_partials", "sum_columns")
    growth = ("grow", "mark_rebuild", "grown_beyond")
    grips = ("grip_partials", "grip_hold")
    resisting = ("pair_moments", "gather_moments", "add_weight")
    wall_bridges = ("wall_bridges", "wall_bridge_partials", "wall_bridge_sums")
    wall_springs = ("wall_contacts", "wall_moments")
    clusters = ("absorbed_forces", "add_clusters")
    periodic = ("bin_periodic", "find_periodic_pairs", "cell_partials", "cell_controls",
                "cell_leapfrog")
    assert set(compiled["kernels"]) == {*kernels, *(f"{name} wet" for name in kernels), *growth,
                                        *grips, *resisting, *wall_bridges, *wall_springs,
                                        *clusters,
                                        *(f"{name} periodic" for name in periodic),
                                        *(f"{name} periodic wet" for name in periodic),
                                        *(f"{name} sheared" for name in (*periodic,
                                                                         "shear_rebuilt")),
                                        "refresh_bridges wet", "exchange_liquid volume"}
    assert all(lines > 0 for lines in compiled["kernels"].values())


@requires("cuda compiler")
def test_a_compile_failure_fails_where_the_gpu_extra_installed_the_compiler():
    """With the gpu extra's NVVM and NVRTC installed, code the compiler rejects (here every
    kernel, for compute capability 5.0, which CUDA 13 no longer targets) fails the check: it
    does not skip."""
    done = compile_ptx("5.0")
    assert done.returncode != 0
    assert "skip" not in done.stdout and "compute capability 5.0" in done.stderr


def test_a_device_twin_is_the_cpu_source_calling_the_twins_of_what_it_calls():
    """pendular.gpu.cuda.device_twin: the device function of a CPU function runs the CPU's own
    code object, and each CPU function it calls by name is replaced by that function's twin,
    down the call tree (the bridges at contact: _follow_contact -> _form_at_contact ->
    lookup_suction -> _suction_cell); one twin per function."""
    from pendular.capillary.bridge_kernels import _follow_contact, _form_at_contact
    from pendular.capillary.table import _suction_cell, lookup_suction
    from pendular.gpu.cuda import device_twin

    chain = (_follow_contact, _form_at_contact, lookup_suction, _suction_cell)
    twins = [device_twin(function) for function in chain]
    assert all(device_twin(function) is twin for function, twin in zip(chain, twins))
    for function, twin, callee in zip(chain, twins, chain[1:]):
        assert twin.py_func.__code__ is function.py_func.__code__
        assert twin.py_func.__globals__[callee.__name__] is device_twin(callee)
        assert function.py_func.__globals__[callee.__name__] is callee   # the CPU's unchanged
