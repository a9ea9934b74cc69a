"""Bad input at every public entry point: a ValueError (TypeError for a wrong kind of object,
FileNotFoundError for a missing file) whose message names the parameter."""

import h5py
import numpy as np
import pytest

from pendular import capillary
from pendular.capillary import CapillaryBridges
from pendular.capillary.table import BridgeTable
from pendular.capillary.toroidal_table import toroidal_table
from pendular.capillary.validation import check_filling_angle, check_radius_ratio, check_suction
from pendular.interop.yade.capillary_files import read_capillary_file
from conftest import two_body_scene
from pendular.dem.checkpoint import CheckpointWriter, load_checkpoint
from pendular.dem.contact_law import ContactForces
from pendular.dem.integrate import Integrator
from pendular.dem.timestep import pwave_timestep
from pendular.dem.neighbors import NeighborList
from pendular.dem.cloud import random_cloud
from pendular.procedures.preparation import PrepareConfig, prepare_sample
from pendular.dem.record import HistoryRecorder
from pendular.dem.sample import load_sample
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.io.vtk import VtkWriter
from pendular.dem.walls import StressServo
from pendular.interop.yade.formats import read_plot_data, read_spheres, write_spheres
from pendular.homogenize import (capillary_stress, contact_line_integral, fabric_tensor,
    wetted_cap_integral)

NAN = float("nan")
ONE = np.zeros((1, 3))
#: The neighbour list and integrator every Simulation needs (not under test here).
PIPELINE = {"neighbors": NeighborList(1e-4), "integrator": Integrator(0.0)}


def scene():
    return two_body_scene([[0, 0, 0], [2e-3, 0, 0]], np.zeros((2, 3)))


