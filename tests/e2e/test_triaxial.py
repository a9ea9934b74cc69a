"""Servo, Love–Weber bookkeeping, determinism, the triaxial test procedure and its command."""

import copy
import json
import os
import subprocess
import sys

import h5py
import numba
import numpy as np
import pytest

from pendular.procedures.preparation import PrepareConfig, prepare_sample
from pendular.homogenize import contact_stress
from pendular.procedures.config import ShearConfig
from pendular.procedures.triaxial import TriaxialShear, summarize

from conftest import ROOT, assert_drawn, run_in_process



def test_prepared_sample_is_static_at_the_confining_stress(small_sample):
    config, sim, report = small_sample
    assert report["unbalanced_force"] <= config.equilibrium_unbalanced
    assert np.allclose(sim.walls.stress(), config.confining, rtol=config.stress_tolerance)
    assert 0.33 < report["porosity"] < 0.47
    assert report["coordination"] > 3.5


def test_love_weber_contact_stress_equals_wall_stress_in_equilibrium(small_sample):
    """Eq. 3.41 over sphere and wall contacts equals the wall stresses of a static packing."""
    _, sim, _ = small_sample
    sim = copy.deepcopy(sim)
    sim.run(20000, until=lambda s: _unbalanced(s) < 1e-4, check_every=500)
    stress = contact_stress(sim.particles, sim.contacts, sim.walls)
    walls = sim.walls.stress()
    assert np.allclose(np.diag(stress), walls, rtol=2e-3)
    # full tensor against the boundary traction (1/V) sum x_c (x) f_wall, x_c on the wall planes
    boundary = np.zeros((3, 3))
    position, radius = sim.particles.position, sim.particles.radius
    for w, plane in enumerate(sim.walls.position):
        axis, outward = w // 2, (1.0 if w % 2 else -1.0)
        overlap = radius - outward * (plane - position[:, axis])
        touching = overlap > 0
        contact_point = position[touching].copy()
        contact_point[:, axis] = plane
        force_on_wall = np.zeros((touching.sum(), 3))
        force_on_wall[:, axis] = outward * 1e6 * radius[touching] * overlap[touching]
        boundary += contact_point.T @ force_on_wall
    boundary /= sim.walls.volume()
    assert np.allclose(stress, boundary, atol=2e-3 * walls.mean())


def _unbalanced(sim):
    from pendular.dem.measure import unbalanced_force
    return unbalanced_force(sim.particles, sim.contacts)


def test_servo_holds_lateral_stress_within_one_percent_in_shear(small_sample):
    config, sim, _ = small_sample
    sim = copy.deepcopy(sim)
    shear = ShearConfig(max_strain=0.05, inertial_number=1e-3, records=50)
    run = TriaxialShear(sim, shear, config.confining, config.radius, config.density)
    sim.run(run.steps)
    history = run.recorder.arrays()
    lateral = history["sigma_wall"][5:, :2]    # past the first 0.5 % of strain
    assert np.abs(lateral / config.confining - 1).mean() < 0.01
    assert np.abs(lateral / config.confining - 1).max() < 0.03
    result = summarize(history)
    assert result["peak_q"] > 0.5 * config.confining     # the sample carries deviatoric load
    assert history["axial_strain"][-1] == pytest.approx(0.05, rel=0.01)


def test_same_seed_gives_identical_samples_for_any_thread_count():
    config = PrepareConfig(particles=150, confining=750.0, seed=7, unload_steps=400)
    first, _ = prepare_sample(config, progress=False)
    again, _ = prepare_sample(config, progress=False)
    assert np.array_equal(first.particles.position, again.particles.position)
    other = PrepareConfig(particles=150, confining=750.0, seed=8, unload_steps=400)
    different, _ = prepare_sample(other, progress=False)
    assert not np.allclose(first.particles.position[:10], different.particles.position[:10])
    if numba.config.NUMBA_NUM_THREADS > 1:
        for sim in (first, again):
            sim.threads = numba.config.NUMBA_NUM_THREADS if sim is first else 1
            sim.run(300)
        assert np.array_equal(first.particles.position, again.particles.position)
        assert np.array_equal(first.contacts.shear_force, again.contacts.shear_force)


