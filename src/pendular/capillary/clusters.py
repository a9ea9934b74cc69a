"""Liquid clusters as connected sets of filled pore units (Melnikov et al. 2015,
docs/liquid_clusters.md 'Clusters').

Two filled units belong to one cluster when they share a throat. Per cluster: its number of
units and its volume [m^3], the sum of its units' pore volumes (pendular.capillary.pores; the
bridges and menisci around a cluster's edge are not in it yet). The largest cluster (by volume)
percolates along an axis when it spans the sample along it: between walls, when it holds units
on both the low and the high face of the hull of the centres; in a periodic cell, when it wraps
around the cell, i.e. a closed path of its throats crosses the cell's faces a net non-zero number
of times along that axis: it joins its own image across those faces, an infinite cluster of
the periodic packing (PoreUnits.throat_shift). In a sheared cell the images are the sheared
lattice's (pendular.capillary.pores.lattice_vectors): a path through the z faces lands on the
image shifted by delta along x, which counts as a crossing of the z faces alone.
"""

from dataclasses import dataclass

import numba
import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import breadth_first_order, connected_components

from pendular.capillary.pores import FACES


@dataclass(frozen=True)
class Clusters:
    """The liquid clusters of a packing. M pore units, C clusters.

    label: (M,) the cluster of each unit, -1 for a unit not filled.
    units: (C,) number of units of each cluster. volume: (C,) [m^3] its pore volume.
    largest: the cluster of the largest volume, -1 without clusters.
    percolates: (3,) bool, whether the largest cluster spans the sample along x, y, z.
    """

    label: np.ndarray
    units: np.ndarray
    volume: np.ndarray
    largest: int
    percolates: np.ndarray

    @property
    def count(self):
        """Number of clusters."""
        return len(self.units)


def find_clusters(pore_units, filled):
    """Clusters of the ``filled`` (M,) bool units of ``pore_units`` (a
    pendular.capillary.pores.PoreUnits)."""
    filled = np.asarray(filled)
    if filled.shape != (pore_units.count,) or filled.dtype != bool:
        raise ValueError(f"filled must be a bool array of shape ({pore_units.count},), one per "
                         f"pore unit; got {filled.dtype} {filled.shape}")
    graph, inner = _filled_graph(pore_units, filled)
    _, component = connected_components(graph, directed=False)
    label = np.full(pore_units.count, -1, np.int64)
    if filled.any():
        _, label[filled] = np.unique(component[filled], return_inverse=True)
    count = label.max() + 1
    units = np.bincount(label[filled], minlength=count)
    volume = np.bincount(label[filled], pore_units.pore_volume[filled], minlength=count)
    largest = int(np.argmax(volume)) if count else -1
    if largest < 0:
        percolates = np.zeros(3, bool)
    elif pore_units.period is None:
        percolates = _spans_hull(pore_units, label == largest)
    else:
        percolates = _wraps(pore_units, graph, inner, label, largest)
    return Clusters(label=label, units=units, volume=volume, largest=largest,
                    percolates=percolates)


def _filled_graph(pore_units, filled):
    """(M, M) sparse graph of the throats between two filled units, each edge holding its
    throat's index + 1; and the indices of those throats."""
    a, b = pore_units.throat_units.T
    inner = np.flatnonzero((b >= 0) & filled[a] & filled[np.maximum(b, 0)])
    count = pore_units.count
    graph = coo_matrix((inner + 1, (a[inner], b[inner])), shape=(count, count)).tocsr()
    return graph, inner


def _spans_hull(pore_units, member):
    """(3,) whether the units ``member`` hold hull faces facing both ways along each axis (a
    face faces the axis of the largest component of its outward normal)."""
    unit, face = np.nonzero((pore_units.neighbours < 0) & member[:, None])
    corners = pore_units.vertices[unit[:, None], FACES[face]]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    outward = np.sum(normal * (corners[:, 0] - pore_units.vertices[unit, face]), axis=1)
    normal *= np.sign(outward)[:, None]
    axis = np.argmax(np.abs(normal), axis=1)
    sign = np.sign(normal[np.arange(len(axis)), axis])
    return np.array([(sign[axis == k] < 0).any() and (sign[axis == k] > 0).any()
                     for k in range(3)])


def _wraps(pore_units, graph, inner, label, cluster):
    """(3,) whether ``cluster`` wraps around the periodic cell along each axis: lay its units
    out without wrapping along a breadth-first tree, then look for a throat whose two units
    then sit a period apart."""
    root = int(np.flatnonzero(label == cluster)[0])
    order, predecessor = breadth_first_order(graph, root, directed=False,
                                             return_predecessors=True)
    child = order[1:]
    if len(child) == 0:         # one unit: no throat of its own to wrap through
        return np.zeros(3, bool)
    parent = predecessor[child]
    edge = np.asarray(graph[parent, child]).ravel() + np.asarray(graph[child, parent]).ravel() - 1
    first = pore_units.throat_units[edge, 0]
    # n_second = n_first - shift across a throat (PoreUnits.throat_shift)
    step = np.where((first == parent)[:, None], -1, 1) * pore_units.throat_shift[edge]
    offset = _propagate(pore_units.count, child, parent, step)
    a, b = pore_units.throat_units[inner].T
    mine = label[a] == cluster
    residual = (offset[b[mine]] - offset[a[mine]] + pore_units.throat_shift[inner[mine]])
    return (residual != 0).any(axis=0)


@numba.njit(cache=True)
def _propagate(count, child, parent, step):
    """(count, 3) image offsets of the units along a breadth-first tree (parents first)."""
    offset = np.zeros((count, 3), np.int64)
    for k in range(len(child)):
        offset[child[k]] = offset[parent[k]] + step[k]
    return offset
