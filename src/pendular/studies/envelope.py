"""Mohr–Coulomb failure envelope from triaxial-compression peaks in the p–q plane (thesis Fig. 5.4).

In axisymmetric compression the Mohr–Coulomb line tau = sigma tan(phi) + c maps to
q = M p + q0 with M = 6 sin(phi) / (3 - sin(phi)) and q0 = c 6 cos(phi) / (3 - sin(phi)).
"""

import numpy as np


def mohr_coulomb_fit(p, q, through_origin=False):
    """Least-squares line through peak points (p, q) [Pa]; returns (phi [deg], cohesion [Pa]).

    With ``through_origin`` the cohesion is fixed at 0 (a dry, cohesionless material).
    """
    p = np.asarray(p, dtype=np.float64)
    q = np.asarray(q, dtype=np.float64)
    if p.shape != q.shape or p.size < (1 if through_origin else 2):
        raise ValueError(f"need matching p and q with at least {1 if through_origin else 2} "
                         f"points, got {p.size} and {q.size}")
    if through_origin:
        slope, intercept = float(p @ q / (p @ p)), 0.0
    else:
        slope, intercept = (float(v) for v in np.polyfit(p, q, 1))
    if not 0.0 <= slope < 3.0:
        raise ValueError(f"fitted slope M = {slope:.3f} is outside the Mohr–Coulomb range [0, 3)")
    sin_phi = 3.0 * slope / (6.0 + slope)
    phi = np.arcsin(sin_phi)
    cohesion = intercept * (3.0 - sin_phi) / (6.0 * np.cos(phi))
    return float(np.degrees(phi)), float(cohesion)
