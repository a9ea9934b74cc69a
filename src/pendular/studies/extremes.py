"""Extremes grid: every input pushed to the ends of its range, one at a time.

``run_grid(out, quick)``; command ``pendular extremes --out DIR [--quick]``.

Around a small wet base case (60 spheres of R = 0.024 mm, E = 1e6 Pa, dt = 0.7 x P-wave step,
750 Pa confining, 30 kPa suction, contact angle 0, suction-controlled exact bridges), one
parameter at a time takes values across its range and a few out of it: suction, contact angle,
radius, Young's modulus, time-step safety factor, particle count, confining stress and water
content (volume-controlled bridges formed at a given suction). Each case prepares a dry sample
(pendular.procedures.preparation.prepare_sample, short), adds capillary.CapillaryBridges, runs a few
thousand steps with the six walls servoed at the confining stress and checks the state; the
particle-count sweep builds 10,000 and 100,000 spheres on a lattice and runs a handful of steps.

A case ends ``ok`` (ran, everything finite, every check within its bound, see BOUNDS),
``refused`` (a ValueError naming the offending parameter, its value and the valid range) or
``failed`` (a crash, a check out of bounds, or an invalid value accepted). Writes
DIR/extremes.json (cases with inputs, status, message, checks; counts per status) and prints a
table. Stresses in Pa, compression positive.
"""

import copy
import json
import math
import re
import time
import traceback

import numpy as np

from pendular.capillary import CapillaryBridges
from pendular.utils.atomic import replacing
from pendular.utils.parameters import Option, default_of
from pendular.dem.measure import kinetic_energy
from pendular.procedures.config import BridgeConfig
from pendular.procedures.preparation import PrepareConfig, prepare_sample, servoed_simulation
from pendular.dem.state import Particles, Walls
from pendular.homogenize import capillary_force_stress, contact_stress

from pendular.io.outputs import OutputFolder

#: The base case; every case changes one of these (``water`` is the formation suction [Pa] of
#: volume-controlled bridges, None for suction control).
BASE = {"suction": 30000.0, "contact_angle": default_of(BridgeConfig, "contact_angle"),
        **{name: default_of(PrepareConfig, name) for name in ("radius", "young",
                                                              "timestep_safety")},
        "particles": 60, "confining": default_of(PrepareConfig, "confining"), "water": None}

#: Values per parameter: (valid values, out-of-range values that must be refused).
GRID = {
    "suction": ([1.0, 10.0, 100.0, 1e3, 3e3, 1e4, 1e5, 1e6, 1e7], [-5.0, math.nan, 1e8]),
    "contact_angle": ([0.0, 20.0, 40.0, 60.0, 80.0], [90.0, -5.0, math.inf]),
    "radius": ([1e-6, 1e-5, 1e-4, 1e-3], [0.0, -1e-5]),
    "young": ([1e4, 1e5, 1e7, 1e8, 1e9], [0.0, -1e6]),
    "timestep_safety": ([0.1, 0.3, 0.5, 0.9], [1.5, 0.0]),
    "particles": ([10, 100, 1000, 10000, 100000], [1, 2.5]),
    "confining": ([0.0, 250.0, 1e4, 1e5, 1e6], [-100.0]),
    "water": ([3e3, 1e4, 1e5, 1e6], [-1.0]),
}

#: The --quick subset: (parameter, value) pairs beyond the base case.
QUICK = [("suction", 1.0), ("suction", 1e7), ("suction", 1e8), ("contact_angle", 80.0),
         ("contact_angle", 90.0), ("radius", 1e-6), ("young", 1e9), ("timestep_safety", 0.9),
         ("timestep_safety", 1.5), ("particles", 10), ("particles", 10000), ("confining", 0.0),
         ("confining", 1e6), ("water", 1e4)]

#: The grid's options (``pendular extremes``; its output folder apart).
OPTIONS = (Option("quick", "a small subset of the grid", default=False, kind=bool),)

#: Steps of the wet phase (servoed at the confining stress), and of the lattice scenes.
WET_STEPS = 2000
LATTICE_STEPS = 5
#: Above this many particles the scene is a lattice, not a prepared sample.
LATTICE_ABOVE = 1000
#: Preparation limit per phase (steps).
PREPARE_STEPS = 60000

#: Bounds of an ``ok`` case (each check's value must not exceed its bound).
BOUNDS = {
    # fastest particle / P-wave speed sqrt(E / rho): a numerical instability runs away past 1
    "max_speed_over_wave_speed": 0.05,
    # kinetic energy / (stress_scale x box volume), the work of the stresses over a 1 % strain
    "kinetic_over_work_scale": 0.01,
    # largest sphere-sphere or sphere-wall overlap / radius
    "max_overlap_over_radius": 0.25,
    # -(mean wall stress) / stress_scale: compression positive, a wall never pulls
    "wall_tension_over_scale": 1e-9,
    # mean wall stress / stress_scale: the servo holds the walls near the confining stress
    "wall_stress_over_scale": 3.0,
    # stress bookkeeping, |diag(sigma_contact + sigma_capillary - sigma_wall - sigma_inertia)|
    # / stress_scale with sigma_inertia = (1/V) sum_p (x_p - box centre) F_p (the resultant
    # forces; zero in static equilibrium, where sigma_wall = sigma_contact + sigma_capillary):
    # an identity, exact up to rounding (1e-14 static, 6e-6 for 100,000 moving spheres)
    "bookkeeping_over_scale": 1e-4,
}
#: stress_scale = confining + |sigma_capillary| + STRESS_FLOOR [Pa] (0 Pa confining is valid).
STRESS_FLOOR = 10.0


