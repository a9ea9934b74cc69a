"""On-the-fly homogenisation of the DEM state (pendular.homogenize.on_the_fly, issue 3 items 1 and 4):
regular lattices against the unit-cell calculation, the wet and dry triaxial histories."""

import itertools
import json

import h5py
import numpy as np
import pytest

from pendular.dem.contact_law import ContactForces
from pendular.dem.neighbors import NeighborList
from pendular.capillary import SURFACE_TENSION, BridgeState, CapillaryBridges
from pendular.dem.integrate import Integrator
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.homogenize import (bridges_in_region, contact_line_integral, homogenize_bridges,
    packing_state, regular_packing)

RADIUS = 2.4e-5
GAMMA = SURFACE_TENSION
SUCTION = 30000.0
BLOCK = 5          # lattice cells per axis
REGION = (1.125, 3.125)   # representative volume, in cells: 2 x 2 x 2 cells, off every bridge centre


def lattice(packing, radius=RADIUS, cells=BLOCK):
    """A block of cells^3 unit cells of ``packing`` with spheres of radius R (1 + 1e-12): every
    neighbour pair overlaps by 2e-12 R, a contact after one force evaluation."""
    basis = [np.zeros(3)] if packing.kind == "scp" else [np.zeros(3), np.full(3, 0.5)]
    corners = np.array(list(itertools.product(range(cells), repeat=3)), dtype=float)
    position = np.concatenate([(corners + site) * packing.cell_size * radius for site in basis])
    particles = Particles(position, np.full(len(position), radius * (1.0 + 1e-12)), 2650.0)
    walls = Walls.box(position.min(axis=0) - 2 * radius, position.max(axis=0) + 2 * radius)
    sim = Simulation(particles, walls, 1e-9, neighbors=NeighborList(0.1 * radius),
                     forces=[ContactForces(1e6, 0.3, 18.0)], integrator=Integrator(0.0))
    sim.evaluate_forces()
    return sim


def wet_with(sim, state):
    """One bridge per contact with the unit cell's bridge (filling angle, volume, force), in the
    per-pair BridgeState that capillary.CapillaryBridges keeps."""
    touching = sim.contacts.overlap > 0.0
    bridges = BridgeState.of(sim.contacts)
    bridges.state[:] = touching
    bridges.volume[:] = np.where(touching, state.bridge_volume, 0.0)
    bridges.force[:] = np.where(touching, state.bridge_force, 0.0)
    bridges.filling_i[:] = np.where(touching, state.filling_angle, 0.0)
    bridges.filling_j[:] = np.where(touching, state.filling_angle, 0.0)
    return touching


def representative_volume(sim, packing, radius=RADIUS):
    """(mask of the bridges centred in the region, its volume): REGION in cells of the lattice."""
    lo = REGION[0] * packing.cell_size * radius
    hi = REGION[1] * packing.cell_size * radius
    return bridges_in_region(sim.particles, sim.contacts, lo, hi), float(np.prod(hi - lo))


@pytest.mark.parametrize("kind, l_prime, contact_angle", [
    ("fcp", None, 0.0), ("fcp", None, 20.0), ("bcc", None, 0.0), ("bcc", 2.5, 20.0), ("scp", None, 10.0)])