def test_triaxial_scenario_writes_its_outputs(tmp_path):
    out = tmp_path / "run"
    command = [sys.executable, os.path.join(ROOT, "scenarios", "triaxial.py"), "--particles",
               "200", "--max-strain", "0.01", "--inertial-number", "2e-3", "--quiet",
               "--out", str(out)]
    subprocess.run(command, check=True, capture_output=True, text=True)
    summary = json.loads((out / "summary.json").read_text())
    for key in ("peak_axial_stress", "peak_q", "p_at_peak", "axial_strain_at_peak",
                "lateral_stress", "initial_porosity", "wall_time_s", "steps",
                "particle_steps_per_s"):
        assert np.isfinite(summary[key]), key
    with h5py.File(out / "history.h5") as handle:
        history = handle["history"]
        rows = len(history["step"])
        assert rows > 10
        shapes = {"sigma_wall": (rows, 3), "sigma_contact": (rows, 3, 3), "fabric": (rows, 3, 3),
                  "axial_strain": (rows,), "volumetric_strain": (rows,), "porosity": (rows,),
                  "coordination": (rows,), "unbalanced_force": (rows,), "time": (rows,)}
        for name, shape in shapes.items():
            assert history[name].shape == shape, name
        sigma = history["sigma_wall"][()]
        assert sigma[0] == pytest.approx([750.0] * 3, rel=1e-3)   # from the isotropic state
        assert np.abs(sigma[:, :2] / 750.0 - 1.0).max() < 0.03      # the servo holds the sides
        love_weber = np.diagonal(history["sigma_contact"][0])      # Love-Weber at equilibrium
        assert love_weber == pytest.approx(sigma[0], rel=0.01)
        strain = history["axial_strain"][()]
        assert strain[0] == 0.0 and np.all(np.diff(strain) > 0.0)
        assert strain[-1] == pytest.approx(0.01, abs=2 * strain[1])
        # the solid volume is conserved: 1 - V/V0 = 1 - (1 - n0) / (1 - n)
        porosity = history["porosity"][()]
        assert history["volumetric_strain"][()] == pytest.approx(
            1.0 - (1.0 - porosity[0]) / (1.0 - porosity), rel=1e-9, abs=1e-15)
        assert 0.3 < porosity[0] < 0.5 and np.all(history["coordination"][()] > 3.0)
        dt = np.diff(history["time"][()]) / np.diff(history["step"][()])
        assert dt == pytest.approx(np.full(rows - 1, dt[0]), rel=1e-9)    # one time step
        assert handle.attrs["particles"] == 200
        assert handle.attrs["confining"] == 750.0
        fabric = history["fabric"][0]
        assert np.trace(fabric) == pytest.approx(1.0)
    assert_drawn(out / "triaxial.png")


@pytest.mark.parametrize("arguments, message", [
    (["--particles", "-5"], "particles"),
    (["--radius", "-1e-5"], "radius"),
    (["--radius", "0"], "radius"),
    (["--porosity", "0.7"], "porosity"),
    (["--friction", "95"], "friction"),
    (["--confining", "nan"], "confining"),
    (["--max-strain", "inf"], "--max-strain"),
    (["--suction", "-5"], "suction"),
    (["--bogus"], "unrecognized arguments"),
])
def test_triaxial_scenario_refuses_bad_input(arguments, message, capsys):
    """scenarios/triaxial.py's command, run in-process (its own interpreter in
    test_triaxial_scenario_writes_its_outputs)."""
    status, err = run_in_process("triaxial", [*arguments, "--out", os.devnull], capsys,
                                 prog="triaxial.py")
    assert status != 0
    assert message in err
