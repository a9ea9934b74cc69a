"""The outputs reference: every summary key a command writes is declared once
(pendular.io.schema.SUMMARY_KEYS: units, meaning, the commands that write it), checked on the
summaries of synthetic histories of every laboratory test, and the generated page lists each
key with its meaning and commands. The run-level keys are checked on real runs
(tests/e2e/test_summaries.py)."""

import importlib.util
import os

import numpy as np
import pytest

from conftest import ROOT
from pendular.io.columns import HISTORY_COLUMNS
from pendular.io.schema import SUMMARY_KEYS, SUMMARY_UNITS, undeclared_keys
from pendular.procedures.config import ShearConfig
from pendular.procedures.cyclic import cyclic_summary
from pendular.procedures.loading import Stage, Strain
from pendular.procedures.triaxial import excess_pore_pressure, path_deviations, undrained_summary
from pendular.procedures.isotropic import isotropic_summary
from pendular.procedures.oedometer import oedometer_summary
from pendular.procedures.path import path_summary
from pendular.procedures.simple_shear import simple_shear_summary
from pendular.procedures.laboratory import stress_balance
from pendular.procedures.triaxial import summarize

ROWS = 200


def history(axial, lateral, *, wet=False, stage=None, **columns):
    """A history of wall stresses ``axial`` on z and ``lateral`` on x and y [Pa] (arrays of
    ROWS), strains rising to 20 %, with ``stage``, ``columns`` and, ``wet``, the capillary
    columns (an isotropic psi of 300 Pa)."""
    sigma = np.column_stack([lateral, lateral, axial]).astype(float)
    strain = np.linspace(0.0, 0.2, len(sigma))
    found = {"step": np.arange(len(sigma)) * 100, "sigma_wall": sigma, "axial_strain": strain,
             "volumetric_strain": -0.05 * (1.0 - np.exp(-strain / 0.02)),
             "porosity": np.full(len(sigma), 0.4), "void_ratio": np.full(len(sigma), 0.66),
             "unbalanced_force": np.full(len(sigma), 1e-3),
             "sigma_contact": np.array([np.diag(row) for row in sigma])}
    if wet:
        psi = np.array([np.eye(3) * 300.0] * len(sigma))
        found.update({"psi": psi, "sigma_effective": found["sigma_contact"] + psi,
                      "sigma_effective_complete": found["sigma_contact"] + 1.1 * psi,
                      "saturation": np.full(len(sigma), 0.05),
                      "suction": np.full(len(sigma), 3e4)})
    if stage is not None:
        found["stage"] = np.asarray(stage)
    found.update(columns)
    return found


def shear(wet=False, extension=False):
    t = np.linspace(0.0, 1.0, ROWS)
    q = 1000.0 * np.sin(np.pi * t) + 600.0 * t
    axial = 750.0 - 0.6 * q if extension else 750.0 + q     # extension: the walls leave
    return history(axial, np.full(ROWS, 750.0), wet=wet)


def assert_declared(summary, command):
    assert not undeclared_keys(summary, command), (command, undeclared_keys(summary, command))


@pytest.mark.parametrize("wet", [False, True])
def test_the_triaxial_summaries_write_declared_keys(wet):
    for direction, b, constant_p in (("compression", None, False), ("extension", None, False),
                                     ("compression", 0.5, False),
                                     ("compression", None, True)):
        found = shear(wet, extension=direction == "extension")
        summary = summarize(found, direction, b)
        summary.update(path_deviations(found, ShearConfig(direction=direction, b=b,
                                                          constant_p=constant_p), 750.0))
        summary["peak_reached"] = True
        assert_declared(summary, "triaxial")
    assert "phi_peak_note" in summarize(shear(wet, extension=True), "extension")


@pytest.mark.parametrize("wet", [False, True])
def test_the_compression_summaries_write_declared_keys(wet):
    axial = np.concatenate([np.linspace(500.0, 2000.0, 100), np.linspace(2000.0, 1000.0, 100)])
    void = np.linspace(0.7, 0.6, ROWS)
    oedometer = history(axial, 0.5 * axial, wet=wet, stage=np.repeat([0, 1], 100),
                        void_ratio=void, k0=np.full(ROWS, 0.5))
    summary = {**oedometer_summary(oedometer, 2000.0, 1000.0), **stress_balance(oedometer)}
    assert_declared(summary, "oedometer")
    p = np.repeat([500.0, 1000.0, 2000.0, 1000.0], 50)
    isotropic = history(p, p, wet=wet, stage=np.repeat(np.arange(4), 50), void_ratio=void)
    assert_declared(isotropic_summary(isotropic, [500.0, 1000.0, 2000.0, 1000.0]),
                    "isotropic")
    path = shear(wet)
    path.update(stage=np.repeat([0, 1], 100), void_ratio=void)
    assert_declared(path_summary(path), "path")