def test_lattice_homogenised_on_the_fly_equals_the_unit_cell(kind, l_prime, contact_angle):
    """A DEM lattice with one bridge per contact gives packing_state's chi, B, psi to 1e-10.

    Construction: a block of 5^3 unit cells of the packing (regular_packing's cell, R = 0.024 mm,
    spheres enlarged by 1e-12 R so that every neighbour pair is a contact of the contact law);
    every contact carries the unit cell's bridge at the suction (packing_state, exact
    Young-Laplace: its filling angle on both spheres and its volume) in the per-pair arrays of
    CapillaryBridges. The representative volume is the box of 2 x 2 x 2 cells starting 1.125
    cells into the block: it is a union of whole (translated) cells, its faces cut no bridge
    centre (they sit at multiples of 1/4 cell), and it lies more than a cell from the block's
    faces, so every bridge centred in it joins two particles of the block. Counting the bridges
    by their centre (bridges_in_region) then counts each bridge of the periodic packing once
    per cell: 8 x bridges_per_cell bridges and 8 x bridges_per_cell bridge volumes over
    8 x cell_volume, which are the unit cell's sums over its own volume (Tables 4.2-4.4).
    """
    packing = regular_packing(kind, l_prime)
    state = packing_state(packing, radius=RADIUS, contact_angle=contact_angle, surface_tension=GAMMA,
                          suction=SUCTION)
    sim = lattice(packing)
    touching = wet_with(sim, state)
    distance = np.linalg.norm(sim.particles.position[sim.contacts.pair_j]
                              - sim.particles.position[sim.contacts.pair_i], axis=1)
    assert np.array_equal(touching, np.abs(distance / (2 * RADIUS) - 1.0) < 1e-9)  # every neighbour
    mask, volume = representative_volume(sim, packing)
    cells = round((REGION[1] - REGION[0]) ** 3)
    assert np.count_nonzero(mask) == cells * packing.bridges_per_cell
    assert volume == pytest.approx(cells * packing.cell_volume * RADIUS**3, rel=1e-14)

    result = homogenize_bridges(sim.particles, sim.contacts, volume, suction=state.suction,
                                contact_angle=contact_angle, surface_tension=GAMMA, mask=mask)
    # B vanishes for isotropic bridge fabrics at theta = 0: compare on the scale of its terms
    line = contact_line_integral(RADIUS, state.filling_angle, contact_angle, GAMMA)
    b_scale = 2 * packing.bridges_per_cell * np.abs(line).max() / (packing.cell_volume * RADIUS**3)
    assert np.abs(result.chi - state.chi).max() <= 1e-10 * np.abs(state.chi).max()
    assert np.abs(result.B - state.B).max() <= 1e-10 * b_scale
    assert np.abs(result.psi - state.psi).max() <= 1e-10 * np.abs(state.psi).max()
    assert result.water_volume / volume == pytest.approx(packing.porosity * state.saturation, rel=1e-12)
    assert result.fabric == pytest.approx(packing.fabric, abs=1e-12)
    assert result.anisotropy == pytest.approx(packing.anisotropy, abs=1e-10)
    if abs(state.a_psi) > 1e-6:
        assert result.a_psi == pytest.approx(state.a_psi, rel=1e-8)


def test_lattice_wetted_by_the_capillary_operation_matches_the_unit_cell():
    """The same FCP lattice wetted by CapillaryBridges itself (table lookup at contact, filling
    angles stored per particle): the unit cell's chi, B, psi to the table's accuracy."""
    packing = regular_packing("fcp")
    state = packing_state(packing, radius=RADIUS, contact_angle=0.0, surface_tension=GAMMA,
                          suction=SUCTION)
    sim = lattice(packing)
    bridges = CapillaryBridges(SUCTION, GAMMA)
    sim.forces.append(bridges)
    bridges.apply(sim)
    assert bridges.count(sim) == np.count_nonzero(sim.contacts.overlap > 0.0)
    mask, volume = representative_volume(sim, packing)
    result = homogenize_bridges(sim.particles, sim.contacts, volume, suction=SUCTION,
                                contact_angle=0.0, surface_tension=GAMMA, mask=mask)
    assert result.chi == pytest.approx(state.chi, rel=2e-3, abs=2e-3 * state.chi.max())
    assert result.psi == pytest.approx(state.psi, rel=2e-3, abs=2e-3 * state.psi.max())
    assert np.abs(result.B).max() < 1e-9 * np.abs(state.psi).max()    # isotropic, theta = 0


