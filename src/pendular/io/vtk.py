"""ParaView time series of a simulation (meshio .vtu files indexed by .pvd collections).

``VtkWriter(folder, period)`` is a writer: on its first call and then every ``period`` steps it
writes, each file under a temporary name then renamed (a killed run never leaves a truncated
file), four series indexed by ParaView collection files whose ``timestep`` (ParaView's time
axis) is one of the frames' field data, named in a comment of the .pvd file: the simulated time
[s], or the writer's ``time_axis`` (a loading path's vtk/: ``axial_strain_percent``, the axial
strain in %, which the field data also hold as the fraction ``axial_strain``). Every file's
field data, declared with their units in pendular.io.schema.VTK_FIELDS: ``step``, ``time``
[s]; a loading path's ``axial_strain`` [-] and ``axial_strain_percent`` [%]; vtk_prep/'s
``phase`` and ``mean_wall_stress`` [Pa].

``particles.pvd`` / ``particles_NNNNNN.vtu`` (NNNNNN: the step), one VTK vertex per sphere,
point data (SI units)::

    id                 particle index
    radius             [m] (ParaView: Glyph, sphere, Scale Array = radius, scale factor 1)
    velocity           (3) [m/s]
    angular_velocity   (3) [rad/s]
    contact_force      [N] sum over the particle's sphere–sphere contacts of the magnitude of
                       the mechanical contact force (normal + shear, ``contacts.force``); wall
                       contacts and capillary forces are not included
    coordination       number of touching sphere–sphere pairs (overlap > 0)
    bridges            number of liquid bridges (capillary.BridgeState; 0 in a dry scene)

``walls.pvd`` / ``walls_NNNNNN.vtu``: the six walls as quads spanning the box, cell data::

    wall               index 0..5 (x-, x+, y-, y+, z-, z+; ``pendular.dem.state.WALL_NAMES``)
    normal_stress      [Pa] force / area, compression positive
    force              [N] normal force of the particles on the wall, compression positive
    velocity           [m/s] outward wall speed of the last step

``bridges.pvd`` / ``bridges_NNNNNN.vtu``: one line per liquid bridge between the two centres,
cell data from capillary.BridgeState::

    force              [N] magnitude of the attractive capillary force
    volume             [m^3]
    delta1, delta2     [deg] filling angles on the smaller / larger sphere

``contacts.pvd`` / ``contacts_NNNNNN.vtu``: the contact network, one line per touching sphere
pair between the two centres (YADE's interaction network), cell data::

    normal_force       [N] spring normal force (compressive, >= 0)
    shear_force        [N] magnitude of the elastic shear force
    bridge             1 when the pair also holds a liquid bridge

In a periodic cell (pendular.dem.cell) the particles are drawn wrapped into the cell, a pair's line
runs from particle i to the image of j it interacts with (so lines through a face stick out
of the cell), and ``walls`` are the cell's faces: normal_stress is the cell's stress on that
axis, force that stress times the face area, velocity the face's speed (low faces fixed at 0).
A scene without bridges (or contacts) gets empty, valid files (0 points, 0 cells). meshio 5.3 cannot read a
file without cells back; ParaView and VTK can.

``pore_mesh`` draws the pore units of the liquid clusters (``pores/pores_NNNN.vtu`` of
``pendular swcc --liquid clusters``, one per stage, indexed by ``pores.pvd`` whose time axis is
the stage): one tetrahedron per unit, cell data ``cluster`` (its cluster, -1 for an empty
unit; ParaView: Threshold cluster >= 0, colour by cluster) and ``pore_volume`` [m^3]; field
data ``stage`` and ``suction`` [Pa].

A writer given ``phases`` (names) also writes a frame whenever its ``phase`` attribute changes
(set by whoever drives the simulation, e.g. pendular.procedures.preparation.prepare_sample), and every frame's
field data holds ``phase``: the index of the current phase in ``phases`` (the triaxial test's
``vtk_prep/`` series: pendular.procedures.laboratory.PREP_PHASES).
"""

import os
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from pendular.capillary.bridge_state import BridgeState
from pendular.dem.neighbors import branch_vectors
from pendular.dem.protocols import state_array
from pendular.io.schema import VTK_FIELDS
from pendular.utils.atomic import replacing
from pendular.utils.validate import check_int

#: The series written, each a .pvd collection of .vtu files.
SERIES = ("particles", "walls", "bridges", "contacts")