CASES = {
    # pendular.dem.state
    "radius negative": (lambda: Particles(np.zeros((2, 3)), [1e-3, -1e-3], 2650.0), "radius"),
    "radius nan": (lambda: Particles(np.zeros((2, 3)), [1e-3, NAN], 2650.0), "radius"),
    "radius count": (lambda: Particles(np.zeros((2, 3)), [1e-3], 2650.0), "radius"),
    "position shape": (lambda: Particles(np.zeros((2, 2)), [1e-3, 1e-3], 2650.0), "position"),
    "position inf": (lambda: Particles([[0, 0, np.inf]], [1e-3], 2650.0), "position"),
    "position text": (lambda: Particles("abc", [1e-3], 2650.0), "position"),
    "no particle": (lambda: Particles(np.zeros((0, 3)), [], 2650.0), "position"),
    "density": (lambda: Particles(ONE, [1e-3], -1.0), "density"),
    "velocity count": (lambda: Particles(ONE, [1e-3], 1.0, velocity=np.zeros((2, 3))),
                       "velocity"),
    "angular_velocity nan": (lambda: Particles(ONE, [1e-3], 1.0,
                                               angular_velocity=[[NAN, 0, 0]]),
                             "angular_velocity"),
    "walls count": (lambda: Walls(position=np.zeros(5)), "walls position"),
    "walls inverted": (lambda: Walls(position=[0, 1, 0, 1, 1, 0]), "walls position"),
    "walls nan": (lambda: Walls(position=[0, 1, 0, 1, 0, NAN]), "walls position"),
    "box inverted": (lambda: Walls.box([0, 0, 0], [1, -1, 1]), "box_hi"),
    "box shape": (lambda: Walls.box([0, 0], [1, 1]), "cannot reshape"),
    # pendular.procedures.preparation
    "particles one": (lambda: PrepareConfig(particles=1), "particles"),
    "particles fraction": (lambda: PrepareConfig(particles=2.5), "particles"),
    "particles text": (lambda: PrepareConfig(particles="many"), "particles"),
    "radius zero": (lambda: PrepareConfig(radius=0.0), "radius"),
    "porosity": (lambda: PrepareConfig(porosity=0.9), "porosity"),
    "young nan": (lambda: PrepareConfig(young=NAN), "young"),
    "young soft": (lambda: PrepareConfig(young=1e4), "young"),
    "confining negative": (lambda: PrepareConfig(confining=-1.0), "confining"),
    "confining beyond young": (lambda: PrepareConfig(confining=1e6), "confining"),
    "timestep_safety": (lambda: PrepareConfig(timestep_safety=1.5), "timestep_safety"),
    "damping": (lambda: PrepareConfig(damping=1.0), "damping"),
    "friction": (lambda: PrepareConfig(friction_deg=90.0), "friction"),
    "seed": (lambda: PrepareConfig(seed=-1), "seed"),
    "unload_steps": (lambda: PrepareConfig(unload_steps=5), "unload_steps"),
    "equilibrium_unbalanced": (lambda: PrepareConfig(equilibrium_unbalanced=0.0),
                               "equilibrium_unbalanced"),
    "max_steps": (lambda: prepare_sample(PrepareConfig(particles=10), max_steps=0), "max_steps"),
    "cloud radius": (lambda: random_cloud(5, 0.6, [0, 0, 0], [1, 1, 1], 0), "radius"),
    "cloud count": (lambda: random_cloud(1000, 0.1, [0, 0, 0], [1, 1, 1], 0), "particles"),
    # operations and the simulation
    "skin": (lambda: NeighborList(0.0), "skin"),
    "contact young": (lambda: ContactForces(-1.0), "young"),
    "shear_ratio": (lambda: ContactForces(1e6, shear_ratio=11.0), "shear_ratio"),
    "contact friction": (lambda: ContactForces(1e6, friction_deg=95.0), "friction"),
    "integrator damping": (lambda: Integrator(damping=-0.1), "damping"),
    "pwave young": (lambda: pwave_timestep([1e-3], 0.0, 2650.0), "young"),
    "pwave radius": (lambda: pwave_timestep([-1e-3], 1e6, 2650.0), "radius"),
    "servo target": (lambda: StressServo("xyz", -1.0, 1.0), "target stress"),
    "servo axes": (lambda: StressServo("xw", 1.0, 1.0), "axes"),
    "dt": (lambda: Simulation(Particles(ONE, [1e-3], 1.0), Walls.box([-1] * 3, [1] * 3), 0.0,
                              **PIPELINE), "dt"),
    "threads": (lambda: Simulation(Particles(ONE, [1e-3], 1.0), Walls.box([-1] * 3, [1] * 3),
                                   1.0, threads=0, **PIPELINE), "threads"),
    "simulation particles": (lambda: Simulation(np.zeros((1, 3)), Walls.box([-1] * 3, [1] * 3),
                                                1.0, **PIPELINE), "particles"),
    "operation": (lambda: Simulation(Particles(ONE, [1e-3], 1.0), Walls.box([-1] * 3, [1] * 3),
                                     1.0, forces=[object()], **PIPELINE), "operation"),
    "run steps": (lambda: scene().run(-1), "steps"),
    "record period": (lambda: HistoryRecorder(0, {}), "record period"),
    "record quantity": (lambda: HistoryRecorder(1, {"x": 3.0}), "quantities['x']"),
    "record rows of unequal lengths": (
        lambda: HistoryRecorder(1, {"step": lambda s: s.step, "time": lambda s: s.time}).load_state(
            {"origin": 0, "end": None, "rows": {"step": np.zeros(3), "time": np.zeros(2)}}),
        "rows/time holds 2 rows and rows/step 3"),
    "checkpoint period": (lambda: CheckpointWriter("c.h5", 0), "checkpoint period"),
    "vtk period": (lambda: VtkWriter("vtk", 0), "vtk period"),
    "vtk compression": (lambda: VtkWriter("vtk", 1, compression="gzip"), "compression"),
    "write_spheres radii": (lambda: write_spheres("s.txt", ONE, [0.0]), "radii"),
    # capillary
    "suction negative": (lambda: CapillaryBridges(-5.0), "suction"),
    "suction nan": (lambda: CapillaryBridges(NAN), "suction"),
    "contact_angle 90": (lambda: CapillaryBridges(1e4, contact_angle=90.0), "contact_angle"),
    "contact_angle negative": (lambda: CapillaryBridges(1e4, contact_angle=-5.0),
                               "contact_angle"),
    "surface_tension": (lambda: CapillaryBridges(1e4, surface_tension=0.0), "surface_tension"),
    "model": (lambda: CapillaryBridges(1e4, model="cylinder"), "model"),
    "control": (lambda: CapillaryBridges(1e4, control="flux"), "control"),
    "suction beyond the table": (lambda: CapillaryBridges(1e9).load_tables(2.4e-5, 2.4e-5),
                                 "suction"),
    "suction below the pendular range": (
        lambda: CapillaryBridges(10.0).load_tables(2.4e-5, 2.4e-5), "suction"),
    "bridge radii": (lambda: CapillaryBridges(1e4).load_tables(-1.0, 1.0), "smallest radius"),
    "bridges on soft spheres": (
        lambda: two_body_scene([[0, 0, 0], [2e-6, 0, 0]], np.zeros((2, 3)), radius=1e-6,
                               extra=[CapillaryBridges(1e4)]).advance(),
        "young"),
    "table contact_angle": (lambda: BridgeTable.build(95.0, radius_ratios=(1.0,), n_suction=3,
                                                      n_distance=3), "contact_angle"),
    "table radius ratio": (lambda: BridgeTable.build(0.0, radius_ratios=(0.5,), n_suction=3,
                                                     n_distance=3), "radius_ratio"),
    "table n_suction": (lambda: BridgeTable.build(0.0, radius_ratios=(1.0,), n_suction=1,
                                                  n_distance=3), "n_suction"),
    "toroidal contact_angle": (lambda: toroidal_table(100.0), "contact_angle"),
    "radius_ratio": (lambda: check_radius_ratio(25.0), "radius_ratio"),
    "suction_star": (lambda: check_suction(-1.0), "suction_star"),
    "filling_angle": (lambda: check_filling_angle(85.0, 20.0), "filling_angle"),
    "solver contact angle": (lambda: capillary.solve_bridge(1.0, 90.0, 1.0, 10.0),
                             "contact_angle"),
    # homogenize
    "cap radius": (lambda: wetted_cap_integral(-1.0, 10.0), "radius"),
    "cap filling angle": (lambda: wetted_cap_integral(1.0, [10.0, 200.0]), "filling_angle[1]"),
    "line contact angle": (lambda: contact_line_integral(1.0, 10.0, 90.0, 0.073),
                           "contact_angle"),
    "line surface tension": (lambda: contact_line_integral(1.0, 10.0, 0.0, -1.0),
                             "surface_tension"),
    "psi suction": (lambda: capillary_stress(np.eye(3), np.zeros((3, 3)), NAN), "suction"),
    "fabric shapes": (lambda: fabric_tensor(np.zeros((4, 3)), np.ones(3, bool)), "mask"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_bad_input_is_refused_with_the_parameter_named(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    call, parameter = CASES[name]
    with pytest.raises((ValueError, TypeError)) as error:
        call()
    assert parameter in str(error.value)


def _junk(path):
    path.write_bytes(bytes(range(256)) * 4)
    return path


def _empty_hdf5(path):
    with h5py.File(path, "w") as handle:
        handle["unrelated"] = 1
    return path


def _truncated_capillary_file(path):
    path.write_text("1\n3\n2\t0\t0\t0\t0\t0\t0\t0\n0.1\t0.2\n")
    return path


FILES = {
    "sample, not HDF5": (load_sample, _junk, "pendular sample"),
    "sample, foreign HDF5": (load_sample, _empty_hdf5, "pendular sample"),
    "checkpoint, not HDF5": (lambda p: load_checkpoint(p, scene()), _junk, "checkpoint"),
    "checkpoint, foreign HDF5": (lambda p: load_checkpoint(p, scene()), _empty_hdf5,
                                 "checkpoint"),
    "spheres, binary": (read_spheres, _junk, "sphere file"),
    "plot data, binary": (read_plot_data, _junk, "saveDataTxt"),
    "capillary file, truncated": (read_capillary_file, _truncated_capillary_file,
                                  "capillary file"),
    "bridge table, not HDF5": (BridgeTable.load, _junk, "bridge table"),
    "bridge table, foreign HDF5": (BridgeTable.load, _empty_hdf5, "bridge table"),
}


@pytest.mark.parametrize("name", list(FILES))
def test_corrupt_or_foreign_files_are_refused_with_the_path_named(name, tmp_path):
    read, make, kind = FILES[name]
    path = make(tmp_path / "file")
    with pytest.raises(ValueError) as error:
        read(str(path))
    assert str(path) in str(error.value) and kind in str(error.value)


def test_missing_file_is_reported_as_missing(tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.h5"):
        load_sample(str(tmp_path / "missing.h5"))


def test_corrupt_table_in_the_cache_is_rebuilt(tmp_path):
    options = dict(radius_ratios=(1.0,), n_suction=6, n_distance=5, suction_max=50.0,
                   directory=tmp_path)
    first = BridgeTable.cached(0.0, **options)
    (cached,) = tmp_path.glob("bridge_table_*.h5")
    _junk(cached)
    again = BridgeTable.cached(0.0, **options)
    assert np.array_equal(first.values, again.values, equal_nan=True)
    assert BridgeTable.load(cached).values.shape == first.values.shape
