"""Cyclic triaxial loading (pendular.procedures.cyclic): its stages, the loop measures against
closed forms on synthetic loops, the summary of a synthetic history, and a strain cycle of the
smallest amplitude on an elastic lattice against its closed-form modulus."""

import itertools
import math

import numpy as np
import pytest

from conftest import StressScene

from pendular.dem.state import Particles, Walls
from pendular.procedures.config import MIN_AXIAL_STRAIN, config_from_dict, config_to_dict
from pendular.procedures.preparation import PrepareConfig
from pendular.procedures.cyclic import CyclicConfig
from pendular.procedures.cyclic import (CyclicPath, cycle_of, cyclic_stages, cyclic_summary,
    damping_resolution, loop_measures)
from pendular.procedures.guards import AxialStressGuard
from pendular.dem.mixed_stress import StageFailed
from pendular.procedures.loading import Strain, Stress
from pendular.procedures.preparation import servoed_simulation
from pendular.procedures.equilibrium import equilibrate


def test_a_cyclic_path_is_a_first_loading_then_unloadings_and_reloadings():
    stages = cyclic_stages(500.0, 2.0, 3, amplitude_q=200.0)
    assert len(stages) == 7
    for k, stage in enumerate(stages):
        sign = 1.0 if k % 2 == 0 else -1.0
        assert stage.stress == {"x": 500.0, "y": 500.0}
        assert stage.strain_rate == {"z": sign * 2.0}
        assert isinstance(stage.until, Stress) and stage.until.axis == "z"
        assert stage.until.value == 500.0 + sign * 200.0
    strained = cyclic_stages(500.0, 2.0, 2, amplitude_strain=1e-3)
    assert [s.until.value for s in strained] == [1e-3, -1e-3, 1e-3, -1e-3, 1e-3]
    assert all(isinstance(s.until, Strain) for s in strained)
    assert [cycle_of(k) for k in range(7)] == [0, 1, 1, 2, 2, 3, 3]
    with pytest.raises(ValueError, match="one of amplitude_q"):
        cyclic_stages(500.0, 2.0, 1, amplitude_q=1.0, amplitude_strain=1e-3)


def test_the_configuration_takes_one_amplitude_and_round_trips_through_json():
    sample = PrepareConfig(particles=100, confining=500.0)
    config = CyclicConfig(sample=sample, amplitude_q=250.0, cycles=3)
    assert config_from_dict(config_to_dict(config)) == config
    assert config.reference_pressure() == pytest.approx(500.0 - 250.0 / 3.0)
    assert config.estimated_steps() is None
    strained = CyclicConfig(sample=sample, amplitude_strain=1e-3, cycles=2)
    assert strained.estimated_steps() == pytest.approx(
        9e-3 / strained.strain_per_step(strained.rate()))
    for fields, words in (({}, "give exactly one"),
                          ({"amplitude_q": 1.0, "amplitude_strain": 1e-3}, "give exactly one"),
                          ({"amplitude_q": 500.0}, "(0, 500) Pa"),
                          ({"amplitude_strain": 0.0}, "amplitude_strain = 0.0"),
                          ({"amplitude_q": 100.0, "cycles": 0}, "cycles = 0")):
        with pytest.raises(ValueError, match=words.replace("(", r"\(").replace(")", r"\)")):
            CyclicConfig(sample=sample, **fields)


def test_a_linear_elastic_loop_has_its_modulus_and_no_damping():
    """q = E eps up and down the same line: E_sec = E, W_D = 0 (the trapezoids of a linear q
    are exact, so the out and back integrals cancel to round-off)."""
    young = 3.7e7
    t = np.linspace(0.5 * math.pi, 2.5 * math.pi, 401)
    strain = 2e-4 * np.sin(t)
    modulus, damping, dissipated, stored = loop_measures(strain, young * strain)
    assert modulus == pytest.approx(young, rel=1e-12)
    assert abs(damping) < 1e-12 and abs(dissipated) < 1e-12 * stored
    assert stored == pytest.approx(0.5 * (young * 2e-4) * 2e-4, rel=1e-9)


