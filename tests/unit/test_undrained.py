"""Undrained (constant-volume) shear: the ConstantVolume control (pendular.dem.walls) against
the volume it holds, step by step, between walls and in a periodic cell; the excess pore
pressure against its definition (pendular.procedures.triaxial.excess_pore_pressure); the
stage's and the configuration's refusals; the undrained summary of a hand-made history."""

from types import SimpleNamespace

import numpy as np
import pytest

from pendular.dem.cell import PeriodicCell
from pendular.dem.state import Walls
from pendular.dem.walls import ConstantStrainRate, ConstantVolume
from pendular.procedures.config import BridgeConfig, ShearConfig
from pendular.procedures.preparation import PrepareConfig
from pendular.procedures.triaxial import TriaxialConfig
from pendular.procedures.loading import Stage, Strain
from pendular.procedures.triaxial import excess_pore_pressure, shear_stage, undrained_summary
from pendular.utils.parameters import ParameterError


@pytest.mark.parametrize("periodic", [False, True])
@pytest.mark.parametrize("rate", [2.0, -3.0])
def test_constant_volume_holds_the_volume_as_z_is_driven(periodic, rate):
    lo, hi = np.zeros(3), np.array([1.0, 2.0, 4.0])
    box = PeriodicCell.box(lo, hi) if periodic else Walls.box(lo, hi)
    sim = SimpleNamespace(walls=box, dt=1e-3)
    volume = box.volume()
    controls = [ConstantStrainRate("z", rate, hi[2]), ConstantVolume(volume)]
    for step in range(1, 101):
        for op in controls:
            op.apply(sim)
        lengths = box.lengths()
        # z at its imposed engineering strain, x and y scaled alike (their ratio kept)
        assert lengths[2] == pytest.approx(hi[2] * (1.0 - rate * 1e-3 * step), rel=1e-12)
        assert lengths[1] / lengths[0] == pytest.approx(2.0, rel=1e-12)
        assert abs(box.volume() / volume - 1.0) < 1e-14
    if not periodic:        # the walls move symmetrically, at the velocity of their last shift
        centre = 0.5 * (box.position[0::2] + box.position[1::2])
        assert centre == pytest.approx(0.5 * hi, rel=1e-12)
        assert np.sign(box.velocity[1]) == np.sign(rate)     # compression: x opens


def test_constant_volume_checkpoints_its_volume():
    held = ConstantVolume(3.0)
    other = ConstantVolume(1.0)
    other.load_state(held.state_dict())
    assert other.volume == 3.0
    with pytest.raises(ValueError, match="volume = -1"):
        ConstantVolume(-1.0)


def test_excess_pore_pressure_is_the_total_mean_stress_change_less_the_effective_one():
    confining = 500.0
    sigma = np.array([[500.0, 502.0, 499.0], [450.0, 440.0, 900.0], [700.0, 720.0, 2100.0]])
    change = excess_pore_pressure(sigma)
    # the definition: p_total = sigma_3 + q / 3 along the conventional total path (sigma_3,
    # the cell pressure, held), p' the mean wall stress, both from the first record
    q = sigma[:, 2] - 0.5 * (sigma[:, 0] + sigma[:, 1])
    p_total = confining + q / 3.0
    p_effective = sigma.mean(axis=1)
    expected = (p_total - p_total[0]) - (p_effective - p_effective[0])
    assert change == pytest.approx(expected, abs=1e-12)
    # = the fall of the effective lateral stress: u rises as sigma'_3 falls
    lateral = 0.5 * (sigma[:, 0] + sigma[:, 1])
    assert change == pytest.approx(-(lateral - lateral[0]), abs=1e-12)
    assert change[0] == 0.0 and change[1] > 0.0 > change[2]


