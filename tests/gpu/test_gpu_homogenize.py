"""Homogenisation on the device (pendular.gpu.homogenize) against the CPU's functions on the
same state, under Numba's CUDA simulator: the 64-sphere walled scene of tests/gpu/simulated.py,
the 64-sphere periodic cell of tests/gpu/periodic_checks.py (pairs through the faces:
branch vectors with their images, the cell's volume, no walls), dry and wet
at 30 kPa (exact bridges at contact), and wet the sheared cell of tests/gpu/shear_checks.py
(Lees–Edwards: the images through the z faces offset along x), after 30 steps, the last on the
device (the others on the CPU: the simulator runs a step slowly).
The device's quantities are computed from the state it holds, which then comes back for the
CPU's (pendular.homogenize.contact_stress, pendular.dem.measure,
pendular.homogenize.on_the_fly, pendular.dem.measure.largest_overlap).
The reduction runs in two blocks (CHUNK = 32), and once more in one block (CHUNK raised to 64
in the simulated process, which reads the module's globals at each launch): in one block the
dry sums are the CPU's in the CPU's order.

The measurements run in tests/gpu/homogenize_checks.py, every scene in one process of its own,
so that the simulator never reaches the process of the other tests.
The differences from the CPU are round-off (docs/gpu.md); in one block the dry sums, the
contact quantities and sigma_capillary are the CPU's bit for bit. Bridges across gaps (GAPS:
the 27 spheres of persist_checks.py, persisting bridges, and of volume_checks.py,
volume-controlled, after GAP_STEPS steps pulled apart) are reduced in two blocks of GAP_CHUNK
and in one.
"""

import numpy as np
import pytest

from conftest import requires
from homogenize_checks import CHUNK, GAPS, MAXIMA, SCENES, SIDE
from simulator import simulated

pytestmark = requires("numba_cuda")


@pytest.fixture(scope="module")
def measured():
    """Every scene's measurements, in one process."""
    return simulated("homogenize_checks.py", *SCENES, *GAPS)


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
