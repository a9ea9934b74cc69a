"""The peak friction angle of a dry triaxial against the rolling friction, linear and
Hertz–Mindlin contacts (docs/physics.md, 'Rolling and twisting resistance').

    pendular campaign TABLE.toml --out DIR      # command "triaxial", particles 1000,
                                                # max_strain 0.15, contact and seed fixed,
                                                # rolling_friction = [0, 0.05, 0.1, 0.2, 0.3]
    python docs/figures/make_rolling_friction.py DIR/campaign.csv [...] \
        [--json docs/figures/rolling_friction.json] [--figure docs/figures/rolling_friction.png]

Reads the campaigns' campaign.csv (one row per run), keeps the finished triaxials, and writes
per contact law and seed the peak friction angle phi [deg], peak q and p [Pa], the axial strain
at the peak and the coordination and porosity of the sample before the shear, against mu_r;
the figure plots phi against mu_r, one line per law and seed.
"""

import argparse
import csv
import json

from pendular.io.plots import pyplot, save_figure

COLUMNS = {"phi_peak_deg": "deg", "peak_q": "Pa", "p_at_peak": "Pa",
           "axial_strain_at_peak": "1", "initial_coordination": "1", "initial_porosity": "1"}


def rows_of(paths):
    """The finished runs of the campaign tables ``paths``: dicts of contact, seed,
    rolling_friction and COLUMNS, sorted."""
    rows = []
    for path in paths:
        with open(path, newline="", encoding="utf-8") as handle:
            for run in csv.DictReader(handle):
                if not run.get("phi_peak_deg"):
                    continue
                rows.append({"contact": run["contact"], "seed": int(run["seed"]),
                             "particles": int(run["particles"]),
                             "rolling_friction": float(run["rolling_friction"]),
                             **{key: float(run[key]) for key in COLUMNS}})
    return sorted(rows, key=lambda r: (r["contact"], r["seed"], r["rolling_friction"]))


def figure(rows, path):
    fig, axes = pyplot().subplots(figsize=(5.5, 4.2))
    for key in sorted({(r["contact"], r["seed"]) for r in rows}):
        mine = [r for r in rows if (r["contact"], r["seed"]) == key]
        axes.plot([r["rolling_friction"] for r in mine], [r["phi_peak_deg"] for r in mine],
                  "o-" if key[0] == "linear" else "s--", label=f"{key[0]}, seed {key[1]}")
    axes.set_xlabel("rolling friction μr")
    axes.set_ylabel("peak friction angle φ [°]")
    axes.legend(fontsize=8)
    save_figure(fig, path)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("tables", nargs="+", help="campaign.csv files")
    parser.add_argument("--json", default="docs/figures/rolling_friction.json")
    parser.add_argument("--figure", default="docs/figures/rolling_friction.png")
    args = parser.parse_args(argv)
    rows = rows_of(args.tables)
    with open(args.json, "w", encoding="utf-8") as handle:
        json.dump({"units": COLUMNS, "runs": rows}, handle, indent=1)
    figure(rows, args.figure)


if __name__ == "__main__":
    main()
