"""What the laboratory commands refuse, in one ``<prog>: error: ...`` line naming what the user
typed (exit status 2), never a traceback or a run without an end: output periods beyond any
run, loading rates a path table sets itself, ranges that start where the help says.

Every case runs in-process through pendular.cli.run_command and is refused before anything
runs, unless its docstring says otherwise.
"""

import os

import pytest

from conftest import ROOT, refused, run_in_process

#: A small laboratory run (each case adds to it).
SMALL = ["--particles", "60", "--quiet"]
#: A path table of three stages (K0 loading, unloading, reloading).
OEDOMETER_TABLE = os.path.join(ROOT, "examples", "paths", "oedometer_unload.toml")
#: An output period beyond 2**64.
HUGE = "99999999999999999999"


def refused_here(capsys, tmp_path, command, argv, *words):
    """``pendular command argv --out OUT`` refused in one line holding ``words``, OUT not made;
    the line."""
    out = tmp_path / "out"
    line = refused(*run_in_process(command, [*argv, "--out", str(out)], capsys), *words)
    assert not out.exists()
    return line


# ---------------------------------------------------------------- output periods
@pytest.mark.parametrize("command", ["triaxial", "oedometer", "isotropic", "path"])
@pytest.mark.parametrize("option", ["--vtk-every", "--checkpoint-every"])
def test_an_output_period_beyond_any_run_is_refused_naming_it(command, option, tmp_path,
                                                              capsys):
    table = [OEDOMETER_TABLE] if command == "path" else []
    refused_here(capsys, tmp_path, command, [*table, *SMALL, option, HUGE],
                 f"{option} = {HUGE}", "valid range [0, ")


@pytest.mark.parametrize("command", ["tension", "swcc"])
def test_a_checkpoint_period_beyond_any_run_is_refused_naming_it(command, tmp_path, capsys):
    """A run setting of these commands (not a field of their configurations), checked as it
    is read."""
    refused_here(capsys, tmp_path, command, ["--checkpoint-every", HUGE],
                 f"--checkpoint-every = {HUGE}", "valid range [0, ")


# ---------------------------------------------------------------- loading rates and lengths
def table(tmp_path, *stages):
    """A path table of ``stages`` (TOML text of each [[stage]]) in ``tmp_path``; its path."""
    path = tmp_path / "path.toml"
    path.write_text("".join(f"[[stage]]\n{stage}\n" for stage in stages))
    return str(path)


LATERAL = 'stress = {x = "confining", y = "confining"}\n'


def test_a_table_stage_at_a_strain_rate_that_never_ends_is_refused_naming_it(tmp_path, capsys):
    path = table(tmp_path, LATERAL + 'strain_rate = {z = 1e-30}\n'
                                     'until = {strain = 0.01, axis = "z"}')
    line = refused_here(capsys, tmp_path, "path", [path, *SMALL],
                        f"{path}: stage 1 would take", "steps", "raise its strain rate",
                        "--force")
    assert "--strain-rate" not in line


def test_a_later_stage_counts_its_strain_from_where_the_earlier_one_ended(tmp_path):
    from pendular.procedures.registry import config_from_options

    quick = LATERAL + 'strain_rate = {z = 1.0}\nuntil = {strain = 0.01, axis = "z"}'
    slow = LATERAL + 'strain_rate = {z = 1e-3}\nuntil = {strain = 0.012, axis = "z"}'
    held = 'strain_rate = {x = 0, y = 0, z = 0}\nuntil = "static"'
    servoed = 'stress = {x = 500, y = 500, z = 500}\nuntil = "static"'
    config = config_from_options("path", {"table": table(tmp_path, quick, held, slow, servoed,
                                                         slow), "particles": 60})
    per_step = config.strain_per_step(1.0)
    (_, r1, s1), (_, r3, s3), (_, r5, s5) = config.stage_rates()     # the held ones move none
    assert (r1, r3, r5) == (1.0, 1e-3, 1e-3)
    assert s1 == pytest.approx(0.01 / per_step)
    assert s3 == pytest.approx(0.002 / (1e-3 * per_step))     # from 0.01, held since
    assert s5 is None                                          # z servoed since: unknown


