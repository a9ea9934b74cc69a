"""Per-bridge tensors of the unsaturated effective stress and their discrete sums (Eqs. 3.43-3.49, 4.5).

A liquid bridge wets a spherical cap of half-angle alpha (its filling angle) on each of its two
particles. In the bridge frame of one particle (origin at its centre, z along the branch vector
toward the other particle, outward unit normal n on the sphere, docs/physics.md 'Effective stress'):

- wetted-cap integral  A_ij  = ∫_{cap} R n_i n_j dΓ                       [m^3]   (Eq. 3.48)
- contact-line integral B'_ij = ∫_{contact line} R gamma n_i e_j dl          [N m]   (Eq. 3.49)

where e is the unit direction of the surface-tension force on the particle: along the liquid-gas
interface where it leaves the solid, at the contact angle theta from the wetted surface, e =
cos(theta) t + sin(theta) n with t the surface tangent pointing into the wetted cap. Its axial
part integrates to the surface-tension force of docs/physics.md 'The bridge model', 2 pi gamma R
sin(alpha) sin(alpha + theta). Both tensors are diag(a, a, c) (axisymmetric about z), so their
rotation onto a bridge normal, Rot(X) = M X M^T with M e_z = normal, does not depend on how M
turns about the normal and is the same for the normal and its opposite: each cap can be rotated
with the bridge's normal, whichever particle it sits on (docs/physics.md 'Errata': rotate onto
the actual normal, not with Eq. 3.26, which sends e_z to azimuth phi + pi).

Discrete sums over the bridges in a volume V (docs/physics.md 'Effective stress'), one cap on each
particle of a bridge (alpha = delta1 on R1, delta2 on R2):

    chi_ij  = (V_w / V) delta_ij + (1/V) sum_bridges [Rot A(R1, delta1) + Rot A(R2, delta2)]   (Eq. 3.44)
    B_ij    = (1/V) sum_bridges [Rot B'(R1, delta1) + Rot B'(R2, delta2)]                       (Eq. 3.45)
    psi_ij  = chi_ij s + B_ij                                                                  (Eq. 3.46)
    sigma'_ij = (sigma_ij - u_a delta_ij) + chi_ij s + B_ij                                    (Eq. 3.43)

with V_w = n Sr V the water volume (sum of the bridge volumes) and s = u_a - u_w the matric
suction. SI units, stresses compression positive, angles in degrees. The functions take plain
arrays (one row per bridge) so that a recorder can pass the live bridge arrays; they are
vectorised numpy, the sums built from each tensor's two diagonal values (axisymmetric_sum):
chi and B of 25,000 bridges in 4 and 5 ms (9 and 11 ms summed from (K, 3, 3) tensors).
"""

import numpy as np

from pendular.utils.validate import check_values
from pendular.homogenize.fabric import principal_anisotropy


def _versine(filling_angle):
    """1 - cos(alpha) = 2 sin^2(alpha/2), accurate for small alpha (degrees in)."""
    return 2.0 * np.sin(0.5 * np.radians(filling_angle)) ** 2


def _axisymmetric(lateral, axial):
    """diag(lateral, lateral, axial) for arrays of values: shape (..., 3, 3)."""
    lateral, axial = np.broadcast_arrays(np.asarray(lateral, float), np.asarray(axial, float))
    tensor = np.zeros(lateral.shape + (3, 3))
    tensor[..., 0, 0] = lateral
    tensor[..., 1, 1] = lateral
    tensor[..., 2, 2] = axial
    return tensor


def wetted_cap_diagonal(radius, filling_angle):
    """(lateral, axial) [m^3]: the wetted-cap integral A = diag(lateral, lateral, axial) in the
    bridge frame (wetted_cap_integral, Eq. 3.48), as arrays of the broadcast arguments."""
    radius = check_values("radius", radius, 0.0, low_inclusive=False, unit="m")
    filling_angle = check_values("filling_angle", filling_angle, 0.0, 180.0, unit="deg")
    versine = _versine(filling_angle)
    scale = np.pi * radius ** 3 / 3.0
    lateral = scale * versine**2 * (3.0 - versine)  # (1 - c)^2 (2 + c), c = 1 - versine
    axial = scale * 2.0 * versine * (3.0 - 3.0 * versine + versine**2)  # 2 (1 - c)(1 + c + c^2)
    return lateral, axial


def wetted_cap_integral(radius, filling_angle):
    """A_ij = ∫ R n_i n_j dΓ over a wetted cap of half-angle alpha, bridge frame (Eq. 3.48) [m^3].

    A = (pi R^3 / 3) diag((1 - cos a)^2 (2 + cos a), same, 2 (1 - cos^3 a)); tr A = R times the
    cap area, and A = (4/3) pi R^3 I for the whole sphere (a = 180 deg, the saturated limit).
    radius [m] and filling_angle [deg] broadcast; returns shape (..., 3, 3).
    """
    return _axisymmetric(*wetted_cap_diagonal(radius, filling_angle))


