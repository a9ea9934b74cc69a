"""Self-describing outputs (pendular.io.schema, pendular.io.history): every history column pendular
writes is declared with units, a new column without them is refused, histories and summaries
read back with their coordinates and units."""

import json
from types import SimpleNamespace

import h5py
import numpy as np
import pytest

from pendular.io.history import read_history, read_summary, write_history
from pendular.io.columns import DIMENSIONS, DIMENSION_LABELS
from pendular.io.columns import HISTORY_COLUMNS
from pendular.io.schema import SCHEMA_VERSION, SUMMARY_UNITS, peak_reached

DRY = ["step", "time", "axial_strain", "volumetric_strain", "sigma_wall", "sigma_contact",
       "porosity", "coordination", "fabric", "anisotropy", "unbalanced_force"]
WET = DRY + ["saturation", "suction", "sigma_capillary", "bridges", "pendular_overlaps", "chi",
             "B", "psi", "sigma_effective", "fabric_bridges", "anisotropy_bridges", "a_psi",
             "psi_interface", "sigma_effective_complete"]
TENSION = ["step", "time", "axial_strain", "tensile_stress", "grip_pull", "sigma_wall",
           "coordination", "unbalanced_force", "bridges", "water_content", "saturation"]
#: Columns of a triaxial at constant water content (closed liquid), besides WET.
LIQUID = ["liquid_bridges", "liquid_film", "liquid_lost", "liquid_total"]
PATHS = ["void_ratio", "k0", "stage", "cycle", "shear_strain", "shear_stress", "normal_stress",
         "excess_pore_pressure"]
#: Columns of a run with liquid clusters (--liquid clusters), besides WET.
CLUSTERS = ["clusters", "liquid_in_bridges", "liquid_in_clusters", "liquid_in_largest_cluster",
            "largest_cluster_percolates", "trimers", "liquid_in_trimers", "saturation_pore_units",
            "chi_with_clusters", "sigma_clusters"]
#: Columns of an impact (pendular.procedures.impact), besides time.
IMPACT = ["overlap", "normal_force", "tangential_force", "angular_velocity"]
CONFIG = {"type": "TriaxialConfig", "fields": {"suction": 30000.0, "particles": 200}}
ROWS = 7


def synthetic(names, rows=ROWS):
    """Columns as a HistoryRecorder gives them (float64, first axis the record)."""
    rng = np.random.default_rng(0)
    columns = {}
    for name in names:
        shape = (rows, *HISTORY_COLUMNS[name].shape)
        columns[name] = rng.random(shape)
    columns["step"] = 100.0 * np.arange(rows)
    columns["time"] = 1e-6 * columns["step"]
    columns["axial_strain"] = np.linspace(0.0, 0.01, rows)
    for name in ("bridges", "pendular_overlaps"):
        if name in columns:
            columns[name] = np.arange(rows, dtype=float) + 50.0
    return columns


def check_against_schema(path, expected=None):
    """Every dataset of ``path``'s history against HISTORY_COLUMNS; the column names."""
    with h5py.File(path) as handle:
        assert handle.attrs["schema_version"] == SCHEMA_VERSION
        assert handle.attrs["pendular_version"]
        json.loads(handle.attrs["config"])
        group = handle["history"]
        columns = [name for name in group if name not in DIMENSIONS]
        if expected is not None:
            assert sorted(columns) == sorted(expected)
        for name in columns:
            declared = HISTORY_COLUMNS[name]
            data = group[name]
            assert data.attrs["units"] == declared.units, name
            assert data.attrs["description"] == declared.description, name
            assert data.attrs.get("equation", "") == declared.equation, name
            assert data.dtype == np.dtype(declared.dtype), name
            assert data.shape[1:] == declared.shape, name
            assert [dim.label for dim in data.dims] == ["record", *declared.dims], name
            for dim, scales in zip(("record", *declared.dims), data.dims):
                assert [scale.name.split("/")[-1] for scale in scales.values()] == [dim], name
        for dim, labels in DIMENSION_LABELS.items():
            if dim in group:
                assert [v.decode() for v in group[dim][()]] == list(labels)
        assert list(group["record"][()]) == list(range(len(group["step"])))
    return columns


def test_every_declared_column_has_units_a_description_and_known_dimensions():
    for name, column in HISTORY_COLUMNS.items():
        assert column.units and column.description, name
        assert set(column.dims) <= set(DIMENSION_LABELS), name
        assert column.dtype in ("float64", "int64"), name
    for name in ("step", "bridges", "pendular_overlaps"):
        assert HISTORY_COLUMNS[name].dtype == "int64"
    assert HISTORY_COLUMNS["psi"].equation == "Eq. 3.46"
    assert HISTORY_COLUMNS["sigma_contact"].dims == ("axis", "component")
    assert HISTORY_COLUMNS["grip_pull"].dims == ("grip",)
    assert (set(WET) | set(TENSION) | set(LIQUID) | set(PATHS) | set(IMPACT) | set(CLUSTERS)
            == set(HISTORY_COLUMNS))


