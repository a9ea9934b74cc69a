"""The trade-off study's outputs (pendular.studies.tradeoff): running a Study or a SeedStudy
and writing what it found.

``write_study`` runs a Study and writes DIR/tradeoff.json, the report DIR/tradeoff.md (the
table of runs, the noise floor, a recommendation per use) and the figure DIR/tradeoff.png (CPU
time against error, one series per knob); ``write_seed_study`` runs a SeedStudy and writes
DIR/seeds_<knob>.json and DIR/seeds_<knob>.md. The file contents are described in
pendular.studies.tradeoff.
"""

from __future__ import annotations

import dataclasses
import os
import shutil

from pendular.io.outputs import OutputFolder
from pendular.io.plots import pyplot, save_figure
from pendular.studies.tradeoff import (CONFINING, KNOBS, PAPER_ERROR, QUANTITIES, REFERENCE,
    SUCTION, USES, SeedStudy, Study, measure, noise_floor, recommendation, run_seed_study,
    seed_rows, setting, settings, text)
from pendular.utils.atomic import write_json, write_text
from pendular.utils.threads import use_threads


def fastest_within(rows, bound, default_time):
    """The row with the largest speed-up over the default run whose peak-q error is within
    ``bound``, and that speed-up."""
    within = [r for r in rows if r["peak_q_error"] <= bound and r["knob"] != "combined"]
    best = min(within, key=lambda r: r["cpu_time_s"])
    return best, default_time / best["cpu_time_s"]


def write_markdown(path, study, reference, rows, noise, floor):
    centre = settings(study.default())
    default = next(r for r in rows if r["knob"] != "combined" and r["settings"] == centre
                   and r["particles"] == study.particles)
    best, speedup = fastest_within(rows, PAPER_ERROR, default["cpu_time_s"])
    lines = [
        "# Speed against accuracy (pendular tradeoff)", "",
        f"`pendular tradeoff --out DIR --particles {study.particles} --max-strain "
        f"{study.max_strain}`: a wet triaxial (suction {SUCTION:g} Pa, lateral {CONFINING:g} Pa) "
        f"of {study.particles} spheres to {study.max_strain:g} axial strain, one knob varied at "
        "a time around the defaults; one Numba thread per run. Errors are relative to the "
        "reference run (P-wave time step at safety 0.35, inertial number 1e-4, table 700 x "
        "160): "
        f"peak q = {reference['peak_q']:.1f} Pa, Sr at peak = "
        f"{100 * reference['saturation_at_peak']:.3f} %, q'/p' at peak = "
        f"{reference['stress_ratio_at_peak']:.4f}; it took {reference['cpu_time_s']:.0f} s of "
        "CPU. Times cover wetting and shear and the run's history and summary, not the "
        "sample's preparation nor figures; CPU time (the run's "
        "process time) is the speed measure, wall time also counts whatever else the machine "
        "was running.", "",
        "![time against error](tradeoff.png)", "",
        "| knob | value | CPU [s] | wall [s] | M particle-steps/s | peak q error | "
        "Sr error | q'/p' error | error |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['knob']} | {text(r['value'])} | {r['cpu_time_s']:.1f} | "
                     f"{r['wall_time_s']:.1f} | {r['particle_steps_per_s'] / 1e6:.2f} | "
                     f"{100 * r['peak_q_error']:.2f} % | {100 * r['saturation_error']:.2f} % | "
                     f"{100 * r['stress_ratio_error']:.2f} % | {100 * r['error']:.2f} % |")
    lines += ["", "## Noise floor", "",
              f"The reference settings on {len(noise)} other samples (seeds "
              f"{', '.join(str(r['seed']) for r in noise)}, prepared the same way) differ from "
              f"the reference by up to {100 * floor['peak_q_error']:.2f} % in peak q, "
              f"{100 * floor['saturation_error']:.2f} % in Sr and "
              f"{100 * floor['stress_ratio_error']:.2f} % in q'/p' at the peak: a knob's error "
              "below this is within the scatter between samples, and a setting cannot be told "
              "from the reference by it.", "",
              "| seed | peak q [Pa] | peak q error | Sr error | q'/p' error |",
              "|---:|---:|---:|---:|---:|"]
    lines += [f"| {r['seed']} | {r['peak_q']:.1f} | {100 * r['peak_q_error']:.2f} % | "
              f"{100 * r['saturation_error']:.2f} % | {100 * r['stress_ratio_error']:.2f} % |"
              for r in noise]
    lines += ["", "## Recommendations", "",
              f"Fastest single-knob run within {PAPER_ERROR:.0%} of the reference on peak q: "
              f"{best['knob']} = {text(best['value'])}, {speedup:.2f} x faster than the "
              f"defaults ({best['cpu_time_s']:.1f} s against {default['cpu_time_s']:.1f} s of "
              "CPU).", ""]
    for use, bound in USES.items():
        chosen = recommendation(rows, bound)
        together = next(r for r in rows if r["knob"] == "combined" and r["value"] == use)
        lines += [f"**{use.capitalize()}** (each knob's cheapest setting with all three errors "
                  f"within {bound:.0%}); all of them together (sample size aside): peak q "
                  f"error {100 * together['peak_q_error']:.2f} %, largest error "
                  f"{100 * together['error']:.2f} %, {together['cpu_time_s']:.1f} s of CPU, "
                  f"{default['cpu_time_s'] / together['cpu_time_s']:.1f} x faster than the "
                  "defaults:", ""]
        for knob in KNOBS:
            if knob in chosen:
                row = chosen[knob]
                lines.append(f"- {knob} = {text(row['value'])} ({100 * row['error']:.1f} %, "
                             f"{row['cpu_time_s']:.1f} s)")
            elif any(r["knob"] == knob for r in rows):
                lines.append(f"- {knob}: no setting within {bound:.0%} (keep the reference's)")
        lines.append("")
    lines += ["Reading the table: the skin leaves the dynamics unchanged (every skin gives a "
              "bit-identical run; only its speed differs) and the record interval changes only "
              "which steps are sampled, so where the peak is read. The sample size changes the "
              "sample itself (smaller samples prepared by the same procedure are looser, with "
              "proportionally more wall layers), so its errors are a size effect, not a "
              "numerical one.", ""]
    write_text(path, "\n".join(lines) + "\n")


