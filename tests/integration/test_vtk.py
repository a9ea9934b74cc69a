"""ParaView series written by pendular.io.vtk.VtkWriter, read back with meshio (and as XML)."""

import copy
import os
import xml.etree.ElementTree as ElementTree

import meshio
import numpy as np
import pytest

import pendular

from conftest import requires, two_body_scene
from pendular.procedures.preparation import PrepareConfig, prepare_sample
from pendular.capillary import BridgeState
from pendular.io.vtk import VtkWriter


@pytest.fixture(scope="module")
def prepared():
    sim, _ = prepare_sample(PrepareConfig(particles=60, unload_steps=200, confining=750.0),
                            progress=False)
    return sim


def read_pvd(path):
    """[(timestep, file)] of a ParaView collection."""
    root = ElementTree.parse(path).getroot()
    assert root.get("type") == "Collection"
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def hand_counts(sim):
    """Per particle: touching pairs and sum of |contact force|, by a plain loop."""
    c = sim.contacts
    count = np.zeros(len(sim.particles), int)
    force = np.zeros(len(sim.particles))
    for k in range(len(c)):
        if c.overlap[k] > 0:
            for p in (c.pair_i[k], c.pair_j[k]):
                count[p] += 1
                force[p] += np.sqrt(np.sum(c.force[k] ** 2))
    return count, force


def test_series_list_every_frame_with_its_time_and_hold_the_particle_arrays(prepared, tmp_path):
    sim = copy.deepcopy(prepared)
    folder = tmp_path / "vtk"
    writer = VtkWriter(folder, period=50)
    sim.writers.append(writer)
    start = sim.step
    times = {}
    for _ in range(120):
        sim.run(1)
        times[sim.step] = sim.time
    writer.close(sim)           # final frame of a run that does not end on a period
    expected = [start + 1] + [s for s in range(start + 1, start + 121) if s % 50 == 0]
    expected.append(start + 120)
    assert [step for step, _ in writer.frames] == expected
    for series in ("particles", "walls", "bridges"):
        frames = read_pvd(folder / f"{series}.pvd")
        assert [name for _, name in frames] == [f"{series}_{s:06d}.vtu" for s in expected]
        assert [t for t, _ in frames] == [times[s] for s in expected]     # repr: exact
        assert all((folder / name).is_file() for _, name in frames)
    assert not [name for name in os.listdir(folder) if ".tmp" in name]

    series = pendular.read_vtk(folder / "particles.pvd")      # the whole series, with meshio
    assert [time for time, _ in series] == [times[s] for s in expected]
    assert np.array_equal(series[-1][1].points, sim.particles.position)
    with pytest.raises(ValueError, match="not a readable ParaView collection"):
        pendular.read_vtk(folder / "particles_000001.vtu.missing")
    mesh = meshio.read(folder / f"particles_{sim.step:06d}.vtu")
    p = sim.particles
    assert np.array_equal(mesh.points, p.position)
    assert mesh.cells[0].type == "vertex" and len(mesh.cells[0].data) == len(p)
    data = mesh.point_data
    assert np.array_equal(data["radius"], p.radius)
    assert np.array_equal(data["id"], np.arange(len(p)))
    assert np.array_equal(data["velocity"], p.velocity)
    assert np.array_equal(data["angular_velocity"], p.angular_velocity)
    count, force = hand_counts(sim)
    assert count.sum() > len(p)                 # a packing: most particles touch
    assert np.array_equal(data["coordination"], count)
    assert np.allclose(data["contact_force"], force, rtol=1e-12, atol=0)
    assert np.array_equal(data["bridges"], np.zeros(len(p)))


def test_walls_are_quads_on_the_wall_planes_with_their_stress(prepared, tmp_path):
    sim = copy.deepcopy(prepared)
    sim.run(10)
    writer = VtkWriter(tmp_path, period=1000)
    writer.apply(sim)           # first call writes whatever the step
    mesh = meshio.read(tmp_path / f"walls_{sim.step:06d}.vtu")
    quads = mesh.cells[0]
    assert quads.type == "quad" and quads.data.shape == (6, 4)
    walls = sim.walls
    for w in range(6):
        axis = w // 2
        corners = mesh.points[quads.data[w]]
        assert np.all(corners[:, axis] == walls.position[w])
        for other in {0, 1, 2} - {axis}:
            assert set(corners[:, other]) == {walls.lo[other], walls.hi[other]}
    assert np.array_equal(mesh.cell_data["wall"][0], np.arange(6))
    stress = mesh.cell_data["normal_stress"][0]
    assert np.array_equal(stress, walls.force / walls.areas())
    assert np.allclose(0.5 * (stress[0::2] + stress[1::2]), 750.0, rtol=0.05)


