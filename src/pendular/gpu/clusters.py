"""Liquid clusters' device side (pendular.capillary.liquid_clusters.LiquidClusters): the pore
units, their filling and their forces stay the host's model (``set_suction``, ``hold_volume``,
``follow_packing``, which fetch the state they read, between two steps of the device); each
step the device adds what the CPU's ``apply`` adds, after the pairs' gather and the bridges'
forces of the same step: the clusters' own forces on the grains (an (N, 3) array uploaded
whenever the host computes it anew: LiquidClusters.version) and, taken off pair by pair, the
share of each bridge's force that the filled units absorb.

The shares are the host's by grain pair (LiquidClusters.absorbed_shares: the keys i N + j of
the units' edges, sorted, and their shares), so that the device needs no map to the host's
neighbour list: ``absorbed_forces`` finds each pair of its rows by bisection and writes -share
times the bridge's force on j from i (the device's ``bridge_pair_force``), and ``add_clusters``
adds the clusters' forces, then each grain's absorbed terms by the CPU's sum
(pendular.dem.neighbors._sum_pair_forces, the CPU's gather_pair_forces), in the CPU's order.
Inside walls only: in a periodic cell the cell's stress would need the clusters' virial
(LiquidClusters.virial) on the device.
"""

import numpy as np

from pendular.capillary.liquid_clusters import LiquidClusters
from pendular.gpu.cuda import cuda, device
from pendular.gpu.forces import sum_pair_forces
from pendular.gpu.operations import DeviceSide, device_side


@device
def edge_share(keys, shares, key):
    """The share of ``keys`` (sorted int64) whose key is ``key``, 0 when none is."""
    low = 0
    high = keys.shape[0]
    while low < high:
        middle = (low + high) // 2
        if keys[middle] < key:
            low = middle + 1
        else:
            high = middle
    if low < keys.shape[0] and keys[low] == key:
        return shares[low]
    return 0.0


@cuda.jit
def absorbed_forces(pair_count, pair_j, bridge_pair_force, keys, shares, absorbed):
    """Every pair k of particle p's row (one thread per particle): ``absorbed`` (K, 3) [N] the
    force on j from i it takes off, -share times the bridge's ``bridge_pair_force`` (K, 3)
    [N] (the CPU's -share * pair_force), share the one of key p N + j in ``keys`` and
    ``shares`` (LiquidClusters.absorbed_shares)."""
    p = cuda.grid(1)
    n = pair_count.shape[0]
    if p >= n:
        return
    for s in range(pair_count[p]):
        k = s * n + p
        taken = -edge_share(keys, shares, p * n + pair_j[k])
        absorbed[k, 0] = taken * bridge_pair_force[k, 0]
        absorbed[k, 1] = taken * bridge_pair_force[k, 1]
        absorbed[k, 2] = taken * bridge_pair_force[k, 2]


@cuda.jit
def add_clusters(cluster_force, pair_count, second_count, second_pair, absorbed, force):
    """Particle p's force (N, 3) [N] plus the clusters' ``cluster_force`` (N, 3) [N], then
    plus its ``absorbed`` pair forces by the CPU's sum (-f of its own pairs, +f of those where
    it is second: LiquidClusters._add_forces)."""
    p = cuda.grid(1)
    n = force.shape[0]
    if p >= n:
        return
    f0 = force[p, 0] + cluster_force[p, 0]
    f1 = force[p, 1] + cluster_force[p, 1]
    f2 = force[p, 2] + cluster_force[p, 2]
    v0, v1, v2 = sum_pair_forces(absorbed, second_pair, range(p, p + pair_count[p] * n, n),
                                 range(p, p + second_count[p] * n, n))
    force[p, 0] = f0 + v0
    force[p, 1] = f1 + v1
    force[p, 2] = f2 + v2


@device_side(LiquidClusters)
class ClustersOnDevice(DeviceSide):
    """LiquidClusters' side: their forces and absorbed shares uploaded at each new ``version``
    of the host's model, their launches after the gather (module docstring)."""

    family = "force"
    role = "clusters"

    def __init__(self, op):
        super().__init__(op)
        self._version = None        # the operation's version uploaded
        self._arrays = None         # (state, cluster force, keys, shares, absorbed buffer)

    def check(self, scene):
        """Inside walls, listed after their bridges (they take off shares of the bridges'
        forces of the same step), which persist across gaps (LiquidClusters' own rule)."""
        if scene.periodic:
            raise ValueError("device='gpu' runs LiquidClusters (--liquid clusters) inside walls "
                             "only, not in a periodic cell (the cell's stress would need the "
                             "clusters' virial on the device)")
        bridges = scene.force("bridges")
        if (bridges is None or bridges.op is not self.op.bridges
                or scene.index(self) < scene.index(bridges)):
            raise ValueError("device='gpu' runs LiquidClusters listed after their bridges only "
                             "(they take off shares of the bridges' forces of the same step)")

    def changed_on_host(self):
        """Whether the host's model computed new forces since the last upload."""
        return self.op.version != self._version

    def launches(self, state, dt):
        """The model's forces and shares uploaded if new, then (kernel, items, arguments) of
        absorbed_forces and add_clusters (none while no unit holds liquid)."""
        op = self.op
        self._version = op.version
        if not op.holds_liquid:
            self._arrays = None
            return []
        count = state.count
        keys, shares = op.absorbed_shares(count)
        # a key beyond every pair's ends the table (never empty)
        keys = np.append(keys, np.int64(count) * count)
        shares = np.append(shares, 0.0)
        absorbed = (self._arrays[4] if self._arrays is not None and self._arrays[0] is state
                    else cuda.to_device(np.zeros((state.width * count, 3))))
        self._arrays = (state, cuda.to_device(np.ascontiguousarray(op.cluster_force)),
                        cuda.to_device(keys), cuda.to_device(shares), absorbed)
        _, cluster_force, keys, shares, absorbed = self._arrays
        s = state
        return [(absorbed_forces, count,
                 (s.pair_count, s.pair_j, s.bridge_pair_force, keys, shares, absorbed)),
                (add_clusters, count,
                 (cluster_force, s.pair_count, s.second_count, s.second_pair, absorbed,
                  s.force))]
