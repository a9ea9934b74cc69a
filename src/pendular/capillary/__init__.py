"""Liquid bridges between spheres: exact Young-Laplace solutions, tables, toroidal approximation.

Units (docs/units.md): R2 >= R1, r = R2/R1, u* = s R2/gamma, d* = D/R2, V* = V/R2**3,
F* = F/(2 pi gamma R2), nn_ii = (1/R2**2) ∫ n_i n_i dS; angles in degrees.

- solve_bridge(r, theta, u*, delta1): exact bridge from its filling angle (pendular.capillary.meniscus).
- bridge_at_distance / rupture_distance / lowest_distance: suction-controlled (pendular.capillary.suction_control).
- bridge_with_volume / rupture_distance_for_volume / volume_contour: volume-controlled (pendular.capillary.volume_control).
- BridgeTable + lookup_suction, VolumeBridgeTable + lookup_volume: tables for Numba kernels.
- toroidal_bridge: thesis Appendix A (pendular.capillary.toroidal).
- CapillaryBridges: the bridge operations of wet DEM scenes (pendular.capillary.bridges), one per
  control, SuctionBridges and VolumeBridges (``CapillaryBridges(..., control=...)`` builds
  either), their per-pair BridgeState (pendular.capillary.bridge_state) and kernels
  (pendular.capillary.bridge_kernels).
- sample_radius_ratios, table_radius_ratios: the radius-ratio nodes of a sample's bridge tables
  (pendular.capillary.radius_ratios).
- formation_suction, gravimetric_water_content: wetting at a water content (pendular.capillary.wetting).
- decompose -> PoreUnits, entry_suction: the Delaunay pore units of a packing and their throats
  (pendular.capillary.pores); find_clusters -> Clusters: clusters of filled units
  (pendular.capillary.clusters). Design: docs/liquid_clusters.md.
"""

from pendular.capillary.bridge_state import BridgeState
from pendular.capillary.clusters import Clusters, find_clusters
from pendular.capillary.bridges import (BRIDGE_MODELS, CONTROLS, LIQUID_MODELS, MAX_ROUGHNESS,
    SURFACE_TENSION, CapillaryBridges, SuctionBridges, VolumeBridges)
from pendular.capillary.meniscus import Bridge, solve_bridge
from pendular.capillary.pores import PoreUnits, decompose
from pendular.capillary.throats import entry_suction
from pendular.capillary.radius_ratios import sample_radius_ratios, table_radius_ratios
from pendular.capillary.suction_control import (bridge_at_distance, lowest_distance,
    rupture_distance)
from pendular.capillary.table import (FIELDS, YADE_RADIUS_RATIOS, BridgeTable, cache_directory,
    lookup_suction)
from pendular.capillary.toroidal import ToroidalBridge, toroidal_bridge
from pendular.capillary.validation import MAX_CONTACT_ANGLE, MAX_SOLVER_RADIUS_RATIO
from pendular.capillary.volume_control import (CONTACT_SUCTION_MAX, bridge_with_volume,
    rupture_distance_for_volume, volume_contour)
from pendular.capillary.volume_table import VOLUME_FIELDS, VolumeBridgeTable, lookup_volume
from pendular.capillary.wetting import formation_suction, gravimetric_water_content

__all__ = [
    "BRIDGE_MODELS",
    "Bridge",
    "BridgeState",
    "CapillaryBridges",
    "CONTROLS",
    "Clusters",
    "PoreUnits",
    "decompose",
    "entry_suction",
    "find_clusters",
    "LIQUID_MODELS",
    "SURFACE_TENSION",
    "SuctionBridges",
    "VolumeBridges",
    "formation_suction",
    "gravimetric_water_content",
    "sample_radius_ratios",
    "table_radius_ratios",
    "BridgeTable",
    "CONTACT_SUCTION_MAX",
    "FIELDS",
    "MAX_SOLVER_RADIUS_RATIO",
    "ToroidalBridge",
    "VOLUME_FIELDS",
    "VolumeBridgeTable",
    "YADE_RADIUS_RATIOS",
    "bridge_at_distance",
    "bridge_with_volume",
    "cache_directory",
    "lookup_suction",
    "lookup_volume",
    "lowest_distance",
    "rupture_distance",
    "rupture_distance_for_volume",
    "solve_bridge",
    "toroidal_bridge",
    "volume_contour",
]
