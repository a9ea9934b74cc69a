"""Homogenisation on the device (pendular.gpu.homogenize) against the CPU's functions on the
same state, under Numba's CUDA simulator: the 64-sphere walled scene of tests/gpu/simulated.py,
the 64-sphere periodic cell of tests/gpu/periodic_checks.py (pairs through the faces:
branch vectors with their images, the cell's volume, no walls), dry and wet
at 30 kPa (exact bridges at contact), and wet the sheared cell of tests/gpu/shear_checks.py
(Lees–Edwards: the images through the z faces offset along x), after 30 steps on the device.
The device's quantities are computed from the state it holds, which then comes back for the
CPU's (pendular.homogenize.contact_stress, pendular.dem.measure,
pendular.homogenize.on_the_fly, pendular.dem.measure.largest_overlap).
The reduction runs in two blocks (CHUNK = 32), and once more in one block (CHUNK raised to 64
in the simulated process, which reads the module's globals at each launch): in one block the
dry sums are the CPU's in the CPU's order.

The measurements run as this file's script, every scene in one process of its own
(``NUMBA_ENABLE_CUDASIM=1 python tests/gpu/test_gpu_homogenize.py dry wet periodic-dry ...``,
simulator.run_checks), so that the simulator never reaches the process of the other tests.
The differences from the CPU are round-off (docs/gpu.md); in one block the dry sums, the
contact quantities and sigma_capillary are the CPU's bit for bit. Bridges across gaps (GAPS:
the 27 spheres of persist_checks.py, persisting bridges, and of volume_checks.py,
volume-controlled, after GAP_STEPS steps pulled apart) are reduced in two blocks of GAP_CHUNK
and in one.
"""

import os

import numpy as np
import pytest

from conftest import requires
from simulator import relative, run_checks, simulated

pytestmark = requires("numba_cuda")

STEPS = 30
#: Spheres a side of the scene's cubic lattice: 64 spheres, two blocks of CHUNK = 32.
SIDE = 4
#: Particles a block of the reduction sums in pendular.gpu.homogenize (two blocks here).
CHUNK = 32
#: Filling angle [deg] given every bridge to count overlapping menisci (none at 30 kPa; the
#: scene's lattice is cubic: neighbours about 90 deg apart).
WIDE = 50.0
#: Largest values (exact in any order): the guard's largest overlap, the radii's range.
MAXIMA = ("largest_overlap", "smallest_radius", "largest_radius")
#: The scenes without bridges across gaps: inside walls, in a periodic cell, sheared.
SCENES = ("dry", "wet", "periodic-dry", "periodic-wet", "sheared-wet")
#: Scenes with bridges across gaps: the 27 spheres of persist_checks.py (persisting
#: suction-controlled bridges) and of volume_checks.py (volume-controlled), pulled apart for
#: GAP_STEPS steps, reduced in blocks of GAP_CHUNK (two blocks) and in one.
GAPS = ("persist", "volume")
GAP_STEPS = 75
GAP_CHUNK = 16


def cpu_homogenization(sim):
    """The CPU's quantities of sim's state (the host holding it), named as
    device_homogenization names them: pendular.homogenize.on_the_fly.homogenized on the host,
    each quantity by its CPU function (tests/integration/test_homogenize_dem.py), the water
    volume homogenize_bridges's (CapillaryBridges.water_volume sums every pair's, zeros
    included: the same to round-off)."""
    from pendular.homogenize.on_the_fly import homogenized

    measures = homogenized(sim)
    out = dict(measures)
    if measures.bridges is not None:    # V_w summed over the bridges alone, as the device sums
        out["water_volume"] = measures.bridge_stress.water_volume
    return out
    homogenization = CapillaryHomogenization(bridges)
    state, _ = homogenization.evaluate(sim)
    out.update({"bridges": state.bridges,
                "pendular_overlaps": bridges.pendular_overlaps(sim),
                "water_volume": state.water_volume,
                "chi": state.chi, "B": state.B, "psi": state.psi,
                "sigma_capillary": homogenization.sigma_capillary(sim),
                "fabric_bridges": state.fabric, "anisotropy_bridges": state.anisotropy,
                "a_psi": state.a_psi, "psi_interface": state.interface})
    return out


def widen_menisci(gpu, filling_angle):
    """Give every bridge the device holds ``filling_angle`` [deg] on both spheres, so that the
    menisci of neighbours closer than twice that overlap."""
    from pendular.gpu.state import BRIDGE_COLUMNS

    bridges = gpu.state.bridges.copy_to_host()
    bridged = bridges[:, BRIDGE_COLUMNS.index("state")] != 0.0
    for field in ("filling_i", "filling_j"):
        bridges[bridged, BRIDGE_COLUMNS.index(field)] = filling_angle
    gpu.state.bridges.copy_to_device(bridges)


