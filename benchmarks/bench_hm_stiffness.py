"""Small-strain stiffness of a Hertz–Mindlin packing against the confining pressure.

    python benchmarks/bench_hm_stiffness.py [--particles 300] [--young 1e9] [--poisson 0.3]
        [--pressures 1000,3000,10000,30000,100000] [--max-strain 0.0001]
        [--probe-steps 20000] [--seed 0]
        [--json docs/figures/hm_stiffness.json] [--figure docs/figures/hm_stiffness.png]

One dry sample of ``--particles`` spheres with the Hertz–Mindlin law of the grains' ``--young``
E [Pa] and ``--poisson`` is prepared at the first pressure (thesis Ch. 5.2.2,
pendular.procedures.preparation), then loaded isotropically to each pressure in turn
(six walls servoed there until static); at each, a copy is sheared in drained triaxial
compression (x, y held at the pressure) to ``--max-strain`` in ``--probe-steps`` steps (a
strain rate far below the inertial-number rate of a shear: a compression wave crosses the
sample in some 100 steps, and 1e-5 of strain at the shear's rate would be read before the
first crossing), and the secant moduli (q - q_0) / eps_a at eps_a = 1e-5 and 5e-5, and where
q - q_0 first reaches 0.01 p and 0.02 p (the same mobilisation at every pressure: the elastic
range of Hertz contacts shrinks as (p / E)^(2/3) towards low pressures, so a fixed strain lies
further out of it there), are read from its history. Hertz's contacts stiffen as
k_n ~ f^(1/3): at a fixed fabric (contacts, their directions and the coordination) a
packing's moduli grow as p^(1/3); a packing that gains contacts as it is pressed grows faster
(about p^(1/2) in sands). The
script fits the exponent n of E ~ p^n over the pressures (least squares in log-log) and
writes the table, the fit and the coordination at each pressure to the JSON and a log-log
figure.
"""

import argparse
import copy
import dataclasses
import json
import os
import platform
import time

import numpy as np

from pendular.dem.measure import coordination, porosity
from pendular.io.plots import pyplot, save_figure
from pendular.procedures.config import ShearConfig
from pendular.procedures.preparation import PrepareConfig, prepare_sample, servoed_simulation
from pendular.procedures.triaxial import TriaxialShear, equilibrate

#: The axial strains [-] of the secant moduli.
STRAINS = (1e-5, 5e-5)
#: The static state a probe starts from: unbalanced force and relative stress error [-].
EQUILIBRIUM = (2e-3, 2e-4)
#: The stress ratios q / p [-] of the secant moduli at a fixed mobilisation.
RATIOS = (0.01, 0.02)


def secant_moduli(history, pressure):
    """(q - q_0) / eps_a [Pa] at each of STRAINS, then at the first strain where q - q_0
    reaches each of RATIOS times ``pressure`` [Pa] (linear interpolation in the history; q_0
    the deviator at the start, the static sample's, within EQUILIBRIUM of the pressure)."""
    sigma = np.asarray(history["sigma_wall"], dtype=np.float64)
    strain = np.asarray(history["axial_strain"], dtype=np.float64)
    q = sigma[:, 2] - 0.5 * (sigma[:, 0] + sigma[:, 1])
    q = q - q[0]
    moduli = [float(np.interp(at, strain, q) / at) for at in STRAINS]
    for ratio in RATIOS:
        target = ratio * pressure
        k = int(np.argmax(q >= target))
        if k == 0:
            moduli.append(float("nan"))
            continue
        t = (target - q[k - 1]) / (q[k] - q[k - 1])
        moduli.append(float(target / (strain[k - 1] + t * (strain[k] - strain[k - 1]))))
    return moduli


def at_pressure(particles, walls, config, pressure, max_strain, records, probe_steps):
    """(the static state at ``pressure`` [Pa] (Particles, Walls), its row: porosity,
    coordination, secant moduli of a triaxial from it, steps)."""
    sample = dataclasses.replace(config, confining=pressure)
    sim = servoed_simulation(particles, walls, sample, pressure, threads=1)
    # far tighter than a test's equilibrium (1 % of the stress): the probe's increments at
    # 1e-5 of strain are a few tenths of a per cent of p at the highest pressures
    steps = equilibrate(sim, unbalanced=EQUILIBRIUM[0], tolerance=EQUILIBRIUM[1],
                        max_steps=2_000_000, phase=f"isotropic loading to {pressure:g} Pa")
    state = copy.deepcopy(sim.particles), copy.deepcopy(sim.walls)
    row = {"pressure": pressure, "porosity": float(porosity(sim.particles, sim.walls)),
           "coordination": float(coordination(sim.contacts, len(sim.particles))),
           "loading_steps": steps, "dt": sim.dt}
    # slow enough that the strain of each modulus takes many wave crossings of the sample
    rate = max_strain / (probe_steps * sim.dt)
    shear = TriaxialShear(sim, ShearConfig(max_strain=max_strain, records=records,
                                           strain_rate=rate), pressure, sample.radius,
                          sample.density)
    sim.run(shear.steps, status=shear.status)
    moduli = secant_moduli(shear.recorder.arrays(), pressure)
    row.update({key: value for key, value in zip(MEASURES, moduli)})
    row.update(shear_steps=shear.steps, strain_rate=rate)
    return state, row


