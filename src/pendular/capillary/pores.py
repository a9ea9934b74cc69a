"""Pore units of a sphere packing: the Delaunay tetrahedra of the centres and their throats.

The pore space is cut into tetrahedral pore units, the cells of the Delaunay triangulation of
the grains' centres (Melnikov et al. 2015, docs/liquid_clusters.md 'Pore units'). A unit has
four grains; the face opposite grain k is a throat, shared with the neighbouring unit across
it. Per unit, in SI units (positions and radii in m):

- ``volume`` [m^3]: the tetrahedron;
- ``solid_angle`` [sr]: the solid angle of the tetrahedron at each of its four grains
  (Van Oosterom & Strackee 1983);
- ``pore_volume`` [m^3]: the tetrahedron less the solid inside it. Each of its four grains
  fills its sector Omega_k R_k^3 / 3 less the part of it beyond the opposite face, where the
  grain crosses that face (flat tetrahedra, ``protrudes``); every other grain whose ball
  reaches into the unit fills its exact intersection with the tetrahedron
  (``ball_tetrahedron_volume``). Where two of the unit's grains overlap, the share phi/(2 pi)
  of their lens (phi the dihedral angle at their edge) is added back, since both sectors count
  it. Neglected: the part of such a lens outside the unit, overlaps with an intruding grain,
  and triple overlaps, all of the order of the square of the overlaps of DEM contacts. The pore
  volumes then sum to the volume covered less the solid in it;
- ``grain_area`` [m^2]: the area Omega_k R_k^2 of each grain's surface in its cone (the
  wetted area of a filled unit; lenses and the surface beyond the opposite face neglected);
- ``throat_radius`` [m] (across the face opposite each grain): the radius of the circle in the
  face's plane tangent to the three grains' great circles (Apollonius' problem; the throat's
  inscribed circle), negative where the three grains close the throat.

A throat's radius and entry suction, the suction at which gas passes it, are
pendular.capillary.throats's.

The decomposition covers the convex hull of the centres; with walls, the strip between that
hull and the walls belongs to no unit yet. In a periodic cell [0, L)^3 it covers the cell
exactly, through the images of the grains (``period``). A sheared cell (Lees–Edwards,
pendular.dem.cell) has ``period`` (Lx, Ly, Lz, delta): the image (ix, iy, iz) of a grain is
shifted by (ix Lx + iz delta, iy Ly, iz Lz) (``lattice_vectors``). The box [0, L)^3 still tiles
space with those images, so the triangulation of the grains' images is cut as the plain cell's:
each unit once, the one whose centroid lies in the box.
"""

from dataclasses import dataclass

import numpy as np
from scipy.spatial import Delaunay, cKDTree

from pendular.capillary.throats import throat_radius
from pendular.utils.validate import check_array, check_range

#: The six edges of a tetrahedron as vertex pairs (a, b), and the other two vertices (c, d).
EDGES = np.array([[0, 1, 2, 3], [0, 2, 1, 3], [0, 3, 1, 2],
                  [1, 2, 0, 3], [1, 3, 0, 2], [2, 3, 0, 1]])
#: Size of the tie-breaking perturbation of a periodic triangulation, per mean grain spacing.
PERTURBATION = 1e-9
#: Gauss–Legendre nodes and weights on [-1, 1] of each panel of ``beyond_face_volume``.
_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(16)
#: The face opposite vertex k, as its three vertices.
FACES = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])


def lattice_vectors(shift, period):
    """(..., 3) [m] the translations of the periodic images ``shift`` (..., 3) int of a cell of
    ``period`` (3,) [m], or a sheared cell's (4,) (Lx, Ly, Lz, delta): (ix Lx + iz delta, iy Ly,
    iz Lz) (pendular.dem.cell)."""
    vector = np.asarray(shift) * np.asarray(period)[:3]
    if len(period) > 3:
        vector[..., 0] += np.asarray(shift)[..., 2] * period[3]
    return vector


def image_shifts(vector, period, rounding=np.rint):
    """(..., 3) int64 the image shifts whose translation (``lattice_vectors``) is nearest to
    ``vector`` (..., 3) [m] (z, then y and x; exact for a lattice vector, or one off it by less
    than half the cell); ``rounding`` np.floor: those of the copy of the box [0, L)^3 that holds
    the point ``vector``."""
    period = np.asarray(period)
    vector = np.asarray(vector, dtype=float)
    shift = np.empty(vector.shape, np.int64)
    shift[..., 2] = rounding(vector[..., 2] / period[2])
    shift[..., 1] = rounding(vector[..., 1] / period[1])
    along = vector[..., 0] - (shift[..., 2] * period[3] if len(period) > 3 else 0.0)
    shift[..., 0] = rounding(along / period[0])
    return shift