def test_the_columns_the_triaxial_records_are_all_declared():
    from pendular.homogenize.on_the_fly import CapillaryHomogenization
    from pendular.procedures.columns import history_columns

    bridges = SimpleNamespace(saturation=None, mean_suction=None, count=None,
                              pendular_overlaps=None, model="exact")
    assert list(history_columns(None, None, 1.0)) == DRY
    assert set(CapillaryHomogenization(bridges).quantities()) == set(WET) - set(DRY)


@pytest.mark.parametrize("names", [DRY, WET, TENSION], ids=["dry", "wet", "tension"])
def test_a_written_history_matches_the_declared_schema(tmp_path, names):
    path = tmp_path / "history.h5"
    write_history(path, synthetic(names), CONFIG, attributes={"confining": 750.0})
    check_against_schema(path, names)
    with h5py.File(path) as handle:
        assert json.loads(handle.attrs["config"]) == CONFIG
        assert handle.attrs["confining"] == 750.0
        assert list(handle["history/step"][()]) == [100 * i for i in range(ROWS)]
    assert not list(tmp_path.glob(".*tmp*"))         # written atomically


def test_an_undeclared_or_misshapen_column_is_refused(tmp_path):
    rows = synthetic(["step", "time"], rows=3)
    path = tmp_path / "h.h5"
    with pytest.raises(ValueError, match="'mystery' is not declared"):
        write_history(path, {**rows, "mystery": np.zeros(3)}, {})
    with pytest.raises(ValueError, match="'sigma_wall' has shape"):
        write_history(path, {**rows, "sigma_wall": np.zeros(3)}, {})
    with pytest.raises(ValueError, match="'psi' has shape"):
        write_history(path, {**rows, "psi": np.zeros((3, 3))}, {})
    with pytest.raises(ValueError, match="'porosity' has 4 records"):
        write_history(path, {**rows, "porosity": np.zeros(4)}, {})
    with pytest.raises(ValueError, match="'bridges' is declared int64"):
        write_history(path, {**rows, "bridges": np.array([1.0, 2.5, 3.0])}, {})
    with pytest.raises(ValueError, match="reserved"):
        write_history(path, rows, {}, attributes={"config": "x"})
    assert not path.exists() and not list(tmp_path.iterdir())


@pytest.mark.parametrize("names", [DRY, WET, TENSION], ids=["dry", "wet", "tension"])
def test_read_history_gives_coordinates_and_units_on_every_variable(tmp_path, names):
    columns = synthetic(names)
    write_history(tmp_path / "history.h5", columns, CONFIG)
    history = read_history(tmp_path, index="record")      # a folder: its history.h5
    assert set(history.coords) >= {"axial_strain", "step", "time"}
    for name in ("axial_strain", "step", "time"):
        assert history[name].dims == ("record",)
        assert history[name].attrs["units"] == HISTORY_COLUMNS[name].units
    assert set(history.data_vars) == set(names) - {"axial_strain", "step", "time"}
    for name, variable in history.variables.items():
        if name in DIMENSION_LABELS:
            assert list(variable.values) == list(DIMENSION_LABELS[name])
            continue
        declared = HISTORY_COLUMNS[name]
        assert variable.attrs["units"] == declared.units, name
        assert variable.attrs["description"] == declared.description, name
        assert variable.dims == ("record", *declared.dims), name
        assert variable.dtype == np.dtype(declared.dtype), name
        np.testing.assert_array_equal(variable.values, columns[name])
    assert history.step.dtype == np.int64
    assert json.loads(history.attrs["config"]) == CONFIG
    assert history.attrs["schema_version"] == SCHEMA_VERSION and history.attrs["pendular_version"]
    assert list(history.sigma_wall.axis.values) == ["x", "y", "z"]
    if "psi" in names:
        assert list(history.psi.component.values) == ["x", "y", "z"]
        assert history.bridges.dtype == np.int64
        assert history.psi.attrs["equation"] == "Eq. 3.46"
        assert float(history.psi.sel(axis="z", component="x")[2]) == columns["psi"][2, 2, 0]
    if "grip_pull" in names:
        assert list(history.grip.values) == ["z-", "z+"]
    by_strain = read_history(tmp_path)        # by default indexed by the rising strain
    assert by_strain.sigma_wall.dims == ("axial_strain", "axis")
    np.testing.assert_array_equal(by_strain.time.sel(axial_strain=0.01), columns["time"][-1])
    assert read_history(tmp_path, index="step").sigma_wall.dims == ("step", "axis")
    with pytest.raises(ValueError, match="index = 'strain' is not one of"):
        read_history(tmp_path, index="strain")


