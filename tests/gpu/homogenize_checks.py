"""The GPU side of tests/gpu/test_gpu_homogenize.py, run under Numba's CUDA simulator in a
process of its own (``NUMBA_ENABLE_CUDASIM=1 python tests/gpu/homogenize_checks.py dry wet
periodic-dry ...``, simulator.run_checks): the device's homogenisation of each scene and the
CPU's of the same state."""

import numpy as np

from simulator import relative, run_checks

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
    """After ``steps`` steps of the scene (all but the last on the CPU, the last on the device):
    {quantity: relative difference device vs CPU}, {quantity: equal bit for bit}, the
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
    sim = cells[cell](wet) if cell else scene(wet=wet, side=SIDE)
    sim.run(steps - 1)          # the scene's motion on the CPU (the simulator is slow) ...
    gpu = GpuSimulation(sim)
    gpu.run(1)                  # ... its last step on the device, which holds the state
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


def measurements(check):
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
    run_checks({name: lambda name=name: measurements(name) for name in (*SCENES, *GAPS)})