def test_per_bridge_suctions_reduce_to_chi_s_plus_b_and_input_is_checked():
    packing = regular_packing("bcc", 2.2)
    state = packing_state(packing, radius=RADIUS, contact_angle=5.0, surface_tension=GAMMA,
                          suction=SUCTION)
    sim = lattice(packing, cells=3)
    touching = wet_with(sim, state)
    volume = sim.walls.volume()
    args = (sim.particles, sim.contacts, volume)
    common = {"contact_angle": 5.0, "surface_tension": GAMMA}
    uniform = homogenize_bridges(*args, suction=SUCTION, **common)
    own = homogenize_bridges(*args, suction=np.where(touching, SUCTION, -1e9), **common)
    assert own.psi == pytest.approx(uniform.chi * SUCTION + uniform.B, rel=1e-13)
    assert own.chi == pytest.approx(uniform.chi, rel=1e-15)
    assert uniform.bridges == np.count_nonzero(touching)
    # bridges of half the suction: the suction terms halve, B stays
    half = homogenize_bridges(*args, suction=np.full(len(touching), 0.5 * SUCTION), **common)
    assert half.psi == pytest.approx(0.5 * SUCTION * uniform.chi + uniform.B, rel=1e-13)
    BridgeState.of(sim.contacts).state[0] = 0
    with pytest.raises(ValueError, match="1 pair.* without a bridge"):
        homogenize_bridges(*args, suction=SUCTION, mask=touching, **common)
    with pytest.raises(ValueError, match="mask has shape"):
        homogenize_bridges(*args, suction=SUCTION, mask=touching[:-1], **common)
    with pytest.raises(ValueError, match="suction has shape"):
        homogenize_bridges(*args, suction=np.ones(3), **common)
    with pytest.raises(ValueError, match="volume"):
        homogenize_bridges(sim.particles, sim.contacts, 0.0, suction=SUCTION, **common)
    with pytest.raises(ValueError, match="region"):
        bridges_in_region(sim.particles, sim.contacts, np.ones(3), np.zeros(3))
    # no bridges at all: zero tensors, undefined anisotropies
    sim.contacts.extra.clear()
    dry = homogenize_bridges(*args, suction=SUCTION, **common)
    assert dry.bridges == 0 and not dry.psi.any() and not dry.fabric.any()
    assert np.isnan(dry.anisotropy) and np.isnan(dry.a_psi)


def test_recorder_columns_follow_the_bridge_operation_volume_control_included():
    """CapillaryHomogenization reads the operation's suction (each bridge's own under volume
    control), caches one evaluation per record and survives a deep copy of the simulation."""
    import copy

    from pendular.homogenize import CapillaryHomogenization

    packing = regular_packing("bcc")
    for control in ("suction", "volume"):
        sim = lattice(packing, cells=3)
        bridges = CapillaryBridges(SUCTION, GAMMA, contact_angle=0.0, control=control)
        sim.forces.append(bridges)
        bridges.apply(sim)
        columns = CapillaryHomogenization(bridges).quantities()
        assert set(columns) == set(CAPILLARY_COLUMNS)
        own = BridgeState.of(sim.contacts).suction if control == "volume" else SUCTION
        expected = homogenize_bridges(sim.particles, sim.contacts, sim.walls.volume(), suction=own,
                                      contact_angle=0.0, surface_tension=GAMMA)
        assert np.array_equal(columns["psi"](sim), expected.psi)
        assert np.array_equal(columns["sigma_effective"](sim),
                              np.diag(sim.walls.stress()) + expected.psi)
        # a bridge formed at contact under volume control holds the formation suction (to the
        # round trip through the suction and volume tables)
        assert columns["psi"](sim) == pytest.approx(expected.chi * SUCTION + expected.B, rel=1e-2)
        homogenization = columns["chi"].__self__
        assert isinstance(homogenization, CapillaryHomogenization)
        assert homogenization.measured(sim) is homogenization.measured(sim)      # cached
        copied = copy.deepcopy({"sim": sim, "columns": columns})
        assert copied["columns"]["chi"].__self__.bridges is copied["sim"].operation(CapillaryBridges)


