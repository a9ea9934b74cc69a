"""What a direct tension (pendular.procedures.tension) reports over its cases: report.md (a
line and a table row per case, against Kim's (2001) measurement and the regular packing's
prediction) and the predictions drawn in plots/strength_vs_water.png. ``config`` is the
run's TensionConfig.
"""

from __future__ import annotations

import numpy as np

from pendular.procedures.reference import KIM_SEPARATION, comparison_packing
from pendular.procedures.tension_pull import prediction
from pendular.utils.atomic import write_text


def strength_predictions(summaries: list[dict], config) -> dict:
    """{void ratio: (water contents [-], tensile strengths [Pa], the packing in words)}: the
    regular packing's prediction (``prediction``) over the water contents of the cases of each
    void ratio, for plots/strength_vs_water.png."""
    curves = {}
    for e in {s["void_ratio_target"] for s in summaries}:
        highest = max(s["water_content_target"] for s in summaries
                      if s["void_ratio_target"] == e)
        grid = np.linspace(0.002, highest * 1.15, 25)
        curves[e] = (grid, [prediction(config, e, w)[0] for w in grid],
                     comparison_packing(e)[1])
    return curves


def case_line(summary: dict) -> str:
    """The progress line of a finished case (``run_case``'s summary): its strength beside
    Kim's measurement, when he made one, and the regular packing's prediction."""
    kim = summary["kim_measured_pa"]
    measured = "no Kim measurement" if kim is None else f"Kim {kim:.1f} Pa"
    return (f"  {summary['case']}: tensile strength {summary['tensile_strength_pa']:.1f} Pa "
            f"({measured}, regular packing prediction {summary['packing_state_pa']:.1f} Pa)")


def percent(value):
    return "" if value is None else f"{100 * value:+.0f} %"


def report_lines(summaries: list[dict], config) -> list[str]:
    """The lines of report.md: one table row per case."""
    sample = config.sample
    lines = [f"# Direct tension, {sample.particles} spheres, R = {sample.radius * 1e3:g} mm, "
             f"contact angle θ = {config.contact_angle:g}°, surface tension "
             f"γ = {config.surface_tension:g} N/m, bridge roughness H/R = {config.roughness:g}",
             "",
             "Tensile strength [Pa] positive in tension. e: core void ratio (box less one "
             "diameter along each wall); w: gravimetric water content (water mass over grain "
             f"mass, Gs = {config.specific_gravity:g}); Sr: degree of saturation; prediction: "
             "tensile strength psi_xx of the regular packing compared with this void ratio at "
             f"the target w (thesis Ch. 4, exact bridges, H/R = {KIM_SEPARATION:g}).",
             "",
             "| e target | e reached (box) | w target [%] | w [%] | Sr | bridges | s_form [Pa] "
             "| DEM | Kim | prediction | DEM/Kim | DEM/prediction |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for s in summaries:
        kim = "" if s["kim_measured_pa"] is None else f"{s['kim_measured_pa']:.1f}"
        lines.append(
            f"| {s['void_ratio_target']:.2f} | {s['void_ratio']:.3f} ({s['void_ratio_box']:.3f}) "
            f"| {100 * s['water_content_target']:.2f} | {100 * s['water_content']:.3f} "
            f"| {s['saturation']:.3f} | {s['bridges']} | {s['formation_suction_pa']:.0f} "
            f"| {s['tensile_strength_pa']:.1f} | {kim} | {s['packing_state_pa']:.1f} "
            f"| {percent(s['relative_difference_to_kim'])} "
            f"| {percent(s['relative_difference_to_packing_state'])} |")
    return lines


def write_report(summaries: list[dict], config, path: str) -> list[str]:
    """report.md at ``path``; returns its lines."""
    lines = report_lines(summaries, config)
    write_text(path, "\n".join(lines) + "\n")
    return lines
