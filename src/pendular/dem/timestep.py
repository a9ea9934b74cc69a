"""The time step: YADE's P-wave estimate, and the critical step of the contact network.

Leapfrog (pendular.dem.integrate) is stable for an undamped linear system while dt < 2 / omega_max,
omega_max^2 the largest eigenvalue of M^-1/2 K M^-1/2: K the stiffness of every contact spring
acting on the particles' translations and rotations, M their masses and moments of inertia.
``critical_timestep`` finds omega_max by Lanczos iteration (ARPACK, scipy.sparse.linalg.eigsh)
with K applied contact by contact (``stiffness_product``), never assembled: about 30 products,
80 ms at 10,000 spheres. A contact of normal n between spheres of radii r_i, r_j is the spring
kn n n^T + ks (I - n n^T) on the relative displacement of the two surface points that touch,
u_j - u_i + r_i n x theta_i + r_j n x theta_j (the contact law's relative velocity, with the
radius as lever arm); a wall contact is kn = E r along the wall's axis. Capillary bridges are
left out: their force falls as the gap opens (a negative stiffness, which does not shorten
the critical step).

YADE's GlobalStiffnessTimeStepper estimates the step from each particle's own stiffness,
min sqrt(m / K_aa) (the diagonal of K); Gershgorin's circle theorem would turn the rows of K
into a bound. On a prepared 10,000-sphere sample at 750 Pa the critical step is 1.50 times
the P-wave estimate min R / sqrt(E / rho), 1.67 times the diagonal estimate and 1.8 times the
Gershgorin bound: both leave most of the stable range unused, hence the eigenvalue itself.
Leapfrog on a prepared 300-sphere packing, undamped, is steady at 0.95 of it and blows up at
1.1 (tests/unit/test_timestep.py). A scene runs at a safety factor times it, computed when a phase
starts (pendular.procedures.preparation.timestep): the factor leaves room for the local damping (up to
1 + damping times the spring force) and for contacts that form during the phase.
"""

import numba
import numpy as np
import scipy.sparse.linalg

from pendular.dem.contact_law import normal_stiffness, wall_contact_stiffness
from pendular.dem.neighbors import branch_vector, build_contacts
from pendular.utils.validate import check_array, check_positive

#: How a scene's time step is chosen: the P-wave estimate of the smallest sphere, or the
#: critical step of its contacts (either multiplied by a safety factor).
TIMESTEP_RULES = ("pwave", "stiffness")


def pwave_timestep(radius, young, density):
    """YADE's P-wave estimate min R / sqrt(E / rho) [s] (to be multiplied by a safety factor)."""
    radius = check_array("radius", np.atleast_1d(radius), positive=True)
    young = check_positive("young", young, "Pa")
    density = check_positive("density", density, "kg/m^3")
    return float(np.min(radius) / np.sqrt(young / density))


def rayleigh_timestep(radius, young, poisson, density):
    """The Rayleigh-wave step pi R_min sqrt(rho / G) / (0.1631 nu + 0.8766) [s] of spheres of
    ``radius`` [m], Young's modulus [Pa], Poisson ratio and density [kg/m^3], G = E / (2 (1 +
    nu)) (to be multiplied by a safety factor): the time a Rayleigh wave takes to cross half a
    sphere's circumference (Li, Xu & Thornton 2005; Thornton 2015), the step of Hertz–Mindlin
    scenes. It depends on the material alone, not on the overlaps: the Hertz stiffness
    2 E* sqrt(R* delta) grows with the load, so a step from the contacts' stiffness would have
    to guess the largest overlap to come, while the energy of the contacts travels at the
    Rayleigh speed whatever the load (docs/physics.md 'Hertz–Mindlin contacts')."""
    radius = check_array("radius", np.atleast_1d(radius), positive=True)
    young = check_positive("young", young, "Pa")
    density = check_positive("density", density, "kg/m^3")
    shear = young / (2.0 * (1.0 + poisson))
    return float(np.pi * np.min(radius) * np.sqrt(density / shear)
                 / (0.1631 * poisson + 0.8766))


