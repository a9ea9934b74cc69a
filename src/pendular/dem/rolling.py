"""Rolling and twisting resistance: the elastic–plastic spring–dashpot ("type C", EPSD) model of
Ai, Chen, Rotter & Ooi (2011), docs/physics.md 'Rolling and twisting resistance'.

A pair in contact (normal n from i to j, overlap δ > 0, mechanical normal force F_n from the
contact law, R* = R_i R_j / (R_i + R_j)) carries a rolling moment M_r (tangent to the contact)
and a twisting moment M_t n, both on i (j gets their opposite):

- rolling: stiffness k_r = 2.25 k_n μ_r² R*² (Ai et al.'s; the spring, dashpot and slider
  are Iwashita & Oda 1998's), limit μ_r R* F_n; each step the stored moment turns with the
  contact (as the shear force: tilt of the normal, then the mean spin about it), loses its
  normal part and is incremented by -k_r Δθ_r, Δθ_r = (ω_i - ω_j)_tangential dt, then capped
  at the limit, on which it stays while the pair rolls;
- twisting: the same spring about the normal, k_t = 2.25 k_n μ_t² R*², limit μ_t R* F_n, on
  Δθ_t = n · (ω_i - ω_j) dt (the torsion analogue of Luding 2008);
- viscous part (Ai et al.'s dashpot): -η C_crit ω_rel, C_crit = 2 sqrt(I k), I the pair's
  equivalent moment of inertia, [1/(I_i + m_i R_i²) + 1/(I_j + m_j R_j²)]⁻¹ for rolling about
  the contact point, [1/I_i + 1/I_j]⁻¹ for twisting about the normal; switched off while the
  spring sits on its limit (their f = 0). Default η = 0: the scenes damp quasi-statically with
  Cundall's local damping, which acts on the torques too.

k_n is the pair's secant stiffness F_n / δ, read from the per-pair arrays that every contact law
fills (``Contacts.normal_force``, ``overlap``, ``normal``): the linear law's k_n itself, and for
a Hertz law 4/3 E* sqrt(R* δ), the k_n LIGGGHTS's ``rolling_friction epsd`` takes from its
Hertz law. F_n is the contact law's elastic spring force alone: a capillary bridge's attraction
does not raise the limit, as it does not raise the Coulomb cap, and a damped law's dashpot
(pendular.dem.hertz_mindlin) is left out of both k_n and the limit. Sphere–wall contacts take
the same springs with the walls' own coefficients (pendular.dem.wall_rolling).
"""

import math

import numba
import numpy as np

from pendular.dem.protocols import PairField, pair_arrays
from pendular.utils.validate import check_range

#: Largest rolling or twisting coefficient: k_r grows as μ_r², and the time step is set by the
#: normal and shear springs alone; up to 0.5 a rolling spring's k_r / I stays below
#: 0.36 k_n / m for equal spheres, well under the normal springs' 2 k_n / m (docs/physics.md).
MAX_RESISTANCE = 0.5

OWNER = "rolling"
FIELDS = (
    PairField("rolling_moment", np.float64, "N m",
              "elastic rolling moment on i (its opposite on j), tangent to the contact", (3,)),
    PairField("twisting_moment", np.float64, "N m",
              "elastic twisting moment on i about the normal i -> j (its opposite on j)"),
    PairField("normal", np.float64, "1",
              "contact normal i -> j of the last evaluation (to turn rolling_moment with it)",
              (3,)),
)


@numba.njit(cache=True, inline="always")
def capped_moment(m0, m1, m2, limit):
    """The rolling spring (m0, m1, m2) [N m] held to its limit moment ``limit`` [N m] (Ai et
    al. 2011, type C: scaled back onto the limit, keeping its direction), and whether it was
    (the contact rolls plastically, its dashpot off)."""
    size = math.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
    if size > limit:
        scale = limit / size
        return m0 * scale, m1 * scale, m2 * scale, True
    return m0, m1, m2, False


@numba.njit(cache=True, inline="always")
def _turned(m0, m1, m2, a0, a1, a2):
    """m - m x a: the vector m turned by the small rotation a [rad] (as the shear force,
    pendular.dem.contact_law._evaluate_pair)."""
    return m0 - (m1 * a2 - m2 * a1), m1 - (m2 * a0 - m0 * a2), m2 - (m0 * a1 - m1 * a0)


