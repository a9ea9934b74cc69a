"""Rolling and twisting resistance between the spheres and the box's walls: the elastic–plastic
spring–dashpot ("type C", EPSD) model of Ai, Chen, Rotter & Ooi (2011) of the pairs
(pendular.dem.rolling), on a sphere of radius R touching a wall (docs/physics.md 'Rolling and
twisting resistance').

The wall is a sphere of infinite radius, mass and inertia that does not turn: the pair's R* is
R (1/R* = 1/R + 1/inf), its relative angular velocity the sphere's own w. With overlap
delta > 0, the wall's unit normal n into the box and F_n the elastic normal force of the
scene's contact law on the wall (linear: kn delta, kn = E R; Hertz: (4/3) E* sqrt(R)
delta^(3/2), E* the grain's and the wall's, pendular.dem.material), k_n = F_n / delta (the
pairs' secant stiffness):

- rolling: a moment M_r in the wall's plane, kept per sphere and wall across steps
  (``wall_rolling_moment`` (N, 6, 3) [N m]), incremented by -k_r w_t dt, w_t = w - (w . n) n,
  k_r = 2.25 k_n mu_r^2 R^2, capped at mu_r R F_n, on which it stays while the sphere rolls;
  the wall's normal is fixed, so the spring needs no turning with the contact;
- twisting: M_t n, M_t kept per sphere and wall (``wall_twisting_moment`` (N, 6) [N m]),
  incremented by -k_t (w . n) dt, k_t = 2.25 k_n mu_t^2 R^2, capped at mu_t R F_n;
- viscous parts (``damping_ratio`` eta, default 0): -eta 2 sqrt(I_eq k) times the
  tangential (normal) angular velocity, I_eq = I + m R^2 for rolling about the contact point,
  I for twisting (the wall's terms 0), off while the spring sits on its limit.

Both moments are couples on the sphere (no lever); the wall, which does not turn, takes their
reaction, which moves no wall (the walls' forces and the servo are as without them). Springs
are zeroed when the sphere leaves the wall. mu_r and mu_t are the wall's own
(pendular.dem.material: a wall's rolling and twisting friction, not a mixture).

With mu_r = 0 and mu_t = 0 (the walls' default) a scene holds no such operation: its results
are those of a scene without wall rolling resistance, bit for bit.
"""

import math

import numba
import numpy as np

from pendular.dem.contact_law import wall_contact_stiffness, wall_gap
from pendular.dem.hertz_mindlin import _stiffnesses
from pendular.dem.material import effective_modulus
from pendular.dem.protocols import state_array
from pendular.dem.rolling import MAX_RESISTANCE, capped_moment
from pendular.utils.validate import check_range


@numba.njit(cache=True, inline="always")
def _sphere_wall_moments(p, position, angular_velocity, radius, mass, inertia, wall_position,
                         hertz, modulus, rolling, twisting, damping_ratio, dt, rolling_moment,
                         twisting_moment, torque):
    """Particle p's rolling and twisting springs on the six walls, walls in order (the body of
    wall_moments's loop and of the device's threads, pendular.gpu.wall_rolling): update
    ``rolling_moment[p]`` and ``twisting_moment[p]``, add the moments to ``torque[p]``;
    arguments as wall_moments'."""
    r = radius[p]
    for w in range(6):
        axis, side, gap = wall_gap(p, w, position, radius, wall_position)
        overlap = -gap
        if overlap <= 0.0:
            rolling_moment[p, w, 0] = 0.0
            rolling_moment[p, w, 1] = 0.0
            rolling_moment[p, w, 2] = 0.0
            twisting_moment[p, w] = 0.0
            continue
        fn = _stiffnesses(hertz, modulus, 0.0, r, overlap,
                          wall_contact_stiffness(modulus, r))[0]
        kn = fn / overlap
        n0 = side if axis == 0 else 0.0
        n1 = side if axis == 1 else 0.0
        n2 = side if axis == 2 else 0.0
        w0 = angular_velocity[p, 0]
        w1 = angular_velocity[p, 1]
        w2 = angular_velocity[p, 2]
        twist_rate = w0 * n0 + w1 * n1 + w2 * n2
        w0 -= twist_rate * n0
        w1 -= twist_rate * n1
        w2 -= twist_rate * n2
        # rolling: a spring in the wall's plane, incremented, capped
        stiffness = 2.25 * kn * rolling * rolling * r * r
        m0 = rolling_moment[p, w, 0] - stiffness * w0 * dt
        m1 = rolling_moment[p, w, 1] - stiffness * w1 * dt
        m2 = rolling_moment[p, w, 2] - stiffness * w2 * dt
        m0, m1, m2, sliding = capped_moment(m0, m1, m2, rolling * r * fn)
        viscous = 0.0
        if not sliding and damping_ratio > 0.0:
            viscous = damping_ratio * 2.0 * math.sqrt((inertia[p] + mass[p] * r * r)
                                                      * stiffness)
        rolling_moment[p, w, 0] = m0
        rolling_moment[p, w, 1] = m1
        rolling_moment[p, w, 2] = m2
        # twisting: a spring about the normal
        stiffness = 2.25 * kn * twisting * twisting * r * r
        t = twisting_moment[p, w] - stiffness * twist_rate * dt
        limit = twisting * r * fn
        twist_viscous = 0.0
        if abs(t) > limit:
            t = math.copysign(limit, t)
        elif damping_ratio > 0.0:
            twist_viscous = damping_ratio * 2.0 * math.sqrt(inertia[p] * stiffness)
        twisting_moment[p, w] = t
        t -= twist_viscous * twist_rate
        torque[p, 0] += m0 - viscous * w0 + t * n0
        torque[p, 1] += m1 - viscous * w1 + t * n1
        torque[p, 2] += m2 - viscous * w2 + t * n2