def contact_line_diagonal(radius, filling_angle, contact_angle, surface_tension):
    """(lateral, axial) [N m]: the contact-line integral B' = diag(lateral, lateral, axial) in
    the bridge frame (contact_line_integral, Eq. 3.49), as arrays of the broadcast arguments."""
    radius = check_values("radius", radius, 0.0, low_inclusive=False, unit="m")
    alpha = np.radians(check_values("filling_angle", filling_angle, 0.0, 180.0, unit="deg"))
    wetting = alpha + np.radians(check_values("contact_angle", contact_angle, 0.0, 90.0,
                                              high_inclusive=False, unit="deg"))
    surface_tension = check_values("surface_tension", surface_tension, 0.0, low_inclusive=False,
                                   unit="N/m")
    scale = np.pi * radius ** 2 * surface_tension
    lateral = -scale * np.sin(alpha) ** 2 * np.cos(wetting)
    axial = scale * np.sin(2.0 * alpha) * np.sin(wetting)
    return lateral, axial


def contact_line_integral(radius, filling_angle, contact_angle, surface_tension):
    """B'_ij = ∫ R gamma n_i e_j dl along the contact line of a cap, bridge frame (Eq. 3.49) [N m].

    B' = pi R^2 gamma diag(-sin^2 a cos(a + theta), same, sin(2a) sin(a + theta)).
    radius [m], filling_angle and contact_angle [deg], surface_tension [N/m] broadcast;
    returns shape (..., 3, 3).
    """
    return _axisymmetric(*contact_line_diagonal(radius, filling_angle, contact_angle, surface_tension))


def rotation_onto(normal):
    """Rotations M (K, 3, 3) with M e_z = normal, for unit normals (K, 3).

    The rotation about e_z x normal (Rodrigues); for normals with n_z < 0 the rotation onto
    -normal followed by a half turn about x, which keeps it well conditioned near -e_z.
    """
    normal = np.asarray(normal, dtype=float)
    flip = normal[:, 2] < 0.0
    n = np.where(flip[:, None], -normal, normal)
    x, y, z = n[:, 0], n[:, 1], n[:, 2]
    k = 1.0 / (1.0 + z)
    rotation = np.empty((len(n), 3, 3))
    rotation[:, 0, 0] = 1.0 - k * x * x
    rotation[:, 0, 1] = -k * x * y
    rotation[:, 0, 2] = x
    rotation[:, 1, 0] = -k * x * y
    rotation[:, 1, 1] = 1.0 - k * y * y
    rotation[:, 1, 2] = y
    rotation[:, 2, 0] = -x
    rotation[:, 2, 1] = -y
    rotation[:, 2, 2] = z
    rotation[flip, :, 1:] *= -1.0
    return rotation


def rotate_to_normal(local_tensor, normal):
    """Rot(X) = M X M^T: bridge-frame tensors (K, 3, 3) turned onto their normals (K, 3)."""
    rotation = rotation_onto(normal)
    return np.einsum("kia,kab,kjb->kij", rotation, local_tensor, rotation, optimize=True)


def axisymmetric_sum(lateral, axial, normal):
    """sum_k M_k diag(a_k, a_k, c_k) M_k^T (3, 3), M_k e_z = normal_k, for the per-bridge
    ``lateral`` a_k and ``axial`` c_k (K,) of axisymmetric bridge-frame tensors (A, B', the
    interface integral) and unit ``normal`` (K, 3).

    Each rotated tensor is a_k I + (c_k - a_k) n_k n_k^T whatever M_k does about the normal, so
    the sum is (sum a_k) I + sum (c_k - a_k) n_k n_k^T: O(K) without building the rotations or
    the (K, 3, 3) tensors (rotate_to_normal does, for one tensor per bridge; tests check the two
    agree)."""
    normal = np.asarray(normal, dtype=float)
    lateral = np.asarray(lateral, dtype=float)
    weight = np.asarray(axial, dtype=float) - lateral
    return lateral.sum() * np.eye(3) + (normal * weight[:, None]).T @ normal


def wetted_caps_sum(normal, radius_1, radius_2, filling_angle_1, filling_angle_2, weight=1.0):
    """sum_bridges w_k [Rot A(R1, delta1) + Rot A(R2, delta2)] (3, 3) [m^3 times w]: the sum of
    Eq. 3.44 over both caps of each bridge, each bridge weighted by ``weight`` (a scalar or (K,),
    e.g. each bridge's own suction; 1 for chi). Arguments as for effective_stress_parameter."""
    lateral_1, axial_1 = wetted_cap_diagonal(radius_1, filling_angle_1)
    lateral_2, axial_2 = wetted_cap_diagonal(radius_2, filling_angle_2)
    return axisymmetric_sum(weight * (lateral_1 + lateral_2), weight * (axial_1 + axial_2), normal)


