"""The blocks a laboratory test and the direct tension share (pendular.procedures.triaxial):
the ParaView frames' period and writer, and the wetting report."""

import os
import time

import numpy as np
import pytest

from conftest import RADIUS, two_body_scene
from pendular.dem.measure import porosity
from pendular.procedures.equilibrium import frame_period, frames_writer, wetting_report


@pytest.mark.parametrize("vtk_every, vtk_frames, steps, unknown, period", [
    (7, 50, 1000, 0, 7),            # a period given wins over the frames
    (0, 50, 1000, 0, 0),            # ... 0: no frames
    (None, 0, 1000, 30, 0),         # no frames asked
    (None, 50, 1000, 30, 20),       # frames over a loading of known length
    (None, 50, 10, 30, 1),          # ... at least one step apart
    (None, 50, None, 30, 30),       # a loading of unknown length: the fallback period
    (None, 0, None, 30, 0),
])
def test_the_frame_period_follows_the_options(vtk_every, vtk_frames, steps, unknown, period):
    assert frame_period(vtk_every, vtk_frames, steps, unknown) == period


def test_frames_are_written_into_vtk_only_with_a_period(tmp_path):
    sim = two_body_scene([[0.0, 0.0, 0.0], [3 * RADIUS, 0.0, 0.0]], np.zeros((2, 3)))
    before = list(sim.writers)
    assert frames_writer(sim, str(tmp_path), 0) is None
    assert sim.writers == before
    writer = frames_writer(sim, str(tmp_path), 5, time_axis="axial_strain_percent")
    assert sim.writers == [*before, writer]
    assert writer.period == 5 and writer.time_axis == "axial_strain_percent"
    assert writer.folder == os.path.join(str(tmp_path), "vtk")


class _Bridges:
    """Stands for a bridge operation: its Sr and bridge count."""

    def saturation(self, sim):
        return 0.25

    def count(self, sim):
        return 3


def test_a_wetting_report_gives_steps_details_then_the_wet_state():
    sim = two_body_scene([[0.0, 0.0, 0.0], [3 * RADIUS, 0.0, 0.0]], np.zeros((2, 3)))
    started = time.perf_counter()
    report = wetting_report(sim, _Bridges(), 120, started, formation_suction_pa=3e4)
    assert list(report) == ["wetting_steps", "wetting_time_s", "formation_suction_pa",
                            "initial_saturation", "initial_bridges", "wet_porosity"]
    assert report["wetting_steps"] == 120 and report["formation_suction_pa"] == 3e4
    assert report["initial_saturation"] == 0.25 and report["initial_bridges"] == 3
    assert report["wet_porosity"] == porosity(sim.particles, sim.walls)
    assert 0.0 <= report["wetting_time_s"] <= time.perf_counter() - started


def test_a_campaign_sample_sizes_a_test_with_the_radius_it_was_prepared_with(tmp_path):
    """The preparation rescales grown spheres to the radius asked, which can leave them an ulp
    off it: the PrepareConfig a campaign stores with its sample sizes the test, so that a
    finished run is recognised as the same configuration when the campaign runs again."""
    import types

    from pendular.dem.sample import save_sample
    from pendular.dem.state import Particles, Walls
    from pendular.procedures.config import config_to_dict, sized_as_sample
    from pendular.procedures.preparation import PrepareConfig

    prepared = PrepareConfig(particles=60, radius=2.4e-5)
    off = np.nextafter(2.4e-5, 1.0)                     # the grown spheres' radius
    centres = np.array([[i, j, k] for i in range(3) for j in range(4) for k in range(5)],
                       float) * 3 * off + 2 * off
    particles = Particles(centres, np.full(60, off), 2650.0)
    walls = Walls.box(np.zeros(3), centres.max(axis=0) + 2 * off)
    path = str(tmp_path / "c500.h5")
    save_sample(path, types.SimpleNamespace(particles=particles, walls=walls), {"steps": 1},
                {"sample": config_to_dict(prepared)})
    sized = sized_as_sample(PrepareConfig(particles=60), path)
    assert sized.radius == 2.4e-5 and sized.particles == 60
    # without a stored configuration, the spheres' own radius
    save_sample(path, types.SimpleNamespace(particles=particles, walls=walls), {"steps": 1})
    assert sized_as_sample(PrepareConfig(particles=60), path).radius == off