@pytest.mark.parametrize("delta", [0.0, 0.05, 0.3, 0.5 * math.pi])
def test_an_elliptical_loop_has_the_damping_ratio_of_its_closed_form(delta):
    """q = a sin t, eps = b sin(t - delta) over one period: W_D = the oint of q d eps =
    integral over [0, 2 pi] of a sin t b cos(t - delta) dt = a b (cos delta * 0 + sin delta *
    pi) = pi a b sin delta; Delta q / 2 = a and Delta eps / 2 = b whatever delta, so W_S =
    a b / 2 and D = W_D / (4 pi W_S) = sin(delta) / 2, E_sec = a / b. The loop sampled at
    N points is an inscribed polygon: its area is (N / 2 pi) sin(2 pi / N) that of the
    ellipse (1 - 1.6e-6 at N = 2000)."""
    a, b = 120.0, 3e-4
    t = np.linspace(0.5 * math.pi, 2.5 * math.pi, 2000, endpoint=False)
    modulus, damping, dissipated, stored = loop_measures(b * np.sin(t - delta), a * np.sin(t))
    assert modulus == pytest.approx(a / b, rel=1e-5)
    assert damping == pytest.approx(0.5 * math.sin(delta), abs=1e-6)
    assert dissipated == pytest.approx(math.pi * a * b * math.sin(delta), abs=1e-5 * a * b)
    # travelled the other way round (unloading above loading), the loop gives energy back
    assert loop_measures(b * np.sin(-t - delta), a * np.sin(-t))[1] == pytest.approx(
        -damping, abs=1e-9)


def synthetic_history(cycles, a, b, delta, ratchet=0.0, swelling=0.0, rows=400):
    """A cyclic path's history: a straight first loading to (b cos delta, a), then per cycle
    the ellipse q = a sin t, eps = b sin(t - delta) + ratchet (t - pi/2) / 2 pi from
    t = pi/2 (q = +a) through 3 pi/2 (q = -a, the end of the unloading) back to 5 pi/2; the
    volumetric strain rises by ``swelling`` a cycle. Lateral stresses 500 Pa."""
    first = np.linspace(0.0, 1.0, rows // 4)
    strain, q, stage = [b * math.cos(delta) * first], [a * first], [np.zeros(len(first))]
    for k in range(cycles):
        t = np.linspace(0.5 * math.pi, 2.5 * math.pi, rows + 1)[1:] + 2 * math.pi * k
        strain.append(b * np.sin(t - delta) + ratchet * (t - 0.5 * math.pi) / (2 * math.pi))
        q.append(a * np.sin(t))
        stage.append(np.where(t <= 1.5 * math.pi + 2 * math.pi * k + 1e-12, 2 * k + 1,
                              2 * k + 2))
    strain, q, stage = map(np.concatenate, (strain, q, stage))
    sigma = np.column_stack([np.full(len(q), 500.0), np.full(len(q), 500.0), 500.0 + q])
    travelled = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(q)))])
    return {"sigma_wall": sigma, "axial_strain": strain, "stage": stage,
            "volumetric_strain": swelling * travelled / (4.0 * a)}


def test_the_summary_measures_each_cycle_and_leaves_out_a_cut_one():
    a, b, delta = 80.0, 2e-4, 0.2
    history = synthetic_history(3, a, b, delta)
    summary = cyclic_summary(history, 3)
    assert [row["cycle"] for row in summary["cycles"]] == [1, 2, 3]
    for row in summary["cycles"]:
        assert row["secant_modulus"] == pytest.approx(a / b, rel=1e-4)
        assert row["damping_ratio"] == pytest.approx(0.5 * math.sin(delta), abs=1e-4)
        assert row["axial_strain_max"] == pytest.approx(b, rel=1e-4)
        assert row["axial_strain_min"] == pytest.approx(-b, rel=1e-4)
        assert row["records"] == 401
    assert summary["secant_modulus_first"] == summary["cycles"][0]["secant_modulus"]
    assert summary["damping_ratio_last"] == summary["cycles"][-1]["damping_ratio"]
    assert summary["axial_strain_at_load"] == pytest.approx(b * math.cos(delta))
    assert summary["q_at_load"] == pytest.approx(a)
    assert "phi_peak_deg" not in summary                # loops to the amplitude: no failure
    assert "secant_modulus_first_effective" not in summary
    cut = cyclic_summary(history, 3, complete=False)
    assert [row["cycle"] for row in cut["cycles"]] == [1, 2]


