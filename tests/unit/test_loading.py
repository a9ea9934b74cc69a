"""Loading paths (pendular.procedures.loading): a stage's per-axis control and its checks, the
mixed conditions' targets, the laboratory paths as stages, and the results' closed forms
(friction angle, b, compression indices), and the run of a stage (run_stage) that every
procedure's stages share."""

import math

import numpy as np
import pytest

from conftest import StressScene

from pendular.dem.walls import ConstantStrainRate, StressServo
from pendular.procedures.isotropic import IsotropicConfig
from pendular.procedures.oedometer import OedometerConfig
from pendular.procedures.preparation import PrepareConfig
from pendular.procedures.config import ShearConfig, config_from_dict, config_to_dict
from pendular.procedures.triaxial import TriaxialConfig
from pendular.dem.simulation import Simulation
from pendular.procedures.loading import MixedStress, Stage, Static, Strain, Stress, run_stage
from pendular.dem.mixed_stress import StageFailed
from pendular.procedures.columns import friction_angle
from pendular.procedures.isotropic import isotropic_stages, isotropic_summary
from pendular.procedures.triaxial import measured_b, shear_stage
from pendular.procedures.oedometer import oedometer_stages, oedometer_summary


def test_the_triaxial_shear_is_one_stage_of_per_axis_control():
    stage = shear_stage(ShearConfig(max_strain=0.2), 750.0, 2.5)
    assert stage.stress == {"x": 750.0, "y": 750.0} and stage.strain_rate == {"z": 2.5}
    assert isinstance(stage.until, Strain) and stage.until.value == 0.2
    extension = shear_stage(ShearConfig(max_strain=0.1, direction="extension"), 750.0, 2.5)
    assert extension.strain_rate == {"z": -2.5} and extension.until.value == -0.1
    true = shear_stage(ShearConfig(b=0.5), 750.0, 2.5)
    assert true.stress == {"x": 750.0} and true.free == ("y",) and true.b == 0.5
    constant = shear_stage(ShearConfig(constant_p=True), 750.0, 2.5)
    assert constant.free == ("x", "y") and constant.mean_stress == 750.0
    # b = 0 alone is the conventional compression (one servo for x and y, bit for bit)
    assert shear_stage(ShearConfig(b=0.0), 750.0, 2.5).stress == {"x": 750.0, "y": 750.0}


def test_oedometric_and_isotropic_paths_as_stages():
    load, unload = oedometer_stages(10000.0, 3.0, unload_to=500.0)
    for stage, rate, end in ((load, 3.0, 10000.0), (unload, -3.0, 500.0)):
        assert stage.strain_rate == {"x": 0.0, "y": 0.0, "z": rate}
        assert isinstance(stage.until, Stress) and stage.until.value == end
    stages = isotropic_stages([500.0, 2000.0, 500.0], 3.0, max_steps=1000)
    assert [s.stress for s in stages] == [{a: v for a in "xyz"} for v in (500.0, 2000.0, 500.0)]
    assert all(isinstance(s.until, Static) and s.max_strain_rate == 3.0 for s in stages)


@pytest.mark.parametrize("build, words", [
    (lambda: Stage(stress={"x": 1.0, "y": 1.0}, strain_rate={"z": 1.0, "x": 0.0},
                   until=Strain(0.1)), "not both"),
    (lambda: Stage(stress={"x": 1.0}, strain_rate={"z": 1.0}, until=Strain(0.1)),
     "axis y has neither"),
    (lambda: Stage(stress={"w": 1.0}), "stress axis = 'w'"),
    (lambda: Stage(stress={"x": -5.0, "y": 1.0, "z": 1.0}), "stress['x'] = -5.0"),
    (lambda: Stage(stress={"x": 1.0}, strain_rate={"z": 1.0}, b=1.5, until=Strain(0.1)),
     "b = 1.5 is outside the valid range [0, 1]"),
    (lambda: Stage(stress={"x": 1.0}, strain_rate={"z": -1.0}, b=0.5, until=Strain(-0.1)),
     "sigma_1 on z"),
    (lambda: Stage(strain_rate={"z": 1.0}, b=0.5, until=Strain(0.1)), "give x a stress"),
    (lambda: Stage(stress={"x": 1.0, "y": 1.0}, strain_rate={"z": 0.0}, mean_stress=1.0),
     "non-zero strain rate"),
    (lambda: Stage(stress={"x": 1.0, "y": 1.0, "z": 1.0}, until=Strain(0.1)),
     "until strain on z needs z driven"),
    (lambda: Stage(stress={"x": 1.0, "y": 1.0}, strain_rate={"z": 1.0}), "keeps moving"),
    (lambda: Stage(stress={"x": 1.0, "y": 1.0}, strain_rate={"z": 1.0}, until=Strain(0.9)),
     "until strain = 0.9"),
])
def test_a_stage_refuses_what_it_cannot_hold_naming_it(build, words):
    with pytest.raises(ValueError, match=words.replace("[", r"\[").replace("(", r"\(")):
        build()


