"""Regenerate the README's figure and its numbers from the current code: one number, one source.

    python docs/figures/make_readme_figure.py [--run DIR] [--machine TEXT]

Runs the README's main job, ``python scenarios/triaxial.py --particles 1000 --suction 30000
--out DIR`` (DIR = runs/readme_figure; 1,000 spheres, 750 Pa, 30 kPa, 25 % axial strain; a few
minutes on 2 cores), unless ``--run DIR`` names a finished run of that command. Copies its
figures into docs/figures/ (wet_triaxial.png, wet_triaxial_stress_ratio.png,
wet_triaxial_saturation.png, wet_triaxial_capillary_stress.png) and writes
docs/figures/wet_triaxial.json: the command, date, machine, pendular version, the run's whole
summary.json (SI units, as pendular.io.schema declares them) and ``substitutions``, the numbers
the docs quote, rounded as printed. docs/conf.py hands them to MyST, so that a page writes
``{{ readme_peak_q_kpa }}`` and never a number of its own.
"""

import argparse
import datetime
import json
import os
import platform
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
COMMAND = ["scenarios/triaxial.py", "--particles", "1000", "--suction", "30000"]
#: Files of the run's folder and their names under docs/figures/.
FIGURES = {"triaxial.png": "wet_triaxial.png",
           os.path.join("plots", "q_p.png"): "wet_triaxial_stress_ratio.png",
           os.path.join("plots", "saturation.png"): "wet_triaxial_saturation.png",
           os.path.join("plots", "capillary_stress.png"): "wet_triaxial_capillary_stress.png"}


def substitutions(summary):
    """The numbers the docs quote, as text [units in the names: kPa, %, deg, or none]."""
    return {
        "readme_peak_q_kpa": f"{summary['peak_q'] / 1000:.2f}",
        "readme_strain_at_peak_pct": f"{100 * summary['axial_strain_at_peak']:.2f}",
        "readme_porosity_dry": f"{summary['initial_porosity']:.3f}",
        "readme_porosity_wet": f"{summary['wet_porosity']:.3f}",
        "readme_saturation_start_pct": f"{100 * summary['initial_saturation']:.2f}",
        "readme_saturation_at_peak_pct": f"{100 * summary['saturation_at_peak']:.2f}",
        "readme_p_effective_at_peak_kpa": f"{summary['p_effective_at_peak'] / 1000:.2f}",
        "readme_phi_peak_deg": f"{summary['phi_peak_deg']:.1f}",
        "readme_phi_peak_effective_deg": f"{summary['phi_peak_effective_deg']:.1f}",
        "readme_steps": f"{summary['steps']:,}",
    }


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--run", default=None,
                        help="a finished run of the README's job to take the figures from")
    parser.add_argument("--out", default=os.path.join("runs", "readme_figure"),
                        help="folder of the run when it is made here")
    parser.add_argument("--machine", default=f"{platform.machine()}, {os.cpu_count()} cores",
                        help="the machine, in words, for the JSON")
    args = parser.parse_args(argv)
    folder, seconds = args.run, None
    if folder is None:
        folder = args.out
        start = time.perf_counter()
        subprocess.run([sys.executable, *COMMAND, "--out", folder], cwd=ROOT, check=True)
        seconds = time.perf_counter() - start
    folder = os.path.join(ROOT, folder)
    with open(os.path.join(folder, "summary.json"), encoding="utf-8") as handle:
        summary = json.load(handle)
    for source, target in FIGURES.items():
        shutil.copyfile(os.path.join(folder, source), os.path.join(HERE, target))
    from pendular.utils.version import software_version

    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d")
    record = {
        "command": "python " + " ".join(COMMAND) + " --out DIR",
        "script": "python docs/figures/make_readme_figure.py",
        "date": date, "machine": args.machine, "pendular_version": software_version(),
        "run_wall_time_s": seconds, "figures": sorted(FIGURES.values()),
        "substitutions": {**substitutions(summary), "readme_date": date,
                          "readme_machine": args.machine},
        "summary": summary,
    }
    with open(os.path.join(HERE, "wet_triaxial.json"), "w", encoding="utf-8") as handle:
        json.dump(record, handle, indent=1, ensure_ascii=False)
        handle.write("\n")
    print(json.dumps(record["substitutions"], indent=1, ensure_ascii=False))


if __name__ == "__main__":
    main()
