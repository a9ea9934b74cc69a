"""Hertz–Mindlin contacts, and viscous damping set from a coefficient of restitution
(docs/physics.md 'Hertz–Mindlin contacts').

Sphere–sphere, overlap delta, effective radius 1/R* = 1/R1 + 1/R2, contact radius
a = sqrt(R* delta), effective mass 1/m* = 1/m1 + 1/m2:

- normal: Hertz, F = (4/3) E* sqrt(R*) delta^(3/2) = (2/3) kn delta, kn = dF/d(delta) = 2 E* a,
  1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (Johnson 1985, Eq. 4.22-4.23);
- tangential: Mindlin's no-slip stiffness kt = 8 G* a, 1/G* = (2 - nu1)/G1 + (2 - nu2)/G2,
  G = E / (2 (1 + nu)) (Mindlin 1949), an incremental spring turned with the contact as the
  linear law's (pendular.dem.contact_law._turned_contact), capped by Coulomb; the
  microslip of Mindlin & Deresiewicz (1953) inside the contact is left out, as in YADE's
  Law2_ScGeom_MindlinPhys_Mindlin and LIGGGHTS's ``tangential history``;
- damping: viscous, 2 gamma sqrt(m* kn) times the normal relative velocity and
  2 gamma sqrt((2/7) m* kt) times the tangential one ((2/7) m*: the mass with which the
  spheres' translations and rotations move the contact point tangentially; with m* the
  dashpots of a dense packing's many contacts on one grain's rotation are too stiff for the
  step), gamma from the coefficient of restitution (pendular.dem.restitution), no
  tension: the normal force, damping included, is at least 0; the Coulomb cap holds the
  spring and the dashpot together, and a sliding contact keeps its force on the cap as its
  spring.

The same damping on the linear law (``DampedLinearForces``: kn of
pendular.dem.contact_law.normal_stiffness, ks = shear_ratio kn) gives a linear contact a
restitution; the linear law without damping stays pendular.dem.contact_law.ContactForces.

Sphere–wall (``ViscoelasticWallForces``): the wall is a body of its own material
(pendular.dem.material: E* and G* of the grain and the wall, the mean of their restitutions,
the wall's friction), rigid by default, the limit of an infinitely stiff wall,
E* = E / (1 - nu^2), G* = G / (2 - nu); R* = R and m* = m (a wall does not move under its
contacts; the linear law's wall: a virtual sphere of the same radius and springs, kn = E R);
its tangential spring lies in the wall's fixed plane, capped at Fn tan(wall friction):
frictionless walls by default.

The per-pair arrays are the contacts' (shear_force: the spring, normal, overlap,
normal_force: the elastic spring's force, without the dashpot, as pendular.dem.neighbors.Contacts
declares it, force: on j from i, damping included), and the forces reach the particles through
the linear law's gather (ContactForces.gather). Readers of normal_force / overlap (the rolling
resistance's k_n, pendular.dem.rolling; a periodic cell's servo stiffness) thus get the
spring's secant stiffness, 2/3 of Hertz's tangent kn or the linear kn, at any damping, not a
stiffness that swings with the normal velocity (above kn while the contact closes, 0 where
the dashpot cancels the spring).

On one thread the pairs are evaluated row by row and, unless a later force joins the gather,
their forces scattered to the particles as they are evaluated: the linear law's one-thread
scheme (pendular.dem.contact_law), the same sums in the same order as the gather's.
"""

import math

import numba
import numpy as np

from pendular.dem import HOT_KERNEL_FASTMATH
from pendular.dem.contact_law import (MAX_SHEAR_RATIO, ContactForces, _contact_gap,
    _first_member, _prefetch_second, _row_sums, _scatter_to_both, _store_row_sums, _stretched,
    _turned_contact, normal_stiffness, wall_contact_stiffness, wall_gap)
from pendular.dem.material import (check_poisson, check_restitution, effective_modulus,
    effective_shear_modulus, rigid_wall, wall_contact)
from pendular.dem.prefetch import prefetch_distance
from pendular.dem.protocols import state_array
from pendular.dem.restitution import damping_ratio
from pendular.utils.validate import check_positive, check_range

