"""Undrained shear and water stages on small scenes through the library: a constant-volume
shear of a prepared sample holds its volume to round-off (within 1e-6 of the start over the
whole shear) and its excess pore pressure is, row by row, its definition; a stepped and a ramped
suction reach their targets as stated; a new water content scales the closed liquid of
volume-controlled bridges, keeps the liquid balance and lowers their suction."""


import numpy as np
import pytest

from pendular import capillary
from pendular.capillary import BridgeState, CapillaryBridges
from pendular.homogenize.invariants import deviator_stress, mean_stress
from pendular.procedures.config import ShearConfig
from pendular.procedures.hydraulic import (SuctionChange, WaterContentChange,
    set_water_content, unit_water_volume, water_content)
from pendular.procedures.loading import LoadingPath
from pendular.procedures.triaxial import excess_pore_pressure, shear_stage
from pendular.procedures.preparation import PrepareConfig, prepare_sample
from conftest import RADIUS, two_body_scene

GAMMA = capillary.SURFACE_TENSION


@pytest.fixture(scope="module")
def undrained_history():
    """A 60-sphere sample prepared at 750 Pa, sheared undrained to 1 % axial strain."""
    config = PrepareConfig(particles=60, confining=750.0, seed=1, unload_steps=2000)
    sim, _ = prepare_sample(config, progress=False)
    volume = sim.walls.volume()
    rate = 2e-5 / sim.dt
    path = LoadingPath(sim, [shear_stage(ShearConfig(drainage="undrained", max_strain=0.01),
                                         750.0, rate)], records=50)
    path.run(sim)
    return path.recorder.arrays(), volume, sim


def test_an_undrained_shear_holds_the_volume_of_a_prepared_sample(undrained_history):
    history, volume, sim = undrained_history
    assert history["axial_strain"][-1] == pytest.approx(0.01, rel=1e-3)
    assert np.abs(history["volumetric_strain"]).max() < 1e-6       # the requirement
    assert abs(sim.walls.volume() / volume - 1.0) < 1e-12          # and in fact round-off
    lengths = sim.walls.lengths()
    assert lengths[0] * lengths[1] * lengths[2] == pytest.approx(volume, rel=1e-12)
    # the lateral walls opened as the axial ones closed, the stresses changed (the sample
    # is sheared, not held)
    assert np.ptp(history["sigma_wall"][:, 2]) > 50.0


def test_the_excess_pore_pressure_of_the_run_is_its_definition(undrained_history):
    history, _, _ = undrained_history
    sigma = history["sigma_wall"]
    change = excess_pore_pressure(sigma)
    confining = 750.0                           # the cell pressure, held on the total path
    p_total = confining + deviator_stress(sigma) / 3.0
    expected = (p_total - p_total[0]) - (mean_stress(sigma) - mean_stress(sigma[0]))
    assert change == pytest.approx(expected, abs=1e-9)
    assert change[0] == 0.0 and np.ptp(change) > 1.0


def chain(control="suction"):
    """Spheres A, B, C in a row, touching, wet with bridges of ``control`` at 30 kPa."""
    touching = 2 * RADIUS * (1 - 1e-4)
    bridges = CapillaryBridges(30000.0, GAMMA, control=control)
    sim = two_body_scene([[0, 0, 0], [touching, 0, 0], [2 * touching, 0, 0]],
                         np.zeros((3, 3)), radius=RADIUS, extra=[bridges])
    sim.run(3)
    return sim, bridges


def test_a_suction_steps_or_ramps_to_its_target():
    sim, bridges = chain()
    stepped = SuctionChange(bridges, 20000.0)
    assert not stepped.done
    stepped.apply(sim)
    assert bridges.suction == 20000.0 and stepped.done
    rate = 1000.0 / sim.dt / 4.0                            # 250 Pa a step
    ramp = SuctionChange(bridges, 21100.0, rate)
    values = []
    for _ in range(6):
        ramp.apply(sim)
        values.append(bridges.suction)
    assert values == pytest.approx([20250.0, 20500.0, 20750.0, 21000.0, 21100.0, 21100.0])
    assert ramp.done
    restored = SuctionChange(bridges, 1.0, 1.0)
    restored.load_state(ramp.state_dict())
    assert (restored.target, restored.rate) == (21100.0, rate)
    with pytest.raises(ValueError, match="needs a sample wetted at a suction"):
        SuctionChange(chain("volume")[1], 1000.0)


def test_a_new_water_content_scales_the_closed_liquid_and_lowers_the_suction():
    sim, bridges = chain("volume")
    bridges.close_liquid(sim, "shared")
    state = BridgeState.of(sim.contacts)
    before = state.volume[state.mask()].copy()
    suction = bridges.mean_suction(sim)
    now = water_content(sim, bridges)
    assert now == pytest.approx(100.0 * before.sum() / unit_water_volume(sim.particles))
    change = WaterContentChange(bridges, 1.5 * now)
    change.apply(sim)
    assert change.done
    state = BridgeState.of(sim.contacts)
    assert state.volume[state.mask()] == pytest.approx(1.5 * before, rel=1e-12)
    assert water_content(sim, bridges) == pytest.approx(1.5 * now, rel=1e-12)
    sim.run(1)                                     # looked up again at their new volume
    assert bridges.mean_suction(sim) < suction      # wetter bridges, lower suction
    assert bridges.liquid_balance(sim)[3] < 1e-12   # the closed amount followed
    assert bridges.liquid_initial == pytest.approx(1.5 * before.sum(), rel=1e-12)
    change.apply(sim)                              # once only
    assert water_content(sim, bridges) == pytest.approx(1.5 * now, rel=1e-12)
    with pytest.raises(ValueError, match=r"water_content = 90 % is outside the valid range "
                                         r"\[[0-9.e-]+, [0-9.e-]+\] %"):
        set_water_content(sim, bridges, 90.0)
    suction_sim, suction_bridges = chain()
    with pytest.raises(ValueError, match="needs a sample wetted at a water content"):
        set_water_content(suction_sim, suction_bridges, 1.0)