def _bridge_arrays(normal, radius_1, radius_2, filling_angle_1, filling_angle_2, volume):
    """Checked bridge arrays: normals (K, 3), radii and filling angles (K,) each."""
    normal = np.asarray(normal, dtype=float)
    if normal.ndim != 2 or normal.shape[1] != 3:
        raise ValueError(f"normal has shape {normal.shape}; expected (K, 3) unit vectors, one per bridge")
    count = len(normal)
    arrays = []
    for name, value in (("radius_1", radius_1), ("radius_2", radius_2),
                        ("filling_angle_1", filling_angle_1), ("filling_angle_2", filling_angle_2)):
        value = np.asarray(value, dtype=float)
        if value.ndim > 1 or (value.ndim == 1 and len(value) != count):
            raise ValueError(f"{name} has shape {value.shape}; expected a scalar or ({count},), one per bridge")
        arrays.append(np.broadcast_to(value, (count,)))
    if not (np.isfinite(volume) and volume > 0.0):
        raise ValueError(f"volume = {volume} is outside the valid range (0, inf) (m^3)")
    return normal, *arrays


def effective_stress_parameter(normal, radius_1, radius_2, filling_angle_1, filling_angle_2,
                               water_volume, volume):
    """chi_ij (3, 3), dimensionless: Eq. 3.44 summed over the bridges in the volume.

    chi = (V_w / V) I + (1/V) sum_bridges [Rot A(R1, delta1) + Rot A(R2, delta2)], with
    V_w / V = n Sr. normal: (K, 3) unit bridge normals; radius_1, radius_2 [m] and
    filling_angle_1, filling_angle_2 [deg] (cap on particle 1 and on particle 2): scalars or (K,);
    water_volume: sum of the bridge volumes [m^3]; volume: V [m^3].
    """
    normal, radius_1, radius_2, filling_angle_1, filling_angle_2 = _bridge_arrays(
        normal, radius_1, radius_2, filling_angle_1, filling_angle_2, volume)
    caps = wetted_caps_sum(normal, radius_1, radius_2, filling_angle_1, filling_angle_2)
    return (water_volume * np.eye(3) + caps) / volume


def surface_tension_stress(normal, radius_1, radius_2, filling_angle_1, filling_angle_2,
                           contact_angle, surface_tension, volume):
    """B_ij (3, 3) [Pa]: Eq. 3.45 summed over the bridges in the volume.

    B = (1/V) sum_bridges [Rot B'(R1, delta1) + Rot B'(R2, delta2)]. Arguments as for
    effective_stress_parameter; contact_angle [deg] (scalar or (K,)), surface_tension [N/m].
    """
    normal, radius_1, radius_2, filling_angle_1, filling_angle_2 = _bridge_arrays(
        normal, radius_1, radius_2, filling_angle_1, filling_angle_2, volume)
    lateral_1, axial_1 = contact_line_diagonal(radius_1, filling_angle_1, contact_angle, surface_tension)
    lateral_2, axial_2 = contact_line_diagonal(radius_2, filling_angle_2, contact_angle, surface_tension)
    return axisymmetric_sum(lateral_1 + lateral_2, axial_1 + axial_2, normal) / volume


def interface_stress(normal, nn11, nn33, surface_tension, volume):
    """(gamma / V) sum_bridges ∫_interface (delta_ij - n_i n_j) dS (3, 3) [Pa]: the liquid-gas
    interface term that Eq. 3.46's psi omits (Duriez, Wan, Pouragha & Darve 2018; YADE's
    MeasureCapStress): in the bridge frame the integral is diag(nn11 + nn33, same, 2 nn11),
    since the area is 2 nn11 + nn33.

    normal: (K, 3) unit bridge normals; nn11, nn33 (K,) [m^2]: ∫ n_x n_x dS and ∫ n_z n_z dS
    over each interface in its bridge frame (capillary.CapillaryBridges.interfaces);
    surface_tension [N/m]; volume V [m^3]. psi + this term is the Love–Weber stress of the
    capillary forces, sign reversed (tests/integration/test_complete_capillary_stress.py)."""
    normal = np.asarray(normal, dtype=float).reshape(-1, 3)
    nn11 = np.broadcast_to(np.asarray(nn11, dtype=float), (len(normal),))
    nn33 = np.broadcast_to(np.asarray(nn33, dtype=float), (len(normal),))
    return surface_tension * axisymmetric_sum(nn11 + nn33, 2.0 * nn11, normal) / volume


def capillary_stress(chi, tension_stress, suction):
    """psi_ij = chi_ij s + B_ij [Pa] (Eq. 3.46); tension_stress = B_ij [Pa], suction s = u_a - u_w [Pa]."""
    return np.asarray(chi) * check_values("suction", suction, unit="Pa") + np.asarray(tension_stress)


def effective_stress(total_stress, chi, tension_stress, suction, air_pressure=0.0):
    """sigma'_ij = (sigma_ij - u_a delta_ij) + chi_ij s + B_ij [Pa], compression positive (Eq. 3.43).

    total_stress: sigma_ij [Pa]; tension_stress: B_ij [Pa]; suction s, air_pressure u_a [Pa].
    """
    return (np.asarray(total_stress) - air_pressure * np.eye(3)
            + capillary_stress(chi, tension_stress, suction))


def capillary_stress_anisotropy(psi):
    """a_psi = 5/2 (psi_z - psi_x) / tr psi from the principal values (Eq. 4.5); NaN if tr psi = 0."""
    return principal_anisotropy(psi)