@numba.njit(cache=True, inline="always")
def _pair_moment(k, i, j, radius, mass, inertia, angular_velocity, normal, overlap,
                 normal_force, rolling_moment, twisting_moment, last_normal, moment, rolling,
                 twisting, damping_ratio, dt):
    """Pair k, of first member i and second member j: pair_moments's update of its springs
    and its ``moment[k]`` (the body of the CPU's loop and of the device's rows,
    pendular.gpu.rolling)."""
    fn = normal_force[k]
    delta = overlap[k]
    if delta <= 0.0 or fn <= 0.0:
        for c in range(3):
            rolling_moment[k, c] = 0.0
            last_normal[k, c] = 0.0
            moment[k, c] = 0.0
        twisting_moment[k] = 0.0
        return
    ri = radius[i]
    rj = radius[j]
    reduced = ri * rj / (ri + rj)
    kn = fn / delta
    n0 = normal[k, 0]
    n1 = normal[k, 1]
    n2 = normal[k, 2]
    w0 = angular_velocity[i, 0] - angular_velocity[j, 0]
    w1 = angular_velocity[i, 1] - angular_velocity[j, 1]
    w2 = angular_velocity[i, 2] - angular_velocity[j, 2]
    twist_rate = w0 * n0 + w1 * n1 + w2 * n2
    w0 -= twist_rate * n0
    w1 -= twist_rate * n1
    w2 -= twist_rate * n2
    # rolling: turn the spring with the contact, keep it tangent, increment, cap
    m0, m1, m2 = _turned(rolling_moment[k, 0], rolling_moment[k, 1], rolling_moment[k, 2],
                         last_normal[k, 1] * n2 - last_normal[k, 2] * n1,
                         last_normal[k, 2] * n0 - last_normal[k, 0] * n2,
                         last_normal[k, 0] * n1 - last_normal[k, 1] * n0)
    spin = 0.5 * dt * (n0 * (angular_velocity[i, 0] + angular_velocity[j, 0])
                       + n1 * (angular_velocity[i, 1] + angular_velocity[j, 1])
                       + n2 * (angular_velocity[i, 2] + angular_velocity[j, 2]))
    m0, m1, m2 = _turned(m0, m1, m2, spin * n0, spin * n1, spin * n2)
    along = m0 * n0 + m1 * n1 + m2 * n2
    stiffness = 2.25 * kn * rolling * rolling * reduced * reduced
    m0 -= along * n0 + stiffness * w0 * dt
    m1 -= along * n1 + stiffness * w1 * dt
    m2 -= along * n2 + stiffness * w2 * dt
    m0, m1, m2, sliding = capped_moment(m0, m1, m2, rolling * reduced * fn)
    viscous = 0.0
    if not sliding and damping_ratio > 0.0:
        equivalent = 1.0 / (1.0 / (inertia[i] + mass[i] * ri * ri)
                            + 1.0 / (inertia[j] + mass[j] * rj * rj))
        viscous = damping_ratio * 2.0 * math.sqrt(equivalent * stiffness)
    rolling_moment[k, 0] = m0
    rolling_moment[k, 1] = m1
    rolling_moment[k, 2] = m2
    # twisting: a spring about the normal, which turns with the contact by itself
    t = twisting_moment[k]
    stiffness = 2.25 * kn * twisting * twisting * reduced * reduced
    t -= stiffness * twist_rate * dt
    limit = twisting * reduced * fn
    twist_viscous = 0.0
    if abs(t) > limit:
        t = math.copysign(limit, t)
    elif damping_ratio > 0.0:
        equivalent = 1.0 / (1.0 / inertia[i] + 1.0 / inertia[j])
        twist_viscous = damping_ratio * 2.0 * math.sqrt(equivalent * stiffness)
    twisting_moment[k] = t
    t -= twist_viscous * twist_rate
    moment[k, 0] = m0 - viscous * w0 + t * n0
    moment[k, 1] = m1 - viscous * w1 + t * n1
    moment[k, 2] = m2 - viscous * w2 + t * n2
    last_normal[k, 0] = n0
    last_normal[k, 1] = n1
    last_normal[k, 2] = n2