def test_ratcheting_and_volume_change_accumulate_cycle_by_cycle():
    history = synthetic_history(3, 80.0, 2e-4, 0.1, ratchet=5e-5, swelling=1e-4)
    summary = cyclic_summary(history, 3)
    for k, row in enumerate(summary["cycles"], start=1):
        assert row["axial_strain_increment"] == pytest.approx(5e-5, rel=1e-9)
        assert row["axial_strain_accumulated"] == pytest.approx(k * 5e-5, rel=1e-9)
        assert row["volumetric_strain_increment"] == pytest.approx(1e-4, rel=1e-9)
    assert summary["axial_strain_accumulated"] == pytest.approx(1.5e-4, rel=1e-9)
    assert summary["volumetric_strain_accumulated"] == pytest.approx(3e-4, rel=1e-9)


def test_a_wet_history_is_also_measured_against_the_effective_stress():
    """An isotropic capillary stress psi = 300 Pa (Eq. 3.43: sigma' = sigma + psi) shifts p'
    but not q': the effective loops have the net loops' modulus and damping."""
    history = synthetic_history(2, 80.0, 2e-4, 0.3)
    history["sigma_effective"] = np.array([np.diag(row + 300.0)
                                           for row in history["sigma_wall"]])
    summary = cyclic_summary(history, 2)
    for row in summary["cycles"]:
        assert row["secant_modulus_effective"] == pytest.approx(row["secant_modulus"])
        assert row["damping_ratio_effective"] == pytest.approx(row["damping_ratio"])
    assert summary["damping_ratio_first_effective"] == pytest.approx(0.5 * math.sin(0.3),
                                                                     abs=1e-4)


def test_a_softening_half_cycle_is_a_failure_peak():
    """A reloading whose q rises to 60 Pa halfway and falls to 54 Pa by its end (a tenth,
    the strain still rising) has a failure peak: phi_peak_deg is the friction angle there,
    asin((sigma_1 - sigma_3) / (sigma_1 + sigma_3)) = asin(60 / 1060)."""
    history = synthetic_history(1, 80.0, 2e-4, 0.0)
    reload = np.flatnonzero(history["stage"] == 2)
    half = len(reload) // 2
    history["sigma_wall"][reload, 2] = 500.0 + np.concatenate(
        [np.linspace(-80.0, 60.0, half + 1), np.linspace(60.0, 54.0, len(reload) - half)[1:]])
    summary = cyclic_summary(history, 1)
    assert summary["phi_peak_deg"] == pytest.approx(math.degrees(math.asin(60.0 / 1060.0)))


def test_an_axial_stress_falling_to_zero_stops_the_path():
    guard = AxialStressGuard(lambda s: "stage 3", "lower --amplitude-strain")
    guard.apply(StressScene((500.0, 500.0, 1e-3), step=42))                  # still pushing: nothing
    for axial in (0.0, -20.0):
        with pytest.raises(StageFailed, match=r"stage 3: the axial stress fell to .* at step "
                                              r"42 and the axial walls cannot pull; lower"):
            guard.apply(StressScene((500.0, 500.0, axial), step=42))


def cubic_lattice(n, radius, young, confining):
    """n^3 equal spheres in a simple cubic lattice between six walls servoed at ``confining``
    [Pa], each contact (kn = E R, sphere-sphere and sphere-wall) at the overlap of that
    stress, 4 confining R / E; the simulation and its configuration."""
    config = PrepareConfig(particles=50, radius=radius, young=young, confining=confining)
    overlap = 4.0 * confining * radius / young
    spacing = 2.0 * radius - overlap
    position = [[radius - overlap + spacing * i for i in index]
                for index in itertools.product(range(n), repeat=3)]
    length = (n - 1) * spacing + 2.0 * (radius - overlap)
    particles = Particles(np.array(position), np.full(n ** 3, radius), config.density)
    sim = servoed_simulation(particles, Walls.box([0.0] * 3, [length] * 3), config, confining)
    return sim, config


