"""What a run reports: ``peak_reached`` judged by the trend of q at the end of the test, and the
terminal summary (units, 4 significant figures, JSON only with --quiet)."""

import json

import numpy as np
import pytest

from conftest import assert_drawn
from pendular.cli import format_summary, format_table, format_value, main, print_summary
from pendular.io.schema import peak_reached, still_rising

#: Axial strain of a 5 % test with 500 records (the tutorial's first run).
STRAIN = np.linspace(0.0, 0.05, 501)


def hyperbolic(strain, q_max=5000.0, reference=0.01):
    """A curve still rising at the end: q = q_max e / (reference + e) [Pa] (Kondner 1963)."""
    return q_max * strain / (reference + strain)


def softening(strain, q_peak=5000.0, at=0.02):
    """A peak of q_peak [Pa] at strain ``at``, then softening: q_peak (e/at) exp(1 - e/at)."""
    return q_peak * strain / at * np.exp(1.0 - strain / at)


def scatter(seed, size=len(STRAIN), amplitude=60.0):
    """DEM-like scatter of the records [Pa]: uniform in +-amplitude."""
    return amplitude * np.random.default_rng(seed).uniform(-1.0, 1.0, size)


def test_a_curve_still_rising_has_no_peak_though_its_maximum_is_before_the_end():
    """The issue's case: on a rising curve the scatter puts the maximum at 4.76 % of a 5 % test,
    3 % of the strain range before its end; the position alone calls it a peak, the trend of
    the last 20 % does not."""
    q = hyperbolic(STRAIN) + scatter(0)
    q[476] = q.max() + 50.0                       # the highest record at 4.76 %
    assert int(np.argmax(q)) == 476 and STRAIN[476] == pytest.approx(0.0476)
    assert STRAIN[476] / STRAIN[-1] < 0.98        # outside the last 2 %: a peak by position
    assert still_rising(STRAIN, q)
    assert peak_reached(STRAIN, q) is False
    assert peak_reached(STRAIN, hyperbolic(STRAIN)) is False            # no scatter: maximum last


def test_a_peak_then_softening_is_a_peak():
    for seed in range(5):
        q = softening(STRAIN) + scatter(seed)
        assert not still_rising(STRAIN, q)
        assert peak_reached(STRAIN, q) is True
    assert peak_reached(STRAIN, softening(STRAIN)) is True


def test_a_stick_slip_plateau_ending_on_a_rising_tooth_is_past_its_peak():
    """A small sample at critical state (the tutorial's first run): q peaks at 3.05 %, then
    climbs and drops in teeth below that peak; the test ends on a tooth's rising edge. q rises
    at the end, but the maximum lies before the last 20 %: the peak was passed."""
    period, start = 0.005, 0.0305
    phase = np.clip(STRAIN - start, 0.0, None) % period / period
    q = np.where(STRAIN < start, 4450.0 * STRAIN / start, 4150.0 + 250.0 * phase)
    assert still_rising(STRAIN, q) and STRAIN[np.argmax(q)] < 0.8 * STRAIN[-1]
    assert peak_reached(STRAIN, q) is True
    # the same teeth rising above the first maximum: the test ends on its way up
    assert peak_reached(STRAIN, q + 3e4 * np.clip(STRAIN - start, 0.0, None)) is False


def test_a_plateau_with_scatter_is_taken_as_the_peak():
    """A loose sample at critical state: q flat with scatter. Its maximum is its strength:
    peak_reached true, unless the scatter puts the maximum in the last 2 %, or in the last
    20 % with an upward trend there beyond twice the slope's standard error (a few seeds in a
    hundred)."""
    plateau = np.minimum(hyperbolic(STRAIN, 8000.0, 0.002), 6000.0)
    reached = [peak_reached(STRAIN, plateau + scatter(seed)) for seed in range(100)]
    assert sum(reached) >= 90, sum(reached)
    for seed in np.flatnonzero(~np.array(reached)):     # each refusal has one of the two reasons
        q = plateau + scatter(int(seed))
        at = STRAIN[np.argmax(q)] / STRAIN[-1]
        assert at >= 0.98 or (at >= 0.8 and still_rising(STRAIN, q))