def mixed(stage):
    servos = {axis: StressServo("xyz"[axis], 1.0, 1.0) for axis in (0, 1)}
    return MixedStress(stage, servos), servos


@pytest.mark.parametrize("b", [0.0, 0.3, 1.0])
def test_mixed_conditions_set_the_lateral_targets_of_their_closed_forms(b):
    sigma = (700.0, 900.0, 1200.0)
    # constant p: sigma_x = sigma_y = (3 p - sigma_z) / 2
    control, servos = mixed(Stage(strain_rate={"z": 1.0}, mean_stress=1000.0,
                                  until=Strain(0.1)))
    control.apply(StressScene(sigma))
    assert servos[0].target == servos[1].target == pytest.approx((3000.0 - 1200.0) / 2)
    # b alone: sigma_y = sigma_3 + b (sigma_1 - sigma_3), sigma_3 the target of x
    control, servos = mixed(Stage(stress={"x": 750.0}, strain_rate={"z": 1.0}, b=b,
                                  until=Strain(0.1)))
    control.apply(StressScene(sigma))
    assert servos[1].target == pytest.approx(750.0 + b * (1200.0 - 750.0))
    # both: p and b hold together
    control, servos = mixed(Stage(strain_rate={"z": 1.0}, mean_stress=1000.0, b=b,
                                  until=Strain(0.1)))
    control.apply(StressScene(sigma))
    s3, s2 = servos[0].target, servos[1].target
    assert (s3 + s2 + 1200.0) / 3.0 == pytest.approx(1000.0)
    assert (s2 - s3) / (1200.0 - s3) == pytest.approx(b)


def test_a_mixed_condition_that_needs_walls_to_pull_stops_the_stage():
    control, _ = mixed(Stage(strain_rate={"z": 1.0}, mean_stress=1000.0, until=Strain(0.1)))
    with pytest.raises(StageFailed, match="walls cannot pull"):
        control.apply(StressScene((700.0, 700.0, 3500.0)))        # 3 p - sigma_z < 0


def test_steps_to_a_strain_from_a_strain_in_either_direction():
    axial = ConstantStrainRate("z", 2.0, 1.0)
    assert axial.steps_to(0.1, 1e-3) == 50
    assert axial.steps_to(0.15, 1e-3, start=0.1) == 25
    pulled = ConstantStrainRate("z", -2.0, 1.0)
    assert pulled.steps_to(-0.1, 1e-3) == 50
    true = ConstantStrainRate("z", -2.0, 1.0, on_current_length=True)
    # L = L0 (1 + 2 dt)^n reaches 1.1 L0 after ceil(log 1.1 / log 1.002) steps
    assert true.steps_to(-0.1, 1e-3) == math.ceil(math.log(1.1) / math.log(1.002))
    with pytest.raises(ValueError, match="sign of the change"):
        axial.steps_to(0.05, 1e-3, start=0.1)


def test_friction_angle_and_b_of_principal_stresses():
    # sin phi = (s1 - s3) / (s1 + s3): s1 = 3 s3 is 30 degrees, whichever axis holds s1
    assert friction_angle([100.0, 100.0, 300.0]) == pytest.approx(30.0)
    assert friction_angle([300.0, 300.0, 100.0]) == pytest.approx(30.0)
    assert friction_angle([100.0, 200.0, 300.0]) == pytest.approx(30.0)
    assert np.isnan(friction_angle([0.0, 0.0, 0.0]))
    b = measured_b(np.array([[100.0, 150.0, 300.0], [100.0, 101.0, 102.0]]), 150.0)
    assert b[0] == pytest.approx(0.25) and np.isnan(b[1])     # sigma_z - sigma_x too small


def test_compression_and_swelling_indices_of_an_e_log_p_path():
    """e = e0 - Cc log10(p / p0) on loading and e = e_max + Cs log10(p_max / p) on unloading."""
    stresses = [500.0, 1000.0, 5000.0, 1000.0, 500.0]
    cc, cs = 0.05, 0.01
    void = [0.8, 0.8 - cc * math.log10(2.0), 0.8 - cc * math.log10(10.0)]
    void += [void[-1] + cs * math.log10(5.0), void[-1] + cs * math.log10(10.0)]
    history = {"sigma_wall": np.array([[p, p, p] for p in stresses]),
               "void_ratio": np.array(void), "stage": np.arange(5),
               "volumetric_strain": np.zeros(5), "step": np.arange(5) * 10}
    summary = isotropic_summary(history, stresses)
    assert summary["compression_index"] == pytest.approx(cc)
    assert summary["swelling_index"] == pytest.approx(cs)
    assert [row["target"] for row in summary["stages"]] == stresses