def test_a_history_of_the_old_layout_reads_with_the_declared_attributes(tmp_path):
    columns = synthetic(WET)
    with h5py.File(tmp_path / "history.h5", "w") as handle:   # pendular 0.1: no attributes
        handle.attrs["confining"] = 750.0
        group = handle.create_group("history")
        for name, values in columns.items():
            group.create_dataset(name, data=values)
    history = read_history(tmp_path / "history.h5", index="record")
    assert history.attrs["schema_version"] == 0 and history.attrs["confining"] == 750.0
    assert history.step.dtype == np.int64 and history.bridges.dtype == np.int64
    assert history.psi.dims == ("record", "axis", "component")
    for name, variable in history.variables.items():
        if name not in DIMENSION_LABELS:
            assert variable.attrs["units"] == HISTORY_COLUMNS[name].units, name


def test_unreadable_histories_are_reported_with_their_path(tmp_path):
    with pytest.raises(ValueError, match="missing.h5.*no such file"):
        read_history(tmp_path / "missing.h5")
    with pytest.raises(ValueError, match="history.h5.*no such file"):
        read_history(tmp_path)
    (tmp_path / "history.h5").write_text("not HDF5")
    with pytest.raises(ValueError, match="history.h5.* is not a readable pendular history"):
        read_history(tmp_path)
    with h5py.File(tmp_path / "empty.h5", "w"):
        pass
    with pytest.raises(ValueError, match="empty.h5.*no group 'history'"):
        read_history(tmp_path / "empty.h5")


def test_peak_reached():
    strain = np.linspace(0.0, 0.1, 101)

    def peaked(row):                               # the maximum at ``row``, falling after it
        return -np.abs(np.arange(101.0) - row)

    assert peak_reached(strain, peaked(40))
    assert peak_reached(strain, peaked(97), window=0.02)   # 3 % of the range before the end
    assert not peak_reached(strain, peaked(97))    # the last 20 %: 17 records up, three down
    assert not peak_reached(strain, peaked(100))   # the maximum is the last row
    assert not peak_reached(strain, peaked(99))    # within the last 2 % of the range
    assert not peak_reached(strain, peaked(97), fraction=0.05)
    assert peak_reached(-strain, peaked(40)) and not peak_reached(-strain, peaked(99))  # tension
    assert not peak_reached(np.zeros(3), np.arange(3.0))    # no strain range


def test_read_summary_of_a_run(tmp_path):
    summary = {"peak_q": 1500.0, "p_at_peak": 1250.0, "axial_strain_at_peak": 0.02,
               "peak_index": 40, "peak_reached": True, "completed": True, "threads": 1,
               "wetting_attempts": [1, 2], "units": {"peak_q": "Pa", "p_at_peak": "Pa",
                                                    "axial_strain_at_peak": "1"}}
    (tmp_path / "summary.json").write_text(json.dumps(summary))
    for source in (tmp_path, tmp_path / "summary.json"):
        frame = read_summary(source)
        assert len(frame) == 1 and frame["peak_q"][0] == 1500.0
        assert bool(frame["peak_reached"][0]) and "units" not in frame
        assert "wetting_attempts" not in frame
        assert frame.attrs["units"] == {"peak_q": "Pa", "p_at_peak": "Pa",
                                        "axial_strain_at_peak": "1", "peak_index": "1",
                                        "threads": "1"}
        assert frame.attrs["source"] == str(tmp_path / "summary.json")


def test_read_summary_of_a_campaign(tmp_path):
    runs = [{"suction": 0, "confining": 750.0, "peak_q": 1.0, "saturation_at_peak": 0.0,
             "folder": "runs/s0_c750"},
            {"suction": 3e4, "confining": 750.0, "peak_q": 2.0, "saturation_at_peak": None,
             "folder": "runs/s30000_c750"}]
    (tmp_path / "campaign.json").write_text(json.dumps(
        {"arguments": {"particles": 300}, "runs": runs, "envelopes": {"0": {"phi_deg": 30}}}))
    for source in (tmp_path, tmp_path / "campaign.json"):
        frame = read_summary(source)
        assert list(frame["peak_q"]) == [1.0, 2.0] and list(frame["suction"]) == [0.0, 3e4]
        assert list(frame["folder"]) == ["runs/s0_c750", "runs/s30000_c750"]
        assert frame.attrs["units"] == {"suction": "Pa", "confining": "Pa", "peak_q": "Pa",
                                        "saturation_at_peak": "1"}
    (tmp_path / "campaign.csv").write_text("run,suction,peak_q,bridges\na,0,1.5,exact\n")
    frame = read_summary(tmp_path / "campaign.csv")
    assert frame["peak_q"][0] == 1.5
    assert frame.attrs["units"] == {"suction": "Pa", "peak_q": "Pa"}    # bridges: a model name