def cases(quick):
    """(parameter, value, must_be_refused) for every case, the base case first."""
    chosen = [("base", None, False)]
    for parameter, (valid, invalid) in GRID.items():
        chosen += [(parameter, v, False) for v in valid]
        chosen += [(parameter, v, True) for v in invalid]
    if quick:
        chosen = [c for c in chosen if c[0] == "base" or (c[0], c[1]) in QUICK]
    return chosen


def inputs_of(parameter, value):
    inputs = dict(BASE)
    if parameter == "water":
        inputs["water"] = value
        inputs["suction"] = value
    elif parameter != "base":
        inputs[parameter] = value
    return inputs


def prepare_config(inputs):
    return PrepareConfig(particles=inputs["particles"], radius=inputs["radius"],
                         young=inputs["young"], timestep_safety=inputs["timestep_safety"],
                         confining=inputs["confining"], seed=0, unload_steps=400)


def bridges_of(inputs):
    control = "suction" if inputs["water"] is None else "volume"
    return CapillaryBridges(inputs["suction"], contact_angle=inputs["contact_angle"],
                            control=control)


def lattice_simulation(config):
    """``config.particles`` spheres on a simple cubic lattice touching their neighbours
    (overlap 1e-3 R) in a box just touching them, six walls servoed at the confining stress."""
    count = config.particles
    side = math.ceil(count ** (1.0 / 3.0))
    spacing = 2.0 * config.radius * (1.0 - 5e-4)
    index = np.arange(count)
    cells = np.stack([index // (side * side), (index // side) % side, index % side], axis=1)
    position = config.radius + spacing * cells
    particles = Particles(position, np.full(count, config.radius), config.density)
    walls = Walls.box(position.min(axis=0) - config.radius * (1.0 - 1e-3),
                      position.max(axis=0) + config.radius * (1.0 - 1e-3))
    return servoed_simulation(particles, walls, config, config.confining)


class SampleCache:
    """Dry prepared samples by their PrepareConfig, copied for each case."""

    def __init__(self):
        self.samples = {}

    def get(self, config):
        key = json.dumps(vars(config), sort_keys=True)
        if key not in self.samples:
            sim, _ = prepare_sample(config, progress=False, max_steps=PREPARE_STEPS)
            self.samples[key] = sim
        return copy.deepcopy(self.samples[key])


def finite_state(sim):
    p = sim.particles
    arrays = (p.position, p.velocity, p.angular_velocity, p.force, p.torque, p.radius,
              sim.walls.position, sim.walls.force)
    return bool(all(np.all(np.isfinite(a)) for a in arrays))


def measure(sim, bridges, young, confining):
    """The checks' values (see BOUNDS) and a few descriptive quantities of the state."""
    p = sim.particles
    radius = float(np.min(p.radius))
    capillary = (capillary_force_stress(sim, bridges) if bridges is not None
                 else np.zeros((3, 3)))
    sigma_wall = sim.walls.stress()
    scale = confining + float(np.max(np.abs(np.diagonal(capillary)))) + STRESS_FLOOR
    wall_overlap = np.maximum(np.concatenate([p.radius[:, None] - (p.position - sim.walls.lo),
                                              p.radius[:, None] - (sim.walls.hi - p.position)]),
                              0.0)
    overlap = max(float(np.max(sim.contacts.overlap, initial=0.0)), float(wall_overlap.max()))
    centre = 0.5 * (sim.walls.lo + sim.walls.hi)
    inertia = np.einsum("pi,pi->i", p.position - centre, p.force) / sim.walls.volume()
    sigma_contact = np.diagonal(contact_stress(p, sim.contacts, sim.walls))
    residual = sigma_contact + np.diagonal(capillary) - sigma_wall - inertia
    speed = float(np.max(np.linalg.norm(p.velocity, axis=1)))
    checks = {
        "max_speed_over_wave_speed": speed / math.sqrt(young / p.density),
        "kinetic_over_work_scale": kinetic_energy(p) / (scale * sim.walls.volume()),
        "max_overlap_over_radius": overlap / radius,
        "wall_tension_over_scale": -float(np.mean(sigma_wall)) / scale,
        "wall_stress_over_scale": float(np.mean(sigma_wall)) / scale,
        "bookkeeping_over_scale": float(np.max(np.abs(residual))) / scale,
    }
    state = {"sigma_wall": sigma_wall.tolist(), "stress_scale": scale,
             "sigma_contact": sigma_contact.tolist(), "sigma_inertia": inertia.tolist(),
             "sigma_capillary": np.diagonal(capillary).tolist(), "steps": sim.step,
             "dt": sim.dt}
    if bridges is not None:
        state.update({"bridges": bridges.count(sim), "saturation": bridges.saturation(sim),
                      "mean_suction": bridges.mean_suction(sim),
                      "pendular_overlaps": bridges.pendular_overlaps(sim)})
    return checks, state


def run_case(inputs, cache):
    """Build and run one case; return (checks, state). ValueError when an input is refused."""
    config = prepare_config(inputs)
    bridges = bridges_of(inputs) if inputs["suction"] != 0.0 else None
    if config.particles > LATTICE_ABOVE:
        sim = lattice_simulation(config)
        steps = LATTICE_STEPS
    else:
        sim = cache.get(config)
        steps = WET_STEPS
    if bridges is not None:
        sim.forces.append(bridges)
    sim.run(steps)
    if not finite_state(sim):
        raise FloatingPointError("state not finite after the run")
    return measure(sim, bridges, config.young, config.confining)


def named_parameter(message, parameter):
    """The parameter a refusal names: ``parameter`` if the message names it, else the first
    ``name = value`` of the message."""
    names = re.findall(r"([A-Za-z_]\w*) = ", message)
    key = {"water": "suction"}.get(parameter, parameter)
    if key in names:
        return key
    return names[0] if names else None


def evaluate(parameter, value, must_refuse, cache):
    inputs = inputs_of(parameter, value)
    case = {"parameter_varied": parameter, "value": value, "inputs": inputs,
            "must_be_refused": must_refuse}
    started = time.perf_counter()
    try:
        checks, state = run_case(inputs, cache)
    except ValueError as error:
        message = str(error)
        case.update(status="refused", parameter=named_parameter(message, parameter),
                    message=message)
        if case["parameter"] is None:
            case.update(status="failed", message=f"refusal names no parameter: {message}")
    except Exception as error:     # noqa: BLE001  a crash is recorded, not raised
        summary = traceback.format_exception(type(error), error, error.__traceback__)
        case.update(status="failed", message=f"{type(error).__name__}: {error}",
                    traceback="".join(summary[-3:]))
    else:
        exceeded = [f"{name} = {checks[name]:.3g} > {bound:g}" for name, bound in BOUNDS.items()
                    if not checks[name] <= bound]
        if must_refuse:
            exceeded.insert(0, f"invalid {parameter} = {value!r} was accepted")
        case.update(status="failed" if exceeded else "ok", checks=checks, state=state,
                    message="; ".join(exceeded))
    case["wall_time_s"] = time.perf_counter() - started
    return case


def _plain(value):
    """JSON-safe value: NaN and inf as text, NumPy scalars as Python numbers."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else str(float(value))
    if isinstance(value, np.integer):
        return int(value)
    return value


def write_report(path, results, quick, wall_time):
    counts = {status: sum(c["status"] == status for c in results)
              for status in ("ok", "refused", "failed")}
    report = {"quick": quick, "base": BASE, "bounds": BOUNDS, "stress_floor": STRESS_FLOOR,
              "wet_steps": WET_STEPS, "lattice_steps": LATTICE_STEPS, "counts": counts,
              "wall_time_s": wall_time, "cases": results}
    with replacing(path) as temporary, open(temporary, "w", encoding="utf-8") as handle:
        json.dump(_plain(report), handle, indent=1)
    return counts


def print_table(results, counts):
    print(f"{'parameter':<16}{'value':>10}  {'status':<8}{'time s':>7}  detail")
    for case in results:
        if case["status"] == "ok":
            detail = (f"speed/c {case['checks']['max_speed_over_wave_speed']:.1e}, overlap/R "
                      f"{case['checks']['max_overlap_over_radius']:.3f}, sigma_wall/scale "
                      f"{case['checks']['wall_stress_over_scale']:.2f}, Sr "
                      f"{case['state'].get('saturation', 0.0):.2g}, pendular overlaps "
                      f"{case['state'].get('pendular_overlaps', 0)}")
        elif case["status"] == "refused":
            detail = f"[{case['parameter']}] {case['message'][:90]}"
        else:
            detail = case["message"][:110]
        value = "" if case["value"] is None else f"{case['value']:g}"
        print(f"{case['parameter_varied']:<16}{value:>10}  {case['status']:<8}"
              f"{case['wall_time_s']:>7.2f}  {detail}")
    print(" ".join(f"{k}: {v}" for k, v in counts.items()))


def run_grid(out, quick=False):
    """Every case of the grid (``quick``: the subset) into ``out``/extremes.json, with the
    table printed; returns the counts per status. ValueError naming ``out`` when it cannot be
    an output folder (pendular.io.outputs.OutputFolder), before any case runs."""
    with OutputFolder(out, "extremes --quick" if quick else "extremes") as folder:
        report = folder.claim("extremes.json")
        started = time.perf_counter()
        cache = SampleCache()
        results = [evaluate(parameter, value, must_refuse, cache)
                   for parameter, value, must_refuse in cases(quick)]
        counts = write_report(report, results, quick, time.perf_counter() - started)
    print_table(results, counts)
    return counts