#: The effective mass of a contact point's tangential motion over m*: a sphere's translation
#: and rotation (I = 2/5 m R^2) together move it as a mass of 2/7 of its own.
TANGENTIAL_MASS = 2.0 / 7.0
#: The contact laws a scene may use: linear springs (the default), Hertz–Mindlin.
CONTACT_LAWS = ("linear", "hertz-mindlin")
@numba.njit(cache=True, inline="always")
def _stiffnesses(hertz, modulus, tangential, radius_star, overlap, linear_kn):
    """(elastic normal force [N], normal tangent stiffness kn [N/m], tangential stiffness kt
    [N/m]) of a contact of effective radius ``radius_star`` [m] and ``overlap`` [m]: Hertz and
    Mindlin with ``modulus`` E* and ``tangential`` G* [Pa]; else linear springs of
    ``linear_kn`` [N/m] and ``tangential`` ks / kn."""
    if hertz:
        a = math.sqrt(radius_star * overlap)
        kn = 2.0 * modulus * a
        return kn * overlap * (2.0 / 3.0), kn, 8.0 * tangential * a
    return linear_kn * overlap, linear_kn, tangential * linear_kn


@numba.njit(cache=True, inline="always")
def _damped_forces(fe, kn, kt, mass_star, damping, un, t0, t1, t2, s0, s1, s2, tan_friction,
                   dt):
    """(normal force [N], spring [N], tangential force [N]) of a contact of elastic force
    ``fe``, stiffnesses kn, kt [N/m], effective mass [kg], damping ratio, normal relative
    velocity ``un`` (positive when parting) and tangential t [m/s], stored spring s [N]
    (turned with the contact): Fn = max(0, fe - 2 gamma sqrt(m* kn) un); spring s - kt t dt;
    tangential force spring - 2 gamma sqrt(m* kt) t, capped at Fn tan(phi), a sliding
    contact's spring set to the capped force."""
    # undamped (the default), the dashpots are exact zeros without their square roots
    normal_dashpot = 2.0 * damping * math.sqrt(mass_star * kn) if damping != 0.0 else 0.0
    fn = max(fe - normal_dashpot * un, 0.0)
    s0 -= kt * t0 * dt
    s1 -= kt * t1 * dt
    s2 -= kt * t2 * dt
    dashpot = (2.0 * damping * math.sqrt(TANGENTIAL_MASS * mass_star * kt) if damping != 0.0
               else 0.0)
    f0 = s0 - dashpot * t0
    f1 = s1 - dashpot * t1
    f2 = s2 - dashpot * t2
    cap = fn * tan_friction
    magnitude = math.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
    if magnitude > cap:
        scale = cap / magnitude
        f0 *= scale
        f1 *= scale
        f2 *= scale
        s0, s1, s2 = f0, f1, f2
    return fn, s0, s1, s2, f0, f1, f2


@numba.njit(cache=True, inline="always")
def _evaluate_damped_pair(k, first, mass_i, j, position, velocity, angular_velocity, radius,
                          mass, image, period, periodic, affine_rate, stretched, shear_force,
                          normal, overlap, normal_force, force, hertz, modulus, tangential,
                          damping, tan_friction, dt):
    """Pair k of first member ``first`` (pendular.dem.contact_law._first_member) of mass
    ``mass_i`` [kg] and second member j, fill its per-pair arrays (module docstring); the
    arguments as viscoelastic_pair_forces'. Returns as pendular.dem.contact_law._evaluate_pair:
    (touching, the force on j from i [N], the normal, the overlap [m])."""
    d0, d1, d2, distance, gap_overlap = _contact_gap(k, first, j, position, radius, image,
                                                     period, periodic, overlap, shear_force,
                                                     normal_force, force)
    if gap_overlap <= 0.0:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, gap_overlap
    n0, n1, n2, s0, s1, s2, v0, v1, v2 = _turned_contact(
        k, first, j, d0, d1, d2, distance, velocity, angular_velocity, radius, affine_rate,
        stretched, shear_force, normal, dt)
    ri = first[9]
    rj = radius[j]
    mj = mass[j]
    fe, kn, kt = _stiffnesses(hertz, modulus, tangential, ri * rj / (ri + rj), gap_overlap,
                              normal_stiffness(modulus, ri, rj))
    un = v0 * n0 + v1 * n1 + v2 * n2
    fn, s0, s1, s2, f0, f1, f2 = _damped_forces(
        fe, kn, kt, mass_i * mj / (mass_i + mj), damping, un, v0 - un * n0, v1 - un * n1,
        v2 - un * n2, s0, s1, s2, tan_friction, dt)
    shear_force[k, 0] = s0
    shear_force[k, 1] = s1
    shear_force[k, 2] = s2
    normal[k, 0] = n0
    normal[k, 1] = n1
    normal[k, 2] = n2
    normal_force[k] = fe            # the spring's: F_n / delta is its secant stiffness
    a0 = fn * n0 + f0
    a1 = fn * n1 + f1
    a2 = fn * n2 + f2
    force[k, 0] = a0
    force[k, 1] = a1
    force[k, 2] = a2
    return True, a0, a1, a2, n0, n1, n2, gap_overlap