def test_a_table_stage_too_fast_to_be_quasi_static_is_refused_as_the_option_is(tmp_path, capsys):
    path = table(tmp_path, LATERAL + 'strain_rate = {z = 1000}\n'
                                     'until = {strain = 0.01, axis = "z"}')
    refused_here(capsys, tmp_path, "path", [path, *SMALL], f"{path}: stage 1", "strain rate 1e+03",
                 "inertial number", "--force")
    refused_here(capsys, tmp_path, "triaxial", [*SMALL, "--strain-rate", "1e3"], "--strain-rate",
                 "inertial number", "--force")


@pytest.mark.parametrize("command, argv, flag", [
    ("path", [OEDOMETER_TABLE, "--strain-rate"], "--strain-rate"),
    ("oedometer", ["--strain-rate"], "--strain-rate"),
    ("simple-shear", ["--shear-rate"], "--shear-rate"),
])
def test_a_rate_beyond_any_loading_names_the_option_typed(command, argv, flag, tmp_path, capsys):
    line = refused_here(capsys, tmp_path, command, [*SMALL, *argv, "1e300"],
                        f"{flag} = 1e+300", "(0, 1e+06] 1/s")
    assert "stage" not in line


def test_a_simple_shear_too_fast_names_its_shear_rate(tmp_path, capsys):
    line = refused_here(capsys, tmp_path, "simple-shear", [*SMALL, "--shear-rate", "1e3"],
                        "shear rate 1e+03 1/s", "inertial number", "lower --shear-rate")
    assert "--strain-rate" not in line


def test_the_longest_cyclic_test_of_a_large_sample_is_refused_as_too_long(tmp_path, capsys):
    refused_here(capsys, tmp_path, "cyclic", ["--amplitude-strain", "0.001", "--cycles", "10000",
                                              "--quiet"],
                 "would take", "at 10000 spheres", "--cycles", "--particles", "--force")


# ---------------------------------------------------------------- what the user typed
@pytest.mark.parametrize("command, diameters, words", [
    ("triaxial", "1e-7,2e-7,4e-7", ["7.14e-08 m", "[1e-06, 1] m"]),
    ("triaxial", "4,6,8", ["2.63 m", "[1e-06, 1] m"]),
    ("tension", "0.05,0.1,0.2", ["0.0357 m", "[1e-06, 0.01] m", "direct tension"]),
])
def test_grains_of_a_grading_curve_out_of_range_blame_psd(command, diameters, words, tmp_path,
                                                           capsys):
    curve = tmp_path / "psd.csv"
    curve.write_text("".join(f"{d},{p}\n" for d, p in zip(diameters.split(","), (0, 50, 100))))
    line = refused_here(capsys, tmp_path, command, ["--psd", str(curve), "--quiet"],
                        "--psd: the grading curve's mean radius", *words)
    assert "--radius" not in line


def test_a_grip_depth_of_0_grips_the_layer_on_the_wall():
    """The preparation grows the radii past the nominal one: a grip reaches at least the
    largest sphere, so that --grip-depth 0 (the help's lower bound) grips the spheres touching
    the wall instead of failing on a depth the user did not type."""
    import numpy as np

    from pendular.dem.state import Walls
    from pendular.procedures.grips import grip_members, grip_reach

    radius = 1e-4
    radii = np.array([1.0002, 1.0001, 1.0003]) * radius          # grown by the preparation
    position = np.array([[0.0, 0.0, radii[0]], [0.0, 0.0, 3.5 * radius],
                         [0.0, 0.0, radii[2] + 1e-9]])
    walls = Walls.box([-1.0, -1.0, 0.0], [1.0, 1.0, 1.0])
    reach = grip_reach(radius, 0.0, radii)
    assert reach == radii.max()
    assert grip_members(position, radii, walls, 4, reach).tolist() == [0]
    assert grip_reach(radius, 1.0, radii) == 3.0 * radius          # the usual depth, as it was
    assert grip_members(position, radii, walls, 4, grip_reach(radius, 1.5, radii)).tolist() == \
        [0, 1, 2]


