"""Fault injection on what pendular reads back (issue 12): checksums and identities
(pendular.utils.integrity), physical checks of samples (pendular.dem.sample), cached bridge tables rebuilt when
tampered (pendular.capillary.table, pendular.capillary.volume_table), and output folders (pendular.io.outputs)."""

import json
import os
import re
import types

import h5py
import numpy as np
import pytest

from pendular.capillary.suction_control import bridge_at_distance
from pendular.capillary.table import NODE_TOLERANCE, BridgeTable, distance_fraction, spot_nodes
from pendular.capillary.volume_table import VolumeBridgeTable
from conftest import zero_bytes
from pendular.utils.integrity import checksum, config_hash, stamp, verify
from pendular.dem.sample import MAX_OVERLAP, check_consistent, load_sample, save_sample
from pendular.dem.state import Particles, Walls

RADIUS = 1e-3
DENSITY = 2650.0


# ---------------------------------------------------------------- helpers
def lattice(n=3, overlap=0.01):
    """(Particles, Walls): n^3 spheres of RADIUS on a cubic lattice, each pair of neighbours
    overlapping by ``overlap`` R, the walls touching the outer spheres."""
    spacing = 2.0 * RADIUS * (1.0 - 0.5 * overlap)
    axis = RADIUS + spacing * np.arange(n)
    position = np.array(np.meshgrid(axis, axis, axis, indexing="ij")).reshape(3, -1).T
    particles = Particles(np.ascontiguousarray(position), np.full(n ** 3, RADIUS), DENSITY)
    walls = Walls.box(np.zeros(3), np.full(3, axis[-1] + RADIUS))
    return particles, walls


def write_sample(path, particles=None, walls=None, config=None):
    if particles is None:
        particles, walls = lattice()
    save_sample(path, types.SimpleNamespace(particles=particles, walls=walls), {"steps": 1},
                config if config is not None else {"radius": RADIUS, "seed": 3})
    return str(path)


def edit(path, change):
    """Apply ``change(handle)`` to the HDF5 file and stamp it again with its own identity:
    a file whose checksum is right but whose content is wrong (a writer's bug, or a forger)."""
    identity = verify(path, kind="file")
    with h5py.File(path, "r+") as handle:
        change(handle)
    stamp(path, identity)


# ---------------------------------------------------------------- checksums and identity
def test_stamped_file_verifies_and_returns_its_identity(tmp_path):
    path = write_sample(tmp_path / "sample.h5")
    identity = verify(path, {"kind": "sample"})
    assert identity["kind"] == "sample" and identity["software_version"]
    assert identity["config_hash"] == config_hash({"seed": 3, "radius": RADIUS})
    assert checksum(path).startswith("sha256:")


def test_config_hash_is_canonical():
    assert config_hash({"a": 1, "b": [1.5, 2]}) == config_hash({"b": [1.5, 2], "a": 1})
    assert config_hash({"a": 1}) != config_hash({"a": 2})
    assert config_hash({"a": np.float64(0.1)}) == config_hash({"a": 0.1})
    assert len(config_hash({})) == 64


def test_zeroed_bytes_in_a_dataset_are_refused(tmp_path):
    path = write_sample(tmp_path / "sample.h5")
    zero_bytes(path, "position")
    with pytest.raises(ValueError, match="checksum mismatch") as error:
        load_sample(path)
    assert path in str(error.value)


def test_an_edited_attribute_is_refused(tmp_path):
    path = str(tmp_path / "checkpoint.h5")
    with h5py.File(path, "w") as handle:
        handle.attrs["step"] = 100
        handle.create_group("particles").create_dataset("position", data=np.ones((4, 3)))
        stamp(handle, {"kind": "checkpoint", "seed": 1})
    verify(path, {"seed": 1}, kind="checkpoint")
    with h5py.File(path, "r+") as handle:
        handle.attrs["step"] = -5
    with pytest.raises(ValueError, match="checksum mismatch: this checkpoint was edited"):
        verify(path, kind="checkpoint")