def test_a_strain_cycle_of_the_smallest_amplitude_leaves_an_elastic_lattice_as_it_was():
    """A 3 x 3 x 3 simple cubic lattice is elastic under axial strain (no contact turns or
    slides, the lateral stress is held): each column of n spheres is n + 1 springs E R in
    series, so E_sec = E R L_z / ((n + 1) A), A = L_x L_y / n^2 the column's cross-section,
    and D = 0. After each cycle the axial walls are back to round-off and the spheres and
    stresses to within the lag of the loading rate, a small fraction of what the cycle
    moved (here about 3e-4; it vanishes with the rate)."""
    n, radius, young, confining = 3, 1e-3, 1e6, 750.0
    sim, _ = cubic_lattice(n, radius, young, confining)
    equilibrate(sim, unbalanced=1e-6, tolerance=1e-6, max_steps=20000)
    lengths = sim.walls.lengths().copy()
    modulus = young * radius * lengths[2] / ((n + 1) * lengths[0] * lengths[1] / n ** 2)
    amplitude = MIN_AXIAL_STRAIN
    rate = amplitude / (2000.5 * sim.dt)            # no stage a whole number of steps
    path = CyclicPath(sim, cyclic_stages(confining, rate, 2, amplitude_strain=amplitude),
                      record_every=50)
    ends, advance = {}, path._next

    def record_end(s):                              # the state at each stage's end
        ends[path.stage] = (s.particles.position.copy(), s.walls.position.copy(),
                            s.walls.stress().copy())
        advance(s)

    path._next = record_end
    path.run(sim)
    history = path.recorder.arrays()
    assert list(np.unique(history["cycle"])) == [0, 1, 2]
    assert np.array_equal(history["cycle"], (history["stage"] + 1) // 2)
    summary = cyclic_summary(history, 2)
    moved = amplitude * lengths[2]                  # the axial walls' travel to +-X [m]
    swing = 2.0 * amplitude * modulus               # the axial stress range of a cycle [Pa]
    position, walls, stress = ends[0]
    for row, stage in zip(summary["cycles"], (2, 4)):
        assert row["secant_modulus"] == pytest.approx(modulus, rel=1e-3)
        assert abs(row["damping_ratio_measured"]) < 2e-3
        assert row["axial_strain_max"] == pytest.approx(-row["axial_strain_min"], rel=1e-9)
        assert np.abs(ends[stage][1] - walls).max() < 1e-12 * radius
        assert np.abs(ends[stage][0] - position).max() < 1e-2 * moved
        assert np.abs(ends[stage][2] - stress).max() < 1e-2 * swing


def test_a_damping_ratio_below_its_resolution_is_null_with_the_resolution_given():
    """A nearly closed loop (delta 0.002: D = 0.001) whose lateral stress stays 2 Pa off the
    confining stress: such a lag could make a loop area of D = 4 * 2 / (pi * 160) = 0.016, so
    D is not measured; nor is a negative D, nor one within the records' scatter; a loop of
    delta 0.3 (D = 0.148), held at the confining stress and smooth, is."""
    history = synthetic_history(2, 80.0, 2e-4, 0.002)
    history["sigma_wall"][:, :2] += 2.0         # the axial stress follows: q is unchanged
    history["sigma_wall"][:, 2] += 2.0
    summary = cyclic_summary(history, 2, confining=500.0)
    for row in summary["cycles"]:
        assert row["damping_ratio"] is None
        assert row["damping_ratio_measured"] == pytest.approx(0.001, abs=2e-4)
        assert row["damping_ratio_resolution"] == pytest.approx(4 * 2.0 / (math.pi * 160.0),
                                                                rel=0.05)
        assert row["damping_ratio_note"].startswith("below resolution: damping_ratio")
    assert summary["damping_ratio_first"] is None and summary["damping_ratio_last"] is None
    assert summary["damping_ratio_note"].startswith("below resolution in cycle(s) 1, 2")
    measured = cyclic_summary(synthetic_history(2, 80.0, 2e-4, 0.3), 2, confining=500.0)
    row = measured["cycles"][0]
    assert row["damping_ratio"] == pytest.approx(0.5 * math.sin(0.3), abs=1e-4)
    assert row["damping_ratio_resolution"] < 1e-3 and "damping_ratio_note" not in measured
    # a loop travelled backwards (unloading above loading) reads D < 0: never a measure
    backwards = synthetic_history(2, 80.0, 2e-4, -0.3)
    assert cyclic_summary(backwards, 2, confining=500.0)["cycles"][0]["damping_ratio"] is None
    # scatter of 3 Pa on every record: a loop area of about 3 * 8e-4 / (4 pi 8e-3) = 0.024
    noisy = synthetic_history(2, 80.0, 2e-4, 0.01)
    noisy["sigma_wall"][:, 2] += np.random.default_rng(0).normal(0.0, 3.0, len(noisy["stage"]))
    row = cyclic_summary(noisy, 2, confining=500.0)["cycles"][0]
    assert row["damping_ratio_resolution"] == pytest.approx(0.024, rel=0.2)
    assert row["damping_ratio"] is None
    assert damping_resolution([0.0, 1.0], [0.0, 1.0], [500.0, 500.0], 500.0, 0.0) is None