@numba.njit(cache=True, parallel=True, fastmath=HOT_KERNEL_FASTMATH)
def viscoelastic_pair_forces(position, velocity, angular_velocity, radius, mass, pair_i, pair_j,
                             image, period, affine_rate, shear_force, normal, overlap,
                             normal_force, force, hertz, modulus, tangential, damping,
                             tan_friction, dt):
    """Evaluate every candidate pair with the damped law (module docstring), filling the
    per-pair arrays as pendular.dem.contact_law.pair_forces does (its arguments, with
    ``mass`` (N,) [kg]); ``hertz``: Hertz–Mindlin with ``modulus`` E* and ``tangential`` G*
    [Pa], else linear springs with ``modulus`` young [Pa] and ``tangential`` ks / kn;
    ``damping``: the damping ratio (pendular.dem.restitution.damping_ratio)."""
    periodic = period[0] != 0.0 or period[1] != 0.0 or period[2] != 0.0
    stretched = _stretched(affine_rate)
    for k in numba.prange(len(pair_i)):
        i = pair_i[k]
        _evaluate_damped_pair(k, _first_member(i, position, velocity, angular_velocity, radius),
                              mass[i], pair_j[k], position, velocity, angular_velocity, radius,
                              mass, image, period, periodic, affine_rate, stretched,
                              shear_force, normal, overlap, normal_force, force, hertz, modulus,
                              tangential, damping, tan_friction, dt)


@numba.njit(cache=True, fastmath=HOT_KERNEL_FASTMATH, _nrt=False)
def serial_viscoelastic_pair_forces(position, velocity, angular_velocity, radius, mass,
                                    row_start, pair_j, image, period, affine_rate, shear_force,
                                    normal, overlap, normal_force, force, hertz, modulus,
                                    tangential, damping, tan_friction, dt, prefetch_ahead):
    """viscoelastic_pair_forces on one thread, row by row (particle i's state read once for
    its row), without the parallel launch and reference counting (the same results; the
    pairs' rows from ``row_start``; ``prefetch_ahead`` as pendular.dem.contact_law.
    pair_forces')."""
    periodic = period[0] != 0.0 or period[1] != 0.0 or period[2] != 0.0
    stretched = _stretched(affine_rate)
    for i in range(len(row_start) - 1):
        first = _first_member(i, position, velocity, angular_velocity, radius)
        for k in range(row_start[i], row_start[i + 1]):
            _prefetch_second(k, pair_j, prefetch_ahead, (position, velocity, angular_velocity),
                             radius)
            _evaluate_damped_pair(k, first, mass[i], pair_j[k], position, velocity,
                                  angular_velocity, radius, mass, image, period, periodic,
                                  affine_rate, stretched, shear_force, normal, overlap,
                                  normal_force, force, hertz, modulus, tangential, damping,
                                  tan_friction, dt)