def write_vtu(path, mesh, compression="zlib", field_data=None):
    """Write a meshio mesh as VTK XML unstructured grid, atomically, with ``field_data`` (name ->
    number, VTK FieldData: meshio's writer drops field data). Meshes without cells are written
    uncompressed (VTK's empty compressed arrays are not read back by every reader)."""
    if not any(len(block.data) for block in mesh.cells):
        compression = None
    with replacing(path) as temporary:
        meshio.write(temporary, mesh, file_format="vtu", compression=compression)
        if field_data:
            _insert_field_data(temporary, field_data)


def _insert_field_data(path, field_data):
    """Add a <FieldData> block of float64 scalars to the VTU file ``path``."""
    arrays = "".join(f'<DataArray type="Float64" Name={quoteattr(name)} NumberOfTuples="1" '
                     f'format="ascii">{float(value)!r}</DataArray>\n'
                     for name, value in field_data.items())
    with open(path, "rb") as handle:
        text = handle.read()
    marker = b"<UnstructuredGrid>"
    text = text.replace(marker, marker + b"\n<FieldData>\n" + arrays.encode() + b"</FieldData>",
                        1)
    with open(path, "wb") as handle:
        handle.write(text)


def read_vtk(path):
    """A ParaView series written here, read with meshio: [(time axis value, meshio.Mesh)] of
    the frames the .pvd file ``path`` lists, in its order (the time axis: the field data the
    writer's ``time_axis`` names, e.g. ``axial_strain_percent`` of a triaxial test's vtk/, the
    time [s] otherwise; each mesh's ``field_data`` holds it).
    ValueError naming the path for a file that is not a ParaView collection."""
    from xml.etree import ElementTree

    path = os.fspath(path)
    try:
        root = ElementTree.parse(path).getroot()
    except (OSError, ElementTree.ParseError) as error:
        raise ValueError(f"series = {path!r} is not a readable ParaView collection: "
                         f"{error}") from None
    if root.get("type") != "Collection":
        raise ValueError(f"series = {path!r} is not a ParaView collection (.pvd)")
    folder = os.path.dirname(path)
    return [(float(frame.get("timestep")), meshio.read(os.path.join(folder, frame.get("file"))))
            for frame in root.iter("DataSet")]


def axial_strain_fields(strain):
    """Field data of a loading path's frame at axial ``strain`` [-]: the fraction and, as the
    series' time axis, the same in %."""
    return {"axial_strain": float(strain), "axial_strain_percent": 100.0 * float(strain)}


def shear_strain_fields(strain):
    """Field data of a simple shear's frame at shear ``strain`` gamma [-]: the fraction and, as
    the series' time axis, the same in %."""
    return {"shear_strain": float(strain), "shear_strain_percent": 100.0 * float(strain)}


def write_pvd(path, frames, time_axis="time"):
    """Write a ParaView collection file listing ``frames`` [(time axis value, file name)],
    atomically; a comment names the time axis, ``time_axis`` (a VTK_FIELDS name), and its
    unit."""
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
             f"  <!-- timestep (ParaView's time axis): each file's field data {time_axis}, in "
             f"{VTK_FIELDS[time_axis].units} (pendular.io.schema.VTK_FIELDS) -->",
             "  <Collection>"]
    lines += [f'    <DataSet timestep="{float(time)!r}" group="" part="0" file={quoteattr(name)}/>'
              for time, name in frames]
    lines += ["  </Collection>", "</VTKFile>", ""]
    with replacing(path) as temporary, open(temporary, "w", encoding="utf-8") as handle:
        handle.write("\n".join(lines))


def _contacts_per_particle(contacts, count):
    """(coordination, sum of contact-force magnitudes [N], bridges) per particle (N,) each."""
    if contacts is None or len(contacts) == 0:
        zeros = np.zeros(count, np.int64)
        return zeros, np.zeros(count), zeros.copy()
    touching = contacts.overlap > 0.0
    first = contacts.pair_i[touching]
    second = contacts.pair_j[touching]
    coordination = (np.bincount(first, minlength=count) + np.bincount(second, minlength=count))
    magnitude = np.linalg.norm(contacts.force[touching], axis=1)
    contact_force = (np.bincount(first, weights=magnitude, minlength=count)
                     + np.bincount(second, weights=magnitude, minlength=count))
    bridges = np.zeros(count, np.int64)
    if BridgeState.present(contacts):
        mask = BridgeState.of(contacts).mask()
        bridges = (np.bincount(contacts.pair_i[mask], minlength=count)
                   + np.bincount(contacts.pair_j[mask], minlength=count))
    return coordination, contact_force, bridges