@pytest.mark.parametrize("wet", [False, True])
def test_the_cyclic_and_simple_shear_summaries_write_declared_keys(wet):
    t = np.linspace(0.0, 5.0 * np.pi, 500)
    q = 100.0 * np.sin(t)
    stage = np.minimum(((t + 0.5 * np.pi) // np.pi).astype(int), 4)
    cyclic = history(750.0 + q, np.full(len(t), 750.0), wet=wet, stage=stage,
                     axial_strain=1e-4 * np.sin(t - 0.1))
    assert_declared(cyclic_summary(cyclic, 2, confining=750.0), "cyclic")
    gamma = np.linspace(0.0, 0.3, ROWS)
    for constant_volume in (False, True):
        simple = history(np.full(ROWS, 1000.0), np.full(ROWS, 1000.0), wet=wet,
                         shear_strain=gamma, shear_stress=600.0 * np.tanh(gamma / 0.02),
                         normal_stress=np.full(ROWS, 1000.0))
        summary = simple_shear_summary(simple, constant_volume)
        assert_declared(summary, "simple-shear")
        assert summary["shear_stress_at_peak"] == pytest.approx(
            summary["peak_stress_ratio"] * summary["normal_stress_at_peak"])


@pytest.mark.parametrize("wet", [False, True])
def test_the_undrained_summary_writes_declared_keys(wet):
    found = shear(wet)
    found["excess_pore_pressure"] = excess_pore_pressure(found["sigma_wall"])
    summary = summarize(found, "compression")
    summary.update(undrained_summary(found, summary["peak_index"]))
    assert ("suction_final" in summary) == wet
    assert_declared(summary, "triaxial")


@pytest.mark.parametrize("water", ["suction", "water_content"])
def test_a_path_changing_its_water_writes_declared_keys(water):
    """A path held at 750 Pa, wetted (the suction lowered, or the water content raised: the
    stage's in %, the history's a fraction), then sheared."""
    held = {axis: 750.0 for axis in "xyz"}
    before, after, given = (3e4, 1e4, 1e4) if water == "suction" else (0.05, 0.08, 8.0)
    stages = [Stage(stress=held), Stage(stress=held, **{water: given}),
              Stage(stress={"x": 750.0, "y": 750.0}, strain_rate={"z": 1.0},
                    until=Strain(0.2))]
    stage = np.repeat([0, 1, 2], [60, 60, 80])
    path = shear(wet=True)
    path.update(stage=stage, void_ratio=np.linspace(0.7, 0.6, ROWS),
                **{water: np.where(stage == 0, before, after)})
    summary = path_summary(path, len(stages), stages)
    assert [row["stage"] for row in summary["water_stages"]] == [1]
    assert "collapse_strain" in summary and "collapse_axial_strain" in summary
    assert_declared(summary, "path")


def test_an_undeclared_key_or_field_is_named():
    assert undeclared_keys({"peak_q": 1.0, "mystery": 2.0, "units": {}}, "triaxial") == \
        ["mystery"]
    assert undeclared_keys({"peak_shear_stress": 1.0}, "triaxial") == ["peak_shear_stress"]
    assert undeclared_keys({"stages": [{"p": 1.0, "odd": 2.0}]}, "isotropic") == ["stages.odd"]


def test_every_key_has_units_a_meaning_and_its_commands():
    from pendular.cli import COMMANDS

    for name, column in HISTORY_COLUMNS.items():
        assert column.commands and set(column.commands) <= set(COMMANDS), name
    for name, key in SUMMARY_KEYS.items():
        assert key.description and key.units, name
        assert key.commands and set(key.commands) <= set(COMMANDS), name
        assert SUMMARY_UNITS[name] == key.units, name


def test_the_generated_reference_lists_every_key_with_its_meaning_and_commands():
    spec = importlib.util.spec_from_file_location(
        "pendular_docs", os.path.join(ROOT, "docs", "_ext", "pendular_docs.py"))
    docs = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(docs)
    page = docs.outputs_tables()
    summary_keys = page.split("## Summary keys")[1].split("\n## ")[0]
    for name, key in SUMMARY_KEYS.items():
        line = next(line for line in summary_keys.splitlines()
                    if line.startswith(f"| `{name}` |"))
        assert docs._cell(key.description) in line
        assert all(command in line for command in key.commands), name


def test_a_measure_that_cannot_be_taken_is_null_with_a_note_saying_why():
    flat = history(np.full(ROWS, 750.0), np.full(ROWS, 750.0))            # q stays 0
    deviations = path_deviations(flat, ShearConfig(b=0.5), 750.0)
    assert deviations["b_deviation"] is None
    assert deviations["b_deviation_note"].startswith("not measured: no record")
    gamma = np.linspace(0.0, 0.3, ROWS)
    unloaded = history(np.full(ROWS, 1000.0), np.full(ROWS, 1000.0), shear_strain=gamma,
                       shear_stress=600.0 * np.tanh(gamma / 0.02),
                       normal_stress=np.where(gamma < 0.25, 1000.0, 0.0))
    summary = simple_shear_summary(unloaded, False)
    assert summary["phi_residual_deg"] is None and summary["residual_stress_ratio"] is None
    assert summary["phi_residual_note"].startswith("not measured: no record in the last 10 %")
    still = history(np.full(3, 1000.0), np.full(3, 1000.0), shear_strain=np.zeros(3),
                    shear_stress=np.zeros(3), normal_stress=np.full(3, 1000.0))
    summary = simple_shear_summary(still, False)
    assert summary["max_dilatancy"] is None and "did not move" in summary["max_dilatancy_note"]
    for found, command in ((deviations, "triaxial"), (summary, "simple-shear")):
        assert_declared(found, command)