@numba.njit(cache=True, fastmath=HOT_KERNEL_FASTMATH, _nrt=False)
def scattered_viscoelastic_pair_forces(position, velocity, angular_velocity, radius, mass,
                                       row_start, pair_j, image, period, affine_rate,
                                       shear_force, normal, overlap, normal_force, force, hertz,
                                       modulus, tangential, damping, tan_friction, dt,
                                       prefetch_ahead, particle_force, particle_torque):
    """serial_viscoelastic_pair_forces with each touching pair's force and torques added to
    its particles' ``particle_force`` [N] and ``particle_torque`` [N m] as it is evaluated: the
    sums of the gather in its order, in one pass over the rows (pendular.dem.contact_law.
    scattered_pair_forces)."""
    periodic = period[0] != 0.0 or period[1] != 0.0 or period[2] != 0.0
    stretched = _stretched(affine_rate)
    for i in range(len(row_start) - 1):
        start = row_start[i]
        stop = row_start[i + 1]
        if start == stop:
            continue
        first = _first_member(i, position, velocity, angular_velocity, radius)
        sums = _row_sums(i, particle_force, particle_torque)
        for k in range(start, stop):
            _prefetch_second(k, pair_j, prefetch_ahead, (position, velocity, angular_velocity,
                                                         particle_force, particle_torque), radius)
            j = pair_j[k]
            touching, a0, a1, a2, n0, n1, n2, overlap_k = _evaluate_damped_pair(
                k, first, mass[i], j, position, velocity, angular_velocity, radius, mass, image,
                period, periodic, affine_rate, stretched, shear_force, normal, overlap,
                normal_force, force, hertz, modulus, tangential, damping, tan_friction, dt)
            if touching:
                sums = _scatter_to_both(sums, j, a0, a1, a2, a0, a1, a2, n0, n1, n2, overlap_k,
                                        first[9], radius, particle_force, particle_torque)
        _store_row_sums(i, sums, particle_force, particle_torque)


@numba.njit(cache=True, inline="always")
def _sphere_on_walls(p, position, velocity, angular_velocity, radius, mass, wall_position,
                     wall_velocity, hertz, modulus, tangential, damping, tan_friction, dt,
                     wall_shear, force, torque, wall_force, wall_stiffness, wall_moment):
    """Particle p's damped contacts with the six walls, walls in order (the body of
    viscoelastic_wall_forces's loop and of the device's threads, pendular.gpu.wall_friction):
    add to ``force[p]`` and ``torque[p]``, update ``wall_shear[p]``, add to the walls' totals
    (6,); arguments as viscoelastic_wall_forces'."""
    r = radius[p]
    for w in range(6):
        axis, side, gap = wall_gap(p, w, position, radius, wall_position)
        overlap = -gap
        if overlap <= 0.0:
            wall_shear[p, w, 0] = 0.0
            wall_shear[p, w, 1] = 0.0
            wall_shear[p, w, 2] = 0.0
            continue
        n0 = side if axis == 0 else 0.0
        n1 = side if axis == 1 else 0.0
        n2 = side if axis == 2 else 0.0
        # the sphere's velocity at its contact point x - r n relative to the wall, whose
        # velocity is -wall_velocity[w] n (outward positive)
        w0 = angular_velocity[p, 0]
        w1 = angular_velocity[p, 1]
        w2 = angular_velocity[p, 2]
        speed = wall_velocity[w]
        u0 = velocity[p, 0] - r * (w1 * n2 - w2 * n1) + speed * n0
        u1 = velocity[p, 1] - r * (w2 * n0 - w0 * n2) + speed * n1
        u2 = velocity[p, 2] - r * (w0 * n1 - w1 * n0) + speed * n2
        un = u0 * n0 + u1 * n1 + u2 * n2
        fe, kn, kt = _stiffnesses(hertz, modulus, tangential, r, overlap,
                                  wall_contact_stiffness(modulus, r))
        fn, s0, s1, s2, f0, f1, f2 = _damped_forces(
            fe, kn, kt, mass[p], damping, un, u0 - un * n0, u1 - un * n1, u2 - un * n2,
            wall_shear[p, w, 0], wall_shear[p, w, 1], wall_shear[p, w, 2], tan_friction, dt)
        wall_shear[p, w, 0] = s0
        wall_shear[p, w, 1] = s1
        wall_shear[p, w, 2] = s2
        f0 += fn * n0
        f1 += fn * n1
        f2 += fn * n2
        force[p, 0] += f0
        force[p, 1] += f1
        force[p, 2] += f2
        lever = overlap * 0.5 - r                   # the contact point at lever n
        torque[p, 0] += lever * (n1 * f2 - n2 * f1)
        torque[p, 1] += lever * (n2 * f0 - n0 * f2)
        torque[p, 2] += lever * (n0 * f1 - n1 * f0)
        wall_force[w] += fn
        wall_stiffness[w] += kn
        wall_moment[w] += (r - overlap) * fn