def into_cell(position, period):
    """(N, 3) [m] copies of ``position`` (N, 3) [m] brought into the periodic cell [0, L)^3 of
    ``period`` (lattice_vectors; a sheared cell's images above in z are shifted by delta)."""
    lengths = np.asarray(period)[:3]
    wrapped = position - lattice_vectors(image_shifts(position, period, np.floor), period)
    return np.clip(wrapped, 0.0, np.nextafter(lengths, 0.0))


def nearest_images(position, reference, period):
    """(..., 3) [m] the periodic images of ``position`` (..., 3) [m] nearest to ``reference``
    (..., 3) [m] (each less than half the cell away from one); ``position`` itself without a
    ``period`` (None)."""
    if period is None:
        return position
    offset = position - reference
    return position - lattice_vectors(image_shifts(offset, period), period)


@dataclass(frozen=True)
class PoreUnits:
    """The pore units of a packing (SI units). M units, T throats.

    grains: (M, 4) indices of the grains at the unit's vertices.
    vertices: (M, 4, 3) [m] their centres as the unit sees them (a periodic image's, unwrapped).
    neighbours: (M, 4) the unit across the face opposite each vertex, -1 on the hull.
    volume: (M,) [m^3] the tetrahedron. pore_volume: (M,) [m^3] its void (module docstring).
    solid_angle: (M, 4) [sr]. grain_area: (M, 4) [m^2].
    protrudes: (M,) bool, a grain crosses the face opposite it (a flat unit).
    throat_radius: (M, 4) [m] of the face opposite each vertex.
    throat_units: (T, 2) the two units of each throat (the second -1 on the hull), first < second.
    throat_of: (M, 4) the throat across the face opposite each vertex.
    throat_shift: (T, 3) int, the image shifts (lattice_vectors) between the throat's face as
    the second unit sees it and as the first does (zero without a period; zero on the hull).
    period: (3,) [m] the periodic cell's lengths, (4,) a sheared cell's (Lx, Ly, Lz, delta), or
    None (walls: the hull of the centres).
    """

    grains: np.ndarray
    vertices: np.ndarray
    neighbours: np.ndarray
    volume: np.ndarray
    pore_volume: np.ndarray
    solid_angle: np.ndarray
    grain_area: np.ndarray
    protrudes: np.ndarray
    throat_radius: np.ndarray
    throat_units: np.ndarray
    throat_of: np.ndarray
    throat_shift: np.ndarray
    period: np.ndarray | None

    @property
    def count(self):
        """Number of pore units."""
        return len(self.grains)

    def grain_solid_angle(self, grain_count):
        """(grain_count,) [sr] the solid angle the units cover around each grain: 4 pi inside."""
        return np.bincount(self.grains.ravel(), self.solid_angle.ravel(), minlength=grain_count)


def throat_sides(pore_units):
    """(unit, face) (T,) each: the first unit of each throat and the face (``FACES``) across
    which it sees it (each throat once)."""
    _, side = np.unique(pore_units.throat_of.ravel(), return_index=True)
    return np.divmod(side, 4)


def tetrahedron_volume(vertices):
    """(M,) [m^3] volumes of tetrahedra with ``vertices`` (M, 4, 3) [m]."""
    a = vertices[:, 1] - vertices[:, 0]
    b = vertices[:, 2] - vertices[:, 0]
    c = vertices[:, 3] - vertices[:, 0]
    return np.abs(np.einsum("ij,ij->i", a, np.cross(b, c))) / 6.0


def triangle_solid_angle(point, triangle):
    """(P,) [sr] the solid angle of ``triangle`` (P, 3, 3) [m] seen from ``point`` (P, 3) [m]
    (Van Oosterom & Strackee 1983: tan(Omega/2) = |a . b x c| / (abc + (a.b)c + (a.c)b +
    (b.c)a), a, b, c the vectors from the point to the corners); 0 from a corner."""
    a, b, c = (triangle[:, i] - point for i in range(3))
    la, lb, lc = (np.linalg.norm(v, axis=1) for v in (a, b, c))
    triple = np.abs(np.einsum("ij,ij->i", a, np.cross(b, c)))
    denominator = (la * lb * lc + np.einsum("ij,ij->i", a, b) * lc
                   + np.einsum("ij,ij->i", a, c) * lb + np.einsum("ij,ij->i", b, c) * la)
    return 2.0 * np.arctan2(triple, denominator)