def test_nested_datasets_and_their_attributes_are_covered(tmp_path):
    path = str(tmp_path / "file.h5")
    with h5py.File(path, "w") as handle:
        handle.create_group("contacts/extra").create_dataset("bridge.volume", data=np.arange(3.0))
        handle["contacts/extra/bridge.volume"].attrs["unit"] = "m^3"
        handle.attrs["names"] = np.array(["a", "b"], dtype=h5py.string_dtype())
        stamp(handle, {"kind": "test"})
    verify(path, kind="test")
    with h5py.File(path, "r+") as handle:
        handle["contacts/extra/bridge.volume"].attrs["unit"] = "mm^3"
    with pytest.raises(ValueError, match="checksum mismatch"):
        verify(path, kind="test")


def test_a_foreign_identity_is_refused_naming_the_key(tmp_path):
    path = str(tmp_path / "checkpoint.h5")
    with h5py.File(path, "w") as handle:
        handle["state"] = np.zeros(8, np.uint8)
        stamp(handle, {"kind": "checkpoint", "seed": 1, "config_hash": "abc"})
    with pytest.raises(ValueError, match="identity mismatch: seed = 1 in the file, 2 expected"):
        verify(path, {"kind": "checkpoint", "seed": 2, "config_hash": "abc"}, kind="checkpoint")


