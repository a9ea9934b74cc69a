"""Homogenisation on the device (pendular.gpu.homogenize) against the CPU's functions on the
same state, under Numba's CUDA simulator: the 64-sphere walled scene of tests/gpu/simulated.py,
dry and wet at 30 kPa (exact bridges at contact), after 30 steps on the device. The device's
quantities are computed from the state it holds, which then comes back for the CPU's
(pendular.homogenize.contact_stress, pendular.dem.measure, pendular.homogenize.on_the_fly,
pendular.procedures.guards.largest_overlap).
The reduction runs in two blocks (CHUNK = 32), and once more in one block (CHUNK raised to 64
in the simulated process, which reads the module's globals at each launch): in one block the
dry sums are the CPU's in the CPU's order.

The measurements run as this file's script in a process of its own
(``NUMBA_ENABLE_CUDASIM=1 python tests/gpu/test_gpu_homogenize.py dry|wet``), so that the
simulator never reaches the process of the other tests. Measured, largest relative differences
from the CPU: two blocks, 3.6e-16 (sigma_contact), 3.2e-16 (fabrics), 2.2e-16 (water volume),
5.1e-16 (chi), 6.5e-15 (B, a deviator: its terms cancel), 5.6e-16 (psi), 1.9e-16
(sigma_capillary), 5.7e-16 (interface term), 1.8e-14 (the anisotropies, from eigenvalues);
one block, dry: equal bit for bit; wet: the contact quantities, the water volume and
sigma_capillary bit for bit, the bridge tensors within 2e-14 (the CPU sums them with NumPy's
vectorised sums and matrix product).
"""

import json
import os
import sys

import numpy as np
import pytest

from simulator import relative, simulated

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


def cpu_homogenization(sim):
    """The CPU's quantities of sim's state, named as device_homogenization names them."""
    from pendular.capillary.bridges import CapillaryBridges
    from pendular.dem.measure import coordination, unbalanced_force
    from pendular.homogenize.contact_stress import contact_stress
    from pendular.homogenize.fabric import fabric_tensor, principal_anisotropy
    from pendular.homogenize.on_the_fly import CapillaryHomogenization
    from pendular.procedures.guards import largest_overlap

    fabric = fabric_tensor(sim.contacts.normal, sim.contacts.overlap > 0.0)
    out = {"sigma_contact": contact_stress(sim.particles, sim.contacts, sim.walls),
           "coordination": coordination(sim.contacts, len(sim.particles)),
           "fabric": fabric, "anisotropy": principal_anisotropy(fabric),
           "unbalanced_force": unbalanced_force(sim.particles, sim.contacts),
           "solid_volume": sim.particles.solid_volume(),
           "largest_overlap": largest_overlap(sim),
           "smallest_radius": sim.particles.radius.min(),
           "largest_radius": sim.particles.radius.max()}
    try:
        bridges = sim.operation(CapillaryBridges)
    except KeyError:
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


def measure(wet, chunk, filling_angle=None):
    """{quantity: relative difference device vs CPU}, {quantity: equal bit for bit}, the
    device's counts, the copies back during the device's homogenisation (device_homogenization,
    then GpuSimulation.homogenized, which must repeat it bit for bit: the same result for the
    same step, a new one a step later), whether the state was still held by the device after
    it, and the error of GpuSimulation.homogenized once the state is back; the reduction in
    blocks of ``chunk`` particles; ``filling_angle`` [deg]: the bridges' widened to it first
    (widen_menisci)."""
    from simulated import scene

    from pendular.gpu import GpuSimulation, homogenize
    from pendular.gpu.homogenize import device_homogenization

    homogenize.CHUNK = chunk

    copies = []
    copy_back = GpuSimulation.copy_back

    def counted(self, part=None):
        copies.append(part or "all")
        return copy_back(self, part)

    gpu = GpuSimulation(scene(wet=wet, side=SIDE))
    gpu.run(STEPS)
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
    gpu.run(1)
    fresh = gpu.homogenized() is not again
    return {"names": sorted(device), "cpu_names": sorted(cpu),
            "difference": {name: relative(cpu[name], device[name]) for name in cpu},
            "equal": {name: bool(np.array_equal(cpu[name], device[name])) for name in cpu},
            "repeatable": all(np.array_equal(device[name], again[name]) for name in device),
            "touching": device["coordination"] * len(gpu.sim.particles) / 2.0,
            "bridges": device.get("bridges", 0),
            "pendular_overlaps": device.get("pendular_overlaps", 0), "copies": copies,
            "held": held,
            "released": released, "cached": cached, "fresh": fresh,
            "psi": device["psi"].tolist() if wet else None}


@pytest.fixture(scope="module", params=["dry", "wet"])
def scene_run(request):
    pytest.importorskip("numba_cuda", reason="numba-cuda is not installed "
                        "(pip install -e '.[gpu]')")
    return request.param == "wet", simulated(os.path.basename(__file__), request.param)


def test_the_reduction_runs_in_two_blocks():
    from pendular.gpu import homogenize

    assert homogenize.CHUNK == CHUNK < SIDE ** 3 <= 2 * CHUNK


def test_the_device_reduces_the_cpu_quantities_without_copying_the_state(scene_run):
    wet, measured = scene_run
    expected = {"sigma_contact", "coordination", "fabric", "anisotropy", "unbalanced_force",
                "solid_volume", *MAXIMA}
    if wet:
        expected |= {"bridges", "pendular_overlaps", "water_volume", "chi", "B", "psi", "sigma_capillary",
                     "fabric_bridges", "anisotropy_bridges", "a_psi", "psi_interface"}
    for run in measured.values():
        assert run["copies"] == [] and run["held"]
        assert run["touching"] > 50                  # a packing, not a gas
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
    water volume and the capillary forces' stress) equal the CPU's exactly."""
    wet, measured = scene_run
    exact = ["sigma_contact", "coordination", "fabric", "anisotropy", "unbalanced_force"]
    if wet:
        exact += ["bridges", "pendular_overlaps", "water_volume", "sigma_capillary"]
    equal = measured["one_block"]["equal"]
    assert all(equal[name] for name in exact), equal


def test_the_wet_capillary_stress_is_compressive(scene_run):
    """psi of bridges at 30 kPa: positive diagonal (chi s dominates B), so a wrong sign or a
    missing term would not pass for agreement."""
    wet, measured = scene_run
    if wet:
        assert min(np.diag(measured["blocks"]["psi"])) > 0.0


def main(check):
    """The measurements of ``check`` ("dry" or "wet") in two blocks and in one."""
    from pendular.gpu import homogenize

    wet = check == "wet"
    out = {"blocks": measure(wet, homogenize.CHUNK), "one_block": measure(wet, 2 * CHUNK)}
    if wet:
        out["wide"] = measure(wet, CHUNK, filling_angle=WIDE)
    return out


if __name__ == "__main__":
    print(json.dumps(main(sys.argv[1])))