def test_a_void_ratio_no_preparation_reaches_states_the_range_in_order(monkeypatch):
    """A small graded sample's void ratio need not fall as the growth friction rises: the
    range refused is the two preparations' void ratios in order, never an inverted one."""
    import types

    from pendular.procedures import tension_pull
    from pendular.procedures.tension import TensionConfig, tension_sample

    reached = {0.0: 0.477, 30.0: 0.429}                 # denser at the higher friction
    monkeypatch.setattr(tension_pull, "prepare_sample", lambda config, **_: (
        types.SimpleNamespace(device="cpu", friction=config.prep_friction_deg),
        {"porosity": 0.3}))
    monkeypatch.setattr(tension_pull, "sample_void_ratio",
                        lambda sim, radius: reached[sim.friction])
    config = TensionConfig(cases=[(0.72, 0.01)], sample=tension_sample(particles=100))
    with pytest.raises(ValueError) as error:
        tension_pull.prepare_void_ratio(config, 0.72, progress=False)
    assert "valid range of this sample, [0.429, 0.477]" in str(error.value)
    assert "growth friction 0 and 30 deg give e = 0.477 and 0.429" in str(error.value)


# ---------------------------------------------------------------- inconsistencies
def test_a_repeat_given_as_text_is_refused_as_other_text_for_numbers_is(tmp_path, capsys):
    path = table(tmp_path, 'repeat = "3"\nstages = [{stress = {x = 500, y = 500, z = 500}}]')
    refused_here(capsys, tmp_path, "path", [path, *SMALL], f"{path}: stage 1", "repeat = '3'",
                 "is text")
    path = table(tmp_path, 'stress = {x = "confining", y = "confining"}\n'
                           'strain_rate = {z = "0.1"}')
    refused_here(capsys, tmp_path, "path", [path, *SMALL], "strain_rate['z'] = '0.1'")


def test_an_isotropic_stress_repeated_in_a_row_is_refused_not_merged(tmp_path, capsys):
    refused_here(capsys, tmp_path, "isotropic", [*SMALL, "--stresses", "1000,1000"],
                 "--stresses = 1000,1000", "stage 2 repeats the 1000 Pa of stage 1")
    from pendular.procedures.registry import config_from_options

    loop = config_from_options("isotropic", {"particles": 60, "stresses": "1000,2000,1000"})
    assert loop.stresses == [1000.0, 2000.0, 1000.0]      # a loading and unloading: valid


def test_the_smallest_simple_shear_is_its_own_documented_minimum(tmp_path, capsys):
    from pendular.procedures.simple_shear import MIN_SIMPLE_SHEAR_PARTICLES
    from pendular.procedures.registry import options_of

    particles = next(o for o in options_of("simple-shear") if o.key == "particles")
    assert f"valid range [{MIN_SIMPLE_SHEAR_PARTICLES}, " in particles.help
    refused_here(capsys, tmp_path, "simple-shear", ["--particles", "50", "--quiet"],
                 "--particles = 50", f"[{MIN_SIMPLE_SHEAR_PARTICLES}, ", "periodic cell")


def test_the_crosschecks_settling_beyond_its_bound_names_settle_steps(tmp_path, capsys):
    line = refused_here(capsys, tmp_path, "crosscheck", ["--settle-steps", HUGE],
                        f"--settle-steps = {HUGE}", "[0, 100000000]")
    assert "--wet-steps" not in line and "YADE" not in line


def test_resuming_a_run_stopped_before_its_sample_says_so(tmp_path, capsys):
    """The folder of a run interrupted during its preparation holds no sample.h5: nothing to
    resume, whatever its --checkpoint-every."""
    folder = tmp_path / "stopped"
    folder.mkdir()
    line = refused(*run_in_process("oedometer", ["--resume", str(folder)], capsys),
                   "sample.h5 is missing", "before its sample existed", "run it again")
    assert "checkpoint_every" not in line