def solid_angles(vertices):
    """(M, 4) [sr] the solid angle of each tetrahedron at each vertex."""
    return np.stack([triangle_solid_angle(vertices[:, k], vertices[:, FACES[k]])
                     for k in range(4)], axis=1)


def dihedral_angles(vertices):
    """(M, 6) [rad] the dihedral angle of each tetrahedron at each edge of ``EDGES``."""
    a, b, c, d = (vertices[:, EDGES[:, k]] for k in range(4))
    axis = b - a
    axis /= np.linalg.norm(axis, axis=2, keepdims=True)
    pc = c - a
    pd = d - a
    pc -= np.sum(pc * axis, axis=2, keepdims=True) * axis
    pd -= np.sum(pd * axis, axis=2, keepdims=True) * axis
    return np.arctan2(np.linalg.norm(np.cross(pc, pd), axis=2), np.sum(pc * pd, axis=2))


def face_angles(vertices):
    """(M, 4, 3) [rad] the angle of the face opposite each vertex at each of its three
    vertices (``FACES`` order)."""
    corners = vertices[:, FACES]                          # (M, 4, 3, 3)
    angles = np.empty(corners.shape[:3])
    for k in range(3):
        u = corners[:, :, (k + 1) % 3] - corners[:, :, k]
        v = corners[:, :, (k + 2) % 3] - corners[:, :, k]
        angles[..., k] = np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1),
                                    np.sum(u * v, axis=-1))
    return angles


