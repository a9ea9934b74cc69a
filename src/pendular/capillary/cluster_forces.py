"""Forces of liquid clusters on their grains, their stress, and the DEM operation that applies
them (docs/liquid_clusters.md 'Forces of a cluster').

A liquid body at suction s [Pa] pulls on each grain it wets through the pressure on the wetted
area and the surface tension along its contact line,

    F = s R^2 ∫_wet n dOmega + gamma ∮_C t dl,

n the grain's outward normal, t the unit vector tangent to the liquid-gas interface at the
contact line, normal to the line, pointing into the interface (``cap_force``: for a wetted cap
of half-angle delta, s pi R^2 sin^2 delta + 2 pi gamma R sin delta sin(delta + theta), the exact
Young-Laplace bridge's force, thesis Eq. 3.48).

For a filled pore unit (pendular.capillary.pores) the wetted area of grain k is the part of its
surface in the unit's cone at k. Closing the cone with its three plane sides (circular sectors
of angle alpha_kf, the face f's angle at k, outward normal n_f of the face) gives its area
vector in closed form:

    R_k^2 ∫_cone n dOmega = - sum_{faces f at k} (alpha_kf R_k^2 / 2) n_f.

The meniscus across a throat f through which a cluster meets gas closes the liquid body: its
equilibrium (pressure s on the throat's open area A_f = area(face) - sum alpha_if R_i^2 / 2, the
tension along its contact line) hands the line's total pull -s A_f n_f to the face's three
grains, shared by their arcs alpha_if R_i. This closure takes the line integral from the
meniscus's equilibrium instead of its shape: every cluster's forces then sum to zero to
round-off (Newton's third law), and a grain inside a cluster (its surface all wetted) feels
none. The forces act at the grains' centres (no torque).
"""

import math

import numpy as np

from pendular.capillary.pores import FACES, face_angles


def cap_force(suction, surface_tension, contact_angle, radius, filling_angle):
    """[N] attraction of a wetted cap of half-angle ``filling_angle`` delta [rad] on a sphere of
    ``radius`` R [m] (pressure ``suction`` s [Pa] on the cap, ``surface_tension`` gamma [N/m]
    along its contact line at ``contact_angle`` theta [rad]): s pi R^2 sin^2 delta +
    2 pi gamma R sin delta sin(delta + theta)."""
    sin = np.sin(filling_angle)
    return (suction * math.pi * radius ** 2 * sin ** 2
            + 2.0 * math.pi * surface_tension * radius * sin
            * np.sin(filling_angle + contact_angle))


def face_normals(vertices, sides=None):
    """(M, 4, 3) unit outward normal of the face opposite each vertex, and (M, 4) its side: the
    sign that turns the face's cross product outward. ``sides`` given (those of an earlier
    position of the same units), those signs instead: the normals then move continuously with
    the grains, and stay opposite across a face two units share, even where a flat unit turns
    inside out."""
    normal, sides, _ = _face_normals_areas(vertices, sides)
    return normal, sides


def _face_normals_areas(vertices, sides=None):
    """face_normals's (normal, sides) and (M, 4) [m^2] the area of each face."""
    corners = vertices[:, FACES]                           # (M, 4, 3, 3)
    normal = np.cross(corners[:, :, 1] - corners[:, :, 0], corners[:, :, 2] - corners[:, :, 0])
    length = np.linalg.norm(normal, axis=2, keepdims=True)
    normal /= length
    if sides is None:
        inward = np.sum((vertices - corners[:, :, 0]) * normal, axis=2)
        sides = -np.sign(inward)
    return normal * sides[..., None], sides, 0.5 * length[..., 0]


class UnitForces:
    """Per pore unit, the force coefficients [m^2] of a filled unit at unit suction:
    ``cone`` (M, 4, 3) the pressure on each grain's wetted cone, and ``meniscus`` (M, 4, 3, 3)
    the pull of the meniscus across each face (opposite vertex f) on its three grains
    (``FACES[f]`` order), should that face meet gas. ``vertices`` (M, 4, 3) [m] and ``radii``
    (M, 4) [m] of the units' grains; ``sides``: face_normals's, of an earlier position of the
    same units (None: outward at these vertices), kept as ``sides``."""

    def __init__(self, vertices, radii, sides=None):
        normal, self.sides, area = _face_normals_areas(vertices, sides)  # (M, 4, 3), (M, 4)
        angle = face_angles(vertices)                      # (M, 4, 3)
        face_radii = radii[:, FACES]                       # (M, 4, 3)
        sector = 0.5 * angle * face_radii ** 2             # alpha R^2 / 2
        self.open_area = area - sector.sum(axis=2)         # (M, 4) A_f [m^2]
        self.cone = np.zeros(vertices.shape)
        for f in range(4):
            for j in range(3):
                self.cone[:, FACES[f, j]] -= sector[:, f, j, None] * normal[:, f]
        arc = angle * face_radii
        share = arc / arc.sum(axis=2, keepdims=True)
        self.meniscus = (-(self.open_area[..., None] * share)[..., None]
                         * normal[:, :, None, :])          # (M, 4, 3, 3)

    def moved(self, units, vertices, radii):
        """UnitForces of the same pore units with ``units`` (U,) moved to ``vertices`` (U, 4,
        3) [m] (grain radii ``radii`` (U, 4) [m]), each face keeping its side; the other
        units' coefficients as they were."""
        moved = UnitForces(vertices, radii, self.sides[units])
        result = object.__new__(UnitForces)
        for name in ("sides", "open_area", "cone", "meniscus"):
            coefficients = getattr(self, name).copy()
            coefficients[units] = getattr(moved, name)
            setattr(result, name, coefficients)
        return result