@pytest.mark.parametrize("command, missing, words", [
    ("swcc", "sample.h5", ["before its sample existed (in the preparation)"]),
    ("tension", "checkpoint.h5", ["before its first checkpoint", "--checkpoint-every 0"]),
])
def test_every_resume_refuses_a_folder_without_its_files_as_the_tests_do(command, missing, words,
                                                                       tmp_path, capsys):
    """The SWCC and the direct tension check the folder of a resume as the laboratory tests
    do (pendular.procedures.resume): one line naming the folder and the missing file."""
    folder = tmp_path / "stopped"
    folder.mkdir()
    refused(*run_in_process(command, ["--resume", str(folder)], capsys),
            f"resume = {str(folder)!r}", f"{missing} is missing", *words, "run it again")


# ---------------------------------------------------------------- direct tension's water
def test_a_water_content_too_low_for_the_compared_packing_names_it_and_its_range(tmp_path,
                                                                                capsys):
    """Below the least water content whose bridges span the separation of the regular
    packing a case is compared with, the refusal names --water-content and its range for the
    sample, not the bridge solver's internal distance."""
    line = refused_here(capsys, tmp_path, "tension",
                        ["--particles", "100", "--void-ratio", "0.7", "--water-content", "0.001",
                         "--quiet"],
                        "--water-content = 0.001 % is outside the valid range [",
                        "% of a sample of void ratio 0.7")
    assert "distance_star" not in line


def test_the_least_water_content_is_where_the_compared_packing_starts_to_hold_bridges():
    """The bound of the refusal above, against pendular.homogenize.packing_state: the
    prediction of the compared packing exists just above it, and not just below."""
    from pendular.procedures.tension import TensionConfig, tension_sample
    from pendular.procedures.tension_pull import prediction

    config = TensionConfig(cases=[(0.7, 0.01)], sample=tension_sample(particles=100))
    least = config.least_water_content(0.7)
    assert 0.0 < least < config.pendular_limit(0.7)
    assert prediction(config, 0.7, least * 1.01)[0] > 0.0
    with pytest.raises(ValueError):
        prediction(config, 0.7, least * 0.99)


def test_too_much_water_for_a_graded_sample_names_the_options_typed(monkeypatch):
    """A water content whose bridges would pass the pendular limit at the contacts of a
    graded sample's smallest grains is refused naming --water-content and the size option
    that made those grains (--radius-spread), not a suction and a radius the user never
    typed. The wetting itself is replaced by what the bridges' check raises."""
    import types

    import numpy as np

    from pendular.capillary.validation import NotPendular
    from pendular.procedures import tension_pull
    from pendular.procedures.tension import TensionConfig, tension_sample
    from pendular.utils.parameters import ParameterError

    def too_wet(*_, **__):
        raise NotPendular("suction = 2676.82 Pa is outside the valid range [3748, inf) Pa",
                          2676.82, 3748.0, 5.5e-5, 49.8)

    monkeypatch.setattr(tension_pull, "wet_to_water_volume", too_wet)
    monkeypatch.setattr(tension_pull.BridgeTable, "cached", lambda *_, **__: None)
    particles = types.SimpleNamespace(radius=np.full(4, 1.1e-4), solid_volume=lambda: 1e-9)
    contacts = types.SimpleNamespace(overlap=np.ones(2), pair_i=np.array([0, 1]),
                                     pair_j=np.array([2, 3]))
    dry = types.SimpleNamespace(particles=particles, contacts=contacts)
    config = TensionConfig(cases=[(0.7, 0.01)], form_gap=0.0,
                           sample=tension_sample(particles=100, radius_spread=0.5))
    with pytest.raises(ParameterError) as error:
        tension_pull.wet(dry, config, 0.01, progress=False)
    line = error.value.on_command_line()
    assert line.startswith("--water-content = 1 % is more than this sample "
                           "(--radius-spread 0.5) holds in the pendular regime")
    assert "lower --water-content or the size spread" in line