def test_the_trend_is_judged_beyond_the_scatter():
    line = 1000.0 + 2e4 * STRAIN
    assert still_rising(STRAIN, line)                          # exact, however small the rise
    assert still_rising(STRAIN, 1000.0 + 1e-6 * STRAIN)
    assert not still_rising(STRAIN, np.full_like(STRAIN, 1234.5678))
    assert not still_rising(STRAIN, 1000.0 - 2e4 * STRAIN)
    # a rise of 2 Pa over the last 20 % under scatter of +-60 Pa is not a rise
    assert not still_rising(STRAIN, 1000.0 + 200.0 * STRAIN + scatter(3))
    # the window holds at least min_records records: of 20 records the last 20 % holds four
    coarse = np.linspace(0.0, 0.05, 20)
    assert still_rising(coarse, hyperbolic(coarse))


def test_peak_reached_in_tension_and_extension():
    """Either sign of the strain: the pull of direct tension, a triaxial extension."""
    assert peak_reached(-STRAIN, softening(STRAIN)) is True
    assert peak_reached(-STRAIN, hyperbolic(STRAIN) + scatter(1)) is False


def test_peak_reached_refuses_a_stress_of_another_length():
    with pytest.raises(ValueError, match="stress has shape"):
        peak_reached(STRAIN, 40)                   # a peak index, as the former signature took
    with pytest.raises(ValueError, match="stress has shape"):
        peak_reached(STRAIN, np.ones(10))


def test_values_have_four_significant_figures_and_their_units():
    assert [format_value(v) for v in (5088.184391328918, 0.04608357012750608, 30000.0,
                                      9999.7, 1116604.278, 3.2e-07, True, None, 12000)] == [
        "5088", "0.04608", "30000", "10000", "1.117e+06", "3.2e-07", "true", "-", "12000"]
    summary = {"peak_q": 4952.32259957551, "axial_strain_at_peak": 0.04608357012750608,
               "phi_peak_deg": 50.125724449895436, "particle_steps_per_s": 1116604.278,
               "axial_contact_lost": False, "units": {"peak_q": "Pa", "phi_peak_deg": "deg"}}
    lines = format_summary(summary, ["peak_q", "axial_strain_at_peak", "phi_peak_deg",
                                     "particle_steps_per_s", "axial_contact_lost"]).split("\n")
    assert [line.split() for line in lines] == [
        ["peak_q", "4952", "Pa"], ["axial_strain_at_peak", "0.04608"],
        ["phi_peak_deg", "50.13", "deg"],
        ["particle_steps_per_s", "1.117e+06", "1/s"],       # the unit from pendular.io.schema
        ["axial_contact_lost", "false"]]


def test_a_list_of_records_is_a_table_with_units_in_its_header():
    """An isotropic path's stages: one row per stage, the units of its columns in the header."""
    summary = {"stages": [{"stage": 0, "target": 500.0, "p": 499.87654, "void_ratio": 0.8123456,
                           "step": 1200},
                          {"stage": 1, "target": 2000.0, "p": 2001.2345, "void_ratio": 0.7912345,
                           "step": 5400}],
               "compression_index": 0.0351234,
               "units": {"stages": {"target": "Pa", "p": "Pa", "void_ratio": "1", "stage": "1",
                                    "step": "1"}, "compression_index": "1"}}
    lines = format_summary(summary, ["stages", "compression_index"]).split("\n")
    assert lines[0].strip() == "stages:"
    assert lines[1].split() == ["stage", "target", "[Pa]", "p", "[Pa]", "void_ratio", "step"]
    assert lines[2].split() == ["0", "500", "499.9", "0.8123", "1200"]
    assert lines[3].split() == ["1", "2000", "2001", "0.7912", "5400"]
    assert lines[4].split() == ["compression_index", "0.03512"]
    assert len({len(line) for line in lines[1:4]}) == 1              # columns aligned
    rows = [{"suction": 3000.0, "saturation": 0.0312345, "psi": [[1.0]]}]
    assert format_table(rows, {"suction": "Pa"})[0].split() == [       # nested values left out
        "suction", "[Pa]", "saturation"]