def test_homogenized_on_the_host_is_the_cpus_measures_bit_for_bit():
    """homogenized(sim) of a state the host holds: one mapping with the device's keys, each
    value that of the CPU function the history's columns used (equal bit for bit), measured
    once per mapping; an unknown name is refused naming the valid ones."""
    from pendular.dem.measure import coordination, largest_overlap, unbalanced_force
    from pendular.homogenize import contact_stress, fabric_tensor, principal_anisotropy
    from pendular.homogenize.on_the_fly import capillary_force_stress, homogenized

    sim = lattice(regular_packing("bcc"), cells=3)
    dry = homogenized(sim)
    assert set(dry) == {"sigma_contact", "coordination", "fabric", "anisotropy",
                        "unbalanced_force", "solid_volume", "largest_overlap",
                        "smallest_radius", "largest_radius"}
    p, c = sim.particles, sim.contacts
    fabric = fabric_tensor(c.normal, c.overlap > 0.0)
    expected = {"sigma_contact": contact_stress(p, c, sim.walls),
                "coordination": coordination(c, len(p)), "fabric": fabric,
                "anisotropy": principal_anisotropy(fabric),
                "unbalanced_force": unbalanced_force(p, c), "solid_volume": p.solid_volume(),
                "largest_overlap": largest_overlap(sim), "smallest_radius": p.radius.min(),
                "largest_radius": p.radius.max()}
    for name, value in expected.items():
        assert np.array_equal(dry[name], value), name
    assert dry["fabric"] is dry["fabric"]                   # measured once
    with pytest.raises(KeyError, match="'chi' is not a homogenised quantity.*sigma_contact"):
        dry["chi"]
    bridges = CapillaryBridges(SUCTION, GAMMA, contact_angle=0.0, model="exact")
    sim.forces.append(bridges)
    bridges.apply(sim)
    wet = homogenized(sim)
    state = homogenize_bridges(sim.particles, sim.contacts, sim.walls.volume(), suction=SUCTION,
                               contact_angle=0.0, surface_tension=GAMMA,
                               interfaces=bridges.interfaces(sim, np.flatnonzero(
                                   BridgeState.of(sim.contacts).mask())))
    assert set(wet) == set(dry) | {"bridges", "pendular_overlaps", "water_volume", "chi", "B",
                                   "psi", "sigma_capillary", "fabric_bridges",
                                   "anisotropy_bridges", "a_psi", "psi_interface"}
    expected = {"bridges": bridges.count(sim), "water_volume": bridges.water_volume(sim.contacts),
                "pendular_overlaps": bridges.pendular_overlaps(sim),
                "sigma_capillary": capillary_force_stress(sim, bridges), "chi": state.chi,
                "B": state.B, "psi": state.psi, "fabric_bridges": state.fabric,
                "anisotropy_bridges": state.anisotropy, "a_psi": state.a_psi,
                "psi_interface": state.interface}
    assert wet["bridges"] > 0
    for name, value in expected.items():
        assert np.array_equal(wet[name], value, equal_nan=True), name


CAPILLARY_COLUMNS = ("chi", "B", "psi", "sigma_effective", "fabric_bridges", "anisotropy_bridges",
                     "a_psi", "saturation", "suction", "sigma_capillary", "bridges",
                     "pendular_overlaps", "psi_interface", "sigma_effective_complete")


def test_dry_history_has_no_capillary_columns(tmp_path):
    """A dry run of what scenarios/triaxial.py runs (pendular.cli.main with its prog), in this
    process (the script's own process runs in the wet_triaxial_run fixture)."""
    from pendular.cli import main

    assert main(["triaxial", "--particles", "60", "--max-strain", "0.002", "--inertial-number",
                 "2e-3", "--quiet", "--out", str(tmp_path)], prog="triaxial.py") == 0
    with h5py.File(tmp_path / "history.h5") as handle:
        history = handle["history"]
        assert not set(CAPILLARY_COLUMNS) & set(history)
        rows = len(history["step"])
        assert history["anisotropy"].shape == (rows,)
        assert np.all(np.abs(history["anisotropy"][:]) < 0.5)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert "peak_q_effective" not in summary and "saturation_at_peak" not in summary