@numba.njit(cache=True)
def viscoelastic_wall_forces(position, velocity, angular_velocity, radius, mass, near_wall,
                             wall_position, wall_velocity, hertz, modulus, tangential, damping,
                             tan_friction, dt, wall_shear, force, torque, wall_force,
                             wall_stiffness, wall_moment):
    """Damped sphere–wall contacts (module docstring) of the particles ``near_wall``
    (pendular.dem.walls.WallForces' arguments and totals, wall_stiffness the contacts' kn):
    add to ``force`` and ``torque``; ``wall_shear`` (N, 6, 3) [N] the springs of each
    particle on each wall, zeroed when it leaves the wall. ``hertz``, ``modulus``,
    ``tangential``: as viscoelastic_pair_forces' (E* and G* of a sphere on a rigid wall);
    ``wall_velocity`` (6,) outward-positive [m/s]. The force acts at the middle of the
    overlap, R - overlap/2 from the centre, as a pair's."""
    wall_force[:] = 0.0
    wall_stiffness[:] = 0.0
    wall_moment[:] = 0.0
    for p in near_wall:
        _sphere_on_walls(p, position, velocity, angular_velocity, radius, mass, wall_position,
                         wall_velocity, hertz, modulus, tangential, damping, tan_friction, dt,
                         wall_shear, force, torque, wall_force, wall_stiffness, wall_moment)


class _DampedContactForces(ContactForces):
    """A damped contact law on every candidate pair of ``sim.contacts`` (module docstring):
    the linear law's per-pair arrays, gather and joined gather (ContactForces), its own pair
    kernel. Subclasses set ``hertz``, ``modulus``, ``tangential`` and ``restitution``."""

    hertz = False

    @property
    def restitution(self):
        return self._restitution

    @restitution.setter
    def restitution(self, value):
        law = "hertz-mindlin" if self.hertz else "linear"
        self._restitution = check_restitution(value)
        self.damping = damping_ratio(self._restitution, law)

    def apply(self, sim):
        """This step's pair forces, gathered onto the particles unless a later force
        operation joins the gather (ContactForces.joined_by); on one thread, as the linear
        law's (ContactForces.apply), row by row and scattered to the particles as they are
        evaluated (the same sums)."""
        p = sim.particles
        c = sim.contacts
        box = sim.walls
        per_pair = (c.image, box.period, box.affine_rate, c.shear_force, c.normal, c.overlap,
                    c.normal_force, c.force, self.hertz, self.modulus, self.tangential,
                    self.damping, self._tan_friction, sim.dt)
        kinematics = (p.position, p.velocity, p.angular_velocity, p.radius, p.mass)
        joined = self.joined_by(sim) is not None
        if numba.get_num_threads() > 1:
            viscoelastic_pair_forces(*kinematics, c.pair_i, c.pair_j, *per_pair)
            if not joined:
                self.gather(sim)
        elif joined:
            serial_viscoelastic_pair_forces(*kinematics, c.row_start, c.pair_j, *per_pair,
                                            prefetch_distance(len(c)))
        else:
            scattered_viscoelastic_pair_forces(*kinematics, c.row_start, c.pair_j, *per_pair,
                                               prefetch_distance(len(c)), p.force, p.torque)
            self._add_face_terms(sim, None)