def lens_volume(distance, radius1, radius2):
    """[m^3] volume of the intersection of two balls of radii ``radius1``, ``radius2`` [m] with
    centres ``distance`` [m] apart (0 apart from overlaps; the smaller ball if one holds the
    other)."""
    d = np.asarray(distance, dtype=float)
    r1 = np.asarray(radius1, dtype=float)
    r2 = np.asarray(radius2, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        lens = (np.pi * (r1 + r2 - d) ** 2
                * (d * d + 2 * d * (r1 + r2) - 3 * (r1 - r2) ** 2) / (12 * d))
    inside = d <= np.abs(r1 - r2)
    smaller = 4.0 / 3.0 * np.pi * np.minimum(r1, r2) ** 3
    return np.where(d >= r1 + r2, 0.0, np.where(inside, smaller, lens))


def beyond_face_volume(apex, radius, triangle):
    """(P,) [m^3] volume of the ball of ``radius`` (P,) [m] about ``apex`` (P, 3) [m] that lies
    beyond the plane of ``triangle`` (P, 3, 3) [m] inside the cone from the apex through the
    triangle: what a sector over-counts where a grain crosses the face opposite it.

    In polar coordinates about the apex, with h its height above the plane and rho the distance
    to a point of the plane, the volume is (h/3) times the integral over the triangle of
    (R^3/rho^3 - 1) where rho < R. The integrand is radial about the foot F of the apex, so the
    triangle splits into the signed triangles (F, P_i, P_j) of its edges; over each, at angle
    phi from the perpendicular to the edge (at distance d from F), the radial integral is
    G(min(a, d / cos phi)) - G(0), G(r) = -R^3/sqrt(h^2 + r^2) - r^2/2, a = sqrt(R^2 - h^2),
    integrated in phi by Gauss–Legendre on the panels between its kinks at +-arccos(d/a)."""
    p0, p1, p2 = triangle[:, 0], triangle[:, 1], triangle[:, 2]
    normal = np.cross(p1 - p0, p2 - p0)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    offset = np.sum((apex - p0) * normal, axis=1)
    h = np.abs(offset)
    foot = apex - offset[:, None] * normal
    a = np.sqrt(np.maximum(radius ** 2 - h ** 2, 0.0))
    r3 = radius ** 3
    total = np.zeros(len(apex))
    for i, j in ((0, 1), (1, 2), (2, 0)):
        pi, pj = triangle[:, i], triangle[:, j]
        along = (pj - pi) / np.linalg.norm(pj - pi, axis=1, keepdims=True)
        t_i = np.sum((pi - foot) * along, axis=1)
        t_j = np.sum((pj - foot) * along, axis=1)
        perpendicular = (pi - foot) - t_i[:, None] * along
        d = np.linalg.norm(perpendicular, axis=1)
        sign = np.sign(np.sum(np.cross(pi - foot, pj - foot) * normal, axis=1))
        phi_i, phi_j = np.arctan2(t_i, d), np.arctan2(t_j, d)
        kink = np.arccos(np.minimum(d / np.where(a > 0, a, 1.0), 1.0))
        lo, hi = np.clip(-kink, phi_i, phi_j), np.clip(kink, phi_i, phi_j)
        # outside the kinks the edge is beyond the disk of radius a: the integrand is constant
        outside = (lo - phi_i) + (phi_j - hi)
        full = -r3 / radius - 0.5 * a ** 2 + r3 / np.maximum(h, 1e-300)
        phi = 0.5 * (hi - lo)[:, None] * (_GAUSS_NODES + 1.0) + lo[:, None]
        cos = np.cos(phi)
        reach = np.minimum(a[:, None], d[:, None] / np.maximum(cos, 1e-300))
        g = (-r3[:, None] / np.sqrt(h[:, None] ** 2 + reach ** 2) - 0.5 * reach ** 2
             + r3[:, None] / np.maximum(h[:, None], 1e-300))
        total += sign * (outside * full + 0.5 * (hi - lo) * (g @ _GAUSS_WEIGHTS))
    return np.where(a > 0, h / 3.0 * total, 0.0)


def ball_tetrahedron_volume(centre, radius, vertices):
    """(P,) [m^3] volume of the intersection of the balls ``centre`` (P, 3), ``radius`` (P,)
    [m] with the tetrahedra ``vertices`` (P, 4, 3) [m], anywhere.

    The tetrahedron is the signed sum of the pyramids from the ball's centre over its four
    faces (+ where the centre is on the tetrahedron's side of the face, - otherwise); the ball
    meets a pyramid in its sector Omega R^3 / 3 (Omega the face's solid angle from the centre)
    less what lies beyond the face (``beyond_face_volume``)."""
    total = np.zeros(len(centre))
    for k in range(4):
        face = vertices[:, FACES[k]]
        normal = np.cross(face[:, 1] - face[:, 0], face[:, 2] - face[:, 0])
        side = np.sign(np.sum((centre - face[:, 0]) * normal, axis=1)) \
            * np.sign(np.sum((vertices[:, k] - face[:, 0]) * normal, axis=1))
        total += side * triangle_solid_angle(centre, face) * radius ** 3 / 3
        height = np.abs(np.sum((centre - face[:, 0]) * normal, axis=1)) \
            / np.linalg.norm(normal, axis=1)
        crossing = (side != 0) & (height < radius)
        total[crossing] -= side[crossing] * beyond_face_volume(centre[crossing],
                                                               radius[crossing], face[crossing])
    return total


def _intruding_volume(vertices, grains, position, radius, period):
    """(M,) [m^3] the volume of the balls of other grains than a unit's four inside it (in a
    periodic cell, of their images near the unit). Candidates: the grains within their radius
    of the unit's bounding sphere (about its centroid) and of each face's plane on its side."""
    centroid = vertices.mean(axis=1)
    reach = np.linalg.norm(vertices - centroid[:, None], axis=2).max(axis=1)
    if period is None:
        points, grain_of, cell = position, np.arange(len(position)), None
    else:
        points, grain_of, _ = _images_near_cell(position, period,
                                                reach.max() + radius.max())
        cell = lattice_vectors(image_shifts(centroid, period, np.floor), period)
    grains_tree = cKDTree(points)
    # the few flat units with a long reach are searched apart, so that the bulk's search stays short
    long_reach = reach > 2.0 * np.median(reach)
    found = []
    for group in (np.flatnonzero(~long_reach), np.flatnonzero(long_reach)):
        if len(group) == 0:
            continue
        at = centroid[group] if period is None else centroid[group] - cell[group]
        pairs = cKDTree(at).sparse_distance_matrix(grains_tree, reach[group].max()
                                                   + radius.max(), output_type="ndarray")
        unit, point = group[pairs["i"]], pairs["j"].astype(np.int64)
        near = pairs["v"] < reach[unit] + radius[grain_of[point]]
        found.append((unit[near], point[near]))
    unit = np.concatenate([f[0] for f in found])
    point = np.concatenate([f[1] for f in found])
    grain = grain_of[point]
    other = np.all(grains[unit] != grain[:, None], axis=1)
    unit, grain, centre = unit[other], grain[other], points[point[other]]
    if period is not None:
        centre = centre + cell[unit]
    for k in range(4):
        face = vertices[unit[:, None], FACES[k]]
        normal = np.cross(face[:, 1] - face[:, 0], face[:, 2] - face[:, 0])
        normal /= np.linalg.norm(normal, axis=1, keepdims=True)
        normal *= np.sign(np.sum((vertices[unit, k] - face[:, 0]) * normal, axis=1))[:, None]
        keep = np.sum((centre - face[:, 0]) * normal, axis=1) > -radius[grain]
        unit, grain, centre = unit[keep], grain[keep], centre[keep]
    inside = ball_tetrahedron_volume(centre, radius[grain], vertices[unit])
    return np.bincount(unit, inside, minlength=len(vertices))


def _images_near_cell(position, period, margin):
    """(points (P, 3) [m], grain_of (P,), shift_of (P, 3) int): the grains at ``position`` (in
    the cell [0, L)^3) and their images (lattice_vectors) within ``margin`` [m] of the cell,
    image by image (shifts in lexicographic order)."""
    lengths = np.asarray(period)[:3]
    reach = np.ceil(margin / lengths).astype(np.int64)
    if len(period) > 3:     # an image above in z is shifted by delta along x
        reach[0] = np.ceil((margin + reach[2] * abs(period[3])) / lengths[0])
    shifts = np.stack(np.meshgrid(*[np.arange(-n, n + 1) for n in reach], indexing="ij"),
                      axis=-1).reshape(-1, 3)
    images = position[None, :, :] + lattice_vectors(shifts, period)[:, None, :]
    keep = np.all((images >= -margin) & (images < lengths + margin), axis=2)
    shift_of, grain_of = np.nonzero(keep)
    return images[shift_of, grain_of], grain_of, shifts[shift_of]


def _heights(vertices):
    """(M, 4) [m] height of each vertex above the plane of the face opposite it."""
    volume = tetrahedron_volume(vertices)
    face_area = np.empty((len(vertices), 4))
    for k in range(4):
        f = vertices[:, FACES[k]]
        face_area[:, k] = 0.5 * np.linalg.norm(np.cross(f[:, 1] - f[:, 0], f[:, 2] - f[:, 0]),
                                               axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(face_area > 0, 3.0 * volume[:, None] / face_area, np.inf)


def _unit_geometry(vertices, radius):
    """Per-unit geometry of tetrahedra ``vertices`` (M, 4, 3) with grain radii ``radius`` (M, 4)."""
    volume = tetrahedron_volume(vertices)
    omega = solid_angles(vertices)
    dihedral = dihedral_angles(vertices)
    edge_length = np.linalg.norm(vertices[:, EDGES[:, 1]] - vertices[:, EDGES[:, 0]], axis=2)
    lens = lens_volume(edge_length, radius[:, EDGES[:, 0]], radius[:, EDGES[:, 1]])
    pore = (volume - np.sum(omega * radius ** 3, axis=1) / 3.0
            + np.sum(lens * dihedral, axis=1) / (2.0 * np.pi))
    # a grain crossing the face opposite it: its sector reaches past the unit
    unit, k = np.nonzero(_heights(vertices) < radius)
    beyond = beyond_face_volume(vertices[unit, k], radius[unit, k],
                                vertices[unit[:, None], FACES[k]])
    pore += np.bincount(unit, beyond, minlength=len(vertices))
    throat = throat_radius(vertices[:, FACES], radius[:, FACES])
    protrudes = np.zeros(len(vertices), bool)
    protrudes[unit] = True
    return volume, omega, pore, omega * radius ** 2, protrudes, throat


def _throats(neighbours):
    """(T, 2) throat_units and (M, 4) throat_of from the units' ``neighbours``."""
    unit = np.repeat(np.arange(len(neighbours)), 4)
    other = neighbours.ravel()
    first = (other < 0) | (unit < other)
    throat_units = np.stack([unit[first], other[first]], axis=1)
    number = np.full(len(unit), -1)
    number[first] = np.arange(first.sum())
    # the second side of an interior throat: the face of the neighbour that points back
    second = np.flatnonzero(~first)
    back = np.argmax(neighbours[other[second]] == unit[second, None], axis=1)
    number[second] = number[other[second] * 4 + back]
    return throat_units, number.reshape(-1, 4)


def _throat_shift(vertices, throat_units, throat_of, period):
    """(T, 3) int image shifts from the first unit's copy of each throat's face to the
    second's."""
    shift = np.zeros((len(throat_units), 3), np.int64)
    if period is None:
        return shift
    face_centre = vertices[:, FACES].mean(axis=2)  # (M, 4, 3)
    unit, face = np.divmod(np.arange(throat_of.size), 4)
    throat = throat_of.ravel()
    second = throat_units[throat, 1] == unit
    first_centre = np.empty((len(throat_units), 3))
    first_centre[throat[~second]] = face_centre[unit[~second], face[~second]]
    shift[throat[second]] = image_shifts(face_centre[unit[second], face[second]]
                                         - first_centre[throat[second]], period)
    return shift


def decompose(position, radius, period=None):
    """Pore units of spheres at ``position`` (N, 3) [m] with ``radius`` (N,) [m].

    Without ``period`` the units fill the convex hull of the centres (a sample between walls).
    With ``period`` (3,) [m] the positions lie in the periodic cell [0, L)^3 and the units fill
    it exactly: each unit once, its vertices the images nearest its centroid in the cell; a
    sheared cell's ``period`` (4,) adds its offset delta [m] (module docstring; |delta| <= Lx,
    as the cell keeps it, pendular.dem.cell)."""
    position = check_array("position", position, (3,))
    radius = check_array("radius", radius, positive=True, length=len(position))
    if len(position) < 4:
        raise ValueError(f"position has {len(position)} spheres; valid: at least 4")
    if period is None:
        triangulation = _delaunay(position)
        grains = triangulation.simplices.astype(np.int64)
        vertices = position[grains]
        neighbours = triangulation.neighbors.astype(np.int64)
        period_array = None
    else:
        period_array = _check_period(period)
        outside = (position < 0) | (position >= period_array[:3])
        if outside.any():
            i, axis = (int(x) for x in np.argwhere(outside)[0])
            raise ValueError(f"position[{i}, {axis}] = {position[i, axis]:g} m is outside the "
                             f"periodic cell's valid range [0, {period_array[axis]:g}) m; wrap "
                             "the positions into the cell first")
        grains, vertices, neighbours = _periodic_units(position, radius, period_array)
    volume, omega, pore, area, protrudes, throat = _unit_geometry(vertices, radius[grains])
    pore -= _intruding_volume(vertices, grains, position, radius, period_array)
    throat_units, throat_of = _throats(neighbours)
    shift = _throat_shift(vertices, throat_units, throat_of, period_array)
    return PoreUnits(grains=grains, vertices=vertices, neighbours=neighbours, volume=volume,
                     pore_volume=pore, solid_angle=omega, grain_area=area, protrudes=protrudes,
                     throat_radius=throat, throat_units=throat_units, throat_of=throat_of,
                     throat_shift=shift, period=period_array)


def _check_period(period):
    """``period`` as a float array: (3,) positive lengths [m], or a sheared cell's (4,) whose
    offset is at most Lx in size."""
    period = np.asarray(period, dtype=float)
    if period.shape not in ((3,), (4,)):
        raise ValueError(f"period has shape {period.shape}; expected (3,), the cell's lengths "
                         "[m], or (4,), a sheared cell's lengths and offset")
    check_array("period", period[:3], positive=True, length=3)
    if len(period) > 3:
        check_range("period[3] (the shear offset)", period[3], -period[0], period[0], unit="m")
    return period


def _delaunay(points):
    """scipy's Delaunay of ``points``, refusing points it leaves out (duplicates)."""
    triangulation = Delaunay(points)
    if len(triangulation.coplanar):
        index = int(triangulation.coplanar[0, 0])
        raise ValueError(f"position[{index}] coincides with another sphere's centre; the pore "
                         "decomposition needs distinct centres")
    return triangulation


def _periodic_units(position, radius, period):
    """(grains, vertices, neighbours) of the periodic cell's units, from the Delaunay
    triangulation of the grains and of their images within a margin of the cell. A unit of
    that triangulation is one of the cell's if its circumsphere lies inside the margin (nothing
    outside it can then be in the circumsphere); the margin doubles until every unit whose
    centroid is in the cell, and its four neighbours, are such units."""
    count = len(position)
    lengths = period[:3]
    spacing = (np.prod(lengths) / count) ** (1.0 / 3.0)
    margin = 2.0 * spacing + 2.0 * radius.max()
    # A fixed perturbation, the same for a grain and its images, settles ties between
    # cospherical points (a lattice) the same way in every period; the geometry is the grains'.
    tie_break = PERTURBATION * spacing * np.random.default_rng(0).uniform(-1, 1, (count, 3))
    while True:
        margin = min(margin, lengths.min())
        points, grain_of, shift_of = _images_near_cell(position, period, margin)
        triangulation = _delaunay(points + tie_break[grain_of])
        simplices = triangulation.simplices
        corners = points[simplices]
        centroid = (points + tie_break[grain_of])[simplices].mean(axis=1)
        cell = image_shifts(centroid, period, np.floor)
        inside = np.flatnonzero(np.all(cell == 0, axis=1))
        neighbours_ext = triangulation.neighbors[inside]
        needed = np.concatenate([inside, neighbours_ext[neighbours_ext >= 0]])
        centre, circumradius = _circumspheres(corners[needed])
        fits = np.all((centre - circumradius[:, None] >= -margin)
                      & (centre + circumradius[:, None] <= lengths + margin), axis=1)
        if (neighbours_ext >= 0).all() and fits.all():
            break
        if margin >= lengths.min():
            raise ValueError(f"the periodic cell {period.tolist()} m is too small for its "
                             f"{count} spheres to be decomposed into pore units")
        margin *= 2.0
    # each point as (grain, image) coded in one integer; a unit as its four sorted codes
    translated = shift_of[simplices[neighbours_ext]] - cell[neighbours_ext][:, :, None, :]
    base = 2 * int(max(np.abs(shift_of).max(), np.abs(translated).max())) + 1
    code = grain_of[simplices] * base ** 3 + _image_code(shift_of[simplices], base)
    key = np.sort(code[inside], axis=1)
    translated = (grain_of[simplices[neighbours_ext]] * base ** 3
                  + _image_code(translated, base))
    wanted = np.sort(translated.reshape(-1, 4), axis=1)
    order = np.lexsort(key.T[::-1])
    sorted_keys = key[order]
    position_of = search_rows(sorted_keys, wanted)
    if (position_of < 0).any():
        raise ValueError("the periodic pore decomposition is inconsistent (degenerate packing)")
    neighbours = order[position_of].reshape(-1, 4)
    grains = grain_of[simplices[inside]].astype(np.int64)
    return grains, corners[inside], neighbours


def _image_code(shift, base):
    """Integer code of image shifts in {-(base - 1) / 2, ..., (base - 1) / 2}^3."""
    half = base // 2
    return ((shift[..., 0] + half) * base + (shift[..., 1] + half)) * base + (shift[..., 2] + half)


def search_rows(sorted_rows, rows):
    """Index in ``sorted_rows`` (lexicographically sorted, unique) of each of ``rows``; -1 if
    absent."""
    dtype = np.dtype([(f"f{i}", sorted_rows.dtype) for i in range(sorted_rows.shape[1])])
    table = np.ascontiguousarray(sorted_rows).view(dtype).ravel()
    query = np.ascontiguousarray(rows).view(dtype).ravel()
    index = np.searchsorted(table, query)
    index = np.minimum(index, len(table) - 1)
    return np.where(table[index] == query, index, -1)


def _circumspheres(corners):
    """(centre (M, 3), radius (M,)) of the spheres through tetrahedra ``corners`` (M, 4, 3); a
    flat tetrahedron (cospherical points of a lattice) gets the smallest sphere through its
    corners, its neighbours' circumsphere being the one that bounds it."""
    edges = corners[:, 1:] - corners[:, :1]
    rhs = 0.5 * np.sum(edges * edges, axis=2)
    scale = np.sum(edges * edges, axis=(1, 2)) ** 1.5
    flat = np.abs(np.linalg.det(edges)) <= 1e-10 * scale
    centre = np.empty((len(corners), 3))
    centre[~flat] = np.linalg.solve(edges[~flat], rhs[~flat][..., None])[..., 0]
    centre[flat] = (np.linalg.pinv(edges[flat]) @ rhs[flat][..., None])[..., 0]
    return corners[:, 0] + centre, np.linalg.norm(centre, axis=1)