def test_wet_triaxial_history_has_the_homogenised_capillary_state(wet_triaxial_run):
    """200 spheres at 30 kPa, 1 % strain: the columns and their bookkeeping at every record."""
    out = wet_triaxial_run
    summary = json.loads((out / "summary.json").read_text())
    with h5py.File(out / "history.h5") as handle:
        history = {name: data[:] for name, data in handle["history"].items()}
    rows = len(history["step"])
    for name in ("chi", "B", "psi", "sigma_effective", "fabric_bridges"):
        assert history[name].shape == (rows, 3, 3), name
    for name in ("a_psi", "anisotropy_bridges", "anisotropy"):
        assert history[name].shape == (rows,) and np.all(np.isfinite(history[name])), name
    chi, b, psi = history["chi"], history["B"], history["psi"]
    assert np.allclose(psi, chi * 30000.0 + b, rtol=1e-12, atol=0)
    diagonal = np.diagonal(psi, axis1=1, axis2=2)
    assert np.all(diagonal > 0.0)                                   # theta = 0, s > 0
    assert np.allclose(np.trace(b, axis1=1, axis2=2), 0.0, atol=1e-9 * diagonal.max())   # tr B'= 0
    assert np.all(np.diagonal(chi, axis1=1, axis2=2) > history["porosity"][:, None]
                  * history["saturation"][:, None])                 # n Sr plus the wetted caps
    assert np.allclose(np.trace(history["fabric_bridges"], axis1=1, axis2=2), 1.0, rtol=1e-12)
    # the bridges are the contacts (they break with contact): the same fabric
    assert np.allclose(history["fabric_bridges"], history["fabric"], atol=1e-3)
    expected = psi + np.stack([np.diag(row) for row in history["sigma_wall"]])
    assert np.allclose(history["sigma_effective"], expected, rtol=1e-13, atol=0)
    for tensor in (chi, b, psi, history["fabric_bridges"]):
        assert np.allclose(tensor, np.swapaxes(tensor, 1, 2), rtol=1e-12, atol=1e-12 * np.abs(tensor).max())
    # psi is several times the confining stress at 30 kPa (Sr ~ 2 %)
    assert np.all(diagonal > 750.0)
    peak = summary["peak_index"]
    effective = np.diag(history["sigma_effective"][peak])
    assert summary["peak_q_effective"] == pytest.approx(effective[2] - 0.5 * (effective[0] + effective[1]))
    assert summary["p_effective_at_peak"] == pytest.approx(effective.mean())
    assert summary["p_effective_at_peak"] > summary["p_at_peak"]
    assert 0.0 < summary["saturation_at_peak"] < 0.1
    # the complete capillary stress: psi + interface term = -sigma_capillary up to the overlaps
    # of touching spheres (about 1 % of their centre distance at 30 kPa)
    complete = psi + history["psi_interface"]
    scale = np.abs(history["sigma_capillary"]).max()
    assert np.allclose(complete, -history["sigma_capillary"], rtol=0, atol=0.02 * scale)
    assert np.all(np.diagonal(history["psi_interface"], axis1=1, axis2=2) > 0.02 * diagonal)
    assert np.allclose(history["sigma_effective_complete"], expected + history["psi_interface"],
                       rtol=1e-13, atol=0)
    complete_peak = np.diag(history["sigma_effective_complete"][peak])
    assert summary["peak_q_effective_complete"] == pytest.approx(
        complete_peak[2] - 0.5 * (complete_peak[0] + complete_peak[1]))
    assert summary["p_effective_complete_at_peak"] == pytest.approx(complete_peak.mean())
