"""Micromechanical effective stress (thesis Eqs. 3.41-3.57) and regular packings (Chapter 4).

- contact_stress: Love-Weber stress of the contact forces (Eq. 3.41).
- fabric_tensor, fabric_anisotropy, principal_anisotropy: fabric (Eqs. 4.1, 3.51, 3.53-3.54).
- bridge_tensors: per-bridge A_ij, B'_ij (Eqs. 3.48-3.49), their rotation onto the bridge normal
  and the discrete sums chi_ij, B_ij, psi_ij, sigma'_ij, a_psi (Eqs. 3.43-3.46, 4.5).
- harmonic: the continuous forms (Eqs. 3.50, 3.55-3.57).
- on_the_fly: the same discrete sums over the bridges of a live DEM state, for the recorders
  (homogenize_bridges, capillary_force_stress, CapillaryHomogenization).
- invariants: q and p of axisymmetric tests.
- regular_packing, packing_state: SCP, BCC, FCP and their pendular states (Tables 4.1-4.4).
"""

from pendular.homogenize.bridge_tensors import (capillary_stress, capillary_stress_anisotropy,
    contact_line_integral, effective_stress, effective_stress_parameter, interface_stress,
    rotate_to_normal, rotation_onto, surface_tension_stress, wetted_cap_integral)
from pendular.homogenize.contact_stress import contact_stress
from pendular.homogenize.fabric import fabric_anisotropy, fabric_tensor, principal_anisotropy
from pendular.homogenize.harmonic import (fabric_density, harmonic_effective_stress_parameter,
    harmonic_surface_tension_stress, thesis_rotation)
from pendular.homogenize.on_the_fly import (BridgeStress, CapillaryHomogenization,
    bridges_in_region, capillary_force_stress, homogenize_bridges)
from pendular.homogenize.packing_state import PackingState, packing_state
from pendular.homogenize.regular_packing import RegularPacking, regular_packing

__all__ = [
    "BridgeStress",
    "CapillaryHomogenization",
    "PackingState",
    "RegularPacking",
    "bridges_in_region",
    "capillary_force_stress",
    "capillary_stress",
    "capillary_stress_anisotropy",
    "contact_line_integral",
    "contact_stress",
    "effective_stress",
    "effective_stress_parameter",
    "fabric_anisotropy",
    "fabric_density",
    "fabric_tensor",
    "harmonic_effective_stress_parameter",
    "harmonic_surface_tension_stress",
    "homogenize_bridges",
    "interface_stress",
    "packing_state",
    "principal_anisotropy",
    "regular_packing",
    "rotate_to_normal",
    "rotation_onto",
    "surface_tension_stress",
    "thesis_rotation",
    "wetted_cap_integral",
]
