"""Golden regression values: a short fixed-seed triaxial, dry and wet, whose peak and a few
history values are pinned.

Tolerance: a relative 1e-9. The run is deterministic (bit for bit on a machine, any thread
count), so a value that moves means the results changed: the physics, the order of a sum, the
time step, the preparation. A change that is meant (a corrected law, a reordered kernel) may
re-pin them: first the physics tests (closed forms, YADE cross-checks) must pass, and the commit
says why the values moved. Another CPU or Numba/LLVM version can change the round-off of the
fast-math kernels (pendular.dem.HOT_KERNEL_FASTMATH) and so these values, which the chaotic
preparation amplifies; CI runs on one kind of machine."""

import h5py
import pytest

from pendular import BridgeConfig, PrepareConfig, ShearConfig, TriaxialConfig, TriaxialTest

#: suction [Pa] -> (peak q [Pa], p at the peak [Pa], initial porosity [-], sigma_wall of record
#: 10 [Pa], saturation at the peak [-] or None).
GOLDEN = {
    0.0: (686.9885545417362, 981.3623189106, 0.4886662043375237,
          (751.9903803329195, 752.9756008103592, 1182.0520001947993), None),
    30000.0: (1611.174110111111, 1288.1960616980411, 0.4886662043375237,
              (751.8472123104177, 755.4241455600089, 1508.6115071818163), 0.011491852497051369),
}
TOLERANCE = 1e-9


@pytest.mark.parametrize("suction", sorted(GOLDEN))
def test_a_short_fixed_seed_triaxial_gives_its_pinned_values(suction, tmp_path):
    config = TriaxialConfig(sample=PrepareConfig(particles=60, seed=3),
                            shear=ShearConfig(max_strain=0.01, inertial_number=2e-3, records=20),
                            bridges=BridgeConfig(suction) if suction else None, vtk_frames=0)
    summary = TriaxialTest(config).run(tmp_path, progress=False, plots=False)
    with h5py.File(tmp_path / "history.h5", "r") as handle:
        record = handle["history/sigma_wall"][10]
    peak_q, p_at_peak, porosity, sigma_wall, saturation = GOLDEN[suction]
    assert summary["peak_q"] == pytest.approx(peak_q, rel=TOLERANCE)
    assert summary["p_at_peak"] == pytest.approx(p_at_peak, rel=TOLERANCE)
    assert summary["initial_porosity"] == pytest.approx(porosity, rel=TOLERANCE)
    assert record.tolist() == pytest.approx(sigma_wall, rel=TOLERANCE)
    if saturation is not None:
        assert summary["saturation_at_peak"] == pytest.approx(saturation, rel=TOLERANCE)
