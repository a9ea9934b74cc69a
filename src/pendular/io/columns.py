"""What every recorded column holds: units, description, dimensions, the commands writing it.

A history file's datasets are declared here once (``HISTORY_COLUMNS``, a Column each);
``pendular.io.history.write_history`` refuses a column that is not, so a new column cannot be
written without its units. (The ParaView frames' field data: pendular.io.schema.VTK_FIELDS.) Units are SI
strings ("1" for dimensionless, "deg" for angles); stresses compression positive. Dimensions:
``record`` (one row per record, always first), ``axis`` (x, y, z), ``component`` (x, y, z: the
second index of a 3x3 tensor), ``grip`` (z-, z+: the grips of direct tension). The summary
keys are declared in pendular.io.schema.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np


#: Labels of the dimensions after ``record`` (HDF5 dimension scales, xarray coordinates).
DIMENSION_LABELS = {"axis": ("x", "y", "z"), "component": ("x", "y", "z"),
                    "grip": ("z-", "z+")}

#: Every dimension name, in the order of a 3x3 tensor's indices after the record.
DIMENSIONS = ("record", *DIMENSION_LABELS)


@dataclass(frozen=True)
class Column:
    """One recorded quantity: units (SI, "1" dimensionless), description, the dimensions after
    ``record`` (names of DIMENSION_LABELS), dtype of the stored values, thesis equation, the
    commands whose history.h5 holds it (HISTORY_WRITERS)."""

    units: str
    description: str
    dims: tuple = ()
    dtype: str = "float64"
    equation: str = ""
    commands: tuple = ()

    @property
    def shape(self):
        """Shape of one record, e.g. (3, 3) for a tensor, () for a scalar."""
        return tuple(len(DIMENSION_LABELS[dim]) for dim in self.dims)

    @property
    def is_integer(self):
        return np.dtype(self.dtype).kind in "iu"


#: The laboratory tests (pendular.procedures.laboratory.LaboratoryTest): what every run writes.
LABORATORY = ("triaxial", "oedometer", "isotropic", "simple-shear", "cyclic", "path")

#: The commands whose history.h5 holds each column, by column: every loading path's
#: (pendular.procedures.columns.history_columns) and the SWCC's; wet, the capillary ones; the
#: closed liquid's; each test's own.
HISTORY_WRITERS = {
    **dict.fromkeys(("porosity", "volumetric_strain", "sigma_contact", "fabric", "anisotropy"),
                    (*LABORATORY, "swcc")),
    **dict.fromkeys(("step", "axial_strain", "sigma_wall", "coordination", "unbalanced_force",
                     "bridges", "saturation"), (*LABORATORY, "swcc", "tension")),
    "time": (*LABORATORY, "swcc", "tension", "impact"),
    **dict.fromkeys(("sigma_capillary", "pendular_overlaps", "chi", "B", "psi",
                     "sigma_effective", "psi_interface", "sigma_effective_complete",
                     "fabric_bridges", "anisotropy_bridges", "a_psi"), (*LABORATORY, "swcc")),
    "suction": (*LABORATORY, "swcc", "tension"),
    **dict.fromkeys(("liquid_bridges", "liquid_film", "liquid_lost"), LABORATORY),
    **dict.fromkeys(("tensile_stress", "grip_pull"), ("tension",)),
    **dict.fromkeys(("clusters", "liquid_in_bridges", "liquid_in_clusters",
                     "liquid_in_largest_cluster", "largest_cluster_percolates",
                     "trimers", "liquid_in_trimers", "saturation_pore_units",
                     "chi_with_clusters", "sigma_clusters"),
                    (*LABORATORY, "swcc", "tension")),
    "water_content": (*LABORATORY, "swcc", "tension"),
    "liquid_total": ("path",),
    "excess_pore_pressure": ("triaxial",),
    "void_ratio": ("oedometer", "isotropic", "cyclic", "path"),
    "k0": ("oedometer", "path"),
    "stage": ("oedometer", "isotropic", "simple-shear", "cyclic", "path"),
    "cycle": ("cyclic",),
    **dict.fromkeys(("shear_strain", "shear_stress", "normal_stress"), ("simple-shear",)),
    **dict.fromkeys(("overlap", "normal_force", "tangential_force", "angular_velocity"),
                    ("impact",)),
}

_VECTOR = ("axis",)
_TENSOR = ("axis", "component")

#: Every history column pendular writes (triaxial dry and wet, direct tension, impact).
HISTORY_COLUMNS = {
    "step": Column("1", "time step number", dtype="int64"),
    "time": Column("s", "simulated time"),
    "axial_strain": Column("1", "axial (z) engineering strain 1 - L/L0, compression positive "
                                "(negative in direct tension)"),
    "volumetric_strain": Column("1", "volumetric strain 1 - V/V0 of the box inside the walls, "
                                     "contraction positive (V0 at the start of the shear)"),
    "sigma_wall": Column("Pa", "mean normal stress on the two walls of each axis (total "
                               "stress; in a periodic cell the Love-Weber stress of contacts "
                               "and bridges over the cell), compression positive", _VECTOR),
    "sigma_contact": Column("Pa", "Love-Weber stress of the mechanical contact forces (sphere "
                                  "and wall contacts), compression positive", _TENSOR,
                            equation="Eq. 3.41"),
    "porosity": Column("1", "porosity of the box inside the walls"),
    "coordination": Column("1", "mean number of sphere-sphere contacts per particle, 2 Nc / N"),
    "fabric": Column("1", "contact fabric tensor (1/2Nc) sum over both orientations of n n",
                     _TENSOR, equation="Eq. 4.1"),
    "anisotropy": Column("1", "contact fabric anisotropy 5/2 (F_z - F_x) / tr F (principal "
                              "values)", equation="Eq. 3.51"),
    "unbalanced_force": Column("1", "mean resultant force on particles / mean contact force"),
    "saturation": Column("1", "degree of saturation Sr = liquid volume / void volume"),
    "suction": Column("Pa", "matric suction s = u_a - u_w (imposed, or the bridges' mean "
                            "under volume control, or a direct tension's with --liquid "
                            "clusters: the suction that holds the water)"),
    "sigma_capillary": Column("Pa", "Love-Weber stress of the capillary forces (tension "
                                    "negative); sigma_wall = sigma_contact + sigma_capillary "
                                    "in equilibrium", _TENSOR),
    "bridges": Column("1", "number of liquid bridges", dtype="int64"),
    "pendular_overlaps": Column("1", "pairs of overlapping menisci on one particle (beyond "
                                     "the pendular limit)", dtype="int64"),
    "chi": Column("1", "effective stress parameter tensor chi_ij", _TENSOR, equation="Eq. 3.44"),
    "B": Column("Pa", "surface-tension stress tensor B_ij", _TENSOR, equation="Eq. 3.45"),
    "psi": Column("Pa", "capillary stress psi_ij = chi_ij s + B_ij", _TENSOR,
                  equation="Eq. 3.46"),
    "sigma_effective": Column("Pa", "effective stress sigma'_ij = diag(sigma_wall) + psi_ij "
                                    "(u_a = 0)", _TENSOR, equation="Eq. 3.43"),
    "psi_interface": Column("Pa", "liquid-gas interface stress (gamma/V) sum ∫ (delta_ij - "
                                  "n_i n_j) dS, which psi omits", _TENSOR,
                            equation="Duriez et al. 2018"),
    "sigma_effective_complete": Column("Pa", "complete effective stress diag(sigma_wall) + "
                                             "psi_ij + psi_interface_ij (u_a = 0)", _TENSOR,
                                       equation="Eq. 3.43 + interface term"),
    "fabric_bridges": Column("1", "liquid-bridge fabric tensor (1/N_LB) sum n n", _TENSOR,
                             equation="Eq. 3.53"),
    "anisotropy_bridges": Column("1", "liquid-bridge fabric anisotropy 5/2 (F_z - F_x) / tr F "
                                      "(NaN without bridges)", equation="Eq. 3.54"),
    "a_psi": Column("1", "capillary stress anisotropy 5/2 (psi_z - psi_x) / tr psi (NaN "
                         "without bridges)", equation="Eq. 4.5"),
    "clusters": Column("1", "number of liquid clusters (connected filled pore units; "
                            "--liquid clusters)", dtype="int64"),
    "liquid_in_bridges": Column("1", "fraction of the liquid held in bridges (their shares "
                                     "outside filled pore units; --liquid clusters)"),
    "liquid_in_clusters": Column("1", "fraction of the liquid held in filled pore units "
                                      "(--liquid clusters)"),
    "liquid_in_largest_cluster": Column("1", "fraction of the liquid held in the largest "
                                             "cluster (--liquid clusters)"),
    "trimers": Column("1", "number of trimers: throats of empty pore units whose three "
                           "bridges' menisci have merged (Scheel et al. 2008; --liquid "
                           "clusters)", dtype="int64"),
    "liquid_in_trimers": Column("1", "fraction of the liquid held in the trimers' bridges, "
                                     "outside filled pore units (a part of liquid_in_bridges; "
                                     "--liquid clusters)"),
    "largest_cluster_percolates": Column("1", "1 where the largest cluster spans the sample "
                                              "along the axis, else 0 (--liquid clusters)",
                                         _VECTOR),
    "saturation_pore_units": Column("1", "liquid in the pore units over their pore volume "
                                         "(--liquid clusters; the strip along the walls "
                                         "left out)"),
    "chi_with_clusters": Column("1", "effective stress parameter of the bridges' shares "
                                     "outside the filled pore units and of the clusters, "
                                     "chi_b + psi_c / s (--liquid clusters)", _TENSOR,
                                equation="Eq. 3.44 with clusters"),
    "sigma_clusters": Column("Pa", "Love-Weber stress of the liquid clusters' forces, less "
                                   "the bridges' shares they absorb (tension negative); "
                                   "sigma_wall = sigma_contact + sigma_capillary + "
                                   "sigma_clusters in equilibrium, and the clusters' "
                                   "part of a periodic cell's stress (--liquid clusters)",
                                   _TENSOR),
    "liquid_bridges": Column("m^3", "liquid held by the bridges (closed liquid: constant "
                                    "water content)"),
    "liquid_film": Column("m^3", "liquid held on grains without a bridge, from ruptured bridges "
                                 "(closed liquid)"),
    "liquid_lost": Column("m^3", "liquid of ruptured bridges removed (closed liquid, model "
                                 "'lost'); bridges + film + lost = the liquid at the start of "
                                 "the shear"),
    "liquid_total": Column("m^3", "closed amount of liquid: the wetting's, plus what the "
                                  "water-content stages of a path added (bridges + film + lost "
                                  "= it)"),
    "excess_pore_pressure": Column("Pa", "undrained shear: excess pore pressure of a "
                                         "saturated sample from the start, Delta p_total - "
                                         "Delta p' with p_total = sigma_3 + q/3 (the "
                                         "conventional total path, sigma_3 held) and p' the "
                                         "mean wall stress"),
    "tensile_stress": Column("Pa", "mean pull of the grips over the cross-section, tension "
                                   "positive"),
    "grip_pull": Column("N", "force of the specimen on each grip, toward the specimen",
                        ("grip",)),
    "water_content": Column("1", "gravimetric water content w = V_w / (Gs V_s)"),
    "void_ratio": Column("1", "void ratio e = n / (1 - n) of the box inside the walls"),
    "k0": Column("1", "coefficient of earth pressure sigma_lateral / sigma_axial of the wall "
                      "stresses (oedometer)"),
    "stage": Column("1", "index of the stage of the loading path running (0 first)",
                    dtype="int64"),
    "cycle": Column("1", "cycle of a cyclic triaxial path running (1 first; 0 the first "
                         "loading)", dtype="int64"),
    "shear_strain": Column("1", "simple shear: shear strain gamma of x with z, the integral of "
                                "the shear rate (a periodic cell's images above in z displaced "
                                "by gamma Lz along x at a constant height)"),
    "shear_stress": Column("Pa", "simple shear: shear stress tau = -(sigma_xz + sigma_zx) / 2 "
                                 "of the cell's Love-Weber stress (compression positive), "
                                 "positive resisting a positive shear", equation="Eq. 3.41"),
    "normal_stress": Column("Pa", "simple shear: normal stress sigma_zz of the cell, "
                                  "compression positive"),
    "overlap": Column("m", "impact: overlap of the sphere with its target"),
    "normal_force": Column("N", "impact: contact force on the sphere along the normal from "
                                "its target, repulsion positive"),
    "tangential_force": Column("N", "impact: contact force on the sphere along the incident "
                                    "tangent (in the plane of incidence)"),
    "angular_velocity": Column("rad/s", "impact: the sphere's angular velocity about the axis "
                                        "normal to the plane of incidence, positive rolling "
                                        "forward"),
}

HISTORY_COLUMNS = {name: replace(column, commands=HISTORY_WRITERS.get(name, ()))
                   for name, column in HISTORY_COLUMNS.items()}
