"""The viscous damping that gives a contact a coefficient of restitution e
(docs/physics.md 'Restitution').

A contact's normal force is F = K delta^p + 2 gamma sqrt(m* k(delta)) d(delta)/dt, no tension
(F >= 0): K delta^p the elastic force (p = 1, linear springs; p = 3/2, Hertz),
k = dF_el/d(delta) = p K delta^(p-1) its tangent stiffness, m* the effective mass and gamma
the damping ratio. With delta = delta0 x and t = T tau, T^2 = m* / (K delta0^(p-1)) and
delta0 chosen so that the impact velocity is 1, the impact reads

    x'' = -max(0, x^p + 2 gamma sqrt(p) x^((p-1)/2) x'),   x(0) = 0, x'(0) = 1,

free of the velocity, the masses and the stiffness: e depends on gamma alone, for both laws
(Tsuji et al. 1992 for Hertz's damping proportional to delta^(1/4); Antypov & Elliott 2011).
The collision ends when the force vanishes (Schwager & Pöschel 2007), here while x' < 0;
the particles then separate at the speed they have, e = -x'(end). ``damping_ratio`` inverts
e(gamma) by solving this equation (scipy's solve_ivp, Brent's root of e(gamma) - e) once per
law and e, cached.

The linear spring's textbook mapping gamma = -ln e / sqrt(ln^2 e + pi^2) holds for a force
that may pull at the end of the contact; without tension the particles part earlier and
faster (Schwager & Pöschel 2007), and for Hertz no closed form exists (Antypov & Elliott
2011, Thornton et al. 2013), hence the numerical mapping for both.
"""

import functools
import math

import scipy.integrate
import scipy.optimize

from pendular.utils.validate import check_range

#: The laws' exponents p of the elastic normal force K delta^p.
EXPONENTS = {"linear": 1.0, "hertz-mindlin": 1.5}
#: Relative tolerance of the impact's integration and of the root in gamma.
_TOLERANCE = 1e-10


def impact_restitution(gamma, exponent):
    """The coefficient of restitution of the dimensionless damped impact (module docstring)
    of damping ratio ``gamma`` >= 0 and force exponent ``exponent`` (1 or 1.5)."""
    lever = 2.0 * gamma * math.sqrt(exponent)
    half = 0.5 * (exponent - 1.0)

    def force(y):
        x = max(y[0], 0.0)
        return x ** exponent + lever * x ** half * y[1]

    def motion(t, y):
        return (y[1], -max(0.0, force(y)))

    def released(t, y):             # the force vanishes while the particles part
        return force(y) if y[1] < 0.0 else 1.0

    released.terminal = True
    released.direction = -1
    # x comes back to 0 within a few pi at any damping: the undamped half period is pi for
    # p = 1 and 3.22 for p = 3/2, and damping shortens the restitution
    solution = scipy.integrate.solve_ivp(motion, (0.0, 50.0), (0.0, 1.0), events=released,
                                         rtol=_TOLERANCE, atol=_TOLERANCE * 1e-2,
                                         max_step=0.01)
    if not solution.t_events[0].size:
        raise RuntimeError(f"the damped impact of damping ratio {gamma:g} did not end")
    return -float(solution.y_events[0][0][1])


@functools.lru_cache(maxsize=None)
def damping_ratio(restitution, law="hertz-mindlin"):
    """The damping ratio gamma [-] of a contact of ``law`` ("linear", "hertz-mindlin") that
    rebounds at ``restitution`` e in (0, 1] (module docstring); 0 for e = 1."""
    restitution = check_range("restitution", restitution, 0.0, 1.0, low_inclusive=False)
    if law not in EXPONENTS:
        raise ValueError(f"law = {law!r} is not one of {tuple(EXPONENTS)}")
    if restitution == 1.0:
        return 0.0
    exponent = EXPONENTS[law]
    high = 1.0
    while impact_restitution(high, exponent) > restitution:
        high *= 2.0
    return float(scipy.optimize.brentq(lambda gamma: impact_restitution(gamma, exponent)
                                       - restitution, 0.0, high, xtol=_TOLERANCE,
                                       rtol=_TOLERANCE))