def measure(wet, chunk, filling_angle=None, cell=None, steps=STEPS):
    """{quantity: relative difference device vs CPU}, {quantity: equal bit for bit}, the
    device's counts, the copies back during the device's homogenisation (device_homogenization,
    then GpuSimulation.homogenized, which must repeat it bit for bit: the same result for the
    same step, a new one a step later), whether the state was still held by the device after
    it, and the error of GpuSimulation.homogenized once the state is back; the reduction in
    blocks of ``chunk`` particles; ``filling_angle`` [deg]: the bridges' widened to it first
    (widen_menisci); ``cell``: "periodic" or "sheared", the cell of periodic_checks.py or
    of shear_checks.py instead of the walls, and the touching pairs through its faces;
    "persist" or "volume", GAPS' scenes after ``steps``, and their bridges across gaps."""
    from periodic_checks import scene as periodic_scene
    from persist_checks import scene as persist_scene
    from shear_checks import scene as sheared_scene
    from simulated import scene
    from volume_checks import scene as volume_scene

    from pendular.capillary.bridge_state import ACROSS_GAP, BridgeState

    from pendular.gpu import GpuSimulation, homogenize
    from pendular.gpu.homogenize import device_homogenization

    homogenize.CHUNK = chunk

    copies = []
    copy_back = GpuSimulation.copy_back

    def counted(self, part=None):
        copies.append(part or "all")
        return copy_back(self, part)

    cells = {"periodic": periodic_scene, "sheared": sheared_scene,
             "persist": lambda wet: persist_scene()[0], "volume": lambda wet: volume_scene()[0]}
    gpu = GpuSimulation(cells[cell](wet) if cell else scene(wet=wet, side=SIDE))
    gpu.run(steps)
    if filling_angle is not None:
        widen_menisci(gpu, filling_angle)
    GpuSimulation.copy_back = counted
    device = device_homogenization(gpu)
    again = gpu.homogenized()
    cached = gpu.homogenized() is again
    GpuSimulation.copy_back = copy_back
    held = "_holder" in gpu.sim.__dict__
    gpu.to_host()
    try:
        gpu.homogenized()
        released = None
    except RuntimeError as error:
        released = str(error)
    cpu = cpu_homogenization(gpu.sim)
    contacts = gpu.sim.contacts
    through_faces = (int(np.count_nonzero(contacts.touching() & np.any(contacts.image != 0,
                                                                         axis=1)))
                     if cell in ("periodic", "sheared") else 0)
    across_gaps = (int(np.count_nonzero(BridgeState.of(contacts).state == ACROSS_GAP))
                   if wet else 0)
    gpu.run(1)
    fresh = gpu.homogenized() is not again
    return {"names": sorted(device), "cpu_names": sorted(cpu),
            "difference": {name: relative(cpu[name], device[name]) for name in cpu},
            "equal": {name: bool(np.array_equal(cpu[name], device[name])) for name in cpu},
            "repeatable": all(np.array_equal(device[name], again[name]) for name in device),
            "touching": device["coordination"] * len(gpu.sim.peek("particles")) / 2.0,
            "bridges": device.get("bridges", 0),
            "pendular_overlaps": device.get("pendular_overlaps", 0), "copies": copies,
            "held": held, "through_faces": through_faces, "across_gaps": across_gaps,
            "released": released, "cached": cached, "fresh": fresh,
            "psi": device["psi"].tolist() if wet else None}


@pytest.fixture(scope="module")
def measured():
    """Every scene's measurements, in one process."""
    return simulated(os.path.basename(__file__), *SCENES, *GAPS)


@pytest.fixture(scope="module", params=SCENES)
def scene_run(request, measured):
    return request.param.endswith("wet"), measured[request.param]


def test_the_reduction_runs_in_two_blocks():
    from pendular.gpu import homogenize

    assert homogenize.CHUNK == CHUNK < SIDE ** 3 <= 2 * CHUNK


def test_the_device_reduces_the_cpu_quantities_without_copying_the_state(scene_run):
    wet, measured = scene_run
    expected = {"sigma_contact", "coordination", "fabric", "anisotropy", "unbalanced_force",
                "solid_volume", *MAXIMA}
    if wet:
        expected |= {"bridges", "pendular_overlaps", "water_volume", "chi", "B", "psi",
                     "sigma_capillary", "fabric_bridges", "anisotropy_bridges", "a_psi",
                     "psi_interface"}
    for run in (measured[key] for key in ("blocks", "one_block", "wide") if key in measured):
        assert run["copies"] == [] and run["held"]
        assert run["touching"] > 50                  # a packing, not a gas
        if measured["cell"]:
            assert run["through_faces"] > 10          # branch vectors through the faces
        if wet:
            assert run["bridges"] == run["touching"]     # bridges at contact
        assert set(run["names"]) == set(run["cpu_names"]) == expected
        for name, difference in run["difference"].items():
            bound = 1e-12 if name.startswith(("anisotropy", "a_psi")) else 1e-13
            assert difference < bound, name
        assert all(run["equal"][name] for name in MAXIMA)     # in any order
        assert run["repeatable"]
        assert "holds no state" in run["released"]
        assert run["cached"] and run["fresh"]


