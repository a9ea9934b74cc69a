"""The direct tension with liquid clusters (pendular.procedures.tension_clusters): the wetting
holds the water content in bridges and clusters, every closed-liquid update of the pull holds
it again to round-off, the clusters' figures are in the history and the summary, and what is
not supported is refused by one error line."""

import copy

import numpy as np
import pytest

from conftest import refused, run_in_process
from pendular.capillary.liquid_clusters import LiquidClusters
from pendular.io.schema import undeclared_keys
from pendular.procedures import tension_pull
from pendular.procedures.preparation import prepare_sample
from pendular.procedures.tension import TensionConfig, tension_sample
from pendular.procedures.tension_clusters import (CLUSTER_FIGURES, ClosedLiquidUpdates,
                                                  cluster_summary)

WATER = 0.0211       # Kim's wettest case at e = 0.72 (fraction)


@pytest.fixture(scope="module")
def config():
    return TensionConfig(sample=tension_sample(particles=200), max_strain=0.004, vtk_frames=0,
                         roughness=0.0, liquid="clusters")


@pytest.fixture(scope="module")
def wetted(config):
    dry, _ = prepare_sample(tension_pull.prepare_config(config, 10.0), progress=False)
    return tension_pull.wet(dry, config, WATER, progress=False)


class Watch:
    """Writer after the closed-liquid updates: the liquid each update found."""

    def __init__(self, clusters):
        self.clusters, self.found = clusters, []

    def apply(self, sim):
        if self.clusters.liquid is not None:
            self.found.append(self.clusters.liquid)


def test_the_wetting_holds_the_water_in_bridges_and_clusters(wetted, config):
    sim, bridges, report = wetted
    clusters = sim.operation(LiquidClusters)
    target = WATER * config.specific_gravity * sim.particles.solid_volume()
    assert clusters.liquid.total == pytest.approx(target, rel=1e-14)
    assert report["water_content"] == pytest.approx(WATER, rel=1e-9)
    assert report["formation_suction_pa"] == clusters.suction == bridges.suction
    assert report["clusters_wet"]["liquid_in_clusters"] > 0.0     # units filled at this w
    assert set(report["clusters_wet"]) == set(CLUSTER_FIGURES)


def test_every_update_of_the_pull_holds_the_water_to_round_off(wetted, config, tmp_path):
    sim = copy.deepcopy(wetted[0])
    bridges = sim.operation(type(wetted[1]))
    clusters = sim.operation(LiquidClusters)
    target = clusters.liquid.total
    pull = tension_pull.Pull(sim, bridges, config, str(tmp_path), progress=False)
    watch = Watch(clusters)
    sim.writers.append(watch)
    assert isinstance(sim.writers[-2], ClosedLiquidUpdates)
    steps, history = pull.run(None)
    updates = {id(liquid): liquid for liquid in watch.found}
    assert len(updates) >= 10
    for liquid in updates.values():
        assert liquid.total == pytest.approx(target, rel=1e-14)
        assert 0.0 <= liquid.front_fraction <= 1.0
    # between updates the suction is held: the water drifts little
    assert np.allclose(history["water_content"], WATER, rtol=0.01)
    for name in CLUSTER_FIGURES:
        assert len(history[name]) == len(history["step"])
    summary = cluster_summary(history, int(np.argmax(history["tensile_stress"])))
    assert set(summary["clusters_at_peak"]) == set(CLUSTER_FIGURES)
    assert undeclared_keys({**summary, "clusters_wet": wetted[2]["clusters_wet"]},
                           "tension") == []


@pytest.mark.parametrize("extra, words", [
    ([], ["--liquid", "--roughness"]),
    (["--roughness", "0", "--periodic"], ["--liquid", "--periodic"]),
])
def test_what_clusters_do_not_support_is_refused(extra, words, capsys, tmp_path):
    status, err = run_in_process("tension", ["--liquid", "clusters", "--particles", "200",
                                             "--vtk-frames", "0", "--out", tmp_path / "out",
                                             *extra], capsys)
    refused(status, err, *words)