#: The row's keys of the moduli of secant_moduli.
MEASURES = (tuple(f"secant_modulus_{at:g}" for at in STRAINS)
            + tuple(f"secant_modulus_q_over_p_{ratio:g}" for ratio in RATIOS))


def exponent(pressures, moduli):
    """n of modulus ~ pressure^n, least squares in log-log."""
    return float(np.polyfit(np.log(pressures), np.log(moduli), 1)[0])


def figure(rows, fits, path):
    """Secant moduli against the pressure, log-log, with the fits and the 1/3 and 1/2 slopes."""
    fig, axes = pyplot().subplots(figsize=(5.5, 4.2))
    pressure = np.array([row["pressure"] for row in rows])
    labels = [f"ε_a = {at:g}" for at in STRAINS] + [f"q/p = {r:g}" for r in RATIOS]
    for key, label, marker in zip(MEASURES, labels, "os^v"):
        modulus = np.array([row[key] for row in rows])
        axes.loglog(pressure, modulus, marker, label=f"q/ε_a at {label}: n = {fits[key]:.3f}")
        for slope, style in ((1.0 / 3.0, ":"), (0.5, "--")):
            axes.loglog(pressure, modulus[0] * (pressure / pressure[0]) ** slope, style,
                        color="grey", linewidth=0.8)
    axes.set_xlabel("confining pressure p [Pa]")
    axes.set_ylabel("secant modulus [Pa]")
    axes.set_title("Hertz–Mindlin: stiffness ~ p^n (dotted 1/3, dashed 1/2)", fontsize=9)
    axes.legend(fontsize=8)
    save_figure(fig, path)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--particles", type=int, default=300)
    parser.add_argument("--young", type=float, default=1e9)
    parser.add_argument("--poisson", type=float, default=0.3)
    parser.add_argument("--pressures", default="1000,3000,10000,30000,100000")
    parser.add_argument("--max-strain", type=float, default=0.0001)
    parser.add_argument("--records", type=int, default=400)
    parser.add_argument("--probe-steps", type=int, default=20000,
                        help="steps of the triaxial probe to --max-strain")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", default=None)
    parser.add_argument("--figure", default=None)
    parser.add_argument("--machine", default=f"{platform.machine()}, {os.cpu_count()} cores")
    args = parser.parse_args(argv)
    pressures = [float(p) for p in args.pressures.split(",")]
    config = PrepareConfig(particles=args.particles, confining=pressures[0], seed=args.seed,
                           contact="hertz-mindlin", young=args.young, poisson=args.poisson)
    started = time.perf_counter()
    sim, report = prepare_sample(config, progress=False, threads=1)
    state = sim.particles, sim.walls
    rows = []
    for pressure in pressures:
        state, row = at_pressure(*state, config, pressure, args.max_strain, args.records,
                                 args.probe_steps)
        rows.append(row)
        print(json.dumps(row), flush=True)
    fits = {key: exponent(pressures, [row[key] for row in rows]) for key in MEASURES}
    fits["coordination"] = exponent(pressures, [row["coordination"] for row in rows])
    result = {"command": "python benchmarks/bench_hm_stiffness.py " + " ".join(
                  f"--{key.replace('_', '-')} {value}" for key, value in
                  (("particles", args.particles), ("young", f"{args.young:g}"),
                   ("poisson", args.poisson), ("pressures", args.pressures),
                   ("max_strain", args.max_strain), ("seed", args.seed))),
              "date": time.strftime("%Y-%m-%d", time.gmtime()), "machine": args.machine,
              "preparation_steps": report.get("steps"),
              "wall_time_s": time.perf_counter() - started,
              "rows": rows, "exponents": fits}
    print(json.dumps(result["exponents"]))
    if args.json:
        with open(args.json, "w") as handle:
            json.dump(result, handle, indent=1)
    if args.figure:
        figure(rows, fits, args.figure)


if __name__ == "__main__":
    main()