@numba.njit(cache=True, parallel=True)
def pair_moments(pair_i, pair_j, radius, mass, inertia, angular_velocity, normal, overlap,
                 normal_force, rolling_moment, twisting_moment, last_normal, moment, rolling,
                 twisting, damping_ratio, dt):
    """Update each pair's rolling and twisting springs (module docstring) and write ``moment``
    (K, 3) [N m], the pair's whole moment on i (springs and viscous parts; its opposite acts on
    j). normal, overlap [m], normal_force [N]: this step's, from the contact law; a pair apart
    (overlap or normal force not positive) has its springs and moment set to zero. rolling,
    twisting: μ_r, μ_t; damping_ratio: η of both viscous parts; dt [s]."""
    for k in numba.prange(len(pair_i)):
        _pair_moment(k, pair_i[k], pair_j[k], radius, mass, inertia, angular_velocity, normal,
                     overlap, normal_force, rolling_moment, twisting_moment, last_normal,
                     moment, rolling, twisting, damping_ratio, dt)


@numba.njit(cache=True, inline="always")
def _sum_moments(moment, second_pair, own_pairs, second_slots):
    """(t0, t1, t2) [N m]: a particle's pair moments in a fixed order, +M of its pairs
    ``own_pairs`` (it is i), then -M of the pairs ``second_pair[slot]`` for ``slot`` in
    ``second_slots`` (it is j); ranges, so that the device's rows (pendular.gpu.rolling) sum
    the same way."""
    t0 = t1 = t2 = 0.0
    for k in own_pairs:
        t0 += moment[k, 0]
        t1 += moment[k, 1]
        t2 += moment[k, 2]
    for slot in second_slots:
        k = second_pair[slot]
        t0 -= moment[k, 0]
        t1 -= moment[k, 1]
        t2 -= moment[k, 2]
    return t0, t1, t2


@numba.njit(cache=True, parallel=True)
def gather_moments(moment, row_start, second_start, second_pair, torque):
    """Add each pair's ``moment`` (K, 3) [N m] to ``torque`` (N, 3): +M to its first member,
    -M to its second. Each particle sums its own pairs, then those in which it is the second
    member, in pair order (_sum_moments): the same sums for any thread count."""
    for p in numba.prange(len(row_start) - 1):
        t0, t1, t2 = _sum_moments(moment, second_pair, range(row_start[p], row_start[p + 1]),
                                  range(second_start[p], second_start[p + 1]))
        torque[p, 0] += t0
        torque[p, 1] += t1
        torque[p, 2] += t2


class RollingResistance:
    """Rolling and twisting moments of the touching pairs (module docstring), a force placed
    after the contact law, whose per-pair arrays it reads.

    rolling, twisting: μ_r and μ_t (dimensionless, [0, MAX_RESISTANCE]); damping_ratio: η of
    the viscous parts ([0, 1], default 0). ``moment``: each pair's moment on its first member
    (K, 3) [N m] of the last evaluation."""

    stateless = True        # its springs are per-pair state, kept by the contacts
    pair_owner = OWNER
    pair_state = FIELDS

    def __init__(self, rolling, twisting=0.0, damping_ratio=0.0):
        self.rolling = check_range("rolling_friction", rolling, 0.0, MAX_RESISTANCE)
        self.twisting = check_range("twisting_friction", twisting, 0.0, MAX_RESISTANCE)
        self.damping_ratio = check_range("damping_ratio", damping_ratio, 0.0, 1.0)
        self.moment = np.zeros((0, 3))

    def pair_moments(self, sim):
        """Each pair's moment on its first member (K, 3) [N m] of the last evaluation."""
        return self.moment

    def apply(self, sim):
        p = sim.particles
        c = sim.contacts
        if len(self.moment) != len(c):
            self.moment = np.zeros((len(c), 3))
        state = pair_arrays(c, self.pair_owner, self.pair_state)
        pair_moments(c.pair_i, c.pair_j, p.radius, p.mass, p.inertia, p.angular_velocity,
                     c.normal, c.overlap, c.normal_force, state["rolling_moment"],
                     state["twisting_moment"], state["normal"], self.moment, self.rolling,
                     self.twisting, self.damping_ratio, sim.dt)
        gather_moments(self.moment, c.row_start, c.second_start, c.second_pair, p.torque)
