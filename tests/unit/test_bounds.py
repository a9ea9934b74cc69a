"""Bounds of the runs (issue 36): what no test can reach is refused before anything runs, in
one ``<prog>: error:`` line naming the option and its valid range (exit 2); a sample crushed
during a run stops with pendular.procedures.guards.SampleCrushed instead of giving stresses of no
meaning.

Option cases run in-process through pendular.cli.run_command (refused before anything runs);
the guard runs on 60-sphere samples prepared here.
"""

import copy

import numpy as np
import pytest

from conftest import refused, run_in_process

from pendular.procedures.config import MAX_AXIAL_STRAIN, MIN_SAMPLE_PARTICLES, ShearConfig
from pendular.procedures.tension import MIN_TENSION_PARTICLES, TensionConfig, tension_sample
from pendular.procedures.tension_pull import case_name
from pendular.procedures.swcc import SwccConfig
from pendular.procedures.triaxial import TriaxialConfig
from pendular.dem.grading import read_grading_curve
from pendular.dem.measure import largest_overlap, porosity
from pendular.procedures.preparation import PrepareConfig, prepare_sample
from pendular.dem.walls import ConstantStrainRate
from pendular.procedures.guards import (MAX_OVERLAP_OVER_RADIUS, MIN_POROSITY_EQUAL, SampleCrushed,
    SampleGuard)
from pendular.procedures.tension_report import case_line
from pendular.procedures.triaxial import TriaxialShear, summarize

#: A short triaxial (the audit's) and a tension command line; each test adds to them.
TRIAXIAL = ["--particles", "200", "--max-strain", "0.02", "--quiet"]
TENSION = ["--particles", "200", "--void-ratio", "0.72", "--water-content", "1", "--quiet"]


# ---------------------------------------------------------------- refused before running
def test_an_axial_strain_no_test_reaches_is_refused(capsys, tmp_path):
    out = ["--out", str(tmp_path / "t")]
    refused_by(capsys, "triaxial", TRIAXIAL + ["--max-strain", "0.9"] + out,
            "--max-strain = 0.9", f"[1e-06, {MAX_AXIAL_STRAIN:g}]", "20-30 %")
    refused_by(capsys, "triaxial", TRIAXIAL + ["--max-strain", "nan"] + out, "--max-strain")
    with pytest.raises(ValueError, match=r"max_strain = 0.6 is outside the valid range"):
        ShearConfig(max_strain=0.6)
    assert ShearConfig(max_strain=MAX_AXIAL_STRAIN).max_strain == MAX_AXIAL_STRAIN
    assert not (tmp_path / "t").exists()


@pytest.mark.parametrize("command, extra", [
    ("triaxial", TRIAXIAL),
    ("swcc", ["--quiet"]),
    ("chapter5", ["--suctions", "0", "--confining", "500", "--quiet"]),
])
def test_a_sample_of_a_few_spheres_is_refused(command, extra, capsys, tmp_path):
    out = tmp_path / "out"
    line = refused_by(capsys, command, extra + ["--particles", "2", "--out", str(out)],
                   "--particles = 2", f"[{MIN_SAMPLE_PARTICLES}, ", "averages")
    assert "triaxial test" in line or "SWCC" in line
    assert not out.exists()


def refused_by(capsys, name, argv, *words):
    """Command ``name`` run in-process with ``argv`` refuses it in one line naming ``words``."""
    line = refused(*run_in_process(name, argv, capsys, prog=name), *words)
    assert line.startswith(f"{name}: error: "), line
    return line


def test_tension_refuses_fewer_spheres_than_its_grips_need(capsys, tmp_path):
    refused_by(capsys, "tension", TENSION + ["--particles", "2", "--out", str(tmp_path / "t")],
            "--particles = 2", f"[{MIN_TENSION_PARTICLES}, 1000000]", "grips")


def test_the_smallest_samples_are_the_tests_own():
    few = PrepareConfig(particles=MIN_SAMPLE_PARTICLES - 1)
    for build in (lambda: TriaxialConfig(sample=few), lambda: SwccConfig(sample=few)):
        with pytest.raises(ValueError, match=r"^particles = 49 is outside the valid range "
                                             r"\[50, 10000000\]"):
            build()
    enough = PrepareConfig(particles=MIN_SAMPLE_PARTICLES)
    assert TriaxialConfig(sample=enough).sample.particles == SwccConfig(
        sample=enough).sample.particles == MIN_SAMPLE_PARTICLES
    few = tension_sample(particles=MIN_TENSION_PARTICLES)
    assert TensionConfig(sample=few).sample.particles == MIN_TENSION_PARTICLES
    with pytest.raises(ValueError, match=r"^particles = 99 is outside the valid range "
                                         r"\[100, 1000000\] for direct tension"):
        TensionConfig(sample=PrepareConfig(particles=MIN_TENSION_PARTICLES - 1))


