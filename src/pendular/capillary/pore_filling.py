"""Which pore units hold liquid at a suction: drainage by Haines jumps, imbibition by pore
filling, and the liquid's account between bridges and filled units (docs/liquid_clusters.md
'The quasi-static cluster model').

The quasi-static model, after Melnikov et al. (2015; Melnikov, K., Mani, R., Wittel, F. K.,
Thielmann, M., Herrmann, H. J., Grain-scale modeling of arbitrary fluid saturation in random
packings, Phys. Rev. E 92, 022206) and the pore-network rules it builds on (Haines 1930;
Lenormand, Zarcone & Sarr 1983):

- every liquid body exchanges liquid through the films on the grains, instantly: all liquid is
  at the one suction s [Pa] (imposed, or found from the liquid volume);
- **drainage** (Haines jump): a filled unit empties when one of its throats opens onto gas (an
  empty unit, or the hull of the centres where the gas outside enters) and s exceeds that
  throat's entry suction: 2 gamma cos(theta) / r_t (r_t its inscribed circle, ``entry_suction``
  of pendular.capillary.pores), or the Mayer–Stowe–Princen balance over the throat's section
  (``mayer_stowe_princen_entry``). Invasion goes on from the units it empties;
- **imbibition** (pore filling): an empty unit fills when s falls to its filling suction
  2 gamma cos(theta) / r_b, r_b the radius of the pore body: the sphere tangent to its four
  grains where that sphere's centre lies inside the unit, and never less than its largest
  throat's radius (so that a unit that fills at s is stable against drainage at s). Liquid
  reaches every unit through the films, so filling needs no filled neighbour;
- the gas is always connected (trapped air is not modelled).

Liquid account: a filled unit holds its pore volume; a bridge on an edge of the pore units
keeps the share of its volume that lies in empty units, its dihedral angles over 2 pi (the
units around an edge fill 2 pi; the rest, on the hull, is the strip outside the units).
"""

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from pendular.capillary.pores import EDGES, FACES, dihedral_angles, throat_sides
from pendular.capillary.throats import (check_entry_estimate, entry_suction,
    mayer_stowe_princen_entry)


def pore_body_radius(vertices, radii):
    """(M,) [m] radius of the sphere tangent from outside to the four spheres of each unit
    (``vertices`` (M, 4, 3) [m], ``radii`` (M, 4) [m]), where its centre lies inside the
    tetrahedron; NaN where it does not (a flat unit) or does not exist.

    With c_0 at the origin, norm(p - c_i)^2 = (R_i + r)^2 minus the same for i = 0 is linear
    in p: 2 d_i . p = d_i . d_i - R_i^2 + R_0^2 - 2 r (R_i - R_0), so p = a + r b, and
    norm(a + r b) = R_0 + r leaves a quadratic in r (R_circumscribed - R for equal spheres)."""
    d = vertices[:, 1:] - vertices[:, :1]
    r0 = radii[:, :1]
    rhs_a = np.sum(d * d, axis=2) - radii[:, 1:] ** 2 + r0 ** 2
    rhs_b = -2.0 * (radii[:, 1:] - r0)
    matrix = 2.0 * d
    good = np.abs(np.linalg.det(matrix)) > 1e-12 * np.sum(d * d, axis=(1, 2)) ** 1.5
    a = np.full((len(d), 3), np.nan)
    b = np.full((len(d), 3), np.nan)
    a[good] = np.linalg.solve(matrix[good], rhs_a[good][..., None])[..., 0]
    b[good] = np.linalg.solve(matrix[good], rhs_b[good][..., None])[..., 0]
    r0 = r0[:, 0]
    qa = np.sum(b * b, axis=1) - 1.0
    qb = np.sum(a * b, axis=1) - r0
    qc = np.sum(a * a, axis=1) - r0 ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        root = np.sqrt(qb * qb - qa * qc)
        roots = np.stack([(-qb - root) / qa, (-qb + root) / qa])
        roots = np.where(np.abs(qa) < 1e-12, -qc / (2.0 * qb), roots)
    lowest = -radii.min(axis=1)
    roots = np.where(np.isfinite(roots) & (roots > lowest), roots, np.inf)
    radius = roots.min(axis=0)
    centre = vertices[:, 0] + a + radius[:, None] * b
    inside = _inside(vertices, centre)
    return np.where(np.isfinite(radius) & (radius > 0) & inside, radius, np.nan)


