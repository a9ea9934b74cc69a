"""Progress bars: the gauges of open-ended phases, the whole run's bar, and bars that change no
result (pendular.utils.progress, pendular.procedures.progress)."""

import math
import re

import numpy as np
import pytest

from pendular.procedures.preparation import PrepareConfig, prepare_sample, static
from pendular.procedures.swcc import SwccConfig
from pendular.procedures.tension import TensionConfig
from pendular.procedures.triaxial import TriaxialConfig
from pendular.procedures.progress import (OPEN_ENDED_STEPS, laboratory_plan, off_equilibrium,
                                          preparation_plan, swcc_plan, tension_plan)
from pendular.utils import progress
from pendular.utils.progress import Approach, Decades, Phase, PhaseBar, whole_run


def readings(values):
    """A quantity returning ``values`` one after the other (the sim is not read)."""
    values = iter(values)
    return lambda sim: next(values)


def test_approach_counts_the_way_to_the_target_and_never_goes_back():
    gauge = Approach(readings([0.0, 1000.0, 500.0, 6000.0]), 5000.0, "Pa")
    assert gauge.total is None                      # not known before the first reading
    assert [gauge.read(None) for _ in range(4)] == [0.0, 1000.0, 1000.0, 5000.0]
    assert gauge.total == 5000.0


def test_approach_from_above_counts_the_stress_lost():
    gauge = Approach(readings([800.0, 700.0, 100.0]), 200.0, "Pa")
    assert [gauge.read(None) for _ in range(3)] == pytest.approx([0.0, 100.0, 600.0])
    assert gauge.total == pytest.approx(600.0)


def test_decades_count_the_fall_of_the_unbalanced_force_to_its_threshold():
    gauge = Decades(readings([1.0, 0.1, 0.5, 1e-4]), 0.01)
    positions = [gauge.read(None) for _ in range(4)]
    assert gauge.total == pytest.approx(2.0)        # log10(1 / 0.01)
    assert positions == pytest.approx([0.0, 1.0, 1.0, 2.0])   # held, then capped at the total


def test_decades_of_a_force_already_small_is_a_bar_full_at_once():
    gauge = Decades(readings([0.001]), 0.01)
    assert gauge.read(None) == gauge.total > 0.0


def test_a_gauge_waits_for_a_finite_reading():
    gauge = Decades(readings([math.inf, 1.0, 0.1]), 0.01)
    assert gauge.read(None) == 0.0 and gauge.total is None
    assert [gauge.read(None) for _ in range(2)] == pytest.approx([0.0, 1.0])
    assert gauge.total == pytest.approx(2.0)


def run_fraction():
    return progress._RUN.bar.n


def test_the_run_bar_counts_steps_of_ended_running_and_planned_phases():
    with whole_run([("a", 100), ("never", 1000), ("b", 100)]):
        assert run_fraction() == 0.0
        bar = PhaseBar("a 1/2", 60)
        bar.update(None, 60)
        assert run_fraction() == pytest.approx(100 * 60 / (100 + 1000 + 100), abs=0.05)
        bar.close()
        bar = PhaseBar("a 2/2", 40)         # a second stage of the same entry
        bar.update(None, 40)
        bar.close()
        bar = PhaseBar("b", 100)            # "never" did not run: its estimate is dropped
        bar.update(None, 50)
        assert run_fraction() == pytest.approx(100 * 150 / 200, abs=0.05)
        PhaseBar("unplanned", 10).close()   # moves nothing
        assert run_fraction() == pytest.approx(75.0, abs=0.05)
        bar.update(None, 50)
        bar.close()
    assert progress._RUN.bar is None