def test_counts_beyond_the_shear_steps_are_refused(capsys, tmp_path):
    out = ["--out", str(tmp_path / "t")]
    steps = int(TriaxialConfig(sample=PrepareConfig(particles=200),
                               shear=ShearConfig(max_strain=0.02)).shear_steps())
    assert 4000 < steps < 10000                        # a P-wave step of 0.7 x 1.24e-6 s
    refused_by(capsys, "triaxial", TRIAXIAL + ["--vtk-frames", "99999999999999999999"] + out,
            "--vtk-frames = 99999999999999999999", f"[0, {steps}]", f"about {steps} steps")
    refused_by(capsys, "triaxial", TRIAXIAL + ["--records", str(steps + 1)] + out,
            f"--records = {steps + 1}", f"[2, {steps}]")
    refused_by(capsys, "triaxial", TRIAXIAL + ["--records", "99999999999999999999"] + out,
            "--records", "[2, 10000000]")
    refused_by(capsys, "triaxial", TRIAXIAL + ["--vtk-every", str(10 * steps)] + out,
            f"--vtk-every = {10 * steps}")
    assert not (tmp_path / "t").exists()


def test_tension_frames_beyond_the_pull_are_refused(capsys, tmp_path):
    out = ["--out", str(tmp_path / "t")]
    steps = int(TensionConfig(cases=[(0.72, 0.01)],
                              sample=tension_sample(particles=200)).pull_steps())
    line = refused_by(capsys, "tension", TENSION + ["--vtk-every", "99999999999999999999"] + out,
                   "--vtk-every = ", f"outside the valid range [0, {steps}]", "the pull")
    assert "dtype" not in line
    refused_by(capsys, "tension", TENSION + ["--max-strain", "1e-5"] + out,
            "--vtk-frames = 20", "the pull to --max-strain 1e-05")
    with pytest.raises(ValueError, match="^vtk_every = "):
        TensionConfig(cases=[(0.72, 0.01)], vtk_every=steps + 1)
    assert TensionConfig(cases=[(0.72, 0.01)], vtk_every=steps).vtk_every == steps
    assert not (tmp_path / "t").exists()


@pytest.mark.parametrize("option, value, repeated", [
    ("--void-ratio", "0.72,0.72", "repeats 0.72"),
    ("--water-content", "1,0.5,1", "repeats 1"),
])
def test_repeated_list_values_are_refused(option, value, repeated, capsys, tmp_path):
    argv = ["--particles", "200", "--quiet", option, value, "--out", str(tmp_path / "t")]
    refused_by(capsys, "tension", argv, option, repeated)
    assert not (tmp_path / "t").exists()


def test_cases_sharing_a_folder_are_refused():
    assert case_name(0.721, 0.01) == case_name(0.722, 0.01) == "e0.72_w1.00"
    with pytest.raises(ValueError, match=r"^cases: .*\(e 0\.721, w 1 %\) "
                                         r".*share the folder e0\.72_w1\.00"):
        TensionConfig(cases=[(0.721, 0.01), (0.722, 0.01)])
    assert len(TensionConfig(cases=[(0.72, 0.01), (0.58, 0.01)]).cases) == 2


def test_options_a_mode_ignores_are_refused(capsys, tmp_path):
    out = ["--out", str(tmp_path / "t")]
    for depth in ("2", "1"):                  # the default, given, is ignored all the same
        refused_by(capsys, "tension", TENSION + ["--periodic", "--grip-depth", depth] + out,
                f"--grip-depth = {depth}", "--periodic", "no grips")
    with pytest.raises(ValueError, match="^grip_depth = 2 does not apply to --periodic"):
        TensionConfig(cases=[(0.72, 0.01)], sample=tension_sample(periodic=True),
                      grip_depth=2.0)
    assert TensionConfig(cases=[(0.72, 0.01)],
                         sample=tension_sample(periodic=True)).grip_depth == 1.0
    sample = str(tmp_path / "sample.h5")
    refused_by(capsys, "triaxial", TRIAXIAL + ["--sample", sample, "--porosity", "0.45"] + out,
            "--porosity", "--sample", "already prepared")
    refused_by(capsys, "triaxial", TRIAXIAL + ["--sample", sample, "--prep-friction", "5"] + out,
            "--prep-friction", "--sample")
    assert not (tmp_path / "t").exists()


def test_a_grading_curve_with_a_third_column_is_refused(capsys, tmp_path):
    path = tmp_path / "psd.csv"
    path.write_text("diameter,passing,note\n# sieves\n3e-5,0\n\n4e-5,50,7\n6e-5,100\n")
    with pytest.raises(ValueError, match=r"psd\.csv': row 5 \['4e-5', '50', '7'\] has 3 "
                                         r"values; valid: 2"):
        read_grading_curve(path)
    refused_by(capsys, "triaxial", TRIAXIAL + ["--psd", str(path), "--out", str(tmp_path / "t")],
            str(path), "row 5", "3 values")
    path.write_text("3e-5,0,\n4e-5,50, \n6e-5,100\n")           # empty trailing cells
    assert read_grading_curve(path) == ((3e-5, 0.0), (4e-5, 50.0), (6e-5, 100.0))
    path.write_text("3e-5,0\n\n4e-5,fifty\n6e-5,100\n")
    with pytest.raises(ValueError, match=r"row 3 \['4e-5', 'fifty'\] is not"):
        read_grading_curve(path)