def plot(path, rows, floor):
    """CPU time against error, one series per knob; the noise floor ``floor`` shaded."""
    figure, axes = pyplot().subplots(figsize=(7, 5))
    for index, knob in enumerate(dict.fromkeys(r["knob"] for r in rows)):
        chosen = [r for r in rows if r["knob"] == knob]
        axes.plot([r["cpu_time_s"] for r in chosen], [100 * max(r["error"], 1e-4) for r in chosen],
                  "o-", color=f"C{index}", label=knob)
        for r in chosen:
            axes.annotate(text(r["value"]), (r["cpu_time_s"], 100 * max(r["error"], 1e-4)),
                          fontsize=6)
    axes.axhline(100 * PAPER_ERROR, color="k", ls=":", lw=1)
    axes.axhspan(1e-2, 100 * floor, color="0.85", zorder=0, label="noise floor (other samples)")
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_xlabel("CPU time, wetting and shear [s]")
    axes.set_ylabel("largest relative error [%]")
    axes.legend(fontsize=7)
    save_figure(figure, path)


#: Files the study owns in its output folder (its runs and samples are reused, not owned).
OUTPUTS = ("tradeoff.json", "tradeoff.md", "tradeoff.png")


def write_study(study, *, docs=None, log=None):
    """Run the Study ``study`` and write tradeoff.json/.md/.png into its folder (and copies
    in ``docs`` if given); returns the tradeoff.json content. One Numba thread; ``log(text)``
    hears of each run."""
    if not isinstance(study, Study):
        raise TypeError(f"study must be a pendular.studies.tradeoff.Study, got {type(study).__name__}")
    if docs is not None and not os.path.isdir(docs):
        raise ValueError(f"docs = {docs!r} is not a folder")
    use_threads(1)
    with OutputFolder(study.out, "tradeoff") as folder:
        paths = {name.rsplit(".", 1)[1]: folder.claim(name) for name in OUTPUTS}
        reference, rows, noise = measure(study, log)
        floor = noise_floor(noise)
        data = {"arguments": {**dataclasses.asdict(study), "docs": docs},
                "suction": SUCTION, "confining": CONFINING, "reference": reference,
                "rows": rows, "noise": noise, "noise_floor": floor}
        write_json(paths["json"], data)
        write_markdown(paths["md"], study, reference, rows, noise, floor)
        plot(paths["png"], rows, floor["error"])
    if docs is not None:
        for path in paths.values():
            shutil.copy(path, docs)
    return data