@numba.njit(cache=True)
def stiffness_product(vector, position, radius, scale_u, scale_r, pair_i, pair_j, image, period,
                      wall_position, young, shear_ratio):
    """(N, 6) M^-1/2 K M^-1/2 ``vector`` (N, 6) (translations, then rotations; module
    docstring) for the touching pairs (found from the positions) and, when ``wall_position``
    (6,) [m] is not empty, the wall contacts; scale_u = 1/sqrt(m), scale_r = 1/sqrt(I)."""
    out = np.zeros((len(radius), 6))
    for k in range(len(pair_i)):
        i = pair_i[k]
        j = pair_j[k]
        d0, d1, d2 = branch_vector(position, i, j, image, k, period)
        distance = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        ri = radius[i]
        rj = radius[j]
        if distance >= ri + rj:
            continue
        n0, n1, n2 = d0 / distance, d1 / distance, d2 / distance
        kn = normal_stiffness(young, ri, rj)
        ks = shear_ratio * kn
        # displacement of the contact: u_j - u_i + n x (r_i theta_i + r_j theta_j)
        a0 = ri * scale_r[i] * vector[i, 3] + rj * scale_r[j] * vector[j, 3]
        a1 = ri * scale_r[i] * vector[i, 4] + rj * scale_r[j] * vector[j, 4]
        a2 = ri * scale_r[i] * vector[i, 5] + rj * scale_r[j] * vector[j, 5]
        e0 = scale_u[j] * vector[j, 0] - scale_u[i] * vector[i, 0] + n1 * a2 - n2 * a1
        e1 = scale_u[j] * vector[j, 1] - scale_u[i] * vector[i, 1] + n2 * a0 - n0 * a2
        e2 = scale_u[j] * vector[j, 2] - scale_u[i] * vector[i, 2] + n0 * a1 - n1 * a0
        along = (kn - ks) * (e0 * n0 + e1 * n1 + e2 * n2)
        f0 = ks * e0 + along * n0
        f1 = ks * e1 + along * n1
        f2 = ks * e2 + along * n2
        # K x: -f on u_i, +f on u_j, -r n x f on each rotation
        m0 = n1 * f2 - n2 * f1
        m1 = n2 * f0 - n0 * f2
        m2 = n0 * f1 - n1 * f0
        out[i, 0] -= scale_u[i] * f0
        out[i, 1] -= scale_u[i] * f1
        out[i, 2] -= scale_u[i] * f2
        out[j, 0] += scale_u[j] * f0
        out[j, 1] += scale_u[j] * f1
        out[j, 2] += scale_u[j] * f2
        out[i, 3] -= scale_r[i] * ri * m0
        out[i, 4] -= scale_r[i] * ri * m1
        out[i, 5] -= scale_r[i] * ri * m2
        out[j, 3] -= scale_r[j] * rj * m0
        out[j, 4] -= scale_r[j] * rj * m1
        out[j, 5] -= scale_r[j] * rj * m2
    if len(wall_position):
        for p in range(len(radius)):
            kn = wall_contact_stiffness(young, radius[p]) * scale_u[p] * scale_u[p]
            for a in range(3):
                if position[p, a] - wall_position[2 * a] < radius[p]:
                    out[p, a] += kn * vector[p, a]
                if wall_position[2 * a + 1] - position[p, a] < radius[p]:
                    out[p, a] += kn * vector[p, a]
    return out


def critical_timestep(sim, young, shear_ratio):
    """2 / omega_max [s]: the critical step of leapfrog for the contact springs of ``sim``
    (young [Pa], shear_ratio ks / kn) between its touching pairs and with its walls (module
    docstring), rounded down to 3 significant digits (the last bits of the iteration, which
    may differ between BLAS builds and thread counts, do not reach the step); inf when
    nothing touches. Reads the neighbour list ``sim.contacts`` and the positions; a scene
    without a list yet gets a list of its touching pairs for this call (``sim`` unchanged:
    its first step still evaluates its forces from scratch)."""
    p, c, box = sim.particles, sim.contacts, sim.walls
    if c is None:
        c = build_contacts(p.position, p.radius, 0.0, period=box.period if box.periodic
                           else None)
    count = len(p.radius)
    arguments = (p.position, p.radius, 1.0 / np.sqrt(p.mass), 1.0 / np.sqrt(p.inertia),
                 c.pair_i, c.pair_j, c.image, np.asarray(box.period, dtype=np.float64),
                 np.zeros(0) if box.periodic else box.position, float(young),
                 float(shear_ratio))
    size = 6 * count
    operator = scipy.sparse.linalg.LinearOperator(
        (size, size), dtype=np.float64,
        matvec=lambda v: stiffness_product(np.reshape(v, (count, 6)), *arguments).ravel())
    start = np.random.default_rng(0).random(size)     # fixed: the same iterations every run
    if not np.any(operator.matvec(start)):
        return np.inf
    largest = scipy.sparse.linalg.eigsh(operator, k=1, which="LA", tol=1e-4,
                                        ncv=min(size - 1, 20), v0=start,
                                        return_eigenvectors=False)[0]
    step = 2.0 / np.sqrt(largest)
    digits = 10.0 ** (np.floor(np.log10(step)) - 2)
    return float(np.floor(step / digits) * digits)