class HertzMindlinForces(_DampedContactForces):
    """Hertz–Mindlin contacts between spheres of one material: ``young`` E [Pa],
    ``poisson`` nu in (-1, 0.5), ``restitution`` e in (0, 1] (normal and tangential damping),
    ``friction_deg`` [deg] (module docstring)."""

    hertz = True

    def __init__(self, young, poisson, restitution=1.0, friction_deg=18.0):
        self.young = check_positive("young", young, "Pa")
        self.poisson = check_poisson(poisson)
        self.modulus = effective_modulus(self.young, self.poisson, self.young, self.poisson)
        self.tangential = effective_shear_modulus(self.young, self.poisson, self.young,
                                                  self.poisson)
        self.restitution = restitution
        self.friction_deg = friction_deg


class DampedLinearForces(_DampedContactForces):
    """The linear law (pendular.dem.contact_law.ContactForces: ``young`` [Pa], ks / kn
    ``shear_ratio``, ``friction_deg`` [deg]) with the viscous damping of ``restitution`` e in
    (0, 1] (module docstring)."""

    def __init__(self, young, shear_ratio=0.3, restitution=1.0, friction_deg=18.0):
        self.young = self.modulus = check_positive("young", young, "Pa")
        self.shear_ratio = self.tangential = check_range("shear_ratio", shear_ratio, 0.0,
                                                         MAX_SHEAR_RATIO)
        self.restitution = restitution
        self.friction_deg = friction_deg


class ViscoelasticWallForces:
    """Damped sphere–wall contacts of the law of ``contact`` (a HertzMindlinForces or
    DampedLinearForces: the grains' material) on walls of the material ``wall``
    (pendular.dem.material.Material; None: rigid_wall, rigid and frictionless, of the grains'
    restitution), module docstring. The contact's E*, G*, restitution and friction follow
    pendular.dem.material.wall_contact; the linear law's wall is its virtual sphere of the
    grains' springs (kn = E R), which takes no Young's modulus of its own. Each particle's
    spring on each wall is kept across steps and checkpoints."""

    def __init__(self, contact, wall=None):
        if not isinstance(contact, _DampedContactForces):
            raise TypeError(f"contact must be a HertzMindlinForces or DampedLinearForces, got "
                            f"{type(contact).__name__}")
        self.wall = rigid_wall(contact.restitution) if wall is None else wall
        self.hertz = contact.hertz
        poisson = contact.poisson if self.hertz else 0.0
        modulus, tangential, self.restitution, self.friction_deg = wall_contact(
            contact.young, poisson, contact.restitution, self.wall)
        if self.hertz:
            self.modulus, self.tangential = modulus, tangential
        elif not self.wall.rigid:
            raise ValueError(f"wall_young = {self.wall.young:g} Pa applies to Hertz-Mindlin "
                             "contacts; valid: a rigid wall (none given) with the linear law, "
                             "whose wall is a sphere of the grains' springs (kn = E R)")
        else:
            self.modulus, self.tangential = contact.young, contact.shear_ratio
        self.damping = damping_ratio(self.restitution,
                                     "hertz-mindlin" if self.hertz else "linear")
        self._tan_friction = float(np.tan(np.radians(self.friction_deg)))
        self.wall_shear = np.zeros((0, 6, 3))

    def state_dict(self):
        """The springs of the particles on the walls, ``wall_shear`` (N, 6, 3) [N]."""
        return {"wall_shear": self.wall_shear}

    def load_state(self, state):
        self.wall_shear = state_array(state, "wall_shear", np.float64, (None, 6, 3))

    def apply(self, sim):
        p = sim.particles
        if len(self.wall_shear) != len(p):
            self.wall_shear = np.zeros((len(p), 6, 3))
        box = sim.walls
        viscoelastic_wall_forces(p.position, p.velocity, p.angular_velocity, p.radius, p.mass,
                                 sim.contacts.near_wall, box.position, box.velocity,
                                 self.hertz, self.modulus, self.tangential, self.damping,
                                 self._tan_friction, sim.dt, self.wall_shear, p.force, p.torque,
                                 box.force, box.stiffness, box.moment)