def boundary_faces(pore_units, filled):
    """(M, 4) bool: the faces of filled units that meet gas (an empty unit or the hull)."""
    across = pore_units.neighbours
    return filled[:, None] & ((across < 0) | ~filled[np.maximum(across, 0)])


def cluster_forces(pore_units, unit_forces, filled, suction, grain_count):
    """(grain_count, 3) [N] the forces of the filled units ``filled`` (M,) bool at
    ``suction`` [Pa] on the grains (module docstring)."""
    force = np.zeros((grain_count, 3))
    units = np.flatnonzero(filled)
    grains = pore_units.grains
    for axis in range(3):
        force[:, axis] = np.bincount(grains[units].ravel(),
                                     unit_forces.cone[units, :, axis].ravel(),
                                     minlength=grain_count)
    unit, face = np.nonzero(boundary_faces(pore_units, filled))
    on = grains[unit[:, None], FACES[face]]                # (B, 3)
    pull = unit_forces.meniscus[unit, face]                # (B, 3, 3)
    for axis in range(3):
        force[:, axis] += np.bincount(on.ravel(), pull[..., axis].ravel(),
                                      minlength=grain_count)
    return suction * force


def equilibrated_sets(unit_forces, units):
    """(U, 4, 3) [m^2] the forces at unit suction of each of ``units`` filled alone on its
    four grains: its cone pressures and the menisci of all its four faces, a set that sums
    to zero. A unit's share in a cluster's forces is its set: the menisci of a face shared
    by two filled units cancel."""
    force = unit_forces.cone[units].copy()                 # (U, 4, 3)
    for f in range(4):
        for j in range(3):
            force[:, FACES[f, j]] += unit_forces.meniscus[units, f, j]
    return force


def partial_forces(pore_units, unit_forces, units, fraction, suction, grain_count):
    """(grain_count, 3) [N] the forces at ``suction`` [Pa] of ``units`` partly filled, each
    holding ``fraction`` [-] of its pore volume (the closed liquid's front,
    pendular.capillary.closed_liquid): that fraction of its equilibrated set (equilibrated_sets),
    added to the clusters' forces of the filled units around it."""
    force = np.zeros((grain_count, 3))
    units = np.asarray(units, np.int64)
    sets = equilibrated_sets(unit_forces, units)
    for axis in range(3):
        force[:, axis] = np.bincount(pore_units.grains[units].ravel(), sets[..., axis].ravel(),
                                     minlength=grain_count)
    return fraction * suction * force


def cluster_stress(pore_units, unit_forces, filled, suction, volume, weight=None,
                   vertices=None):
    """(3, 3) [Pa] the stress of the clusters' forces, compression positive, over ``volume``
    [m^3]: -(1/V) sum x (x) F, taken unit by unit over each filled unit's self-equilibrated
    set (equilibrated_sets; the menisci of faces shared by two filled units cancel in the
    grains' forces), at the positions the unit sees (a periodic image's, unwrapped); with
    ``weight`` (M,) [-], each unit's set in that share (a partly filled unit), ``filled`` then
    the units with a share; ``vertices`` (M, 4, 3) [m]: the grains' positions where the
    forces act (those ``unit_forces`` were computed at; None: the decomposition's). It is the
    clusters' share of the complete capillary stress psi + I (docs/capillary.md), as -(1/V)
    sum x (x) F of the bridges' forces is theirs."""
    units = np.flatnonzero(filled)
    force = equilibrated_sets(unit_forces, units)
    if weight is not None:
        force *= np.asarray(weight, float)[units, None, None]
    at = (pore_units.vertices if vertices is None else vertices)[units]
    centred = at - at.mean(axis=1, keepdims=True)
    return -suction / volume * np.einsum("uki,ukj->ij", centred, force)