def test_undrained_summary_of_a_hand_made_history():
    rows = 40
    strain = np.linspace(0.0, 0.1, rows)
    lateral = 500.0 - 3000.0 * strain + 40000.0 * strain ** 2     # contracts, then dilates
    axial = lateral + 20000.0 * strain
    sigma = np.stack([lateral, lateral, axial], axis=1)
    history = {"sigma_wall": sigma, "axial_strain": strain,
               "volumetric_strain": np.full(rows, 1e-16),
               "excess_pore_pressure": excess_pore_pressure(sigma)}
    summary = undrained_summary(history, rows - 1)
    assert summary["excess_pore_pressure_at_peak"] == pytest.approx(-(lateral[-1] - 500.0))
    assert summary["excess_pore_pressure_max"] == pytest.approx(-(lateral.min() - 500.0))
    p = sigma.mean(axis=1)
    assert summary["p_min"] == p.min()
    assert summary["axial_strain_at_p_min"] == strain[np.argmin(p)]
    assert summary["max_volume_change"] == 1e-16
    path = summary["effective_stress_path"]
    assert path["p"][0] == p[0] and path["p"][-1] == p[-1] and len(path["q"]) == 21
    assert all(type(v) is float for v in path["excess_pore_pressure"])


def test_an_undrained_shear_is_one_constant_volume_stage():
    stage = shear_stage(ShearConfig(drainage="undrained", max_strain=0.1), 500.0, 2.0)
    assert stage == Stage(strain_rate={"z": 2.0}, volume="constant", until=Strain(0.1))
    extension = shear_stage(ShearConfig(drainage="undrained", direction="extension"), 500.0, 2.0)
    assert extension.strain_rate == {"z": -2.0} and extension.volume == "constant"
    # drained as before
    assert shear_stage(ShearConfig(), 500.0, 2.0) == Stage(
        stress={"x": 500.0, "y": 500.0}, strain_rate={"z": 2.0}, until=Strain(0.25))


@pytest.mark.parametrize("fields, words", [
    ({"volume": "constnat"}, ["volume = 'constnat'; valid: 'constant'"]),
    ({"volume": "constant", "stress": {"x": 5.0}},
     ["moves x and y to hold the volume: give them neither"]),
    ({"volume": "constant", "mean_stress": 500.0}, ["moves x and y"]),
    ({"volume": "constant", "strain_rate": {"z": 0.0}}, ["needs z driven at a non-zero"]),
])
def test_a_constant_volume_stage_is_refused_when_the_volume_cannot_set_x_and_y(fields, words):
    fields = {"strain_rate": {"z": 1.0}, "until": Strain(0.1), **fields}
    with pytest.raises(ValueError) as raised:
        Stage(**fields)
    for word in words:
        assert word in str(raised.value)


def test_undrained_refuses_b_and_constant_p_and_holds_the_water_of_a_wet_sample():
    for other in ({"b": 0.5}, {"constant_p": True}):
        with pytest.raises(ParameterError, match="drainage = 'undrained' holds the volume"):
            ShearConfig(drainage="undrained", **other)
    with pytest.raises(ParameterError, match="drainage = 'undecided'"):
        ShearConfig(drainage="undecided")
    sample = PrepareConfig(particles=100, confining=500.0)
    wet = TriaxialConfig(sample=sample, bridges=BridgeConfig(30000.0),
                         shear=ShearConfig(drainage="undrained"))
    assert wet.undrained and wet.bridges.control == "volume"      # bridges of constant volume
    drained = TriaxialConfig(sample=sample, bridges=BridgeConfig(30000.0))
    assert not drained.undrained and drained.bridges.control == "suction"
    with pytest.raises(ParameterError, match="--persist-bridges do not apply"):
        TriaxialConfig(sample=sample, bridges=BridgeConfig(30000.0, persist=True),
                       shear=ShearConfig(drainage="undrained"))


def test_a_device_other_than_the_cpu_refuses_the_host_only_stages():
    from pendular.procedures.loading import check_stages_device

    undrained = Stage(strain_rate={"z": 1.0}, volume="constant", until=Strain(0.1))
    wetting = Stage(stress={a: 500.0 for a in "xyz"}, suction=1000.0)
    for stage, key in ((undrained, "volume = 'constant'"), (wetting, "suction = 1000.0")):
        check_stages_device([stage], "cpu")
        with pytest.raises(ValueError, match=f"--device gpu: stage 2 has {key}, whose control "
                                             "runs on the CPU only; valid: --device cpu"):
            check_stages_device([Stage(stress={a: 500.0 for a in "xyz"}), stage], "gpu")
