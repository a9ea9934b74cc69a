"""Path tables (pendular.procedures.path): every key of a stage read into loading.Stage,
named values, repeated groups, one error naming the file, the entry and the key, the
configuration's JSON round trip, and the generic path summary against hand-made histories."""

import dataclasses

import numpy as np
import pytest

from pendular.procedures.preparation import PrepareConfig
from pendular.procedures.config import (ShearConfig, config_from_dict, config_to_dict,
    quasi_static_rate)
from pendular.procedures.path import TablePathConfig
from pendular.procedures.loading import Stage, Static, Strain, Stress
from pendular.procedures.path import (UNTIL_KINDS, build_stages, lowest_stress,
    path_summary, read_table, stage_keys)

SAMPLE = PrepareConfig(particles=100, confining=750.0)
#: A stage with z driven, to which a test adds its end.
DRIVEN = "[[stage]]\nstress = {x = 5, y = 5}\nstrain_rate = {z = 1}\n"


def table(tmp_path, text, name="path.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def stages_of(tmp_path, text, confining=750.0, rate=2.0):
    read = read_table(table(tmp_path, text))
    return build_stages(read["stages"], read["source"], confining=confining, rate=rate)


def error_of(tmp_path, text, name="path.toml"):
    """The one-line message of the ValueError a table raises (read and built)."""
    with pytest.raises(ValueError) as raised:
        stages_of(tmp_path, text) if name == "path.toml" else read_table(tmp_path / name)
    message = str(raised.value)
    assert "\n" not in message
    return message


def test_every_key_of_a_stage_is_read_into_stage(tmp_path):
    stages = stages_of(tmp_path, """
[[stage]]
stress = {x = 500, y = 600.5}
strain_rate = {z = 0.25}
until = {strain = 0.05, axis = "z"}

[[stage]]
strain_rate = {z = 0.5}
mean_stress = 700
b = 0.5
until = {stress = 900, axis = "z", strain_limit = 0.2}

[[stage]]
stress = {x = 1000, y = 1000, z = 1000}
max_strain_rate = 3
until = {static = true, max_steps = 5000, unbalanced = 0.02, tolerance = 0.03, check_every = 50}

[[stage]]
stress = {x = 800, y = 800, z = 800}
until = "static"
""")
    assert stages[0] == Stage(stress={"x": 500.0, "y": 600.5}, strain_rate={"z": 0.25},
                              until=Strain(0.05, "z"))
    assert stages[1] == Stage(strain_rate={"z": 0.5}, mean_stress=700.0, b=0.5,
                              until=Stress(900.0, "z", 0.2))
    assert stages[2] == Stage(stress={a: 1000.0 for a in "xyz"}, max_strain_rate=3.0,
                              until=Static(5000, 0.02, 0.03, 50))
    assert stages[3] == Stage(stress={a: 800.0 for a in "xyz"}, until=Static())
    # the table's keys are Stage's fields, read from the dataclass
    assert stage_keys() == tuple(f.name for f in dataclasses.fields(Stage))
    assert set(UNTIL_KINDS) >= {"strain", "stress", "static"}


def test_a_stage_without_until_ends_static_and_the_axis_defaults_to_z(tmp_path):
    stages = stages_of(tmp_path, """
[[stage]]
stress = {x = 750, y = 750, z = 750}
[[stage]]
stress = {x = 750, y = 750}
strain_rate = {z = -1}
until = {stress = 500}
""")
    assert stages[0].until == Static()
    assert stages[1].until == Stress(500.0, "z")


def test_named_values_are_the_confining_stress_and_the_quasi_static_rate(tmp_path):
    stages = stages_of(tmp_path, """
[[stage]]
stress = {x = "confining", y = "confining"}
strain_rate = {z = "quasi-static"}
until = {strain = 0.1}
[[stage]]
strain_rate = {x = 0, y = 0, z = "-quasi-static"}
until = {stress = "confining"}
[[stage]]
mean_stress = "confining"
strain_rate = {z = "quasi-static"}
until = {strain = 0.2}
[[stage]]
stress = {x = 900, y = 900, z = 900}
max_strain_rate = "quasi-static"
""", confining=640.0, rate=0.125)
    assert stages[0].stress == {"x": 640.0, "y": 640.0} and stages[0].strain_rate == {"z": 0.125}
    assert stages[1].strain_rate["z"] == -0.125 and stages[1].until == Stress(640.0)
    assert stages[2].mean_stress == 640.0
    assert stages[3].max_strain_rate == 0.125


def test_a_group_repeats_its_stages_in_order_and_groups_nest(tmp_path):
    stages = stages_of(tmp_path, """
[[stage]]
stress = {x = 100, y = 100, z = 100}

[[stage]]
repeat = 3
stages = [
  {stress = {x = 200, y = 200, z = 200}},
  {repeat = 2, stages = [{stress = {x = 300, y = 300, z = 300}}]},
]

[[stage]]
stress = {x = 400, y = 400, z = 400}
""")
    assert [s.stress["x"] for s in stages] == [100, 200, 300, 300] * 1 + [200, 300, 300] * 2 + [400]
    # the sub-table form of a group is the same list
    nested = stages_of(tmp_path, """
[[stage]]
repeat = 2
[[stage.stages]]
stress = {x = 200, y = 200, z = 200}
[[stage.stages]]
stress = {x = 300, y = 300, z = 300}
""")
    assert [s.stress["z"] for s in nested] == [200, 300, 200, 300]


@pytest.mark.parametrize("text, words", [
    ("[[stage]]\nstres = {x = 5}\n",
     ["path.toml: stage 1: unknown key 'stres'; valid: stress, strain_rate, until"]),
    ("[[stage]]\nstress = {x = 5, y = 5, z = 5}\n[[stage]]\nstrain_rate = {z = 1}\nspeed = 3\n",
     ["path.toml: stage 2: unknown key 'speed'", "repeat, stages (a group repeated)"]),
    ("[[stage]]\nrepeat = 2\nstages = [{stress = {x = 5, y = 5, z = 5}, until = 'statik'}]\n",
     ["path.toml: stage 1.1: until = 'statik'", "'strain', 'stress', 'static'"]),
    (DRIVEN + "until = {strain = 0.1, axs = 'z'}\n",
     ["path.toml: stage 1: until: unknown key 'axs'; valid: strain, axis"]),
    ("[[stage]]\nstress = {x = 5, y = 5, z = 5}\nuntil = {static = true, steps = 5}\n",
     ["stage 1: until: unknown key 'steps'; valid: static, max_steps, unbalanced, tolerance"]),
    (DRIVEN + "until = 'strain'\n",
     ["stage 1: until = 'strain'", "needs its value"]),
    (DRIVEN + "until = {strain = 0.1, stress = 5}\n",
     ["stage 1: until", "names 2 ends"]),
    ("[[stage]]\nstress = {x = 5, y = 5, z = 5}\nuntil = {static = false}\n",
     ["stage 1: until static = False; valid: true"]),
    ("[[stage]]\nrepeat = 2\nstress = {x = 5}\nstages = []\n",
     ["stage 1: key 'stress' beside repeat and stages"]),
    ("[[stage]]\nrepeat = 0\nstages = [{stress = {x = 5, y = 5, z = 5}}]\n",
     ["stage 1: repeat = 0 is outside the valid range [1, "]),
    ("[[stage]]\nrepeat = 2.5\nstages = [{stress = {x = 5, y = 5, z = 5}}]\n",
     ["stage 1: repeat = 2.5 is not an integer"]),
    ("[[stage]]\nrepeat = 2\nstages = []\n", ["stage 1: stages = []; valid: a non-empty list"]),
    ("[[stage]]\nrepeat = 100000\nstages = [{stress = {x = 5, y = 5, z = 5}}, "
     "{stress = {x = 6, y = 6, z = 6}}]\n", ["more than 100000 stages"]),
    # values Stage refuses: its message, prefixed with the file and the stage
    ("[[stage]]\nstress = {x = 5, y = 5, z = 5}\n[[stage]]\nstress = {x = 5, y = 5, z = 5}\n"
     "strain_rate = {z = 1}\n", ["path.toml: stage 2: axis z: give a stress or a strain rate"]),
    ("[[stage]]\nstress = {x = -5, y = 5, z = 5}\n",
     ["path.toml: stage 1: stress['x'] = -5 Pa is outside the valid range [0, inf] Pa"]),
    ("[[stage]]\nstress = {x = 5, y = 5, w = 5}\n", ["stage 1: stress axis = 'w'"]),
    (DRIVEN + "b = 1.5\n",
     ["stage 1: b = 1.5 is outside the valid range [0, 1]"]),
    ("[[stage]]\nstress = {x = 5, y = 5}\n", ["stage 1: axis z has neither a stress nor"]),
    (DRIVEN,
     ["stage 1: until static needs every axis servoed or held"]),
    (DRIVEN + "until = {strain = 0.9}\n",
     ["stage 1: until strain = 0.9 is outside the valid range [-0.5, 0.5]"]),
    # named values, booleans and shapes
    ("[[stage]]\nstress = {x = 'confinig', y = 5, z = 5}\n",
     ["stage 1: stress['x'] = 'confinig'; valid: a number or 'confining'"]),
    ("[[stage]]\nstress = {x = 5, y = 5}\nstrain_rate = {z = 'fast'}\nuntil = {strain = 0.1}\n",
     ["strain_rate['z'] = 'fast'; valid: a number or 'quasi-static' or '-quasi-static'"]),
    ("[[stage]]\nstress = {x = 5, y = 5}\nstrain_rate = {z = true}\nuntil = {strain = 0.1}\n",
     ["stage 1: strain_rate['z'] = True is not a number"]),
    ("[[stage]]\nstress = 5\n", ["stage 1: stress = 5; valid: a value per axis"]),
    (DRIVEN + "b = 'half'\n",
     ["stage 1: b = 'half' is not a number"]),
    (DRIVEN + "until = {strain = 'quasi-static'}\n",
     ["stage 1: until strain = 'quasi-static'; valid: a number"]),
    ("stage = [1, 2]\n", ["path.toml: stage 1 = 1; valid: a table of stress"]),
    # the table itself
    ("", ["path.toml: no stage; valid: at least one [[stage]]"]),
    ("[sample]\nparticles = 100\n", ["path.toml: unknown key 'sample'; valid: stage",
                                    "on the command line"]),
    ("[[stage]\n", ["path.toml is not a valid TOML table"]),
])
def test_a_bad_table_is_refused_in_one_line_naming_file_stage_and_key(tmp_path, text, words):
    message = error_of(tmp_path, text)
    for word in words:
        assert word in message, message


def test_an_unreadable_table_is_named(tmp_path):
    message = error_of(tmp_path, "", name="missing.toml")
    assert "missing.toml cannot be read: No such file or directory" in message
    (tmp_path / "bytes.toml").write_bytes(b"\xff\xfe[[stage]]")
    assert "bytes.toml is not a TOML table: byte" in error_of(tmp_path, "", name="bytes.toml")


def triaxial_config(tmp_path, text, **options):
    read = read_table(table(tmp_path, text))
    return TablePathConfig(sample=SAMPLE, **read, **options)


TRIAXIAL = """
[[stage]]
stress = {x = "confining", y = "confining"}
strain_rate = {z = "quasi-static"}
until = {strain = 0.25, axis = "z"}
"""


def test_the_triaxial_as_a_table_has_the_rate_of_the_triaxial_bit_for_bit(tmp_path):
    config = triaxial_config(tmp_path, TRIAXIAL, inertial_number=2e-3, records=50)
    shear = ShearConfig(inertial_number=2e-3)
    expected = shear.rate(SAMPLE.radius, SAMPLE.density, SAMPLE.confining)
    assert config.rate() == expected
    assert config.loading_stages() == [Stage(stress={"x": 750.0, "y": 750.0},
                                             strain_rate={"z": expected}, until=Strain(0.25))]


def test_the_rate_is_taken_at_the_lowest_stress_of_the_path(tmp_path):
    text = """
[[stage]]
strain_rate = {x = 0, y = 0, z = "quasi-static"}
until = {stress = 5000}
[[stage]]
strain_rate = {x = 0, y = 0, z = "-quasi-static"}
until = {stress = 300}
[[stage]]
stress = {x = 0, y = 400, z = 400}
"""
    config = triaxial_config(tmp_path, text)
    assert config.reference_pressure() == 300.0        # below the confining 750 Pa; 0 skipped
    read = read_table(tmp_path / "path.toml")
    assert lowest_stress(read["stages"], "t", 200.0) == 200.0
    assert config.rate() == quasi_static_rate(3e-4, None, SAMPLE.radius, SAMPLE.density, 300.0)
    assert config.loading_stages()[1].strain_rate["z"] == -config.rate()


def test_the_configuration_round_trips_through_json_and_rebuilds_the_same_stages(tmp_path):
    config = triaxial_config(tmp_path, """
[[stage]]
stress = {x = "confining", y = "confining", z = 1000}
max_strain_rate = "quasi-static"
[[stage]]
repeat = 2
stages = [{strain_rate = {x = 0, y = 0, z = -0.5}, until = {stress = 500}},
          {strain_rate = {x = 0, y = 0, z = 0.5}, until = {stress = 1000}}]
""")
    again = config_from_dict(config_to_dict(config))
    assert again == config and isinstance(again, TablePathConfig)
    assert again.loading_stages() == config.loading_stages()
    assert len(again.loading_stages()) == 5
    assert again.source.endswith("path.toml")


def test_records_apply_to_one_stage_ending_at_a_strain(tmp_path):
    with pytest.raises(ValueError, match=r"^records = 50 applies to a path of one stage "
                                         r"ending at a strain.*has 2 stage"):
        triaxial_config(tmp_path, TRIAXIAL + TRIAXIAL, records=50)
    with pytest.raises(ValueError, match=r"^records = 1 is outside the valid range \[2, "):
        triaxial_config(tmp_path, TRIAXIAL, records=1)


def test_a_stress_beyond_the_contacts_stiffness_is_refused_with_its_stage(tmp_path):
    with pytest.raises(ValueError, match=r"path.toml: stage 2: until stress = 1e\+06 Pa is "
                                         r"outside the valid range"):
        triaxial_config(tmp_path, TRIAXIAL.replace("0.25", "0.1") + """
[[stage]]
strain_rate = {x = 0, y = 0, z = 1}
until = {stress = 1e6}
""")


# ---------------------------------------------------------------- the summary

def history(sigma, strain, stage, void=None):
    """A hand-made history of wall stresses (rows, 3), axial strains and stage indices."""
    sigma = np.asarray(sigma, dtype=float)
    rows = len(sigma)
    return {"sigma_wall": sigma, "axial_strain": np.asarray(strain, dtype=float),
            "volumetric_strain": 0.5 * np.asarray(strain, dtype=float),
            "void_ratio": np.linspace(0.8, 0.7, rows) if void is None else np.asarray(void),
            "step": np.arange(rows) * 10, "stage": np.asarray(stage)}


def test_the_summary_gives_each_stage_end_and_p_and_q():
    sigma = [[500, 500, 500], [500, 500, 800], [500, 500, 1100], [600, 700, 1200],
             [600, 700, 900]]
    summary = path_summary(history(sigma, [0, 0.01, 0.02, 0.03, 0.02], [0, 0, 0, 1, 1]), 3)
    rows = summary["stages"]
    assert [r["row"] for r in rows] == [2, 4, 4]        # stage 2 ended at once, where 1 did
    assert [r["stage"] for r in rows] == [0, 1, 2]
    assert rows[0]["p"] == pytest.approx(700.0) and rows[0]["q"] == pytest.approx(600.0)
    assert rows[1]["q"] == pytest.approx(900.0 - 650.0)
    assert rows[1]["sigma_wall"] == [600.0, 700.0, 900.0] and rows[1]["step"] == 40
    assert summary["initial_void_ratio"] == 0.8 and summary["final_void_ratio"] == 0.7
    # q rose to the end of the stage and then unloaded: no peak within a stage
    assert summary["has_peak"] is False and "peak_q" not in summary


def test_a_peak_is_found_where_q_rises_then_falls_within_a_stage():
    strain = np.linspace(0.0, 0.2, 41)
    q = 1000.0 * strain / (0.02 + strain) * np.exp(-3.0 * strain)       # peak then softening
    sigma = np.stack([np.full_like(q, 500.0), np.full_like(q, 500.0), 500.0 + q], axis=1)
    summary = path_summary(history(sigma, strain, np.zeros(41, dtype=int)))
    peak = int(np.argmax(q))
    assert summary["has_peak"] is True and summary["peak_index"] == peak
    assert summary["peak_q"] == pytest.approx(q[peak])
    assert summary["p_at_peak"] == pytest.approx(500.0 + q[peak] / 3.0)
    sigma_1, sigma_3 = 500.0 + q[peak], 500.0
    assert summary["phi_peak_deg"] == pytest.approx(
        np.degrees(np.arcsin((sigma_1 - sigma_3) / (sigma_1 + sigma_3))))
    assert summary["axial_strain_at_peak"] == strain[peak] and summary["peak_stage"] == 0
    # the same q still rising at the end: no peak
    rising = sigma[: peak + 1]
    assert path_summary(history(rising, strain[: peak + 1],
                                np.zeros(peak + 1, dtype=int)))["has_peak"] is False


def test_a_wet_summary_adds_the_effective_stress():
    sigma = np.array([[500.0, 500.0, 500.0], [500.0, 500.0, 900.0]])
    made = history(sigma, [0.0, 0.01], [0, 0])
    made["sigma_effective"] = np.array([np.diag(s + 300.0) for s in sigma])
    row = path_summary(made)["stages"][0]
    assert row["p_effective"] == pytest.approx(row["p"] + 300.0)
    assert row["q_effective"] == pytest.approx(row["q"])


def test_change_suction_refuses_volume_controlled_bridges_and_a_bad_suction():
    from pendular.procedures.config import BridgeConfig
    from pendular.procedures.path import change_suction

    volume = BridgeConfig(suction=3e4, control="volume").build()
    with pytest.raises(ValueError, match="control = 'volume': change_suction needs "
                                         "suction-controlled bridges"):
        change_suction(None, volume, 3e5, stress={"z": 1e4})
    with pytest.raises(ValueError, match=r"suction = -5 Pa is outside the valid range"):
        change_suction(None, BridgeConfig(suction=3e4).build(), -5, stress={"z": 1e4})
