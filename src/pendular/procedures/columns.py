"""What a loading path records: its history columns and the measures they are made of.

``history_columns``: the columns every laboratory history has (step, time, strains, wall and
Love–Weber stresses, porosity, coordination; wet, the bridges' and the effective stresses;
with liquid clusters, theirs: ``cluster_columns``; pendular.io.columns.HISTORY_COLUMNS);
``void_ratio``, ``k0`` and ``COMPRESSION_COLUMNS``, the compression tests' own;
``friction_angle`` of principal stresses. Stresses compression positive [Pa].
"""

from __future__ import annotations

import math

import numpy as np

from pendular.dem.measure import porosity
from pendular.procedures.config import WATER_DENSITY
from pendular.homogenize.invariants import lateral_stress
from pendular.homogenize.on_the_fly import homogenized


def capillary_operation(sim):
    """The scene's capillary bridge operation, or None for a dry scene."""
    found = [op for op in sim.forces if hasattr(op, "water_volume")]
    return found[0] if found else None


def cluster_operation(sim):
    """The scene's liquid clusters (pendular.capillary.liquid_clusters.LiquidClusters), or None
    (--liquid pendular, or dry)."""
    from pendular.capillary.liquid_clusters import LiquidClusters   # a dry run never needs it

    return next((op for op in sim.forces if isinstance(op, LiquidClusters)), None)


def cluster_columns(clusters):
    """History columns of the liquid clusters (pendular.io.columns.HISTORY_COLUMNS), their
    figures measured once per state; ``saturation`` and ``water_content``: of the bridges and
    clusters together;
    ``chi_with_clusters``: chi of the bridges' shares outside the filled units and of the
    clusters, ``sigma_clusters`` the Love–Weber stress of the clusters' forces
    (pendular.homogenize.clusters)."""
    from pendular.capillary.wetting import gravimetric_water_content
    from pendular.homogenize.clusters import chi_with_clusters, cluster_force_stress

    last = {}

    def measures(sim):
        """The clusters' figures of ``sim``'s state, its liquid's account, measured once."""
        key = (sim.step, id(clusters.found))          # a stage's start changes the state
        if last.get("key") != key:
            account = clusters.account(sim)
            last.update(clusters.statistics(sim, account), key=key, account=account)
        return last

    def figure(name):
        return lambda sim: measures(sim)[name]

    columns = {name: figure(name) for name in (
        "clusters", "liquid_in_bridges", "liquid_in_clusters", "liquid_in_largest_cluster",
        "trimers", "liquid_in_trimers", "saturation_pore_units", "saturation")}
    percolates = figure("largest_cluster_percolates")
    columns["largest_cluster_percolates"] = lambda sim: np.array(percolates(sim), float)
    columns["water_content"] = lambda sim: gravimetric_water_content(
        measures(sim)["account"].total, sim.particles.solid_volume(),
        sim.particles.density / WATER_DENSITY)
    columns["chi_with_clusters"] = lambda sim: chi_with_clusters(
        sim, clusters, np.array(measures(sim)["psi_clusters"]))
    columns["sigma_clusters"] = lambda sim: cluster_force_stress(sim, clusters)
    return columns


def measured(name):
    """Column ``name`` of a history: the homogenised quantity ``name`` of the state, measured
    where it is held (pendular.homogenize.on_the_fly.homogenized)."""

    def quantity(sim):
        return homogenized(sim)[name]

    return quantity


def solid_fraction_porosity(sim):
    """Porosity of the box [-] (pendular.dem.measure.porosity) from the spheres' volume
    measured where the state is held (pendular.homogenize.on_the_fly.homogenized)."""
    return 1.0 - homogenized(sim)["solid_volume"] / sim.walls.volume()


def history_columns(sim, axial, reference_volume, bridges=None):
    """Recorded columns of a loading path's history (name -> function of sim); ``axial``
    measures the axial strain (``strain(walls)``); pendular.io.schema declares their units. A
    wet scene adds the capillary and homogenised columns of
    pendular.homogenize.on_the_fly.CapillaryHomogenization (Eqs. 3.43-3.46, 3.53-3.54, 4.5)
    and, with liquid clusters among the scene's forces, ``cluster_columns``."""

    columns = {
        "step": lambda s: s.step,
        "time": lambda s: s.time,
        "axial_strain": lambda s: axial.strain(s.walls),
        "volumetric_strain": lambda s: 1.0 - s.walls.volume() / reference_volume,
        "sigma_wall": lambda s: s.walls.stress(),
        "sigma_contact": measured("sigma_contact"),
        "porosity": solid_fraction_porosity,
        "coordination": measured("coordination"),
        "fabric": measured("fabric"),                                       # Eq. 4.1
        "anisotropy": measured("anisotropy"),                               # Eq. 3.51
        "unbalanced_force": measured("unbalanced_force"),
    }
    if bridges is not None:
        from pendular.homogenize.on_the_fly import CapillaryHomogenization

        columns.update(CapillaryHomogenization(bridges).quantities())
        if bridges.liquid != "reservoir":             # a closed amount of liquid
            columns.update({"liquid_bridges": lambda s: bridges.liquid_balance(s)[0],
                            "liquid_film": lambda s: bridges.liquid_balance(s)[1],
                            "liquid_lost": lambda s: bridges.liquid_balance(s)[2]})
        clusters = cluster_operation(sim)
        if clusters is not None:
            columns.update(cluster_columns(clusters))
    return columns


def void_ratio(sim):
    """Void ratio e = n / (1 - n) of the box [-] (n: pendular.dem.measure.porosity)."""
    sim.fetch("particles")          # all of a device run's state (Simulation.fetch)
    n = porosity(sim.particles, sim.walls)
    return n / (1.0 - n)


#: History columns of the oedometric and isotropic paths beyond the triaxial's.
COMPRESSION_COLUMNS = {"void_ratio": void_ratio}


def k0(sim):
    """sigma_lateral / sigma_axial of the walls [-] (the coefficient of earth pressure; NaN
    while the axial stress is not positive)."""
    sigma = sim.walls.stress()
    return float(lateral_stress(sigma) / sigma[2]) if sigma[2] > 0.0 else math.nan


def friction_angle(sigma):
    """Mobilised friction angle [deg] of principal stresses ``sigma`` (..., 3) [Pa]:
    asin((sigma_1 - sigma_3) / (sigma_1 + sigma_3)), sigma_1 and sigma_3 the largest and the
    least (Mohr-Coulomb without cohesion); NaN where sigma_1 + sigma_3 <= 0."""
    sigma = np.asarray(sigma, dtype=np.float64)
    high, low = sigma.max(axis=-1), sigma.min(axis=-1)
    total = high + low
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(total > 0.0, (high - low) / np.where(total > 0.0, total, 1.0), np.nan)
    return np.degrees(np.arcsin(np.clip(ratio, -1.0, 1.0)))