def particle_mesh(sim):
    """One vertex per sphere with the point data listed in the module docstring."""
    p = sim.particles
    count = len(p)
    coordination, contact_force, bridges = _contacts_per_particle(sim.contacts, count)
    position = np.array(p.position)
    if sim.walls.periodic:         # wrapped into the cell (the live list keeps its images)
        position = np.mod(position, sim.walls.lengths())
    return meshio.Mesh(
        position, [("vertex", np.arange(count, dtype=np.int64)[:, None])],
        point_data={"id": np.arange(count, dtype=np.int64), "radius": np.array(p.radius),
                    "velocity": np.array(p.velocity),
                    "angular_velocity": np.array(p.angular_velocity),
                    "contact_force": contact_force, "coordination": coordination,
                    "bridges": bridges})


def wall_mesh(walls):
    """The six walls as quads (4 points each, wall w's points are 4w..4w+3) spanning the box;
    of a periodic cell, its six faces, with the cell's stress on each axis as normal_stress,
    that stress times the area as force and the faces' speeds (the low faces stay at 0)."""
    lo = walls.position[0::2]
    hi = walls.position[1::2]
    corners = np.array([[0, 0], [1, 0], [1, 1], [0, 1]])
    points = np.empty((24, 3))
    for w in range(6):
        axis = w // 2
        u, v = [a for a in range(3) if a != axis]
        block = points[4 * w:4 * w + 4]
        block[:, axis] = walls.position[w]
        block[:, u] = np.where(corners[:, 0] == 0, lo[u], hi[u])
        block[:, v] = np.where(corners[:, 1] == 0, lo[v], hi[v])
    quads = np.arange(24, dtype=np.int64).reshape(6, 4)
    if walls.periodic:
        normal_stress = np.repeat(walls.stress(), 2)
        velocity = np.zeros(6)
        velocity[1::2] = walls.rate * walls.lengths()
        force = normal_stress * walls.areas()
    else:
        normal_stress = walls.force / walls.areas()
        velocity = np.array(walls.velocity)
        force = np.array(walls.force)
    return meshio.Mesh(points, [("quad", quads)], cell_data={
        "wall": [np.arange(6, dtype=np.int64)], "normal_stress": [normal_stress],
        "force": [force], "velocity": [velocity]})


def _lines(sim, mask):
    """(points, line cells) of segments from centre i to centre j of the pairs ``mask`` of
    ``sim.contacts`` (in a periodic cell, from i wrapped into the cell to the image of j)."""
    contacts, position = sim.contacts, sim.particles.position
    index = np.flatnonzero(mask)
    count = len(index)
    start = position[contacts.pair_i[index]]
    end = position[contacts.pair_j[index]]
    if sim.walls.periodic:         # from i in the cell to the image of j it interacts with
        shift = np.mod(start, sim.walls.lengths()) - start
        start = start + shift
        end = start + branch_vectors(position, contacts, sim.walls.period, index)
    points = np.concatenate([start, end]) if count else np.zeros((0, 3))
    lines = np.stack([np.arange(count), np.arange(count, 2 * count)], axis=1).astype(np.int64)
    return points, lines


def bridge_mesh(sim):
    """One line per liquid bridge (centre to centre) with the cell data of the module
    docstring; no points and no cells when there is no bridge."""
    contacts = sim.contacts
    if contacts is None or not BridgeState.present(contacts):
        return meshio.Mesh(np.zeros((0, 3)), [("line", np.zeros((0, 2), np.int64))])
    state = BridgeState.of(contacts)
    mask = state.mask()
    first, second = contacts.pair_i[mask], contacts.pair_j[mask]
    points, lines = _lines(sim, mask)
    radius = sim.particles.radius
    i_smaller = radius[first] <= radius[second]
    on_i, on_j = state.filling_i[mask], state.filling_j[mask]
    data = {"force": [np.array(state.force[mask])], "volume": [np.array(state.volume[mask])],
            "delta1": [np.where(i_smaller, on_i, on_j)],
            "delta2": [np.where(i_smaller, on_j, on_i)]}
    return meshio.Mesh(points, [("line", lines)], cell_data=data)