def test_read_summary_of_tension_cases(tmp_path):
    cases = [{"case": "e0.72_w0.47", "tensile_strength_pa": 600.0, "bridges": 900},
             {"case": "e0.58_w0.43", "tensile_strength_pa": 800.0, "bridges": 1200}]
    (tmp_path / "tension.json").write_text(json.dumps({"cases": cases, "wall_time_s": 10.0}))
    frame = read_summary(tmp_path)
    assert list(frame["case"]) == ["e0.72_w0.47", "e0.58_w0.43"]
    assert frame.attrs["units"] == {"tensile_strength_pa": "Pa", "bridges": "1"}


def test_unreadable_summaries_are_reported_with_their_path(tmp_path):
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="empty.*no summary.json"):
        read_summary(tmp_path / "empty")
    with pytest.raises(ValueError, match="missing.json.*no such file"):
        read_summary(tmp_path / "missing.json")
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(ValueError, match="bad.json.* is not a readable pendular summary"):
        read_summary(tmp_path / "bad.json")
    (tmp_path / "list.json").write_text("[1, 2]")
    with pytest.raises(ValueError, match="list.json.*expected a JSON object"):
        read_summary(tmp_path / "list.json")
    (tmp_path / "runs.json").write_text('{"runs": 3}')
    with pytest.raises(ValueError, match="runs.json.*'runs' is not a list"):
        read_summary(tmp_path / "runs.json")
    (tmp_path / "empty.csv").write_text("")
    with pytest.raises(ValueError, match="empty.csv.* is not a readable pendular summary"):
        read_summary(tmp_path / "empty.csv")


def test_a_wet_triaxial_run_describes_itself(wet_triaxial_run):
    """The outputs of a real run (scenarios/triaxial.py, 200 spheres at 30 kPa): every dataset
    as declared, read back with units, a summary whose numbers all have units."""
    assert set(check_against_schema(wet_triaxial_run / "history.h5")) == set(WET)
    history = read_history(wet_triaxial_run)
    for name, variable in history.variables.items():
        assert name in DIMENSION_LABELS or variable.attrs["units"], name
    assert json.loads(history.attrs["config"])["type"] == "TriaxialConfig"
    lateral = history["sigma_wall"].sel(axis=["x", "y"]).mean("axis")
    assert float(lateral[-1]) == pytest.approx(750.0, rel=0.05)
    summary = json.loads((wet_triaxial_run / "summary.json").read_text())
    numbers = {k for k, v in summary.items()
               if isinstance(v, (int, float)) and not isinstance(v, bool)}
    assert numbers <= set(summary["units"]) <= set(SUMMARY_UNITS)
    assert isinstance(summary["peak_reached"], bool) and summary["completed"] is True
    frame = read_summary(wet_triaxial_run)
    assert len(frame) == 1 and frame.attrs["units"]["peak_q"] == "Pa"


def test_a_simple_shear_history_is_indexed_by_its_shear_strain(tmp_path):
    """A simple shear's records are indexed by gamma, the strain it drives, not by the vertical
    strain (which may rise too); after a consolidation stage (gamma 0 there) by record."""
    columns = synthetic(DRY + ["shear_strain", "shear_stress", "normal_stress"])
    columns["shear_strain"] = np.linspace(0.0, 0.2, len(columns["step"]))
    write_history(tmp_path / "history.h5", columns, CONFIG)
    history = read_history(tmp_path)
    assert history.sigma_wall.dims == ("shear_strain", "axis")
    assert float(history.shear_stress.sel(shear_strain=0.2)) == columns["shear_stress"][-1]
    columns["shear_strain"][:2] = 0.0                 # a consolidation first
    write_history(tmp_path / "history.h5", columns, CONFIG)
    assert read_history(tmp_path).sigma_wall.dims == ("record", "axis")
    assert read_history(tmp_path, index="shear_strain").shear_strain.dims == ("shear_strain",)


def test_no_key_is_declared_twice():
    """A dict literal keeps the last of two equal keys silently: a second declaration of a
    summary key or column would take the first one's commands away."""
    import ast

    import pendular.io.schema as schema

    with open(schema.__file__, encoding="utf-8") as handle:
        tree = ast.parse(handle.read())
    for node in ast.walk(tree):
        if isinstance(node, ast.Dict):
            keys = [key.value for key in node.keys if isinstance(key, ast.Constant)]
            assert len(keys) == len(set(keys)), sorted({k for k in keys if keys.count(k) > 1})