def test_a_wide_table_is_cut_into_blocks_each_led_by_the_row_name():
    """A cyclic path's cycles: 16 columns in blocks of at most 100 characters."""
    names = [f"measure_{k}" for k in range(15)]
    rows = [{"cycle": c, **{name: 1000.0 * (c + 1) + k for k, name in enumerate(names)}}
            for c in range(3)]
    lines = format_table(rows, {name: "Pa" for name in names})
    blocks = "\n".join(lines).split("\n\n")
    assert len(blocks) > 1 and all(len(line) <= 100 for line in lines)
    headers = [block.split("\n")[0].split() for block in blocks]
    assert all(header[0] == "cycle" for header in headers)
    shown = [word for header in headers for word in header[1:] if word != "[Pa]"]
    assert shown == names                                  # every column once, in order
    assert all(block.split("\n")[3].split()[0] == "2" for block in blocks)


def test_a_record_of_values_is_one_line_with_its_units():
    summary = {"grading": {"D50": 4.8e-05, "Cu": 1.0}, "stress_balance_flagged": [],
               "units": {"grading": {"D50": "m", "Cu": "1"}}}
    assert [line.split(None, 1)[1].strip() for line in format_summary(
        summary, ["grading", "stress_balance_flagged"]).split("\n")] == [
        "D50 4.8e-05 m, Cu 1", "none"]


def test_quiet_prints_the_shown_keys_as_json(capsys):
    summary = {"peak_q": 4952.32259957551, "completed": True, "units": {"peak_q": "Pa"}}
    print_summary(summary, ("peak_q", "absent"), quiet=True)
    assert json.loads(capsys.readouterr().out) == {"peak_q": 4952.32259957551}


@pytest.mark.slow
def test_the_terminal_summary_of_a_wet_run(tmp_path, capsys):
    """A 150-sphere wet triaxial to 1 % strain: each shown key of summary.json printed on its
    line with its value to 4 significant figures and its unit, no JSON; the ParaView time axis
    in the unit of the frames' field data; the q-p' stress path in plots/."""
    import pendular
    from pendular.procedures.triaxial import SHOWN

    out = tmp_path / "run"
    status = main(["triaxial", "--particles", "150", "--max-strain", "0.01",
                   "--inertial-number", "2e-3", "--suction", "30000", "--out", str(out)])
    assert status == 0
    printed = capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    assert "{" not in printed and '"' not in printed
    lines = {line.split()[0]: line.split()[1:] for line in printed.splitlines()
             if line.startswith("  ")}
    shown = [key for key in SHOWN if key in summary]
    assert len(shown) >= 12 and set(lines) == set(shown)
    for key in shown:
        value, *unit = lines[key]
        if summary[key] is None:               # a measure not taken (its note says why)
            assert (value, unit) == ("-", []), key
            continue
        if isinstance(summary[key], str):      # a note, as it is
            assert " ".join([value, *unit]) == summary[key], key
            continue
        assert float(value) == pytest.approx(summary[key], rel=5e-4), key
        digits = value.split("e")[0].replace(".", "").replace("-", "").strip("0")
        assert len(digits) <= 4, (key, value)
        expected = summary["units"].get(key, "1")
        assert unit == ([] if expected == "1" else [expected]), key
    assert lines["peak_q"][1] == "Pa" and lines["phi_peak_deg"][1] == "deg"
    assert isinstance(summary["peak_reached"], bool)
    assert ("peak_reached false" in printed) == (not summary["peak_reached"])
    assert printed.rstrip().endswith(f"outputs in {out}")
    frames = pendular.read_vtk(out / "vtk" / "particles.pvd")
    for time_value, mesh in frames:
        assert time_value == mesh.field_data["axial_strain_percent"][0]
        assert time_value == pytest.approx(100.0 * mesh.field_data["axial_strain"][0])
    assert "axial_strain_percent" in (out / "vtk" / "particles.pvd").read_text()
    assert_drawn(out / "plots" / "stress_path.png")


def test_quiet_leaves_stdout_to_the_json_alone(capsys):
    """--quiet: the closing line of a command goes to stderr, its results as JSON to stdout,
    so that json.loads reads stdout whole."""
    from pendular.cli import print_result

    print_result(True, "campaign: 4 runs; outputs in out", runs=4, out="out")
    printed = capsys.readouterr()
    assert json.loads(printed.out) == {"runs": 4, "out": "out"}
    assert "outputs in out" in printed.err
    print_result(False, "campaign: 4 runs; outputs in out", runs=4)
    assert capsys.readouterr().out == "campaign: 4 runs; outputs in out\n"