def test_a_truncated_file_is_refused_naming_the_path(tmp_path):
    path = write_sample(tmp_path / "sample.h5")
    os.truncate(path, os.path.getsize(path) // 2)
    with pytest.raises(ValueError, match="not a readable pendular sample") as error:
        load_sample(path)
    assert path in str(error.value)


def test_a_file_without_checksum_is_refused_with_what_to_do(tmp_path):
    path = str(tmp_path / "old.h5")
    particles, walls = lattice()
    with h5py.File(path, "w") as handle:      # the layout of pendular 0.1
        for name in ("position", "radius", "velocity", "angular_velocity"):
            handle[name] = getattr(particles, name)
        handle["walls"] = walls.position
        handle.attrs.update({"density": DENSITY, "report": "{}", "config": "{}"})
    with pytest.raises(ValueError, match="no checksum .* older than 0.2.*prepare the sample"):
        load_sample(path)


# ---------------------------------------------------------------- samples: physical checks
def test_a_valid_sample_loads_and_matches_its_run(tmp_path):
    path = write_sample(tmp_path / "sample.h5")
    particles, walls, report, config = load_sample(
        path, expected={"radius": RADIUS, "particles": 27, "density": DENSITY})
    assert len(particles) == 27 and report == {"steps": 1} and config["seed"] == 3
    assert np.array_equal(walls.position, lattice()[1].position)


def test_a_sample_with_50_percent_overlaps_is_refused(tmp_path):
    path = write_sample(tmp_path / "sample.h5", *lattice(overlap=0.5))
    with pytest.raises(ValueError, match=r"particles \d+ and \d+ .* overlap by 0.5 of the "
                                         rf"smaller radius; valid range: overlaps up to "
                                         rf"{MAX_OVERLAP:g}"):
        load_sample(path)


def test_a_sphere_far_outside_the_box_is_refused(tmp_path):
    particles, walls = lattice()
    particles.position[13] = [0.5, 0.5, 0.5]
    path = write_sample(tmp_path / "sample.h5", particles, walls)
    with pytest.raises(ValueError, match="particle 13 .* overlaps wall x\\+ .* its centre lies "
                                         "outside the box"):
        load_sample(path)


def test_a_sphere_through_a_wall_is_refused(tmp_path):
    particles, walls = lattice()
    particles.position[0, 2] = 0.5 * RADIUS       # half its radius beyond the z- wall
    path = write_sample(tmp_path / "sample.h5", particles, walls)
    with pytest.raises(ValueError, match="particle 0 .* overlaps wall z- .* by 0.5 of its radius"):
        load_sample(path)


def test_all_spheres_at_one_point_are_refused(tmp_path):
    particles, walls = lattice()
    particles.position[:] = 3.0 * RADIUS
    path = write_sample(tmp_path / "sample.h5", particles, walls)
    with pytest.raises(ValueError, match="all 27 particles are at one point"):
        load_sample(path)


def test_a_crowded_sample_is_refused_without_a_quadratic_search(tmp_path):
    rng = np.random.default_rng(1)
    position = 0.05 + 1e-6 * rng.random((20000, 3))
    particles = Particles(position, np.full(20000, RADIUS), DENSITY)
    walls = Walls.box(np.zeros(3), np.full(3, 0.1))
    path = write_sample(tmp_path / "sample.h5", particles, walls)
    with pytest.raises(ValueError, match="20000 particle centres lie in one cube"):
        load_sample(path)


def test_non_finite_values_are_refused(tmp_path):
    path = write_sample(tmp_path / "sample.h5")

    def poison(handle):
        handle["velocity"][4, 1] = np.nan
    edit(path, poison)
    with pytest.raises(ValueError, match=r"velocity\[4, 1\] = nan is not finite"):
        load_sample(path)


@pytest.mark.parametrize("parameter, requested", [
    ("radius", {"radius": 1.5 * RADIUS}), ("particles", {"particles": 1000}),
    ("density", {"density": 2500.0})])
def test_a_sample_from_another_run_is_refused_naming_the_parameter(tmp_path, parameter,
                                                                     requested):
    path = write_sample(tmp_path / "sample.h5")
    expected = {"radius": RADIUS, "particles": 27, "density": DENSITY, **requested}
    with pytest.raises(ValueError, match=parameter) as error:
        load_sample(path, expected=types.SimpleNamespace(**expected))
    assert path in str(error.value)


def test_radius_tolerance_is_relative_1e_9():
    made = {"radius": RADIUS, "particles": 27, "density": DENSITY}
    check_consistent(made, {"radius": RADIUS * (1 + 1e-12)})
    with pytest.raises(ValueError, match="radius = "):
        check_consistent(made, {"radius": RADIUS * (1 + 1e-8)})


# ---------------------------------------------------------------- table caches
SUCTION_OPTIONS = dict(radius_ratios=(1.0,), n_suction=6, n_distance=5, suction_max=50.0)


def cached_suction(tmp_path):
    table = BridgeTable.cached(0.0, directory=tmp_path, **SUCTION_OPTIONS)
    (path,) = tmp_path.glob("bridge_table_*.h5")
    return table, str(path)


def test_a_valid_cache_is_used_silently(tmp_path, capsys):
    first, path = cached_suction(tmp_path)
    capsys.readouterr()
    again = BridgeTable.cached(0.0, directory=tmp_path, **SUCTION_OPTIONS)
    assert capsys.readouterr().err == ""
    assert np.array_equal(first.values, again.values)
    assert verify(path, kind="table cache")["table"] == "suction"


def _doubled_forces(handle):
    handle["values"][..., 0] = 2.0 * handle["values"][..., 0]


def _fewer_nodes(handle):
    values = handle["values"][:, :, :3]
    low, rupture = handle["distance_low"][()], handle["distance_rupture"][()]
    for name in ("values", "distance_low", "distance_rupture"):
        del handle[name]
    handle["values"], handle["distance_low"], handle["distance_rupture"] = values, low, rupture


def _nan_node(handle):
    handle["values"][0, 2, 1, 0] = np.nan


def _farther_rupture(handle):
    handle["distance_rupture"][...] = 1.5 * handle["distance_rupture"][()]


@pytest.mark.parametrize("tamper, restamp, reason", [
    (_doubled_forces, False, "checksum mismatch"),
    (_doubled_forces, True, "from the exact solver"),
    (_farther_rupture, True, "rupture distance d*"),
    (_fewer_nodes, True, "values has shape"),
    (_fewer_nodes, False, "checksum mismatch"),
    (_nan_node, True, "NaN or infinite nodes"),
])
def test_a_tampered_table_cache_is_rebuilt(tmp_path, capsys, tamper, restamp, reason):
    first, path = cached_suction(tmp_path)
    if restamp:
        edit(path, tamper)
    else:
        with h5py.File(path, "r+") as handle:
            tamper(handle)
    capsys.readouterr()
    again = BridgeTable.cached(0.0, directory=tmp_path, **SUCTION_OPTIONS)
    err = capsys.readouterr().err
    (warning,) = [line for line in err.splitlines() if line.startswith("warning:")]
    assert "rebuilding" in warning and reason in warning and path in warning
    assert "building bridge table" in err          # the rebuild says what it builds
    assert np.array_equal(first.values, again.values)
    verify(path, kind="table cache")        # the rebuilt file replaced the tampered one
    assert np.array_equal(BridgeTable.load(path).values, first.values)


def test_a_restamped_table_with_doubled_forces_is_rebuilt_with_exact_forces(
        tmp_path, monkeypatch, capsys):
    """A valid checksum over doubled forces: the spot check against the exact solver finds
    it, says so in one line and rebuilds the table in the cache folder ($PENDULAR_CACHE)."""
    monkeypatch.setenv("PENDULAR_CACHE", str(tmp_path))
    BridgeTable.cached(0.0, **SUCTION_OPTIONS)
    (path,) = tmp_path.glob("bridge_table_*.h5")
    edit(str(path), _doubled_forces)
    assert verify(str(path), kind="table cache")       # the checksum alone passes it
    capsys.readouterr()
    table = BridgeTable.cached(0.0, **SUCTION_OPTIONS)
    err = capsys.readouterr().err
    (warning,) = [line for line in err.splitlines() if line.startswith("warning:")]
    found, exact = map(float, re.search(r"force = (\S+) in the file, (\S+) from the exact "
                                        r"solver", warning).groups())
    assert str(path) in warning and found == pytest.approx(2.0 * exact, rel=1e-9)
    # every interior node of the rebuilt table holds the exact solver's force, in memory and
    # on disk
    suction, n_distance = table.suction, table.n_distance
    on_disk = BridgeTable.load(str(path))
    for k in range(1, table.n_suction):
        low, rupture = table.distance_low[0, k], table.distance_rupture[0, k]
        for j in range(1, n_distance - 1):
            distance = low + (rupture - low) * distance_fraction(j / (n_distance - 1))
            force = bridge_at_distance(1.0, 0.0, suction[k], distance).force
            assert table.values[0, k, j, 0] == pytest.approx(force, rel=1e-12)
            assert on_disk.values[0, k, j, 0] == table.values[0, k, j, 0]
    capsys.readouterr()
    BridgeTable.cached(0.0, **SUCTION_OPTIONS)         # now used as it is
    assert capsys.readouterr().err == ""


def test_a_valid_table_passes_the_spot_check_at_every_node(tmp_path):
    """The spot check never rebuilds a valid table: every node of a built table agrees with
    the exact solver far within NODE_TOLERANCE (the same kernels solve both)."""
    table = BridgeTable.build(20.0, radius_ratios=(1.0, 2.0), n_suction=5, n_distance=4,
                              suction_max=50.0)
    table.check_nodes(count=2 * 5 * 4)
    assert len(spot_nodes(table.values.shape[:3], 2 * 5 * 4)) > 20
    nodes = spot_nodes((10, 350, 80))
    assert {i for i, _, _ in nodes} == set(range(10))        # every radius ratio
    assert all(0 <= k < 350 and 0 <= j < 80 for _, k, j in nodes)
    table.values[1, 3, 2, 4] *= 1.0 + 10 * NODE_TOLERANCE
    with pytest.raises(ValueError, match=r"node r = 2, u\* = \S+, distance index 2 of 4: "
                                         r"nn11 = \S+ in the file, \S+ from the exact solver"):
        table.check_nodes(count=2 * 5 * 4)


def test_an_old_table_cache_without_checksum_is_rebuilt(tmp_path, capsys):
    first, path = cached_suction(tmp_path)
    first.save(path)                        # the unstamped layout of pendular 0.1
    capsys.readouterr()
    BridgeTable.cached(0.0, directory=tmp_path, **SUCTION_OPTIONS)
    assert "no checksum" in capsys.readouterr().err
    verify(path, kind="table cache")


def test_a_tampered_volume_table_cache_is_rebuilt(tmp_path, capsys):
    options = dict(radius_ratios=(1.0,), n_volume=3, n_distance=3, directory=tmp_path)
    first = VolumeBridgeTable.cached(0.0, **options)
    (path,) = tmp_path.glob("volume_bridge_table_*.h5")
    with h5py.File(path, "r+") as handle:
        _doubled_forces(handle)
    capsys.readouterr()
    again = VolumeBridgeTable.cached(0.0, **options)
    assert "checksum mismatch" in capsys.readouterr().err
    assert np.array_equal(first.values, again.values)
    edit(str(path), _nan_node)
    again = VolumeBridgeTable.cached(0.0, **options)
    assert "NaN" in capsys.readouterr().err
    assert np.array_equal(first.values, again.values)
    edit(str(path), _doubled_forces)            # a valid checksum over doubled forces
    again = VolumeBridgeTable.cached(0.0, **options)
    (warning,) = capsys.readouterr().err.splitlines()[:1]
    assert re.search(r"rebuilding it: node r = 1, V\* = \S+, distance index \d of 3: force = "
                     r"\S+ in the file, \S+ from the exact solver", warning), warning
    assert np.array_equal(first.values, again.values)
    assert np.array_equal(VolumeBridgeTable.load(path).values, first.values)
    again.check_nodes(count=3 * 3)              # the built table agrees at every node


# ---------------------------------------------------------------- output folders
@pytest.fixture
def OutputFolder():
    from pendular.io.outputs import OutputFolder
    return OutputFolder


def test_a_second_run_on_one_folder_is_refused_while_the_first_runs(tmp_path, OutputFolder):
    out = str(tmp_path / "run")
    with OutputFolder(out, "triaxial --seed 1"):
        with pytest.raises(ValueError, match="in use by another pendular run .*triaxial --seed 1")\
                as error:
            with OutputFolder(out, "triaxial --seed 2"):
                pass
        assert out in str(error.value)
    with OutputFolder(out, "triaxial --seed 2"):     # free again once the first ended
        pass


def test_files_owned_by_a_previous_run_are_removed(tmp_path, OutputFolder):
    out = tmp_path / "run"
    with OutputFolder(out, "wet run") as folder:
        for name in ("q.png", "vtk/frame_000001.vtu"):
            path = folder.claim(name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            open(path, "w").close()
        folder.claim("vtk")
    (out / "notes.txt").write_text("the user's own file")
    with open(out / ".pendular-outputs.json") as handle:
        manifest = json.load(handle)
    assert manifest["finished"] and manifest["files"] == ["q.png", "vtk", "vtk/frame_000001.vtu"]

    with OutputFolder(out, "wet run, resumed", keep=True) as folder:
        assert (out / "q.png").exists() and folder.files == manifest["files"]
    with OutputFolder(out, "dry run") as folder:
        assert sorted(folder.removed) == manifest["files"]
        assert not (out / "q.png").exists() and not (out / "vtk").exists()
        assert (out / "notes.txt").exists() and folder.files == []


def test_a_manifest_never_removes_files_outside_its_folder(tmp_path, OutputFolder):
    out = tmp_path / "run"
    out.mkdir()
    outside = tmp_path / "precious.txt"
    outside.write_text("keep")
    (out / ".pendular-outputs.json").write_text(json.dumps(
        {"files": ["../precious.txt", str(outside), ".pendular.lock"]}))
    with OutputFolder(out, "run") as folder:
        with pytest.raises(ValueError, match="cannot own"):
            folder.claim("../elsewhere.txt")
    assert outside.read_text() == "keep"


def test_bad_output_paths_are_refused_with_one_clear_error(tmp_path, OutputFolder):
    existing = tmp_path / "file.txt"
    existing.write_text("x")
    cases = {"": "is empty", str(existing): "exists and is a file",
             "/dev/null": "exists and is not a folder",
             str(existing / "below"): "cannot create the folder"}
    if os.geteuid() == 0:       # root writes everywhere except in /proc
        cases["/proc"] = "not writable"
    else:
        locked = tmp_path / "read-only"
        locked.mkdir(mode=0o500)
        cases[str(locked)] = "not writable"
    for path, reason in cases.items():
        with pytest.raises(ValueError, match=reason) as error:
            with OutputFolder(path, "run"):
                pass
        assert repr(path) in str(error.value)
