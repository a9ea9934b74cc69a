"""What every summary key holds: units, description, the commands writing it.

Every summary key, with its units, meaning and the commands that write it: SUMMARY_KEYS
(docs/outputs.md is generated from it and from the history columns of pendular.io.columns,
which ``pendular.io.history.write_history`` checks a history against; ``undeclared_keys``
names what a summary holds beyond them). The ParaView frames' field data: VTK_FIELDS. Units
are SI strings ("1" for dimensionless, "deg" for angles); stresses compression positive.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pendular.dem.grading import GRADING_UNITS
from pendular.io.columns import Column, LABORATORY

#: Version of the history/summary layout (attributes, dimension names).
SCHEMA_VERSION = 1

#: Field data of the ParaView frames (pendular.io.vtk.VtkWriter: one number a .vtu file, the
#: same in the four series). A series' time axis (the .pvd ``timestep``, ParaView's time
#: slider) is one of these, named in a comment of its .pvd file.
VTK_FIELDS = {
    "step": Column("1", "time step number of the frame"),
    "stage": Column("1", "the stage of an SWCC path (drying then wetting, from 0): the time "
                         "axis of its pores/"),
    "suction": Column("Pa", "the suction of the stage (an SWCC's pores/)"),
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


@dataclass(frozen=True)
class Key:
    """One summary key: its units (SI, "1" dimensionless, "record" a list of history rows; a
    dict for a nested record: the units of its fields), what it holds and the commands that
    write it (names of pendular.cli.COMMANDS)."""

    units: object
    description: str
    commands: tuple


#: The tests whose summary holds a peak of q.
SHEARS = ("triaxial", "path")
_T, _S, _C, _TEN = ("triaxial",), ("simple-shear",), ("cyclic",), ("tension",)
_E, _I, _CAL = ("envelope",), ("impact",), ("calibrate",)
_COMPRESSION = ("oedometer", "isotropic", "path")
_INDICES = ("oedometer", "isotropic")
#: The fields of a row of the SWCC (swcc.json ``drying`` and ``wetting``,
#: pendular.procedures.swcc).
SWCC_STAGE_UNITS = {"suction": "Pa", "saturation": "1", "bridges": "1",
                    "bridges_across_gaps": "1", "porosity": "1", "volumetric_strain": "1",
                    "chi": "1", "chi_tensor": "1", "psi": "Pa", "psi_interface": "Pa",
                    "sigma_wall": "Pa", "coordination": "1", "pendular_overlaps": "1",
                    "steps": "1",
                    # --liquid clusters (pendular.capillary.liquid_clusters.statistics)
                    "clusters": "1", "filled_units": "1", "pore_units": "1",
                    "liquid_in_bridges": "1", "liquid_in_clusters": "1",
                    "liquid_in_largest_cluster": "1", "largest_cluster_percolates": "1",
                    "trimers": "1", "liquid_in_trimers": "1", "psi_clusters": "Pa",
                    "saturation_pore_units": "1",
                    "chi_with_clusters": "1"}

#: The clusters' figures of a direct tension's case (--liquid clusters,
#: pendular.procedures.tension_clusters).
TENSION_CLUSTER_UNITS = {"suction": "Pa", "clusters": "1", "liquid_in_bridges": "1",
                         "liquid_in_clusters": "1", "liquid_in_largest_cluster": "1",
                         "largest_cluster_percolates": "1", "trimers": "1",
                         "liquid_in_trimers": "1", "saturation_pore_units": "1"}
#: The clusters' figures of a laboratory test at a suction (--liquid clusters,
#: pendular.procedures.loading_clusters): the tension's, the saturation of bridges and
#: clusters, chi (tr / 3) with clusters and of the bridges alone, and p' with clusters.
LABORATORY_CLUSTER_UNITS = {**TENSION_CLUSTER_UNITS, "saturation": "1",
                            "chi_with_clusters": "1", "chi": "1",
                            "p_effective_with_clusters": "Pa"}

#: Units of the run options in campaign rows (pendular.procedures.laboratory.parameters, TensionConfig) and
#: of the columns a Chapter 5 campaign.json adds.
OPTION_UNITS = {
    "particles": "1", "radius": "m", "radius_spread": "1", "porosity": "1", "young": "Pa", "shear_ratio": "1",
    "friction": "deg", "prep_friction": "deg", "rolling_friction": "1",
    "twisting_friction": "1", "gravity": "m/s^2", "wall_friction": "deg", "contact": "1", "poisson": "1",
    "restitution": "1", "wall_young": "Pa", "wall_poisson": "1", "wall_restitution": "1",
    "wall_rolling_friction": "1", "wall_twisting_friction": "1",
    "density": "kg/m^3", "damping": "1",
    "timestep_safety": "1", "prep_stress": "Pa", "confining": "Pa", "seed": "1",
    "skin_factor": "1", "max_strain": "1", "inertial_number": "1", "strain_rate": "1/s",
    "records": "1", "suction": "Pa", "wet_steps": "1", "vtk_every": "1",
    "checkpoint_every": "1", "contact_angle": "deg", "surface_tension": "N/m",
    "roughness": "1", "liquid": "1", "specific_gravity": "1", "residual": "1", "grip_depth": "1",
    "entry_suction": "1",
    "void_ratio_tolerance": "1", "vtk_frames": "1", "timestep": "s",
    "saturation_at_20_percent": "1", "water_content_percent": "%",
    "b": "1", "axial_stress": "Pa", "stresses": "Pa", "stage_steps": "1",
    "record_strain": "1", "amplitude_q": "Pa", "amplitude_strain": "1", "unload_to": "Pa",
}

#: Every summary key pendular writes (summary.json of the laboratory tests, tension.json
#: ``cases``), declared once: docs/outputs.md is generated from it, a summary's ``units`` block
#: is taken from it, and the tests refuse a written key that is not here. Keys that are text
#: or flags have units "1". Stresses compression positive; strains compression positive.
SUMMARY_KEYS = {
    # -- the peak of a shear (pendular.procedures.triaxial.summarize; path.path_summary)
    "peak_q": Key("Pa", "the peak of q: the largest in compression, the least (most "
                        "negative) in extension; q = sigma_z - (sigma_x + sigma_y)/2, the von "
                        "Mises deviatoric stress at b != 0; the '_at_peak' keys are of its "
                        "record", SHEARS),
    "peak_index": Key("1", "history row of the peak of q", SHEARS),
    "peak_axial_stress": Key("Pa", "largest axial (z) wall stress of the shear (compression)",
                             _T),
    "min_axial_stress": Key("Pa", "least axial (z) wall stress of the shear (extension)", _T),
    "axial_contact_lost": Key("1", "extension: whether the axial stress fell to 0, the axial "
                                   "walls (which cannot pull) having left the sample; the "
                                   "shear then ends there", _T),
    "p_at_peak": Key("Pa", "mean stress p = (sigma_x + sigma_y + sigma_z)/3 at the peak of q",
                     SHEARS),
    "axial_strain_at_peak": Key("1", "axial strain at the peak of q (negative in extension)",
                                SHEARS),
    "principal_difference_at_peak": Key("Pa", "sigma_1 - sigma_3, largest less least wall "
                                              "stress, at the peak of q", _T),
    "lateral_stress": Key("Pa", "mean over the shear of (sigma_x + sigma_y)/2", _T),
    "phi_peak_deg": Key("deg", "mobilised friction angle asin((sigma_1 - sigma_3)/(sigma_1 + "
                               "sigma_3)) of the net stresses at the peak (simple shear: "
                               "atan of the peak tau/sigma_n; cyclic: at a failure peak only); "
                               "null with phi_peak_note when it cannot be measured",
                        (*SHEARS, "simple-shear", "cyclic")),
    "phi_peak_note": Key("1", "why phi_peak_deg is null (text)", _T),
    "peak_reached": Key("1", "whether the maximum of q (simple shear: of tau/sigma_n) is a "
                             "peak the test went past (pendular.io.schema.peak_reached); false "
                             "when the test ended on its way up or lost axial contact",
                        (*_T, *_S)),
    "has_peak": Key("1", "path: whether a stage went past a peak of q", ("path",)),
    "peak_stage": Key("1", "path: index of the stage holding the peak of q", ("path",)),
    "saturation_at_peak": Key("1", "degree of saturation Sr at the peak of q", _T),
    "suction_at_peak": Key("Pa", "matric suction at the peak of q", _T),
    "peak_q_effective": Key("Pa", "q' of the effective stress (Eq. 3.43) at the peak of q",
                            SHEARS),
    "p_effective_at_peak": Key("Pa", "p' of the effective stress (Eq. 3.43) at the peak of q",
                               SHEARS),
    "phi_peak_effective_deg": Key("deg", "friction angle of the effective stress at the peak "
                                         "of q (simple shear: of tau'/sigma_n'); null with "
                                         "phi_peak_note when it cannot be measured",
                                  (*SHEARS, *_S)),
    "peak_q_effective_complete": Key("Pa", "q' of the complete effective stress (psi and the "
                                           "liquid-gas interface term) at the peak of q", _T),
    "p_effective_complete_at_peak": Key("Pa", "p' of the complete effective stress at the "
                                              "peak of q", _T),
    # -- the critical state (pendular.procedures.critical_state)
    "phi_cs_deg": Key("deg", "friction angle at the critical state, of the mean net stresses "
                             "over the last 5 % of axial strain; null when not reached "
                             "(critical_state_note)", _T),
    "M_cs": Key("1", "critical state stress ratio: mean |q| / mean p over that window; null "
                     "when not reached", _T),
    "void_ratio_cs": Key("1", "mean void ratio over that window; null when not reached", _T),
    "critical_state_note": Key("1", "the critical state rule as judged on this test: reached, "
                                    "or why not (q/p drift, |d eps_v / d eps_a| against their "
                                    "tolerances)", _T),
    "phi_cs_effective_deg": Key("deg", "phi_cs_deg of the effective stress (Eq. 3.43)", _T),
    "M_cs_effective": Key("1", "M_cs of the effective stress (Eq. 3.43)", _T),
    # -- how closely a shear held its path (triaxial.path_deviations)
    "mean_stress_deviation": Key("1", "--constant-p: largest |p / confining - 1| over the "
                                      "records", _T),
    "b_deviation": Key("1", "--b: largest |b measured - b| over the records with sigma_z - "
                            "sigma_x of at least a tenth of the confining stress; null "
                            "without such records", _T),
    "b_deviation_note": Key("1", "why b_deviation is null", _T),
    # -- an undrained triaxial (triaxial.undrained_summary; history excess_pore_pressure)
    "drainage": Key("1", "'undrained' when the shear held the volume (text)", _T),
    "excess_pore_pressure_at_peak": Key("Pa", "undrained: excess pore pressure Delta u of a "
                                              "saturated sample at the peak of q", _T),
    "excess_pore_pressure_final": Key("Pa", "undrained: Delta u at the end of the shear", _T),
    "excess_pore_pressure_max": Key("Pa", "undrained: the largest Delta u of the shear", _T),
    "p_min": Key("Pa", "undrained: the least mean wall stress p (the effective stress of the "
                       "saturated sample) over the shear", _T),
    "axial_strain_at_p_min": Key("1", "undrained: axial strain at p_min, where a contracting "
                                      "sample turns to dilating (phase transformation)", _T),
    "suction_final": Key("Pa", "undrained, wet: suction at the end of the shear (it changes "
                               "at a constant water content)", _T),
    "saturation_final": Key("1", "undrained, wet: Sr at the end of the shear", _T),
    "effective_stress_path": Key({"axial_strain": "1", "p": "Pa", "q": "Pa",
                                  "excess_pore_pressure": "Pa", "p_effective": "Pa",
                                  "suction": "Pa", "saturation": "1"},
                                 "undrained: the stress path at points evenly spaced over "
                                 "the history (triaxial.PATH_POINTS; each field a list): axial "
                                 "strain, p and q of the wall stresses, Delta u and, wet, p' "
                                 "of Eq. 3.43, the suction and Sr", _T),
    # -- every laboratory run (TriaxialTest's run, pendular.procedures.triaxial)
    "completed": Key("1", "whether the loading reached its end (false: interrupted or "
                          "failed; error says why)", LABORATORY),
    "phase": Key("1", "the phase a run stopped in: prepare, wet, shear, write", LABORATORY),
    "error": Key("1", "what stopped the loading, when it failed", LABORATORY),
    "stopped": Key("1", "why a loading ended before its last stage's end with its results "
                        "(the axial walls left the sample)", _T),
    "initial_porosity": Key("1", "porosity of the prepared (or loaded) sample, before any "
                                 "wetting", LABORATORY),
    "initial_coordination": Key("1", "coordination number of the prepared sample", LABORATORY),
    "porosity_before_wetting": Key("1", "wet runs: porosity of the dry sample at the "
                                        "confining stress", LABORATORY),
    "porosity_after_wetting": Key("1", "wet runs: porosity once wetted and equilibrated, the "
                                       "one the loading starts from", LABORATORY),
    "void_ratio_before_wetting": Key("1", "wet runs: e = n/(1 - n) before wetting",
                                     LABORATORY),
    "void_ratio_after_wetting": Key("1", "wet runs: e after wetting", LABORATORY),
    "wall_time_s": Key("s", "wall-clock time of the run", (*LABORATORY, "swcc", "tension")),
    "preparation_time_s": Key("s", "wall-clock time of the preparation", LABORATORY),
    "shear_time_s": Key("s", "wall-clock time of the loading", LABORATORY),
    "steps": Key("1", "time steps of the loading", LABORATORY),
    "preparation_steps": Key("1", "time steps of the preparation (by phase when a dict)",
                             LABORATORY),
    "particle_steps_per_s": Key("1/s", "particles times steps of the loading per second of "
                                       "wall-clock time", LABORATORY),
    "dt": Key("s", "time step (impact: 1/STEPS_PER_CONTACT of the contact's closed-form "
                   "duration)", (*LABORATORY, *_TEN, *_I)),
    "strain_rate": Key("1/s", "axial strain rate of the loading (tension: of the pull)",
                       (*LABORATORY, *_TEN)),
    "inertial_number": Key("1", "inertial number I = rate 2R sqrt(rho / p) at the reference "
                                "stress (GDR MiDi 2004)", (*LABORATORY, *_TEN)),
    "max_unbalanced_force": Key("1", "largest unbalanced force ratio over the records",
                                LABORATORY),
    "mean_unbalanced_force": Key("1", "mean unbalanced force ratio over the records",
                                 LABORATORY),
    "threads": Key("1", "Numba threads of the run", LABORATORY),
    "device": Key("1", "where the run ran: cpu or gpu", LABORATORY),
    "grading": Key(GRADING_UNITS, "the grading of the radii: D10, D30, D50, D60 [m], Cu, Cc, "
                                  "radius_min, radius_max, radius_mean [m]",
                   (*LABORATORY, *_TEN, "swcc")),
    "stress_balance_error": Key("1", "largest per-record |sigma_wall - Love-Weber stress of "
                                     "contacts and bridges| / p over the records: how far "
                                     "from quasi-static equilibrium", LABORATORY),
    "stress_balance_bound": Key("1", "the bound beyond which a record is flagged (0.05)",
                                LABORATORY),
    "stress_balance_flagged": Key("record", "history rows whose stress balance error exceeds "
                                            "the bound", LABORATORY),
    # -- the wetting (triaxial.wetting_report)
    "wetting": Key("1", "laboratory tests: the wetting protocol (text: isotropic, "
                        "at-shear, constant-volume, water-content); swcc: the rows of the "
                        "wetting branch, their fields as drying's", (*LABORATORY, "swcc")),
    "wetting_steps": Key("1", "time steps of the wetting's equilibria", LABORATORY),
    "wetting_time_s": Key("s", "wall-clock time of the wetting", (*LABORATORY, *_TEN)),
    "initial_saturation": Key("1", "degree of saturation Sr once wetted", LABORATORY),
    "initial_bridges": Key("1", "liquid bridges once wetted", LABORATORY),
    "wet_porosity": Key("1", "porosity once wetted (as porosity_after_wetting)", LABORATORY),
    "sigma_wall_at_constant_volume": Key("Pa", "constant-volume wetting: the wall stresses "
                                               "(x, y, z) the bridges made, walls fixed",
                                         LABORATORY),
    "wetting_attempts": Key({"formation_suction_pa": "Pa", "steps": "1",
                             "water_volume": "m^3", "water_content": "1"},
                            "water-content wetting: each try at a formation suction, its "
                            "steps and the liquid its bridges held (tension: as a water "
                            "content)", (*LABORATORY, *_TEN)),
    "formation_suction_pa": Key("Pa", "water-content wetting: the suction the bridges formed "
                                      "at", (*LABORATORY, *_TEN)),
    "water_content": Key("1", "gravimetric water content w held by the bridges (tension: of "
                              "the case after wetting)", (*LABORATORY, *_TEN)),
    "liquid_initial": Key("m^3", "closed liquid: the liquid at the start of the loading",
                          LABORATORY),
    "liquid_balance_error": Key("1", "closed liquid: largest |bridges + film + lost - "
                                     "initial| / initial over the records", LABORATORY),
    "liquid_lost_fraction": Key("1", "closed liquid: the fraction of the liquid lost by the "
                                     "end", LABORATORY),
    # -- oedometer (oedometer_summary)
    "k0": Key("1", "K0 = sigma_lateral / sigma_axial of the wall stresses at the axial stress "
                   "target", ("oedometer",)),
    "k0_effective": Key("1", "K0 of the effective stress (Eq. 3.43) there", ("oedometer",)),
    "k0_final": Key("1", "K0 at the end of the unloading", ("oedometer",)),
    "axial_stress_target": Key("Pa", "--axial-stress, the loading's target", ("oedometer",)),
    "axial_stress_at_load": Key("Pa", "axial stress at the end of the loading",
                                ("oedometer",)),
    "lateral_stress_at_load": Key("Pa", "lateral stress at the end of the loading",
                                  ("oedometer",)),
    "axial_strain_at_load": Key("1", "axial strain at the end of the (first) loading",
                                ("oedometer", *_C)),
    "initial_void_ratio": Key("1", "void ratio the loading starts from (after any wetting)",
                              _COMPRESSION),
    "void_ratio_at_load": Key("1", "void ratio at the end of the loading", ("oedometer",)),
    "constrained_modulus": Key("Pa", "secant constrained modulus M = delta sigma_v / "
                                     "delta eps_a over the loading", ("oedometer",)),
    "constrained_modulus_tangent": Key("Pa", "tangent M over the last 20 % of the loading's "
                                             "strain", ("oedometer",)),
    "constrained_modulus_tangent_note": Key("1", "why constrained_modulus_tangent is null",
                                            ("oedometer",)),
    "constrained_modulus_unloading": Key("Pa", "secant M of the unloading", ("oedometer",)),
    "compression_index": Key("1", "Cc = -delta e / delta log10 sigma over the loading "
                                  "(isotropic: of p)", _INDICES),
    "compression_index_effective": Key("1", "Cc against the effective stress", _INDICES),
    "swelling_index": Key("1", "Cs = -delta e / delta log10 sigma over the unloading",
                          _INDICES),
    "swelling_index_effective": Key("1", "Cs against the effective stress", _INDICES),
    "unload_to": Key("Pa", "--unload-to, the unloading's target", ("oedometer",)),
    "axial_stress_final": Key("Pa", "axial stress at the end of the path", ("oedometer",)),
    "axial_strain_final": Key("1", "axial strain at the end of the path", ("oedometer",)),
    "void_ratio_final": Key("1", "void ratio at the end of the path", ("oedometer",)),
    # -- isotropic and path tables (isotropic_summary, path.path_summary)
    "stages": Key({"target": "Pa", "p": "Pa", "p_effective": "Pa", "q": "Pa",
                   "q_effective": "Pa", "sigma_wall": "Pa", "void_ratio": "1",
                   "axial_strain": "1", "volumetric_strain": "1", "stage": "1", "step": "1",
                   "row": "1", "axial_strain_change": "1", "volumetric_strain_change": "1",
                   "suction": "Pa", "saturation": "1", "water_content": "1"},
                  "one row per stage, its end state: target stress, p, q (and p', q'), "
                  "the wall stresses, e, the strains, the stage, step and history row; a "
                  "path's also the strains' changes over the stage and, wet, the suction, Sr "
                  "and water content at its end", ("isotropic", "path")),
    "final_void_ratio": Key("1", "void ratio at the end of the path", ("isotropic", "path")),
    "water_stages": Key({"stage": "1", "axial_strain_change": "1",
                         "volumetric_strain_change": "1", "suction_before": "Pa",
                         "suction_after": "Pa", "water_content_before": "1",
                         "water_content_after": "1"},
                        "path: one row per stage that changes the water "
                        "(path.wetting_strains): its index, the suction or the water "
                        "content (a fraction) before and after it, its axial and volumetric "
                        "strain changes", ("path",)),
    "collapse_strain": Key("1", "path: volumetric strain over the stages that wet the sample "
                                "(suction lowered, water content raised): at a held stress, "
                                "the collapse on wetting, compression positive", ("path",)),
    "collapse_axial_strain": Key("1", "path: axial strain over the stages that wet the sample",
                                 ("path",)),
    # -- cyclic (cyclic.cyclic_summary)
    "cycles": Key({"cycle": "1", "secant_modulus": "Pa", "damping_ratio": "1",
                   "damping_ratio_measured": "1", "damping_ratio_resolution": "1",
                   "damping_ratio_note": "1", "secant_modulus_effective": "Pa",
                   "damping_ratio_effective": "1", "damping_ratio_effective_measured": "1",
                   "damping_ratio_effective_resolution": "1",
                   "damping_ratio_effective_note": "1",
                   "dissipated_energy": "Pa", "strain_energy": "Pa", "q_max": "Pa",
                   "q_min": "Pa", "axial_strain_max": "1", "axial_strain_min": "1",
                   "axial_strain_increment": "1", "axial_strain_accumulated": "1",
                   "volumetric_strain": "1", "volumetric_strain_increment": "1",
                   "records": "1"},
                  "one row per complete cycle: its loop's secant modulus E_sec and damping "
                  "ratio D = W_D / (4 pi W_S) (null below its resolution, with the measured "
                  "value, the resolution and a note), W_D, W_S, the extremes of q and "
                  "strain, the strains' increments and accumulation, the rows of the loop", _C),
    "cycles_completed": Key("1", "complete cycles", _C),
    "secant_modulus_first": Key("Pa", "E_sec of the first cycle", _C),
    "secant_modulus_last": Key("Pa", "E_sec of the last cycle", _C),
    "damping_ratio_first": Key("1", "D of the first cycle (null below its resolution)", _C),
    "damping_ratio_last": Key("1", "D of the last cycle (null below its resolution)", _C),
    "damping_ratio_note": Key("1", "which cycles' D are below their resolution", _C),
    "secant_modulus_first_effective": Key("Pa", "E_sec of the effective q', first cycle", _C),
    "secant_modulus_last_effective": Key("Pa", "E_sec of the effective q', last cycle", _C),
    "damping_ratio_first_effective": Key("1", "D of the effective q', first cycle", _C),
    "damping_ratio_last_effective": Key("1", "D of the effective q', last cycle", _C),
    "axial_strain_accumulated": Key("1", "axial strain accumulated over the cycles since the "
                                         "first loading (ratcheting)", _C),
    "volumetric_strain_accumulated": Key("1", "volumetric strain accumulated over the cycles",
                                         _C),
    "q_at_load": Key("Pa", "q at the end of the first loading", _C),
    # -- simple shear (simple_shear.simple_shear_summary)
    "peak_shear_stress": Key("Pa", "the largest shear stress tau; its companions end in "
                                   "'_at_peak_stress'", _S),
    "shear_strain_at_peak_stress": Key("1", "gamma at the largest tau", _S),
    "normal_stress_at_peak_stress": Key("Pa", "sigma_n at the largest tau", _S),
    "peak_shear_stress_reached": Key("1", "whether the largest tau is a peak the test went "
                                          "past", _S),
    "peak_stress_ratio": Key("1", "the peak of tau / sigma_n; its companions end in "
                                  "'_at_peak'", _S),
    "shear_strain_at_peak": Key("1", "gamma at the peak of tau / sigma_n", _S),
    "normal_stress_at_peak": Key("Pa", "sigma_n at the peak of tau / sigma_n", _S),
    "shear_stress_at_peak": Key("Pa", "tau at the peak of tau / sigma_n", _S),
    "residual_stress_ratio": Key("1", "mean tau / sigma_n over the last fifth of the shear "
                                      "strain", _S),
    "phi_residual_deg": Key("deg", "atan of residual_stress_ratio", _S),
    "phi_residual_note": Key("1", "why residual_stress_ratio and phi_residual_deg are null",
                             _S),
    "normal_stress_final": Key("Pa", "sigma_n at the end", _S),
    "max_dilatancy": Key("1", "drained: the largest -d eps_v / d gamma over windows of a "
                              "tenth of the shear strain range (dilation positive)", _S),
    "dilatancy_angle_deg": Key("deg", "atan of max_dilatancy", _S),
    "max_dilatancy_note": Key("1", "why max_dilatancy and dilatancy_angle_deg are null", _S),
    "volumetric_strain_of_shear": Key("1", "drained: eps_v at the end, from the shear's start",
                                      _S),
    "max_volume_change": Key("1", "constant volume (simple shear --constant-volume, undrained "
                                  "triaxial): the largest |V / V_start - 1|, the volume held "
                                  "(round-off)", (*_T, *_S)),
    "peak_stress_ratio_effective": Key("1", "wet: the peak of tau' / sigma_n'", _S),
    "shear_strain_at_peak_effective": Key("1", "wet: gamma at the peak of tau' / sigma_n'", _S),
    "phi_residual_effective_deg": Key("deg", "wet: the residual friction angle of tau' / "
                                             "sigma_n'", _S),
    # -- direct tension, one case of tension.json (pendular.procedures.tension)
    "void_ratio_target": Key("1", "the case's void ratio target", _TEN),
    "void_ratio": Key("1", "void ratio of the sample's core after preparation", _TEN),
    "void_ratio_box": Key("1", "void ratio of the box inside the walls", _TEN),
    "void_ratio_wet": Key("1", "void ratio of the core once wetted", _TEN),
    "prep_friction_deg": Key("deg", "friction angle of the preparation that reached the void "
                                    "ratio", _TEN),
    "water_content_target": Key("1", "the case's water content target", _TEN),
    "saturation": Key("1", "degree of saturation once wetted", _TEN),
    "bridges": Key("1", "liquid bridges once wetted", _TEN),
    "coordination_wet": Key("1", "coordination number once wetted", _TEN),
    "unbalanced_force_wet": Key("1", "unbalanced force ratio once wetted", _TEN),
    "tensile_strength_pa": Key("Pa", "the peak of the tensile stress", _TEN),
    "axial_extension_at_peak": Key("1", "axial extension at the peak", _TEN),
    "water_content_at_peak": Key("1", "water content at the peak", _TEN),
    "bridges_at_peak": Key("1", "liquid bridges at the peak", _TEN),
    "final_tensile_stress_pa": Key("Pa", "tensile stress at the end of the pull", _TEN),
    "final_axial_extension": Key("1", "axial extension at the end of the pull", _TEN),
    "ruptured": Key("1", "whether the stress fell below --residual of the strength", _TEN),
    "kim_measured_pa": Key("Pa", "Kim's (2001) measured strength of the case, null outside "
                                 "his cases", _TEN),
    "packing_state_pa": Key("Pa", "the packing-state prediction of the strength", _TEN),
    "packing_state_packing": Key("1", "the regular packing of that prediction (text)", _TEN),
    "relative_difference_to_kim": Key("1", "strength / Kim's - 1", _TEN),
    "relative_difference_to_packing_state": Key("1", "strength / prediction - 1", _TEN),
    "mean_unbalanced_force_to_peak": Key("1", "mean unbalanced force ratio before the peak",
                                         _TEN),
    "unbalanced_force_at_peak": Key("1", "unbalanced force ratio at the peak", _TEN),
    "pull_steps": Key("1", "time steps of the pull", _TEN),
    "pull_time_s": Key("s", "wall-clock time of the pull", _TEN),
    "grip_particles": Key("1", "particles held by each grip (z-, z+)", _TEN),
    "case": Key("1", "the case's name: e<void ratio>_w<water content %>", _TEN),
    "cluster_updates": Key("1", "--liquid clusters: updates of the clusters during the "
                                "loading (one every 50 history rows)", LABORATORY),
    "cluster_update_time_s": Key("s", "--liquid clusters: wall-clock time of those updates",
                                 LABORATORY),
    "clusters_final": Key(LABORATORY_CLUSTER_UNITS, "--liquid clusters: the clusters' figures "
                          "at the history's last row (their number, the liquid's fractions, "
                          "percolation, saturations, chi with clusters and of the bridges, "
                          "p' = p + chi_with_clusters s)",
                          ("oedometer", "isotropic", "cyclic", "path", "simple-shear")),
    "clusters_wet": Key(LABORATORY_CLUSTER_UNITS, "--liquid clusters: the suction that holds "
                        "(tension) or is imposed on (a laboratory test) the water once wetted "
                        "and the clusters then (their number, the liquid's fractions in "
                        "bridges, clusters and the largest, its percolation along x, y, z, the "
                        "saturation of the pore units; a laboratory test adds the saturation, "
                        "chi with clusters and p' = p + chi_with_clusters s)",
                        (*_TEN, *LABORATORY)),
    "clusters_at_peak": Key(LABORATORY_CLUSTER_UNITS, "--liquid clusters: the same at the peak "
                            "(the history's row; a triaxial or path adds the bridges' chi)",
                            (*_TEN, *SHEARS)),
    # -- the soil-water characteristic curve, swcc.json (pendular.procedures.swcc)
    "drying": Key(SWCC_STAGE_UNITS, "one row per suction of the drying branch, each stage's "
                               "equilibrium: suction, Sr, bridges (and across gaps), "
                               "porosity, eps_v, chi (its trace / 3, and the tensor), psi, "
                               "the interface term, the wall stresses, coordination, "
                               "overlapping menisci, steps", ("swcc",)),
    "hysteresis": Key({"suction": "Pa", "saturation_difference": "1",
                       "bridges_difference": "1"},
                      "per suction, drying less wetting: Sr and bridges", ("swcc",)),
    "bridges_formed_across_gaps": Key("1", "bridges formed across gaps over the path",
                                      ("swcc",)),
    "regular_packings": Key("1", "chi of the regular packings (scp, bcc, fcp) at each "
                                 "suction, null where their bridges merge (thesis Ch. 4)",
                            ("swcc",)),
    "thesis_fig_5_5": Key("1", "the thesis's Fig. 5.5 Sr read at its suctions [Pa] "
                               "(reference values)", ("swcc",)),
    "preparation": Key({"porosity": "1", "coordination": "1", "steps": "1"},
                       "the prepared sample: porosity, coordination, steps by phase",
                       ("swcc",)),
    "config": Key("1", "the run's configuration (pendular.procedures.config.config_to_dict)",
                  ("swcc",)),
    # -- a strength envelope (pendular.studies.envelope): the Mohr–Coulomb line q = M p + q0,
    # M = 6 sin(phi) / (3 - sin(phi)), q0 = c 6 cos(phi) / (3 - sin(phi)), fitted to the
    # tests' peaks in net stresses and ('_effective') in the effective stresses of Eq. 3.43
    **{name.format(suffix): Key(units, f"{text} ({stresses})", _E)
       for suffix, stresses in (("", "net stresses"),
                                ("_effective", "effective stresses, Eq. 3.43; dry: the net"))
       for name, units, text in (
           ("phi{}_deg", "deg", "friction angle phi of the Mohr–Coulomb line fitted to the "
                                "tests' peaks"),
           ("phi{}_error_deg", "deg", "standard error of phi (delta method; null with two "
                                      "tests, fit_error_note)"),
           ("phi{}_through_origin_deg", "deg", "phi of the line through the origin (c = 0)"),
           ("cohesion{}", "Pa", "cohesion c of the fitted line"),
           ("cohesion{}_error", "Pa", "standard error of c (null with two tests)"),
           ("failure_line_slope{}", "1", "slope M of the failure line q = M p + q0"),
           ("failure_line_slope{}_error", "1", "standard error of M (null with two tests)"),
           ("failure_line_intercept{}", "Pa", "intercept q0 of the failure line"),
           ("failure_line_intercept{}_error", "Pa", "standard error of q0 (null with two "
                                                    "tests)"))},
    "confining": Key("Pa", "envelope: the tests' confining stresses", _E),
    "suction": Key("Pa", "envelope: the tests' suction (null at a water content, where each "
                         "test's is an output)", _E),
    "water_content_percent": Key("%", "envelope: the tests' water content (--water-content)",
                                 _E),
    "particles": Key("1", "envelope: particles of each test's sample", _E),
    "fit_points": Key("1", "tests the lines are fitted to", _E),
    "degrees_of_freedom": Key("1", "of the fit: fit_points - 2", _E),
    "fit_error_note": Key("1", "why the standard errors are null (two tests: no scatter)", _E),
    "effective_note": Key("1", "dry tests: the effective stress is the net stress", _E),
    "peak_not_reached": Key("Pa", "confining stresses of the tests whose q still rose at "
                                  "their end (peak_reached false)", _E),
    "tests": Key({"run": "1", "reused": "1", "confining": "Pa", "peak_q": "Pa",
                  "p_at_peak": "Pa", "peak_axial_stress": "Pa", "axial_strain_at_peak": "1",
                  "phi_peak_deg": "deg", "peak_reached": "1", "saturation_at_peak": "1",
                  "suction_at_peak": "Pa", "peak_q_effective": "Pa",
                  "p_effective_at_peak": "Pa", "phi_peak_effective_deg": "deg",
                  "sigma_1_at_peak": "Pa", "sigma_3_at_peak": "Pa",
                  "sigma_1_effective_at_peak": "Pa", "sigma_3_effective_at_peak": "Pa"},
                 "envelope: one row per triaxial, by confining stress: its run folder, "
                 "whether an earlier run was reused, its peak (its summary.json's keys) and the "
                 "principal stresses there, sigma_1 = p + 2q/3 and sigma_3 = p - q/3, net and "
                 "effective", _E),
    # -- one collision, summary.json of ``pendular impact`` (pendular.procedures.impact)
    "effective_modulus": Key("Pa", "impact: Hertz's E* of the contact, the sphere's and its "
                                   "target's (pendular.dem.material); null with the linear "
                                   "law", _I),
    "contact_restitution": Key("1", "impact: the coefficient of restitution the contact is "
                                    "damped for: the sphere's, or with a wall the mean of "
                                    "the sphere's and the wall's", _I),
    "max_normal_force": Key("N", "impact: the peak normal contact force on the sphere", _I),
    "max_overlap": Key("m", "impact: the peak overlap of the sphere with its target", _I),
    "contact_duration": Key("s", "impact: how long the normal force was positive", _I),
    "normal_restitution": Key("1", "impact: -(rebound / incident) velocity of the sphere's "
                                   "centre along the initial normal", _I),
    "tangential_restitution": Key("1", "impact: rebound / incident velocity of the sphere's "
                                       "centre along the incident tangent (signed); null at "
                                       "normal incidence", _I),
    "rebound_angular_velocity": Key("rad/s", "impact: the sphere's angular velocity after the "
                                             "contact, about the axis normal to the plane of "
                                             "incidence (positive: rolling forward)", _I),
    "rebound_angle_deg": Key("deg", "impact: angle of the rebound velocity from the normal",
                             _I),
    "rayleigh_timestep": Key("s", "impact: the Rayleigh-wave time step of the sphere "
                                  "(pendular.dem.timestep.rayleigh_timestep), for comparison",
                             _I),
    # -- a calibration, summary.json of ``pendular calibrate`` (pendular.studies.calibration):
    # errors and the filter's uncertainty are RMS differences and variances in units of each
    # data column's range
    "test": Key("1", "calibrate: the laboratory command calibrated (text)", _CAL),
    "data": Key("1", "calibrate: the measured curve's CSV (absolute path)", _CAL),
    "columns": Key("1", "calibrate: the data's columns compared, the control first", _CAL),
    "parameters": Key("1", "calibrate: per fitted option, its posterior mean and std (every "
                           "iteration's samples together), the best run's value, the prior's low, "
                           "high and std, all in the option's own unit (its field 'unit'), "
                           "and 'constrained': whether the std is at most 0.7 of the prior's "
                           "(calibration.UNCONSTRAINED_FRACTION)",
                      _CAL),
    "best_run": Key("1", "calibrate: folder of the run closest to the data (runs/<name>)",
                    _CAL),
    "best_error": Key("1", "calibrate: RMS difference of the best run's curve from the data, "
                           "in units of each data column's range", _CAL),
    "seed_noise": Key("1", "calibrate: per data column, the likelihood's variance, the "
                           "scatter between samples of different seeds at the first "
                           "iteration's best sample (the column's range squared)", _CAL),
    "iterations": Key({"iteration": "1", "runs": "1", "sigma": "1", "best_error": "1",
                       "weighted_error": "1"},
                      "calibrate: one row per iteration of the filter: its index, the runs "
                      "that finished, the filter's sigma, the least and the filter's weighted "
                      "RMS error", _CAL),
    "runs": Key("1", "calibrate: runs of every iteration together, the seed runs included",
                _CAL),
}

#: Units of the columns of a calibration's posterior.csv (pendular.studies.calibration), one row
#: per sample of every iteration; the fitted options, between ``run`` and ``weight``, are in
#: their own units (OPTION_UNITS), given in summary.json's ``units["posterior"]``.
POSTERIOR_COLUMNS = {
    "iteration": Key("1", "the filter's iteration, from 0", _CAL),
    "sample": Key("1", "the sample's index in its iteration", _CAL),
    "run": Key("1", "its run folder under runs/ (text)", _CAL),
    "weight": Key("1", "its weight in the posterior, every iteration's samples together "
                       "(summing to 1 over the file)", _CAL),
    "error": Key("1", "RMS difference of its curve from the data, in units of each data "
                      "column's range", _CAL),
}


def summary_units(command):
    """Units of the summary keys ``command`` writes (SUMMARY_KEYS)."""
    return {name: key.units for name, key in SUMMARY_KEYS.items() if command in key.commands}


def undeclared_keys(summary, command):
    """The keys of ``summary`` (a summary.json's dict, or one tension.json case) that
    SUMMARY_KEYS does not declare for ``command``, and ``key.field`` for the fields of a
    nested record's rows that its units do not declare; its ``units`` block left out."""
    found = []
    for name, value in summary.items():
        key = SUMMARY_KEYS.get(name)
        if name == "units":
            continue
        if key is None or command not in key.commands:
            found.append(name)
            continue
        rows = value if isinstance(value, list) else [value]
        if isinstance(key.units, dict) and name != "grading":
            found += [f"{name}.{field}" for row in rows if isinstance(row, dict)
                      for field in row if field not in key.units]
    return sorted(set(found))


#: Units of a direct-tension case (tension.json ``cases``, pendular.procedures.tension).
TENSION_SUMMARY_UNITS = summary_units("tension")

#: Units of every summary key pendular writes (summary.json, tension.json cases, campaign
#: rows: the run options too); a summary.json carries the units of its own keys in its
#: ``units`` block.
SUMMARY_UNITS = {**OPTION_UNITS, **{name: key.units for name, key in SUMMARY_KEYS.items()}}


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