@numba.njit(cache=True)
def wall_moments(position, angular_velocity, radius, mass, inertia, near_wall, wall_position,
                 hertz, modulus, rolling, twisting, damping_ratio, dt, rolling_moment,
                 twisting_moment, torque):
    """Rolling and twisting moments (module docstring) of the particles ``near_wall`` on the
    walls at ``wall_position`` (6,) [m], added to ``torque`` (N, 3) [N m]; their springs
    ``rolling_moment`` (N, 6, 3) and ``twisting_moment`` (N, 6) [N m] updated. ``hertz``:
    Hertz's normal force of E* ``modulus`` [Pa], else the linear law's kn = ``modulus`` R;
    ``rolling``, ``twisting``: mu_r, mu_t; ``damping_ratio``: eta; ``dt`` [s]."""
    for p in near_wall:
        _sphere_wall_moments(p, position, angular_velocity, radius, mass, inertia,
                             wall_position, hertz, modulus, rolling, twisting, damping_ratio,
                             dt, rolling_moment, twisting_moment, torque)


class WallRollingResistance:
    """Rolling and twisting moments of the spheres on the walls (module docstring), a force of
    a walled scene. ``contact``: the scene's contact law (its normal force on a wall: a
    HertzMindlinForces', or the linear law's kn = E R); ``wall``: the walls' Material
    (pendular.dem.material), whose ``rolling_friction`` and ``twisting_friction`` are mu_r and
    mu_t ([0, MAX_RESISTANCE]); ``damping_ratio``: eta of the viscous parts ([0, 1]). Each
    particle's springs on each wall are kept across steps and checkpoints."""

    def __init__(self, contact, wall, damping_ratio=0.0):
        self.hertz = bool(getattr(contact, "hertz", False))
        self.modulus = (effective_modulus(contact.young, contact.poisson, wall.young,
                                          wall.poisson) if self.hertz else contact.young)
        self.rolling = check_range("wall_rolling_friction", wall.rolling_friction, 0.0,
                                   MAX_RESISTANCE)
        self.twisting = check_range("wall_twisting_friction", wall.twisting_friction, 0.0,
                                    MAX_RESISTANCE)
        self.damping_ratio = check_range("damping_ratio", damping_ratio, 0.0, 1.0)
        self.wall_rolling_moment = np.zeros((0, 6, 3))
        self.wall_twisting_moment = np.zeros((0, 6))

    def state_dict(self):
        """The springs of the particles on the walls: ``wall_rolling_moment`` (N, 6, 3) and
        ``wall_twisting_moment`` (N, 6) [N m]."""
        return {"wall_rolling_moment": self.wall_rolling_moment,
                "wall_twisting_moment": self.wall_twisting_moment}

    def load_state(self, state):
        self.wall_rolling_moment = state_array(state, "wall_rolling_moment", np.float64,
                                               (None, 6, 3))
        self.wall_twisting_moment = state_array(state, "wall_twisting_moment", np.float64,
                                                (len(self.wall_rolling_moment), 6))

    def apply(self, sim):
        p = sim.particles
        if len(self.wall_rolling_moment) != len(p):
            self.wall_rolling_moment = np.zeros((len(p), 6, 3))
            self.wall_twisting_moment = np.zeros((len(p), 6))
        wall_moments(p.position, p.angular_velocity, p.radius, p.mass, p.inertia,
                     sim.contacts.near_wall, sim.walls.position, self.hertz, self.modulus,
                     self.rolling, self.twisting, self.damping_ratio, sim.dt,
                     self.wall_rolling_moment, self.wall_twisting_moment, p.torque)


def wall_resistance(contact, wall):
    """The walls' rolling resistance as a list of forces: one WallRollingResistance when the
    walls' Material ``wall`` has rolling or twisting friction above 0, else none (a scene pays
    only for what it uses; its results then as before)."""
    if wall.rolling_friction > 0.0 or wall.twisting_friction > 0.0:
        return [WallRollingResistance(contact, wall)]
    return []
