"""Angle of repose of a poured pile against the rolling friction (pendular.studies.repose).

    python benchmarks/bench_repose.py [--rolling 0,0.1,0.3] [--contacts linear]
        [--grains 800] [--seeds 0] [--json docs/figures/repose.json]
        [--figure docs/figures/repose.png]
    python benchmarks/bench_repose.py --gather A.json B.json ... --json ALL.json --figure F.png

Each run pours ``--grains`` spheres of R = 1 mm, 2650 kg/m^3, E = 1e7 Pa (nu 0.3 with
Hertz–Mindlin), contact friction 30 deg, restitution 0.5, Cundall damping 0.2, g = 9.81 m/s^2
onto a rough floor of fixed spheres, until at rest, and reads the angle of the heap's flank.
The JSON holds each run's summary (angle, heap radius and height, profile, time, steps, wall
time); the figure the surface profiles and the angle against mu_r. ``--gather`` instead
reads the runs of earlier JSON files (e.g. one per seed), fits their angles again from their
profiles (pendular.studies.repose.flank_angle) and writes them together.
"""

import argparse
import json
import os
import platform
import time

from pendular.io.plots import pyplot, save_figure
from pendular.procedures.preparation import PrepareConfig
import numpy as np

from pendular.studies.repose import PileConfig, flank_angle, pour_pile


def material(contact, rolling):
    """The grains of every run, with the contact law ``contact`` and rolling friction."""
    return PrepareConfig(radius=1e-3, density=2650.0, young=1e7, poisson=0.3,
                         friction_deg=30.0, restitution=0.5, gravity=9.81,
                         rolling_friction=rolling, contact=contact)


def figure(rows, path):
    """Surface profiles h(r) of each run, and the angle against mu_r per contact law."""
    fig, (left, right) = pyplot().subplots(1, 2, figsize=(10, 4))
    for row in rows:
        left.plot([r * 1e3 for r in row["profile_r"]], [h * 1e3 for h in row["profile_h"]],
                  label=f"{row['contact']}, μr = {row['rolling_friction']:g}, seed {row['seed']}")
    left.set_xlabel("distance from the axis r [mm]")
    left.set_ylabel("surface height h [mm]")
    left.legend(fontsize=7)
    for contact in sorted({row["contact"] for row in rows}):
        mine = sorted((r for r in rows if r["contact"] == contact),
                      key=lambda r: r["rolling_friction"])
        right.plot([r["rolling_friction"] for r in mine], [r["angle_deg"] for r in mine], "o",
                   label=contact)
    right.set_xlabel("rolling friction μr")
    right.set_ylabel("angle of repose [°]")
    right.legend()
    save_figure(fig, path)


def gather(paths, json_path, figure_path):
    """The runs of the JSON files ``paths``, each angle and heap radius fitted again from its
    profile, into one JSON and its figure."""
    rows, sources = [], []
    for path in paths:
        with open(path, encoding="utf-8") as handle:
            data = json.load(handle)
        sources.append({key: data[key] for key in ("command", "date", "machine")})
        for row in data["runs"]:
            angle, edge = flank_angle(np.array(row["profile_r"]), np.array(row["profile_h"]))
            rows.append({**row, "angle_deg": angle, "heap_radius": edge,
                         "heap_height": max(row["profile_h"])})
    if json_path:
        with open(json_path, "w") as handle:
            json.dump({"sources": sources, "runs": rows}, handle, indent=1)
    if figure_path:
        figure(rows, figure_path)
    for row in rows:
        print(f"{row['contact']:>13} seed {row['seed']} mu_r {row['rolling_friction']:g}: "
              f"{row['angle_deg']:.2f} deg, heap radius {row['heap_radius'] * 1e3:.0f} mm")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rolling", default="0,0.1,0.3")
    parser.add_argument("--contacts", default="linear")
    parser.add_argument("--grains", type=int, default=800)
    parser.add_argument("--floor-side", type=float, default=64.0)
    parser.add_argument("--seeds", default="0")
    parser.add_argument("--json", default=None)
    parser.add_argument("--figure", default=None)
    parser.add_argument("--machine", default=f"{platform.machine()}, {os.cpu_count()} cores")
    parser.add_argument("--gather", nargs="+", metavar="JSON",
                        help="the runs of these JSON files, their angles fitted again")
    args = parser.parse_args(argv)
    if args.gather:
        gather(args.gather, args.json, args.figure)
        return
    rows = []
    for contact in args.contacts.split(","):
        for seed in (int(s) for s in args.seeds.split(",")):
            for rolling in (float(m) for m in args.rolling.split(",")):
                started = time.perf_counter()
                row = pour_pile(PileConfig(material(contact, rolling), grains=args.grains,
                                           floor_side=args.floor_side, seed=seed))
                row.update(contact=contact, rolling_friction=rolling, seed=seed,
                           wall_time_s=time.perf_counter() - started)
                rows.append(row)
                print(json.dumps({k: v for k, v in row.items()
                                  if not k.startswith("profile")}), flush=True)
                if args.json:       # each run as it ends: a long sweep keeps what it has
                    with open(args.json, "w") as handle:
                        json.dump({"command": "python benchmarks/bench_repose.py --rolling "
                                              f"{args.rolling} --contacts {args.contacts} "
                                              f"--grains {args.grains} --seeds {args.seeds}",
                                   "date": time.strftime("%Y-%m-%d", time.gmtime()),
                                   "machine": args.machine, "runs": rows}, handle, indent=1)
    if args.figure:
        figure(rows, args.figure)


if __name__ == "__main__":
    main()