def pore_mesh(pore_units, label):
    """The pore units (pendular.capillary.pores.PoreUnits) as tetrahedra over their grains'
    centres (a periodic unit's vertices as it sees them), cell data: ``cluster`` (``label``
    (M,), the unit's cluster, -1 empty; pendular.capillary.clusters), ``pore_volume`` [m^3]."""
    points = pore_units.vertices.reshape(-1, 3)
    cells = np.arange(len(points), dtype=np.int64).reshape(-1, 4)
    data = {"cluster": [np.asarray(label, np.int64)],
            "pore_volume": [np.array(pore_units.pore_volume)]}
    return meshio.Mesh(points, [("tetra", cells)], cell_data=data)


class PoreFrames:
    """The ParaView series ``folder``/pores.pvd of a run with liquid clusters: one
    pores_NNNN.vtu a frame (``pore_mesh``: the pore units, cell data ``cluster`` and
    ``pore_volume``), ParaView's time axis ``time_axis`` (a VTK_FIELDS name)."""

    def __init__(self, folder, time_axis):
        self.folder, self.time_axis = folder, time_axis
        self.frames = []
        self.numbers = []            # the frames' numbers, in the order written

    @staticmethod
    def file_name(number):
        """The file of frame ``number``."""
        return f"pores_{number:04d}.vtu"

    def state_dict(self):
        """The frames written so far (the .pvd of a resumed run lists them): ``numbers`` (F,)
        and ``values`` (F,), their time-axis values. A resumed run writes into its own
        folder."""
        return {"numbers": np.array(self.numbers, np.int64),
                "values": np.array([value for value, _ in self.frames], np.float64)}

    def load_state(self, state):
        numbers = state_array(state, "numbers", np.int64, (None,))
        values = state_array(state, "values", np.float64, (len(numbers),))
        outside = (numbers < 0) | (numbers > 9999)
        if outside.any():
            k = int(np.argmax(outside))
            raise ValueError(f"numbers[{k}] = {numbers[k]} is outside the valid range [0, 9999]")
        self.numbers = [int(number) for number in numbers]
        self.frames = [(float(value), self.file_name(number))
                       for number, value in zip(self.numbers, values)]

    def write(self, number, pore_units, label, field_data):
        """Frame ``number`` of the pore units ``pore_units`` labelled by cluster ``label``
        (-1 empty), ``field_data`` (name -> number, the time axis among them); the .pvd
        rewritten with the frames so far."""
        os.makedirs(self.folder, exist_ok=True)
        name = self.file_name(number)
        write_vtu(os.path.join(self.folder, name), pore_mesh(pore_units, label),
                  field_data=field_data)
        self.frames.append((field_data[self.time_axis], name))
        self.numbers.append(number)
        write_pvd(os.path.join(self.folder, "pores.pvd"), self.frames,
                  time_axis=self.time_axis)


def contact_mesh(sim):
    """The contact network: one line per touching sphere pair (centre to centre) with cell data
    normal_force [N] (spring, compressive), shear_force [N] (magnitude of the elastic shear
    force) and bridge (1 when the pair holds a liquid bridge)."""
    contacts = sim.contacts
    if contacts is None:
        return meshio.Mesh(np.zeros((0, 3)), [("line", np.zeros((0, 2), np.int64))])
    touching = contacts.overlap > 0.0
    points, lines = _lines(sim, touching)
    bridge = (BridgeState.of(contacts).mask()[touching] if BridgeState.present(contacts)
              else np.zeros(int(np.count_nonzero(touching)), bool))
    return meshio.Mesh(points, [("line", lines)], cell_data={
        "normal_force": [np.array(contacts.normal_force[touching])],
        "shear_force": [np.linalg.norm(contacts.shear_force[touching], axis=1)],
        "bridge": [bridge.astype(np.int64)]})


