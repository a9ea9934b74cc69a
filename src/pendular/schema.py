"""What every recorded column and summary key holds: units, description, dimensions, equation.

A history file's datasets are declared here once; ``pendular.io.write_history`` refuses a
column that is not, so a new column cannot be written without its units. Units are SI strings
("1" for dimensionless); stresses compression positive. Dimensions: ``record`` (one row per
record), ``axis`` (x, y, z), ``component`` (x, y, z: the second index of a 3x3 tensor),
``grip`` (z-, z+).
"""

from __future__ import annotations

from dataclasses import dataclass

#: Version of the history/summary layout (attributes, dimension names).
SCHEMA_VERSION = 1

#: Labels of the non-record dimensions.
DIMENSION_LABELS = {"axis": ("x", "y", "z"), "component": ("x", "y", "z"),
                    "grip": ("z-", "z+")}


@dataclass(frozen=True)
class Column:
    """One recorded quantity: units, description, dims after ``record``, dtype, equation."""

    units: str
    description: str
    dims: tuple = ()
    dtype: str = "float64"
    equation: str = ""


_VECTOR = ("axis",)
_TENSOR = ("axis", "component")

#: Every history column pendular writes (triaxial dry and wet, direct tension).
HISTORY_COLUMNS = {
    "step": Column("1", "time step number", dtype="int64"),
    "time": Column("s", "simulated time"),
    "axial_strain": Column("1", "axial (z) engineering strain, compression positive"),
    "volumetric_strain": Column("1", "volumetric strain 1 - V/V0, contraction positive"),
    "sigma_wall": Column("Pa", "mean normal stress on the two walls of each axis, compression "
                               "positive (total stress)", _VECTOR),
    "sigma_contact": Column("Pa", "Love-Weber stress of the mechanical contact forces "
                                  "(sphere and wall contacts)", _TENSOR, equation="Eq. 3.41"),
    "porosity": Column("1", "porosity of the box inside the walls"),
    "coordination": Column("1", "mean number of sphere-sphere contacts per particle"),
    "fabric": Column("1", "contact fabric tensor (1/2Nc) sum n n", _TENSOR, equation="Eq. 4.1"),
    "anisotropy": Column("1", "contact fabric anisotropy 5/2 (F_z - F_x) / tr F",
                         equation="Eq. 3.51"),
    "unbalanced_force": Column("1", "mean resultant force on particles / mean contact force"),
    "saturation": Column("1", "degree of saturation Sr = liquid volume / void volume"),
    "suction": Column("Pa", "matric suction (imposed, or the bridges' mean under volume "
                            "control)"),
    "sigma_capillary": Column("Pa", "Love-Weber stress of the capillary forces (tension "
                                    "negative); sigma_wall = sigma_contact + sigma_capillary "
                                    "in equilibrium", _TENSOR),
    "bridges": Column("1", "number of liquid bridges", dtype="int64"),
    "pendular_overlaps": Column("1", "pairs of overlapping menisci on one particle (beyond "
                                     "the pendular limit)", dtype="int64"),
    "chi": Column("1", "effective stress parameter tensor chi_ij", _TENSOR, equation="Eq. 3.44"),
    "B": Column("Pa", "surface-tension stress tensor B_ij", _TENSOR, equation="Eq. 3.45"),
    "psi": Column("Pa", "capillary stress psi = chi s + B", _TENSOR, equation="Eq. 3.46"),
    "sigma_effective": Column("Pa", "effective stress diag(sigma_wall) + psi (u_a = 0)",
                              _TENSOR, equation="Eq. 3.43"),
    "fabric_bridges": Column("1", "liquid-bridge fabric tensor", _TENSOR, equation="Eq. 3.53"),
    "anisotropy_bridges": Column("1", "liquid-bridge fabric anisotropy", equation="Eq. 3.54"),
    "a_psi": Column("1", "capillary stress anisotropy 5/2 (psi_z - psi_x) / tr psi",
                    equation="Eq. 4.5"),
    "tensile_stress": Column("Pa", "mean pull of the grips over the cross-section, tension "
                                   "positive"),
    "grip_pull": Column("N", "force of the specimen on each grip, toward the specimen",
                        ("grip",)),
    "water_content": Column("1", "gravimetric water content w = V_w / (Gs V_s)"),
}

#: Units of summary.json keys (those not listed are dimensionless or text).
SUMMARY_UNITS = {
    "peak_axial_stress": "Pa", "peak_q": "Pa", "p_at_peak": "Pa", "lateral_stress": "Pa",
    "peak_q_effective": "Pa", "p_effective_at_peak": "Pa", "axial_strain_at_peak": "1",
    "saturation_at_peak": "1", "initial_porosity": "1", "initial_coordination": "1",
    "wall_time_s": "s", "preparation_time_s": "s", "shear_time_s": "s", "wetting_time_s": "s",
    "steps": "1", "preparation_steps": "1", "particle_steps_per_s": "1/s", "dt": "s",
    "strain_rate": "1/s", "inertial_number": "1", "max_unbalanced_force": "1",
    "mean_unbalanced_force": "1", "initial_saturation": "1", "initial_bridges": "1",
    "wet_porosity": "1", "wetting_steps": "1", "stress_balance_error": "1",
}


def peak_reached(axial_strain, index, fraction=0.02):
    """Whether the maximum at row ``index`` is a peak: False when it lies within the last
    ``fraction`` of the strain range (the test ended before the stress fell)."""
    first, last = float(axial_strain[0]), float(axial_strain[-1])
    span = last - first
    if span <= 0.0:
        return False
    return float(axial_strain[index]) < last - fraction * span