def _inside(vertices, point):
    """(M,) whether ``point`` (M, 3) lies in the tetrahedra ``vertices`` (M, 4, 3)."""
    edges = (vertices[:, 1:] - vertices[:, :1]).transpose(0, 2, 1)
    with np.errstate(invalid="ignore"):
        ok = np.all(np.isfinite(point), axis=1) & (np.abs(np.linalg.det(edges)) > 0)
    weights = np.full((len(point), 3), -1.0)
    weights[ok] = np.linalg.solve(edges[ok], (point - vertices[:, 0])[ok][..., None])[..., 0]
    return np.all(weights >= 0, axis=1) & (weights.sum(axis=1) <= 1.0)


@dataclass(frozen=True)
class FillingThresholds:
    """The suctions [Pa] at which the units of a PoreUnits drain and fill.

    throat_entry: (T,) entry suction of each throat (inf where its grains close it).
    filling: (M,) filling suction of each unit, at most the entry suction of its throats (the
    two units of a throat see its radius to round-off; its entry takes the wider).
    """

    throat_entry: np.ndarray
    filling: np.ndarray


def filling_thresholds(pore_units, radius, surface_tension, contact_angle=0.0,
                       entry="inscribed"):
    """FillingThresholds of ``pore_units`` with grains of ``radius`` (N,) [m]
    (``surface_tension`` [N/m], ``contact_angle`` [deg]; module docstring). ``entry``, one of
    ENTRY_ESTIMATES: the throats' entry suctions through their inscribed circles
    (``entry_suction``) or by the Mayer–Stowe–Princen balance over their sections
    (``mayer_stowe_princen_entry``, taken on the first unit's side of each throat)."""
    check_entry_estimate(entry)
    radii = radius[pore_units.grains]
    throat = np.full(len(pore_units.throat_units), -np.inf)
    np.maximum.at(throat, pore_units.throat_of.ravel(), pore_units.throat_radius.ravel())
    body = pore_body_radius(pore_units.vertices, radii)
    finite = np.where(np.isfinite(pore_units.throat_radius), pore_units.throat_radius, np.nan)
    body = np.fmax(body, np.nanmax(finite, axis=1))
    if entry == "inscribed":
        entry = entry_suction(throat, surface_tension, contact_angle)
    else:
        unit, face = throat_sides(pore_units)
        entry = mayer_stowe_princen_entry(pore_units.vertices[unit[:, None], FACES[face]],
                                          radii[unit[:, None], FACES[face]], surface_tension,
                                          contact_angle)
    filling = np.minimum(entry_suction(body, surface_tension, contact_angle),
                         entry[pore_units.throat_of].min(axis=1))
    return FillingThresholds(throat_entry=entry, filling=filling)


def imbibe(thresholds, filled, suction):
    """(M,) bool: ``filled`` with every unit whose filling suction is at least ``suction``
    [Pa] filled."""
    return filled | (thresholds.filling >= suction)


def drain(pore_units, thresholds, filled, suction):
    """(M,) bool: ``filled`` after the Haines jumps at ``suction`` [Pa]: filled units whose
    throat of entry suction below it opens onto gas empty, in turn, until none does. The gas
    enters through the hull of the centres (a sample between walls); in a periodic cell with
    no empty unit, the filled unit of the lowest entry suction empties first once passed
    (the gas's nucleus)."""
    filled = np.array(filled, dtype=bool)
    first, second = pore_units.throat_units.T
    inner = second >= 0
    other = np.where(inner, second, 0)
    open_ = thresholds.throat_entry < suction
    if pore_units.period is not None and filled.all() and open_.any():
        weakest = np.full(pore_units.count, np.inf)
        np.minimum.at(weakest, first, thresholds.throat_entry)
        np.minimum.at(weakest, other[inner], thresholds.throat_entry[inner])
        if weakest.min() < suction:
            filled[int(np.argmin(weakest))] = False
    while True:
        gas_first = ~filled[first]
        gas_second = ~inner | ~filled[other]
        emptied = np.concatenate([first[open_ & filled[first] & gas_second],
                                  other[open_ & inner & filled[other] & gas_first]])
        if len(emptied) == 0:
            return filled
        filled[emptied] = False