def test_dry_scene_writes_an_empty_valid_bridge_file(prepared, tmp_path):
    sim = copy.deepcopy(prepared)
    VtkWriter(tmp_path, period=10).apply(sim)
    path = tmp_path / f"bridges_{sim.step:06d}.vtu"
    root = ElementTree.parse(path).getroot()        # meshio 5.3 cannot read a file without cells
    assert root.get("type") == "UnstructuredGrid"
    piece = root.find("UnstructuredGrid/Piece")
    assert piece.get("NumberOfPoints") == "0" and piece.get("NumberOfCells") == "0"
    names = {array.get("Name") for array in piece.find("Cells")}
    assert names == {"connectivity", "offsets", "types"}
    assert read_pvd(tmp_path / "bridges.pvd") == [(sim.time, path.name)]


def test_bridges_are_lines_with_their_data(prepared, tmp_path):
    sim = copy.deepcopy(prepared)
    sim.run(1)
    c = sim.contacts
    touching = np.flatnonzero(c.overlap > 0)
    chosen = touching[[0, len(touching) // 2]]
    bridges = BridgeState.of(c)
    bridges.state[chosen] = 1
    bridges.force[:] = np.arange(len(c), dtype=float) * 1e-6
    bridges.volume[:] = np.arange(len(c), dtype=float) * 1e-15
    bridges.filling_i[:] = 20.0            # equal spheres: delta1 on pair_i
    bridges.filling_j[:] = 15.0
    writer = VtkWriter(tmp_path, period=1)
    writer.apply(sim)
    mesh = meshio.read(tmp_path / f"bridges_{sim.step:06d}.vtu")
    lines = mesh.cells[0]
    assert lines.type == "line" and lines.data.shape == (2, 2)
    p = sim.particles.position
    for line, k in zip(lines.data, chosen):
        assert np.array_equal(mesh.points[line], p[[c.pair_i[k], c.pair_j[k]]])
    assert np.array_equal(mesh.cell_data["force"][0], chosen * 1e-6)
    assert np.array_equal(mesh.cell_data["volume"][0], chosen * 1e-15)
    assert np.array_equal(mesh.cell_data["delta1"][0], [20.0, 20.0])
    assert np.array_equal(mesh.cell_data["delta2"][0], [15.0, 15.0])
    particles = meshio.read(tmp_path / f"particles_{sim.step:06d}.vtu").point_data["bridges"]
    expected = np.zeros(len(sim.particles), int)
    for k in chosen:
        expected[[c.pair_i[k], c.pair_j[k]]] += 1
    assert np.array_equal(particles, expected)


def test_filling_angles_of_the_capillary_operation_are_sorted_by_radius(tmp_path):
    """The capillary operation stores angles per pair member; delta1 is on the smaller sphere."""
    sim = two_body_scene([[0, 0, 0], [2.9e-3, 0, 0], [5.8e-3, 0, 0]], np.zeros((3, 3)),
                         radius=[2e-3, 1e-3, 2e-3])
    sim.run(1)
    c = sim.contacts
    assert list(zip(c.pair_i, c.pair_j)) == [(0, 1), (1, 2)] and np.all(c.overlap > 0)
    bridges = BridgeState.of(c)
    bridges.state[:] = 1
    bridges.force[:] = [1e-5, 2e-5]
    bridges.volume[:] = [1e-12, 2e-12]
    bridges.filling_i[:] = [10.0, 30.0]
    bridges.filling_j[:] = [25.0, 12.0]
    VtkWriter(tmp_path, period=1).apply(sim)
    mesh = meshio.read(tmp_path / f"bridges_{sim.step:06d}.vtu")
    # pair (0, 1): sphere 1 is the smaller; pair (1, 2): sphere 1 again
    assert np.array_equal(mesh.cell_data["delta1"][0], [25.0, 30.0])
    assert np.array_equal(mesh.cell_data["delta2"][0], [10.0, 12.0])
    counts = meshio.read(tmp_path / f"particles_{sim.step:06d}.vtu").point_data["bridges"]
    assert np.array_equal(counts, [1, 2, 1])


def test_contact_network_series_and_strain_field_data(prepared, tmp_path):
    """contacts.pvd: one line per touching pair with its normal and shear force; every frame
    carries its step, time and the writer's field data (e.g. the axial strain)."""
    sim = copy.deepcopy(prepared)
    sim.run(1)
    VtkWriter(tmp_path, period=1, field_data=lambda s: {"axial_strain": 0.0125}).apply(sim)
    mesh = meshio.read(tmp_path / f"contacts_{sim.step:06d}.vtu")
    c = sim.contacts
    touching = np.flatnonzero(c.overlap > 0)
    assert mesh.cells[0].type == "line" and len(mesh.cells[0].data) == len(touching)
    assert np.array_equal(mesh.cell_data["normal_force"][0], c.normal_force[touching])
    assert np.allclose(mesh.cell_data["shear_force"][0],
                       np.linalg.norm(c.shear_force[touching], axis=1))
    assert not mesh.cell_data["bridge"][0].any()
    root = ElementTree.parse(tmp_path / f"contacts_{sim.step:06d}.vtu").getroot()
    fields = {array.get("Name"): float(array.text)
              for array in root.find("UnstructuredGrid/FieldData")}
    assert fields == {"step": sim.step, "time": sim.time, "axial_strain": 0.0125}
    assert read_pvd(tmp_path / "contacts.pvd") == [(sim.time, f"contacts_{sim.step:06d}.vtu")]


def test_writer_input_is_checked(tmp_path):
    with pytest.raises(ValueError, match="vtk period"):
        VtkWriter(tmp_path, period=0)
    with pytest.raises(ValueError, match="compression"):
        VtkWriter(tmp_path, period=1, compression="gzip")


# ---------------------------------------------------------------- read back with VTK itself

#: Point or cell arrays of each series (pendular.io.vtk docstring); bridges and contacts carry
#: theirs only when they have cells.
SERIES_ARRAYS = {
    "particles": ("point", {"id", "radius", "velocity", "angular_velocity", "contact_force",
                            "coordination", "bridges"}),
    "walls": ("cell", {"wall", "normal_stress", "force", "velocity"}),
    "bridges": ("cell", {"force", "volume", "delta1", "delta2"}),
    "contacts": ("cell", {"normal_force", "shear_force", "bridge"}),
}


def vtk_frames(folder, series):
    """[(pvd timestep, vtkUnstructuredGrid)] of every frame of ``folder``/``series``.pvd, read
    with VTK's own XML reader (tests that call it need vtk: ``requires("vtk")``)."""
    import vtk

    frames = []
    for timestep, name in read_pvd(folder / f"{series}.pvd"):
        reader = vtk.vtkXMLUnstructuredGridReader()
        reader.SetFileName(str(folder / name))
        reader.Update()
        assert reader.GetErrorCode() == 0, name
        frames.append((timestep, reader.GetOutput()))
    return frames


def vtk_arrays(data):
    """name -> NumPy array of a vtkDataSetAttributes / vtkFieldData."""
    from vtk.util.numpy_support import vtk_to_numpy
    return {data.GetArrayName(i): vtk_to_numpy(data.GetArray(i))
            for i in range(data.GetNumberOfArrays())}


@requires("vtk")
@pytest.mark.parametrize("folder", ["vtk", "vtk_prep"])
def test_every_series_of_a_wet_run_reads_back_with_vtk(wet_triaxial_run, folder):
    """Each series of the shear (vtk/) and of the preparation and wetting (vtk_prep/) opens
    with the vtk package: 200 spheres, six wall quads, two points per bridge or contact line,
    the declared arrays, and field data step, time and axial_strain (shear: the .pvd time axis
    is the axial strain in %, field data axial_strain_percent) or phase (preparation: every
    phase of a wet run, in order)."""
    from pendular.procedures.laboratory import PREP_PHASES

    path = wet_triaxial_run / folder
    steps = None
    for series, (where, names) in SERIES_ARRAYS.items():
        frames = vtk_frames(path, series)
        assert len(frames) >= 10
        fields = [vtk_arrays(grid.GetFieldData()) for _, grid in frames]
        if steps is None:
            steps = [f["step"][0] for f in fields]
            assert steps == sorted(set(steps))
        assert [f["step"][0] for f in fields] == steps          # every series, same frames
        for (timestep, grid), field in zip(frames, fields):
            points, cells = grid.GetNumberOfPoints(), grid.GetNumberOfCells()
            data = vtk_arrays(grid.GetPointData() if where == "point" else grid.GetCellData())
            if series == "particles":
                assert points == cells == 200
                assert data["radius"].shape == (200,) and data["velocity"].shape == (200, 3)
            elif series == "walls":
                assert (points, cells) == (24, 6)
                assert list(data["wall"]) == list(range(6))
            else:
                assert points == 2 * cells
            if cells:
                assert set(data) == names, (series, sorted(data))
                assert all(len(values) == cells for values in data.values())
            if folder == "vtk":
                assert set(field) == {"step", "time", "axial_strain", "axial_strain_percent"}
                assert timestep == field["axial_strain_percent"][0]      # the same unit, %
                assert timestep == pytest.approx(100.0 * field["axial_strain"][0], abs=1e-12)
            else:
                assert set(field) == {"step", "time", "phase", "mean_wall_stress"}
                assert timestep == field["time"][0]
    if folder == "vtk":
        strain = [f["axial_strain"][0] for f in fields]
        assert 0.0 < strain[0] < 1e-3                  # the first step of the shear
        assert np.all(np.diff(strain) > 0.0)
        assert strain[-1] == pytest.approx(0.01, rel=0.02)
        bridges = vtk_arrays(vtk_frames(path, "contacts")[-1][1].GetCellData())["bridge"]
        assert bridges.any()                       # a wet run: contacts holding bridges
    else:
        phases = [PREP_PHASES[int(f["phase"][0])] for f in fields]
        assert list(dict.fromkeys(phases)) == ["growth", "friction", "unload", "equilibrate",
                                               "wetting"]
        last = vtk_frames(path, "bridges")[-1][1]
        assert last.GetNumberOfCells() > 0            # the wetted sample holds bridges
        assert fields[-1]["mean_wall_stress"][0] == pytest.approx(750.0, rel=0.02)