def test_a_case_without_kim_measurement_says_so():
    summary = {"case": "e0.72_w1.00", "tensile_strength_pa": 512.34, "kim_measured_pa": None,
               "packing_state_pa": 601.0}
    line = case_line(summary)
    assert "None" not in line and "no Kim measurement" in line and "512.3 Pa" in line
    assert "Kim 480.0 Pa" in case_line(dict(summary, kim_measured_pa=480.0))


def test_tension_surface_tension_is_chapter4s():
    """The tension default stays thesis Chapter 4's 0.074 N/m (the value its comparison with
    Kim and the regular packing prediction use), a constant apart from Chapter 5's 0.073."""
    from pendular.capillary import SURFACE_TENSION
    from pendular.procedures.reference import CHAPTER4_SURFACE_TENSION

    assert TensionConfig().surface_tension == CHAPTER4_SURFACE_TENSION == 0.074
    assert SwccConfig().surface_tension == SURFACE_TENSION == 0.073


# ---------------------------------------------------------------- the guard
@pytest.fixture(scope="module")
def prepared():
    """A static 60-sphere sample at 750 Pa (its simulation and configuration); copy it."""
    sample = PrepareConfig(particles=60, seed=1, unload_steps=400)
    sim, _ = prepare_sample(sample, progress=False)
    return sim, sample


def test_a_static_sample_is_within_the_bounds(prepared):
    sim, _ = prepared
    overlap, measured = SampleGuard(10).check(sim)
    assert 0.0 < overlap < 0.1 * MAX_OVERLAP_OVER_RADIUS
    assert measured == porosity(sim.particles, sim.walls)
    assert overlap == largest_overlap(sim)


def test_a_squeezed_sample_stops_naming_the_bound(prepared):
    sim, _ = prepared
    sim = copy.deepcopy(sim)
    axial = ConstantStrainRate("z", 200.0, sim.walls.lengths()[2])
    sim.controls = [axial]                       # the lateral walls held: the volume shrinks
    sim.writers.append(SampleGuard(20, describe=lambda s: f"axial strain "
                                                          f"{axial.strain(s.walls):.3f}"))
    with pytest.raises(SampleCrushed) as crushed:
        sim.run(axial.steps_to(0.6, sim.dt))
    message = str(crushed.value)
    assert isinstance(crushed.value, ValueError)
    assert "the sample is crushed at step" in message and "axial strain 0." in message
    assert f"beyond the bound {MAX_OVERLAP_OVER_RADIUS:g}" in message or (
        f"[{MIN_POROSITY_EQUAL:.3g}, " in message)
    assert "--max-strain" in message and "--young" in message
    assert sim.step % 20 == 0 and axial.strain(sim.walls) < 0.6


def test_the_porosity_bounds_are_checked(prepared):
    sim, _ = prepared
    measured = porosity(sim.particles, sim.walls)
    guard = SampleGuard(1, porosity_range=(measured + 0.01, 0.9), remedy="raise --porosity")
    with pytest.raises(SampleCrushed, match=rf"porosity {measured:.3g}, outside the range "
                                            rf"\[{measured + 0.01:.3g}, 0\.9\].*raise --porosity"):
        guard.check(sim)
    for bad in ((0.5, 0.4), (0.2, 0.3, 0.4), (-0.1, 0.5)):
        with pytest.raises(ValueError, match="porosity_range"):
            SampleGuard(1, porosity_range=bad)
    with pytest.raises(ValueError, match="guard period"):
        SampleGuard(0)


def test_a_normal_shear_does_not_trip_the_guard_nor_change_it(prepared):
    sim, sample = prepared
    shear = ShearConfig(max_strain=0.01, inertial_number=2e-3, records=20)
    histories = []
    for guarded in (False, True):
        scene = copy.deepcopy(sim)
        run = TriaxialShear(scene, shear, sample.confining, sample.radius, sample.density)
        if guarded:
            scene.writers.append(SampleGuard(run.recorder.period))
        scene.run(run.steps)
        histories.append(run.recorder.arrays())
    unguarded, guarded = histories
    assert guarded["axial_strain"][-1] == pytest.approx(0.01, rel=0.02)
    sigma = guarded["sigma_wall"]
    q = sigma[:, 2] - 0.5 * (sigma[:, 0] + sigma[:, 1])
    assert summarize(guarded)["peak_q"] == q.max() > 0.0
    for name in unguarded:
        np.testing.assert_array_equal(guarded[name], unguarded[name], err_msg=name)


def test_a_periodic_cell_has_no_wall_overlaps():
    sample = PrepareConfig(particles=60, seed=1, unload_steps=400, periodic=True)
    sim, _ = prepare_sample(sample, progress=False)
    overlap, measured = SampleGuard(1).check(sim)
    touching = sim.contacts.overlap > 0.0
    assert overlap == pytest.approx(np.max(sim.contacts.overlap[touching])
                                    / sim.particles.radius[0])
    assert MIN_POROSITY_EQUAL < measured < 0.45