@dataclass(frozen=True)
class UnitEdges:
    """The edges (grain pairs) of the pore units, each once. E edges.

    pair: (E, 2) the two grains, first < second. unit_edge: (M, 6) the edge of each of a
    unit's ``EDGES``. dihedral: (M, 6) [rad] the unit's dihedral angle there.
    """

    pair: np.ndarray
    unit_edge: np.ndarray
    dihedral: np.ndarray

    def filled_share(self, filled):
        """(E,) the share of the space around each edge that filled units hold: their
        dihedral angles / 2 pi, at most 1."""
        share = np.bincount(self.unit_edge[filled].ravel(), self.dihedral[filled].ravel(),
                            minlength=len(self.pair)) / (2.0 * math.pi)
        return np.minimum(share, 1.0)

    def share(self, weight):
        """(E,) the share of the space around each edge that the units' liquid holds, each
        unit counted with ``weight`` (M,) [-] (1 filled, a fraction partly filled, 0 empty):
        the weighted dihedral angles / 2 pi, at most 1."""
        share = np.bincount(self.unit_edge.ravel(), (self.dihedral * weight[:, None]).ravel(),
                            minlength=len(self.pair)) / (2.0 * math.pi)
        return np.minimum(share, 1.0)

    def of_pairs(self, pair_i, pair_j):
        """(K,) the edge of each pair of grains (pair_i < pair_j), -1 for a pair that is not
        an edge."""
        count, keys, order = self._lookup
        pair_i, pair_j = np.asarray(pair_i, np.int64), np.asarray(pair_j, np.int64)
        known = pair_j < count                  # a grain beyond the edges' is on none
        wanted = np.where(known, pair_i * count + pair_j, -1)
        where = np.minimum(np.searchsorted(keys, wanted), max(len(keys) - 1, 0))
        found = known & (len(keys) > 0) & (keys[where] == wanted)
        return np.where(found, order[where], -1)

    @cached_property
    def _lookup(self):
        """(count, the edges' keys first * count + second sorted, their edges) for of_pairs,
        sorted once per set of edges."""
        count = int(self.pair.max(initial=0)) + 1
        keys = self.pair[:, 0] * count + self.pair[:, 1]
        order = np.argsort(keys)
        return count, keys[order], order


def unit_edges(pore_units):
    """UnitEdges of ``pore_units`` (a periodic pair of grains seen through two images counts
    once: its grains name it)."""
    ends = pore_units.grains[:, EDGES[:, :2]]          # (M, 6, 2)
    ends = np.sort(ends, axis=2)
    count = int(pore_units.grains.max()) + 1
    keys = ends[..., 0] * count + ends[..., 1]
    unique, inverse = np.unique(keys.ravel(), return_inverse=True)
    pair = np.stack([unique // count, unique % count], axis=1)
    return UnitEdges(pair=pair, unit_edge=inverse.reshape(-1, 6),
                     dihedral=dihedral_angles(pore_units.vertices))


@dataclass(frozen=True)
class LiquidAccount:
    """Where the liquid is [m^3]: ``bridges`` (the shares of bridges in empty units and
    outside the units), ``clusters`` (filled units, and a closed liquid's partly filled
    front), ``largest`` (the largest cluster); ``absorbed`` the bridges' shares inside filled
    units (counted in ``clusters``); ``film`` a closed liquid's liquid on the grains
    (pendular.capillary.closed_liquid)."""

    bridges: float
    clusters: float
    largest: float
    absorbed: float
    film: float = 0.0

    @property
    def total(self):
        """The liquid held [m^3]."""
        return self.bridges + self.clusters + self.film

    def fractions(self):
        """{bridges, clusters, largest}: fractions of the liquid held (0 without liquid)."""
        total = self.total
        return {name: (getattr(self, name) / total if total > 0 else 0.0)
                for name in ("bridges", "clusters", "largest")}


def liquid_account(pore_units, edges, clusters, bridge_volume, pair_edge, weight=None,
                   film=0.0):
    """LiquidAccount of the filled units (``clusters``, pendular.capillary.clusters.Clusters)
    and of the bridges of volume ``bridge_volume`` (K,) [m^3] on the edges ``pair_edge`` (K,)
    (UnitEdges.of_pairs, -1: not an edge, the bridge all in empty space); a closed liquid's
    ``weight`` (M,) [-] (its partly filled front's liquid counted with the clusters') and
    ``film`` [m^3]."""
    filled = clusters.label >= 0
    if weight is None:
        share, front = edges.filled_share(filled), 0.0
    else:
        share = edges.share(weight)
        front = float(np.dot(np.where(filled, 0.0, weight), pore_units.pore_volume))
    absorbed_share = np.where(pair_edge >= 0, share[np.maximum(pair_edge, 0)], 0.0)
    absorbed = float(np.sum(bridge_volume * absorbed_share))
    largest = float(clusters.volume[clusters.largest]) if clusters.largest >= 0 else 0.0
    return LiquidAccount(bridges=float(np.sum(bridge_volume)) - absorbed,
                         clusters=float(np.sum(clusters.volume)) + front, largest=largest,
                         absorbed=absorbed, film=float(film))
