"""Coulomb friction between the spheres and the box's walls (docs/physics.md 'Wall friction').

A sphere of radius R touching wall w (overlap delta, unit normal n into the box) carries, on top
of the wall's normal spring, a tangential spring s in the wall's plane, kept per sphere and
wall across steps (``wall_shear`` (N, 6, 3) [N], a checkpoint's state) and zeroed when the
sphere leaves the wall:

- increment: s <- s - kt u_t dt, u_t the tangential velocity of the sphere's contact point
  x - R n relative to the wall (translation, spin R w x n; the wall moves along n only);
- Coulomb: |s| <= tan(phi_w) F_n, a sliding contact's spring held on the cap (the linear
  sphere–sphere law's rule, pendular.dem.contact_law);
- the tangential force acts on the sphere at its contact point, R - delta/2 from the centre as
  a pair's, and adds the moment (-(R - delta/2) n) x s to its torque; its reaction, -s, acts on
  the wall in the wall's plane: the wall's normal force (the servo's and the wall stress's
  ``Walls.force``) is the normal springs' sum as without friction.

The stiffnesses are the scene's contact law's, with the wall's material mixed with the
grains' (pendular.dem.material, docs/physics.md 'Materials and mixing rules'): linear,
kn = E R (a virtual sphere of the same radius and springs) and kt = shear_ratio kn, the
linear law's ratio; Hertz–Mindlin, the wall of pendular.dem.hertz_mindlin.
ViscoelasticWallForces (kt = 8 G* a; a rigid wall by default, G* = G / (2 - nu)). phi_w is
the walls' own friction angle, not a mixture of the grains' and the walls'.

For the linear law this is ``FrictionalWallForces``: the damped law's sphere–wall kernel
(pendular.dem.hertz_mindlin.viscoelastic_wall_forces) with linear springs, and a dashpot
where the wall's restitution is below 1, one law for every sphere–wall contact. With
phi_w = 0 and elastic walls a scene keeps the frictionless pendular.dem.walls.WallForces
(``wall_law``), bit for bit as before.
"""

from pendular.dem.contact_law import MAX_FRICTION_DEG
from pendular.dem.hertz_mindlin import (DampedLinearForces, ViscoelasticWallForces,
    _DampedContactForces)
from pendular.dem.material import rigid_wall
from pendular.dem.walls import WallForces
from pendular.utils.validate import check_range

#: Valid wall friction angles [deg]: [0, 90), a contact's (MAX_FRICTION_DEG).
WALL_FRICTION_RANGE = (0.0, MAX_FRICTION_DEG)


def check_wall_friction(friction_deg):
    """``friction_deg`` [deg] as float; ValueError naming wall_friction outside [0, 90)."""
    return check_range("wall_friction", friction_deg, *WALL_FRICTION_RANGE,
                       high_inclusive=False, unit="deg")


class FrictionalWallForces(ViscoelasticWallForces):
    """Linear sphere–wall springs, kn = E R and kt = ``shear_ratio`` kn, with Coulomb friction
    of ``friction_deg`` [deg] in [0, 90) (module docstring); ``young`` E [Pa] of the grains,
    whose contacts are elastic; walls of ``restitution`` (a contact rebounds at its mean
    with the grains' 1, pendular.dem.material). Each particle's spring on each wall,
    ``wall_shear`` (N, 6, 3) [N], is kept across steps and checkpoints."""

    def __init__(self, young, shear_ratio=0.3, friction_deg=30.0, restitution=1.0):
        super().__init__(DampedLinearForces(young, shear_ratio, 1.0),
                         rigid_wall(restitution, check_wall_friction(friction_deg)))


def wall_law(contact, young, wall=None):
    """The sphere–wall operation that goes with the contact law ``contact`` (a ContactForces
    or a damped law of pendular.dem.hertz_mindlin) on walls of the material ``wall``
    (pendular.dem.material.Material; None: rigid and frictionless, of the grains'
    restitution): the damped law's walls (ViscoelasticWallForces); for the undamped linear law
    of ``young`` [Pa], WallForces(``young``) on rigid, frictionless, elastic walls, else
    FrictionalWallForces."""
    if isinstance(contact, _DampedContactForces):
        return ViscoelasticWallForces(contact, wall)
    if wall is None or (wall.rigid and wall.friction_deg == 0.0 and wall.restitution == 1.0):
        return WallForces(young)
    if not wall.rigid:      # refused there: the linear law's walls take no modulus of their own
        return ViscoelasticWallForces(DampedLinearForces(young, contact.shear_ratio), wall)
    return FrictionalWallForces(young, contact.shear_ratio, wall.friction_deg,
                                wall.restitution)