def test_overlapping_menisci_are_counted_as_on_the_cpu(scene_run):
    """At 30 kPa no menisci overlap; with every filling angle widened to 50 deg the menisci of
    neighbours less than 100 deg apart do (the lattice's, about 90 deg apart), and the device
    counts the CPU's."""
    wet, measured = scene_run
    if wet:
        assert measured["blocks"]["pendular_overlaps"] == 0
        wide = measured["wide"]
        assert wide["pendular_overlaps"] > 50 and wide["equal"]["pendular_overlaps"]
        for name, difference in wide["difference"].items():
            bound = 1e-12 if name.startswith(("anisotropy", "a_psi")) else 1e-13
            assert difference < bound, name


def test_in_one_block_the_contact_sums_are_the_cpus_bit_for_bit(scene_run):
    """One block sums the pairs in the CPU's order: the contact quantities (and, wet, the
    water volume and the capillary forces' stress) equal the CPU's exactly. In a periodic
    cell the fabric, counts and unbalanced force do; the sums over branch vectors through the
    faces and the water volume agree to round-off (the host's list is rebuilt from the
    device's as the state comes back, its particles wrapped again)."""
    wet, measured = scene_run
    periodic = measured["cell"] is not None
    exact = ["coordination", "fabric", "anisotropy", "unbalanced_force"]
    if not periodic:
        exact.append("sigma_contact")
    if wet:
        exact += ["bridges", "pendular_overlaps"]
        if not periodic:
            exact += ["water_volume", "sigma_capillary"]
    equal = measured["one_block"]["equal"]
    assert all(equal[name] for name in exact), equal


def test_the_wet_capillary_stress_is_compressive(scene_run):
    """psi of bridges at 30 kPa: positive diagonal (chi s dominates B), so a wrong sign or a
    missing term would not pass for agreement."""
    wet, measured = scene_run
    if wet:
        assert min(np.diag(measured["blocks"]["psi"])) > 0.0


@pytest.fixture(scope="module", params=GAPS)
def gap_run(request, measured):
    return measured[request.param]


def test_bridges_across_gaps_are_reduced_on_the_device_as_on_the_cpu(gap_run):
    """Persisting and volume-controlled bridges, some across gaps: every quantity the CPU's
    functions give (the capillary forces' stress from the forces applied at the last step,
    the interface term at each bridge's gap, volume control's psi at each bridge's own
    suction and its interface from the volume table), no copy of the state."""
    expected = {"sigma_contact", "coordination", "fabric", "anisotropy", "unbalanced_force",
                "solid_volume", *MAXIMA, "bridges", "pendular_overlaps", "water_volume", "chi",
                "B", "psi", "sigma_capillary", "fabric_bridges", "anisotropy_bridges", "a_psi",
                "psi_interface"}
    for run in (gap_run["blocks"], gap_run["one_block"]):
        assert run["copies"] == [] and run["held"]
        assert run["across_gaps"] >= 2 and run["bridges"] > run["across_gaps"]
        assert set(run["names"]) == set(run["cpu_names"]) == expected
        for name, difference in run["difference"].items():
            bound = 1e-12 if name.startswith(("anisotropy", "a_psi")) else 1e-13
            assert difference < bound, name
        assert all(run["equal"][name] for name in MAXIMA)
        assert run["equal"]["bridges"] and run["equal"]["pendular_overlaps"]
        assert run["repeatable"] and run["cached"] and run["fresh"]
        assert min(np.diag(run["psi"])) > 0.0


def main(check):
    """The measurements of ``check`` ("dry" or "wet", inside walls; "periodic-dry",
    "periodic-wet" or "sheared-wet", in a periodic cell, sheared in the last) in two blocks and
    in one; GAPS' scenes in two blocks of GAP_CHUNK and in one."""
    if check in GAPS:
        return {name: measure(True, chunk, cell=check, steps=GAP_STEPS)
                for name, chunk in (("blocks", GAP_CHUNK), ("one_block", 2 * GAP_CHUNK))}
    cell, _, kind = check.rpartition("-")
    cell = cell or None
    wet = kind == "wet"
    out = {"cell": cell, "blocks": measure(wet, CHUNK, cell=cell),
           "one_block": measure(wet, 2 * CHUNK, cell=cell)}
    if wet:
        out["wide"] = measure(wet, CHUNK, filling_angle=WIDE, cell=cell)
    return out


if __name__ == "__main__":
    run_checks({name: lambda name=name: main(name) for name in (*SCENES, *GAPS)})
