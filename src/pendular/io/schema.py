"""What every recorded column and summary key holds: units, description, dimensions, equation.

A history file's datasets are declared here once; ``pendular.io.history.write_history`` refuses a
column that is not, so a new column cannot be written without its units. Units are SI strings
("1" for dimensionless, "deg" for angles); stresses compression positive. Dimensions:
``record`` (one row per record, always first), ``axis`` (x, y, z), ``component`` (x, y, z:
the second index of a 3x3 tensor), ``grip`` (z-, z+: the grips of direct tension).

Columns by test (pendular.procedures.loading.history_columns, pendular.procedures.tension):

- triaxial, dry: step, time, axial_strain, volumetric_strain, sigma_wall, sigma_contact,
  porosity, coordination, fabric, anisotropy, unbalanced_force;
- triaxial, wet: the dry ones and saturation, suction, sigma_capillary, bridges,
  pendular_overlaps, chi, B, psi, sigma_effective, fabric_bridges, anisotropy_bridges, a_psi
  and, with exact bridges, psi_interface and sigma_effective_complete
  (pendular.homogenize.on_the_fly.CapillaryHomogenization); at a water content (closed liquid)
  liquid_bridges, liquid_film, liquid_lost;
- oedometer and isotropic paths (pendular.procedures.triaxial.OedometerTest, IsotropicTest):
  the triaxial's, and void_ratio; the oedometer k0; stage when the path has several stages;
- cyclic triaxial (pendular.procedures.cyclic.CyclicTest): the oedometer's less k0, and cycle;
- simple shear (pendular.procedures.simple_shear.SimpleShearTest): the loading path's,
  shear_strain, shear_stress and normal_stress;
- direct tension: step, time, axial_strain, tensile_stress, grip_pull, sigma_wall,
  coordination, unbalanced_force, and wet: bridges, water_content, saturation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pendular.dem.grading import GRADING_UNITS

#: Version of the history/summary layout (attributes, dimension names).
SCHEMA_VERSION = 1

#: Labels of the dimensions after ``record`` (HDF5 dimension scales, xarray coordinates).
DIMENSION_LABELS = {"axis": ("x", "y", "z"), "component": ("x", "y", "z"),
                    "grip": ("z-", "z+")}

#: Every dimension name, in the order of a 3x3 tensor's indices after the record.
DIMENSIONS = ("record", *DIMENSION_LABELS)


@dataclass(frozen=True)
class Column:
    """One recorded quantity: units (SI, "1" dimensionless), description, the dimensions after
    ``record`` (names of DIMENSION_LABELS), dtype of the stored values, thesis equation."""

    units: str
    description: str
    dims: tuple = ()
    dtype: str = "float64"
    equation: str = ""

    @property
    def shape(self):
        """Shape of one record, e.g. (3, 3) for a tensor, () for a scalar."""
        return tuple(len(DIMENSION_LABELS[dim]) for dim in self.dims)

    @property
    def is_integer(self):
        return np.dtype(self.dtype).kind in "iu"


_VECTOR = ("axis",)
_TENSOR = ("axis", "component")

#: Every history column pendular writes (triaxial dry and wet, direct tension).
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
                            "under volume control)"),
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
    "liquid_bridges": Column("m^3", "liquid held by the bridges (closed liquid: constant "
                                    "water content)"),
    "liquid_film": Column("m^3", "liquid held on grains without a bridge, from ruptured bridges "
                                 "(closed liquid)"),
    "liquid_lost": Column("m^3", "liquid of ruptured bridges removed (closed liquid, model "
                                 "'lost'); bridges + film + lost = the liquid at the start of "
                                 "the shear"),
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
}

#: Field data of the ParaView frames (pendular.io.vtk.VtkWriter: one number a .vtu file, the
#: same in the four series). A series' time axis (the .pvd ``timestep``, ParaView's time
#: slider) is one of these, named in a comment of its .pvd file.
VTK_FIELDS = {
    "step": Column("1", "time step number of the frame"),
    "time": Column("s", "simulated time; the time axis of the direct tension's vtk/ and of "
                        "vtk_prep/"),
    "axial_strain": Column("1", "axial (z) strain 1 - L/L0 of a loading path's vtk/ "
                                "(triaxial, oedometer, isotropic), compression positive, as "
                                "the history's axial_strain"),
    "axial_strain_percent": Column("%", "the same axial strain in %: the time axis of a loading "
                                        "path's vtk/"),
    "shear_strain": Column("1", "shear strain gamma of a simple shear's vtk/, as the "
                                "history's shear_strain"),
    "shear_strain_percent": Column("%", "the same shear strain in %: the time axis of a simple "
                                        "shear's vtk/"),
    "phase": Column("1", "vtk_prep/: index of the phase (0 growth, 1 friction, 2 unload, "
                         "3 equilibrate, 4 sample, 5 wetting)"),
    "mean_wall_stress": Column("Pa", "vtk_prep/: mean normal stress on the walls, compression "
                                     "positive"),
}

#: Units of a triaxial summary.json (pendular.procedures.triaxial.summarize and TriaxialTest).
TRIAXIAL_SUMMARY_UNITS = {
    "peak_axial_stress": "Pa", "peak_q": "Pa", "p_at_peak": "Pa", "lateral_stress": "Pa",
    "peak_q_effective": "Pa", "p_effective_at_peak": "Pa",
    "peak_q_effective_complete": "Pa", "p_effective_complete_at_peak": "Pa",
    "suction_at_peak": "Pa", "liquid_balance_error": "1", "liquid_lost_fraction": "1",
    "liquid_initial": "m^3", "water_content": "1", "formation_suction_pa": "Pa",
    "axial_strain_at_peak": "1",
    "peak_index": "1", "saturation_at_peak": "1", "initial_porosity": "1",
    "initial_coordination": "1", "wall_time_s": "s", "preparation_time_s": "s",
    "shear_time_s": "s", "wetting_time_s": "s", "steps": "1", "preparation_steps": "1",
    "particle_steps_per_s": "1/s", "dt": "s", "strain_rate": "1/s", "inertial_number": "1",
    "max_unbalanced_force": "1", "mean_unbalanced_force": "1", "threads": "1",
    "initial_saturation": "1", "initial_bridges": "1", "wet_porosity": "1",
    "wetting_steps": "1", "stress_balance_error": "1", "stress_balance_bound": "1",
    "stress_balance_flagged": "record", "grading": GRADING_UNITS,
    "min_axial_stress": "Pa", "phi_peak_deg": "deg", "phi_peak_effective_deg": "deg",
    "mean_stress_deviation": "1", "b_deviation": "1",
}

#: Units of an oedometer summary.json (pendular.procedures.loading.oedometer_summary).
OEDOMETER_SUMMARY_UNITS = {
    "k0": "1", "k0_effective": "1", "k0_final": "1", "axial_stress_target": "Pa",
    "axial_stress_at_load": "Pa", "lateral_stress_at_load": "Pa", "axial_strain_at_load": "1",
    "initial_void_ratio": "1", "void_ratio_at_load": "1", "constrained_modulus": "Pa",
    "constrained_modulus_tangent": "Pa", "constrained_modulus_unloading": "Pa",
    "compression_index": "1", "compression_index_effective": "1", "unload_to": "Pa",
    "axial_stress_final": "Pa", "axial_strain_final": "1", "void_ratio_final": "1",
    "swelling_index": "1", "swelling_index_effective": "1",
}

#: Units of an isotropic summary.json (pendular.procedures.loading.isotropic_summary) and of
#: a path table's (pendular.procedures.path_table.path_summary): their ``stages`` rows hold
#: the end state of each stage.
ISOTROPIC_SUMMARY_UNITS = {
    "stages": {"target": "Pa", "p": "Pa", "p_effective": "Pa", "q": "Pa", "q_effective": "Pa",
               "sigma_wall": "Pa", "void_ratio": "1", "axial_strain": "1",
               "volumetric_strain": "1", "stage": "1", "step": "1", "row": "1"},
    "final_void_ratio": "1", "peak_stage": "1",
}

#: Units of a direct-tension case (tension.json ``cases``, pendular.procedures.tension).
TENSION_SUMMARY_UNITS = {
    "void_ratio_target": "1", "void_ratio": "1", "void_ratio_box": "1", "void_ratio_wet": "1",
    "prep_friction_deg": "deg", "water_content_target": "1", "formation_suction_pa": "Pa",
    "water_content": "1", "saturation": "1", "bridges": "1", "coordination_wet": "1",
    "unbalanced_force_wet": "1", "tensile_strength_pa": "Pa", "axial_extension_at_peak": "1",
    "water_content_at_peak": "1", "bridges_at_peak": "1", "final_tensile_stress_pa": "Pa",
    "final_axial_extension": "1", "kim_measured_pa": "Pa", "packing_state_pa": "Pa",
    "relative_difference_to_kim": "1", "relative_difference_to_packing_state": "1",
    "strain_rate": "1/s", "inertial_number": "1", "mean_unbalanced_force_to_peak": "1",
    "unbalanced_force_at_peak": "1", "pull_steps": "1", "dt": "s", "wetting_time_s": "s",
    "pull_time_s": "s",
    "grading": GRADING_UNITS,
}

#: Units of the run options in campaign rows (pendular.procedures.triaxial.parameters, TensionConfig) and
#: of the columns a Chapter 5 campaign.json adds.
OPTION_UNITS = {
    "particles": "1", "radius": "m", "radius_spread": "1", "porosity": "1", "young": "Pa", "shear_ratio": "1",
    "friction": "deg", "prep_friction": "deg", "density": "kg/m^3", "damping": "1",
    "timestep_safety": "1", "prep_stress": "Pa", "confining": "Pa", "seed": "1",
    "skin_factor": "1", "max_strain": "1", "inertial_number": "1", "strain_rate": "1/s",
    "records": "1", "suction": "Pa", "wet_steps": "1", "vtk_every": "1",
    "checkpoint_every": "1", "contact_angle": "deg", "surface_tension": "N/m",
    "roughness": "1", "specific_gravity": "1", "residual": "1", "grip_depth": "1",
    "void_ratio_tolerance": "1", "vtk_frames": "1", "timestep": "s",
    "saturation_at_20_percent": "1", "water_content_percent": "%",
    "b": "1", "axial_stress": "Pa", "stresses": "Pa", "stage_steps": "1",
    "record_strain": "1", "amplitude_q": "Pa", "amplitude_strain": "1", "unload_to": "Pa",
}

#: Units of a cyclic triaxial summary.json (pendular.procedures.cyclic.cyclic_summary); its
#: ``cycles`` rows hold the measures of each cycle's loop.
CYCLIC_SUMMARY_UNITS = {
    "cycles": {"cycle": "1", "secant_modulus": "Pa", "damping_ratio": "1",
               "secant_modulus_effective": "Pa", "damping_ratio_effective": "1",
               "dissipated_energy": "Pa", "strain_energy": "Pa", "q_max": "Pa", "q_min": "Pa",
               "axial_strain_max": "1", "axial_strain_min": "1",
               "axial_strain_increment": "1", "axial_strain_accumulated": "1",
               "volumetric_strain": "1", "volumetric_strain_increment": "1", "records": "1"},
    "cycles_completed": "1", "secant_modulus_first": "Pa", "secant_modulus_last": "Pa",
    "damping_ratio_first": "1", "damping_ratio_last": "1",
    "secant_modulus_first_effective": "Pa", "secant_modulus_last_effective": "Pa",
    "damping_ratio_first_effective": "1", "damping_ratio_last_effective": "1",
    "axial_strain_accumulated": "1", "volumetric_strain_accumulated": "1",
    "axial_strain_at_load": "1", "q_at_load": "Pa",
}

#: Units of a simple shear summary.json (pendular.procedures.simple_shear.simple_shear_summary)
#: and of its options.
SIMPLE_SHEAR_SUMMARY_UNITS = {
    "peak_shear_stress": "Pa", "shear_strain_at_peak_stress": "1", "peak_stress_ratio": "1",
    "shear_strain_at_peak": "1", "normal_stress_at_peak": "Pa", "residual_stress_ratio": "1",
    "phi_residual_deg": "deg", "normal_stress_final": "Pa", "max_dilatancy": "1",
    "peak_stress_ratio_effective": "1", "shear_strain_at_peak_effective": "1",
    "phi_residual_effective_deg": "deg",
    "dilatancy_angle_deg": "deg", "volumetric_strain_of_shear": "1", "max_volume_change": "1",
    "normal_stress": "Pa",
}

#: Units of a calibration's summary.json (pendular.studies.calibration): errors and the
#: filter's uncertainty are RMS differences and variances in units of each data column's
#: range; each fitted parameter's mean, std, best, low, high and prior_std are in its own
#: ``unit``, given beside them.
CALIBRATION_SUMMARY_UNITS = {
    "best_error": "1", "seed_noise": "1", "runs": "1",
    "iterations": {"iteration": "1", "runs": "1", "sigma": "1", "best_error": "1",
                   "weighted_error": "1"},
}

#: Units of the columns of a calibration's posterior.csv beside the fitted options (in their
#: own units, OPTION_UNITS): the posterior weight of the sample in its iteration, and its RMS
#: error to the data in units of each data column's range.
POSTERIOR_UNITS = {"iteration": "1", "sample": "1", "weight": "1", "error": "1"}

#: Units of every summary key pendular writes (summary.json, tension.json cases, campaign
#: rows); keys not listed are text, flags or nested records. A summary.json carries the units
#: of its own keys in its ``units`` block.
SUMMARY_UNITS = {**OPTION_UNITS, **TENSION_SUMMARY_UNITS, **TRIAXIAL_SUMMARY_UNITS,
                 **OEDOMETER_SUMMARY_UNITS, **ISOTROPIC_SUMMARY_UNITS, **CYCLIC_SUMMARY_UNITS,
                 **SIMPLE_SHEAR_SUMMARY_UNITS, **CALIBRATION_SUMMARY_UNITS}


def still_rising(axial_strain, stress, window=0.2, min_records=5):
    """Whether ``stress`` still rises at the end of a history: the least-squares slope of the
    stress against the strain travelled over the last ``window`` of the strain range (at least
    the last ``min_records`` records) is positive by more than twice its standard error, so
    that the records' scatter alone does not make a rise (the last fifth of a test sees the
    rise of a flattening curve that the scatter hides over a shorter span). Either sign of the
    strain (tension)."""
    strain, stress = _strain_and_stress(axial_strain, stress)
    travelled = np.abs(strain - strain[0])
    before = np.flatnonzero(travelled < (1.0 - window) * travelled[-1])
    start = before[-1] + 1 if len(before) else 0
    rows = slice(min(start, max(len(strain) - min_records, 0)), None)
    x, y = travelled[rows], stress[rows]
    if len(x) < 3:                 # no scatter to judge by: the last step decides
        return bool(y[-1] > y[0])
    dx = x - x.mean()
    spread = np.sum(dx * dx)
    if spread == 0.0:
        return False
    slope = np.sum(dx * (y - y.mean())) / spread
    residual = y - y.mean() - slope * dx
    error = np.sqrt(np.sum(residual * residual) / (len(x) - 2) / spread)
    return bool(slope > 2.0 * error)


def peak_reached(axial_strain, stress, fraction=0.02, window=0.2, min_records=5):
    """Whether the maximum of ``stress`` (q, or -q in extension, or a tensile stress) over a
    history is a peak the test went past: False when it lies within the last ``fraction`` of
    the strain range, when it lies within the last ``window`` and the stress still rises there
    (still_rising, at least ``min_records`` records: the test ended on its way up), or when
    the strain did not move. A maximum before the last ``window`` is a peak even when q rises
    again at the end below it (a stick-slip tooth, a late hardening). On a plateau with
    scatter (a loose sample at critical state) the maximum is taken as the peak: True, unless
    the scatter puts it in the last ``fraction``, or in the last ``window`` with an upward
    trend there beyond twice the slope's standard error."""
    strain, stress = _strain_and_stress(axial_strain, stress)
    span = strain[-1] - strain[0]
    if not np.isfinite(span) or span == 0.0:
        return False
    travelled = (strain[int(np.argmax(stress))] - strain[0]) / span
    if travelled >= 1.0 - fraction:
        return False
    return not (travelled >= 1.0 - window and still_rising(strain, stress, window, min_records))


def _strain_and_stress(axial_strain, stress):
    """The two series of a history as float arrays of one value per record (ValueError)."""
    strain = np.asarray(axial_strain, dtype=float)
    stress = np.asarray(stress, dtype=float)
    if strain.ndim != 1 or len(strain) == 0:
        raise ValueError(f"axial_strain has shape {strain.shape}; expected one value per record")
    if stress.shape != strain.shape:
        raise ValueError(f"stress has shape {stress.shape}; expected one value per record, "
                         f"{strain.shape}")
    return strain, stress