def test_an_open_ended_phase_refines_its_estimate_from_its_gauge():
    with whole_run([("settle", 1000), ("shear", 1000)]):
        bar = PhaseBar(Phase("settle", Approach(readings([0.0, 50.0]), 100.0, "Pa")), 10**6)
        bar.update(None, 100, last=True)                # first reading: the start
        assert run_fraction() == pytest.approx(100 * 100 / 2000, abs=0.05)
        bar.update(None, 100, last=True)                # half way after 200 steps: 400 in all,
        assert run_fraction() == pytest.approx(100 * 200 / 2000, abs=0.05)   # 1000 planned
        bar.close()
        bar = PhaseBar("shear", 500)                    # once ended, the steps it took count
        bar.update(None, 250)
        assert run_fraction() == pytest.approx(100 * 450 / (200 + 1000), abs=0.05)
        bar.close()


def test_the_plans_follow_the_configuration():
    sample = PrepareConfig(particles=150, unload_steps=400)
    assert [p for p, _ in preparation_plan(sample)] == ["grow radii", "set friction", "unload",
                                                        "equilibrate"]
    assert dict(preparation_plan(sample))["unload"] == 400
    assert preparation_plan(sample, loaded=True) == [("equilibrate", OPEN_ENDED_STEPS)]
    triaxial = TriaxialConfig(sample=sample)
    assert laboratory_plan(triaxial, "shear")[-1] == ("shear", triaxial.estimated_steps())
    suctions = SwccConfig(sample=sample, suctions=[1e3, 1e4, 1e5])
    assert swcc_plan(suctions)[-2:] == [("drying", 3 * OPEN_ENDED_STEPS),
                                        ("wetting", 2 * OPEN_ENDED_STEPS)]
    tension = TensionConfig(sample=sample, cases=[(0.7, 0.01), (0.7, 0.02), (0.6, 0.01)])
    plan = tension_plan(tension)
    assert [p if isinstance(p, str) else "tune" for p, _ in plan] == [
        "tune", "wet", "pull", "wet", "pull", "tune", "wet", "pull"]
    assert dict(plan)["pull"] == tension.pull_steps()


def test_a_tuple_of_prefixes_holds_every_repeated_preparation():
    with whole_run([(("grow", "unload"), 100), ("pull", 100)]):
        for label in ("grow radii", "unload", "grow radii", "unload", "grow radii"):
            bar = PhaseBar(label, 30)
            bar.update(None, 30)
            bar.close()                   # 150 steps: more than the 100 planned
        assert run_fraction() == pytest.approx(100 * 150 / 250, abs=0.05)
        bar = PhaseBar("pull e0.7", 100)
        bar.update(None, 50)
        assert run_fraction() == pytest.approx(100 * 200 / 250, abs=0.05)
        bar.close()


def test_a_preparation_shows_bars_with_totals_and_changes_no_result(capsys):
    config = PrepareConfig(particles=150, confining=750.0, seed=7, unload_steps=400)
    quiet, _ = prepare_sample(config, progress=False, threads=1)
    assert capsys.readouterr().err == ""
    with whole_run(preparation_plan(config)):
        shown, _ = prepare_sample(config, progress=True, threads=1)
    err = capsys.readouterr().err.replace("\r", "\n")
    assert np.array_equal(quiet.particles.position, shown.particles.position)
    assert np.array_equal(quiet.particles.velocity, shown.particles.velocity)
    assert np.array_equal(quiet.walls.position, shown.walls.position)
    for label, unit in (("grow radii", "Pa"), ("set friction", "decade"), ("unload", "step"),
                        ("equilibrate", "decade")):
        totals = re.findall(rf"{label}: +\d+%\|[^|]*\| [\d.]+/([\d.]+) \[.*{unit}", err)
        assert totals and float(totals[-1]) > 0.0, label
    assert re.search(r"run: 100%\|", err)
    assert math.isclose(float(re.findall(r"unload: +\d+%\|[^|]*\| [\d.]+/([\d.]+)", err)[-1]),
                        400)
    # the equilibrium's gauge falls to 1 where the equilibrium's own test is met
    for unbalanced in (1e-5, 1e-3, 1e-1):
        for tolerance in (1e-5, 1e-3, 1e-1):
            ratio = off_equilibrium(unbalanced, tolerance)(shown)
            assert static(unbalanced, tolerance)(shown) == (ratio <= 1.0)