class VtkWriter:
    """Writer of the particle, wall and bridge series (module docstring) into ``folder``.

    Writes on its first call and then whenever ``sim.step % period == 0``; the .pvd index files
    are rewritten with every frame (so that a killed run leaves a usable series) and by
    ``close()``. ``frames`` lists (step, time axis value) of the frames written. ``compression``:
    "zlib" (default) or None (larger files, about 10x faster to write). Every file's field data
    holds ``step``, ``time`` [s] and what ``field_data(sim)`` returns (name -> number, names of
    pendular.io.schema.VTK_FIELDS, e.g. the axial strain of a triaxial test); ``time_axis``,
    the name of one of them, is the .pvd ``timestep`` (default the time; e.g.
    ``axial_strain_percent``: ParaView's time slider then in % of axial strain, the unit the
    frame's field data give it).
    ``phases``: names of the phases of a multi-phase run; the writer then has an attribute
    ``phase`` (one of them, set by the driver of the run), writes a frame at the first step of
    each new phase and stores the phase's index as field data ``phase``.
    """

    def __init__(self, folder, period, compression="zlib", field_data=None, time_axis="time",
                 phases=None):
        if time_axis not in VTK_FIELDS:
            raise ValueError(f"vtk time_axis = {time_axis!r} is not one of the field data "
                             f"{', '.join(VTK_FIELDS)}")
        self.folder = os.fspath(folder)
        self.field_data = field_data
        self.time_axis = time_axis
        self.phases = None if phases is None else tuple(phases)
        self.phase = None
        self._frame_phase = None
        self.period = check_int("vtk period", period, low=1)
        if compression not in ("zlib", "lzma", None):
            raise ValueError(f"compression = {compression!r} is not one of 'zlib', 'lzma', None")
        self.compression = compression
        self.frames = []
        os.makedirs(self.folder, exist_ok=True)

    def state_dict(self):
        """The frames written so far: ``frame_steps`` (F,) and ``frame_values`` (F,), their
        steps and time-axis values (the .pvd index of a resumed run lists them); with
        ``phases``, ``phase`` and ``frame_phase`` (that of the last frame), None before one.
        A resumed run writes into its own folder."""
        state = {"frame_steps": np.array([step for step, _ in self.frames], np.int64),
                 "frame_values": np.array([value for _, value in self.frames], np.float64)}
        if self.phases is not None:
            state.update(phase=self.phase, frame_phase=self._frame_phase)
        return state

    def load_state(self, state):
        steps = state_array(state, "frame_steps", np.int64, (None,))
        values = state_array(state, "frame_values", np.float64, (len(steps),))
        if self.phases is not None:
            for key in ("phase", "frame_phase"):
                if state[key] is not None and state[key] not in self.phases:
                    raise ValueError(f"{key} = {state[key]!r} is not one of {self.phases}")
            self.phase, self._frame_phase = state["phase"], state["frame_phase"]
        self.frames = [(int(step), float(value)) for step, value in zip(steps, values)]

    def apply(self, sim):
        if (not self.frames or sim.step % self.period == 0
                or (self.phases is not None and self.phase != self._frame_phase)):
            self.write(sim)

    def write(self, sim):
        """Write the frame of the current step (once per step) and update the index files."""
        if self.frames and self.frames[-1][0] == sim.step:
            return
        sim.fetch()                 # a device run's state, all of it (Simulation.fetch)
        meshes = {"particles": particle_mesh(sim), "walls": wall_mesh(sim.walls),
                  "bridges": bridge_mesh(sim), "contacts": contact_mesh(sim)}
        fields = {"step": sim.step, "time": sim.time}
        if self.phases is not None:
            if self.phase not in self.phases:
                raise ValueError(f"vtk phase = {self.phase!r} is not one of {self.phases}")
            fields["phase"] = self.phases.index(self.phase)
            self._frame_phase = self.phase
        if self.field_data is not None:
            fields.update(self.field_data(sim))
        if self.time_axis not in fields:
            raise ValueError(f"vtk time_axis = {self.time_axis!r} is not in the frame's field "
                             f"data {', '.join(fields)}")
        for series, mesh in meshes.items():
            write_vtu(os.path.join(self.folder, self.file_name(series, sim.step)), mesh,
                      self.compression, fields)
        self.frames.append((int(sim.step), float(fields[self.time_axis])))
        self.close()

    def file_name(self, series, step):
        """Name of the .vtu file of ``series`` at ``step`` (relative to the folder)."""
        return f"{series}_{step:06d}.vtu"

    def close(self, sim=None):
        """Write the .pvd index files; with ``sim``, first write its current state if not yet
        written (call at the end of a run)."""
        if sim is not None and (not self.frames or self.frames[-1][0] != sim.step):
            self.write(sim)
            return
        for series in SERIES:
            write_pvd(os.path.join(self.folder, f"{series}.pvd"),
                      [(time, self.file_name(series, step)) for step, time in self.frames],
                      self.time_axis)

    finish = close