def write_seed_study(study, log=None):
    """Run the SeedStudy ``study``; write seeds_<knob>.json and seeds_<knob>.md in its
    folder; returns the JSON content."""
    if not isinstance(study, SeedStudy):
        raise TypeError(f"study must be a pendular.studies.tradeoff.SeedStudy, got "
                        f"{type(study).__name__}")
    stem = f"seeds_{study.knob}"
    with OutputFolder(study.out, "tradeoff") as folder:
        paths = {ext: folder.claim(f"{stem}.{ext}") for ext in ("json", "md")}
        results = run_seed_study(study, log)
        rows, scatter = seed_rows(study, results)
        data = {"arguments": dataclasses.asdict(study), "suction": SUCTION,
                "confining": CONFINING, "reference_settings": REFERENCE, "rows": rows,
                "reference_scatter": scatter, "runs": results}
        write_json(paths["json"], data)
        write_seed_markdown(paths["md"], study, rows, scatter)
    return data


def write_seed_markdown(path, study, rows, scatter):
    def cell(stats):
        return (f"{100 * stats['mean']:+.2f} ± {100 * stats['sd']:.2f} % "
                f"({100 * stats['largest']:.2f})")

    labels = " | ".join(label for _, label in QUANTITIES)
    lines = [f"# {study.knob} across {study.seeds} samples (pendular tradeoff --knob)", "",
             f"`pendular tradeoff --out DIR --knob {study.knob} --seeds {study.seeds} "
             f"--particles {study.particles} --max-strain {study.max_strain}`: the wet "
             f"triaxial of the trade-off study (suction {SUCTION:g} Pa, lateral {CONFINING:g} "
             f"Pa) on {study.seeds} samples (seeds {study.seed}-{study.seed + study.seeds - 1}), "
             "one Numba thread per run. On each sample: the reference (time-step safety "
             "0.35 of the P-wave estimate, inertial number 1e-4, table 700 x 160) and every "
             f"setting of {study.knob}.", "",
             "**Same sample** (paired): each quantity's relative error against the same "
             "sample's reference, mean ± standard deviation over the samples (largest). The "
             "mean is the setting's systematic effect; the spread is the chaos of a granular "
             "run, which any change of the step turns into another trajectory.", "",
             f"| {study.knob} | CPU [s] | steps | {labels} | within the scatter |",
             "|---|---:|---:|---:|---:|---:|---|"]
    lines += [f"| {text(r['value'])} | {r['cpu_time_s']:.1f} | {r['steps']:.0f} | "
              + " | ".join(cell(r[f]["paired"]) for f, _ in QUANTITIES)
              + f" | {'yes' if r['within_scatter'] else 'no'} |"
              for r in rows if not r["prepared_with_it"]]
    lines += ["", "**Scatter between samples** (the references): "
              + ", ".join(f"{label} {scatter[f]['mean']:.4g} ± "
                          f"{100 * scatter[f]['relative_sd']:.2f} %" for f, label in QUANTITIES)
              + ". A setting is within the scatter when the mean of its errors is within one "
              "standard deviation of the references across samples, for all three.", ""]
    if any(r["prepared_with_it"] for r in rows):
        default = setting(study.study(study.seed).default(), study.knob)
        chains = [r for r in rows if r["prepared_with_it"] or r["value"] == default]
        lines += ["**Samples prepared with the setting** (the whole chain it gives, against "
                  "the default's on its own samples; other samples, so not paired): each "
                  "quantity against the references' mean, mean ± standard deviation over the "
                  "samples (largest), and the samples' porosity and coordination.", "",
                  f"| {study.knob} | samples | porosity | coordination | CPU [s] | {labels} |",
                  "|---|---|---:|---:|---:|---:|---:|---:|"]
        lines += [f"| {text(r['value'])} | "
                  f"{'prepared with it' if r['prepared_with_it'] else f'default ({default})'} | "
                  f"{r['porosity']:.4f} | {r['coordination']:.2f} | {r['cpu_time_s']:.1f} | "
                  + " | ".join(cell(r[f]["against_references"]) for f, _ in QUANTITIES) + " |"
                  for r in chains]
    write_text(path, "\n".join(lines) + "\n")