def test_oedometer_summary_reads_k0_and_the_constrained_modulus():
    """A linear path sigma_v = M eps, sigma_h = K0 sigma_v from 500 Pa, unloaded halfway."""
    modulus, k = 2e5, 0.45
    strain = np.concatenate([np.linspace(0.0, 0.02, 21), np.linspace(0.02, 0.015, 6)[1:]])
    axial = 500.0 + modulus * strain
    lateral = np.where(np.arange(26) <= 20, 500.0 + k * modulus * strain, 0.0)
    history = {"sigma_wall": np.stack([lateral, lateral, axial], axis=1),
               "axial_strain": strain, "void_ratio": 0.8 - strain,
               "stage": (np.arange(26) > 20).astype(int)}
    summary = oedometer_summary(history, axial[20], unload_to=axial[-1])
    assert summary["k0"] == pytest.approx((500.0 + k * modulus * 0.02) / (500.0 + modulus * 0.02))
    assert summary["constrained_modulus"] == pytest.approx(modulus)
    assert summary["constrained_modulus_tangent"] == pytest.approx(modulus)
    assert summary["constrained_modulus_unloading"] == pytest.approx(modulus)
    assert summary["compression_index"] == pytest.approx(0.02 / math.log10(axial[20] / 500.0))


@pytest.mark.parametrize("build, words", [
    (lambda: ShearConfig(b=-0.1), "b = -0.1 is outside the valid range [0, 1]"),
    (lambda: ShearConfig(b=0.5, direction="extension"), "needs --direction compression"),
    (lambda: ShearConfig(direction="sideways"), "direction = 'sideways'"),
    (lambda: OedometerConfig(sample=PrepareConfig(particles=100, confining=500.0),
                             axial_stress=400.0), "axial_stress = 400 Pa"),
    (lambda: OedometerConfig(sample=PrepareConfig(particles=100), axial_stress=5000.0,
                             unload_to=6000.0), "unload_to = 6000 Pa is outside"),
    (lambda: IsotropicConfig(sample=PrepareConfig(particles=100), stresses=[500.0, 0.0]),
     "stresses = 0.0 Pa is outside the valid range (0, 1e+07]"),
    (lambda: IsotropicConfig(sample=PrepareConfig(particles=100), stresses=[500.0]),
     "at least 2 stresses"),
])
def test_configurations_refuse_bad_paths_naming_the_option(build, words):
    with pytest.raises(ValueError) as error:
        build()
    assert words in str(error.value)


def test_path_configurations_round_trip_through_json():
    for config in (TriaxialConfig(sample=PrepareConfig(particles=100),
                                  shear=ShearConfig(b=0.25, constant_p=True)),
                   OedometerConfig(sample=PrepareConfig(particles=100), unload_to=500.0),
                   IsotropicConfig(sample=PrepareConfig(particles=100),
                                   stresses=[500.0, 2000.0, 300.0])):
        assert config_from_dict(config_to_dict(config)) == config


# ---------------------------------------------------------------- the run of a stage

class Clock:
    """A scene whose steps change nothing but the step count, run by Simulation's own loop
    (run_chunks), that notes the steps at which a stage's end was asked."""

    def __init__(self, end):
        self.step, self.end, self.asked = 0, end, []

    def run(self, steps, *, until=None, check_every=100, progress=None, status=None):
        def advance():
            self.step += 1
        return Simulation.run_chunks(self, steps, advance, until=until,
                                     check_every=check_every)

    def ended(self, start, every):
        """The stage's end: reached from step ``end`` on, seen at its checks only."""
        def ended(sim):
            self.asked.append(sim.step)
            taken = sim.step - start
            return taken > 0 and taken % every == 0 and sim.step >= self.end
        return ended


def test_a_stage_ends_at_its_first_check_past_its_end():
    clock = Clock(end=700)
    assert run_stage(clock, clock.ended(0, 200), start=0, limit=10000, every=200) == 800
    assert clock.step == 800 and clock.asked[1:] == [200, 400, 600, 800, 800]


def test_a_stage_stopped_between_checks_checks_where_an_uninterrupted_one_did():
    clock = Clock(end=800)
    ended = clock.ended(100, 200)       # the stage started at step 100
    clock.step = 100
    assert run_stage(clock, ended, start=100, limit=10000, every=200, budget=350) == 350
    assert clock.step == 450
    clock.asked.clear()                 # resumed from step 450: next check at 500, not 650
    assert run_stage(clock, ended, start=100, limit=10000, every=200) == 450
    assert clock.step == 900 and [s for s in clock.asked if s > 450] == [500, 700, 900, 900]


def test_a_stage_stops_at_its_limit_and_leaves_the_verdict_to_its_caller():
    clock = Clock(end=math.inf)
    assert run_stage(clock, clock.ended(0, 200), start=0, limit=500, every=200) == 500
    assert clock.step == 500 and clock.asked[1:] == [200, 400, 500, 500]
    assert run_stage(clock, clock.ended(0, 200), start=0, limit=500, every=200) == 0
