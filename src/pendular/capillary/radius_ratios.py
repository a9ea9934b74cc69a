"""The radius-ratio nodes of the bridge tables of a DEM sample (docs/capillary.md, 'Unequal
spheres in the DEM loop').

A bridge table is built at radius ratios r = R2/R1 >= 1 (the larger radius over the smaller):
YADE's nodes 1 ... 10 (``table_radius_ratios``), or nodes fitted to the radii of a sample
(``sample_radius_ratios``: one at each distinct pair ratio, or geometric nodes for a continuous
size distribution), so that the bridge operations (pendular.capillary.bridges) read every
pair's own ratio exactly or interpolate within a small bound.
"""

import math

import numpy as np

from pendular.capillary.table import YADE_RADIUS_RATIOS


def table_radius_ratios(largest_ratio):
    """YADE's radius ratios 1 ... 10 up to the first one covering ``largest_ratio``."""
    if largest_ratio > YADE_RADIUS_RATIOS[-1] * (1.0 + 1e-12):
        raise ValueError(f"radius ratio R2/R1 = {largest_ratio:g} of the sample is outside the "
                         f"valid range [1, {YADE_RADIUS_RATIOS[-1]:g}] of the bridge tables")
    for index, ratio in enumerate(YADE_RADIUS_RATIOS):
        if ratio >= largest_ratio * (1.0 - 1e-12):
            return YADE_RADIUS_RATIOS[:index + 1]
    return YADE_RADIUS_RATIOS


#: Largest number of distinct pair radius ratios that get a table node each (exact lookups).
EXACT_RATIO_NODES = 24
#: Spacing factor of the geometric radius-ratio nodes of a sample with more distinct ratios.
RATIO_NODE_FACTOR = 1.1


def sample_radius_ratios(radii):
    """Radius-ratio nodes of the bridge tables of a sample with these sphere radii [m].

    Equal spheres only: (1.0,), the first of YADE's nodes (as ``table_radius_ratios(1)``).
    Otherwise the tables are exact for every pair of the sample, not interpolated between
    YADE's ratios 1, 1.1, 1.25, ..., 5, 10 (linear interpolation in r between those costs about
    1 % in force between 2 and 3 and 5 % between 5 and 10 mid-range, 5 % and 14 % near
    rupture, up to 3 % in rupture distance; docs/capillary.md): a node at each distinct ratio
    R2/R1 of two radii of the sample (and 1 if two spheres have the same radius), computed as
    the bridge kernels compute a pair's ratio (max / min of the two radii), so every pair
    reads its own node exactly, up to
    EXACT_RATIO_NODES nodes; beyond that (a continuous size distribution) geometric nodes
    1 = r_0 < ... < r_n = the sample's largest ratio rounded up to 0.01 (so that samples of one
    grading share their cached tables), r_(k+1) / r_k <= RATIO_NODE_FACTOR,
    interpolated within 0.15 % in force, 0.4 % in volume and 0.06 % in rupture distance up to
    0.9 of the rupture distance (0.4 % and 0.7 % at 0.99 of it). Building a node takes about
    0.5 s (suction table) and 4 s (volume table, one core), once: tables are cached by their
    nodes. ValueError beyond YADE's largest ratio 10.
    """
    sizes, counts = np.unique(np.asarray(radii, dtype=np.float64), return_counts=True)
    if sizes.size == 0 or not sizes[0] > 0.0:
        raise ValueError(f"radii = {sizes.tolist()[:3]}... must be positive (at least one sphere)")
    if sizes.size == 1:
        return table_radius_ratios(1.0)
    largest = float(sizes[-1] / sizes[0])
    table_radius_ratios(largest)                  # range check
    if sizes.size - 1 <= EXACT_RATIO_NODES:      # else more distinct ratios than that anyway
        ratios = {float(sizes[b] / sizes[a]) for a in range(sizes.size)
                  for b in range(a + 1, sizes.size)}
        if np.any(counts > 1):
            ratios.add(1.0)
        if len(ratios) <= EXACT_RATIO_NODES:
            return tuple(sorted(ratios))
    # the last node rounded up to 3 digits: samples of one grading share their cached tables
    largest = min(math.ceil(largest * 100.0) / 100.0, YADE_RADIUS_RATIOS[-1])
    n = math.ceil(math.log(largest) / math.log(RATIO_NODE_FACTOR) - 1e-9)
    return (1.0, *(largest ** (k / n) for k in range(1, n)), largest)
