"""Accuracy measurements published in docs/capillary.md; run `python -m
pendular.capillary.verification`.

- reference_bridge: an independent integration of the meridian (scipy solve_ivp in arc length,
  no use of the force invariant), the reference for the exact solver;
- solver_accuracy: largest relative differences of solve_bridge from it over a sample;
- table_interpolation_error / volume_table_interpolation_error: lookups against the exact
  stable bridges at random points, for given table resolutions;
- toroidal_errors: the toroidal approximation against the exact bridge of the same filling
  angle, contact angle and separation.
"""

import math

import numpy as np
from scipy.integrate import solve_ivp

from pendular.capillary.meniscus import solve_bridge
from pendular.capillary.suction_control import (bridge_at_distance, rupture_point,
    stable_filling_angle)
from pendular.capillary.table import BridgeTable
from pendular.capillary.toroidal import toroidal_bridge
from pendular.capillary.volume_control import bridge_with_volume, volume_contour
from pendular.capillary.volume_table import VolumeBridgeTable


def reference_bridge(radius_ratio, contact_angle, suction_star, filling_angle, rtol=1e-12):
    """Bridge from the meridian ODE dx/dl = cos(phi), dy/dl = sin(phi), dphi/dl = cos(phi)/y + s/gamma.

    Integrates (R1 units) from the contact line on sphere 1 to the neck (phi = 0), then on to
    the first point where y = r cos(phi + theta) (contact angle theta on sphere 2), with the
    volume and interface integrals as extra unknowns. Returns a dict in the units of
    docs/units.md with the force evaluated on sphere 1 (`force`), at the neck (`force_neck`)
    and on sphere 2 (`force_2`).
    """
    theta, delta1, r = math.radians(contact_angle), math.radians(filling_angle), radius_ratio
    suction1 = suction_star / r

    def rates(_, z):
        y, phi = z[1], z[2]
        c, s = math.cos(phi), math.sin(phi)
        return [c, s, c / y + suction1, math.pi * y * y * c, math.pi * y * c * c, 2.0 * math.pi * y * s * s]

    def neck(_, z):
        return z[2]

    def meets_sphere2(_, z):
        return z[1] - r * math.cos(z[2] + theta)

    neck.terminal, neck.direction = True, 1.0
    meets_sphere2.terminal, meets_sphere2.direction = True, 1.0
    start = [math.cos(delta1), math.sin(delta1), delta1 + theta - 0.5 * math.pi, 0.0, 0.0, 0.0]
    scale = math.sin(delta1)
    options = dict(method="DOP853", rtol=rtol, atol=1e-14 * scale, max_step=0.05 * scale + 0.01)
    to_neck = solve_ivp(rates, (0.0, 20.0), start, events=neck, **options)
    at_neck = to_neck.y_events[0][0] if to_neck.t_events[0].size else np.asarray(start, dtype=float)
    to_end = solve_ivp(rates, (0.0, 20.0), at_neck, events=meets_sphere2, **options)
    end = to_end.y_events[0][0]
    delta2 = 0.5 * math.pi - theta - end[2]
    versine1, versine2 = 1.0 - math.cos(delta1), 1.0 - math.cos(delta2)
    caps = math.pi / 3.0 * (versine1**2 * (3.0 - versine1) + r**3 * versine2**2 * (3.0 - versine2))
    y_neck = at_neck[1]
    return {
        "distance": (end[0] + r * math.cos(delta2) - r - 1.0) / r,
        "volume": (end[3] - caps) / r**3,
        "force": (math.sin(delta1) * math.sin(delta1 + theta) + 0.5 * suction1 * math.sin(delta1) ** 2) / r,
        "force_neck": (y_neck + 0.5 * suction1 * y_neck**2) / r,
        "force_2": (r * math.sin(delta2) * math.sin(delta2 + theta) + 0.5 * suction1 * (r * math.sin(delta2)) ** 2) / r,
        "delta2": math.degrees(delta2),
        "nn11": end[4] / r**2,
        "nn33": end[5] / r**2,
    }


def solver_accuracy(n_samples=300, seed=0, largest_suction=1e4):
    """Largest relative differences of solve_bridge from reference_bridge.

    Samples theta in [0, 80] deg, r in [1, 10], u* log-uniform in [1e-3, largest_suction] (one
    sample in four at u* = 0) and delta1 uniform in [0.5, 90 - theta] deg. The distance is
    compared relative to max(|d*|, 1e-3). Returns {quantity: (error, (theta, r, u*, delta1))}.
    """
    rng = np.random.default_rng(seed)
    worst = {}
    for k in range(n_samples):
        theta = rng.uniform(0.0, 80.0)
        r = rng.uniform(1.0, 10.0)
        suction = 0.0 if k % 4 == 0 else 10.0 ** rng.uniform(-3.0, math.log10(largest_suction))
        delta1 = rng.uniform(0.5, 90.0 - theta)
        exact = solve_bridge(r, theta, suction, delta1)
        reference = reference_bridge(r, theta, suction, delta1)
        for name in ("distance", "volume", "force", "delta2", "nn11", "nn33"):
            floor = 1e-3 if name == "distance" else 0.0
            error = abs(getattr(exact, name) - reference[name]) / max(abs(reference[name]), floor)
            if error >= worst.get(name, (-1.0,))[0]:
                worst[name] = (error, (theta, r, suction, delta1))
        for name in ("force_neck", "force_2"):
            error = abs(reference[name] - exact.force) / exact.force
            if error >= worst.get(name, (-1.0,))[0]:
                worst[name] = (error, (theta, r, suction, delta1))
    return worst


def _summary(errors):
    """{'max', 'rms'} of each column of an (n_samples, n_quantities) array of relative errors."""
    errors = np.abs(np.array(errors))
    return {"max": errors.max(axis=0), "rms": np.sqrt((errors**2).mean(axis=0))}


def table_interpolation_error(n_suction, n_distance, contact_angle=0.0, radius_ratio=1.0, n_samples=400, seed=0,
                              suction_max=15000.0):
    """Lookups of a one-radius-ratio BridgeTable against bridge_at_distance at random points.

    Points: u* = suction_scale (exp(xi) - 1) with xi uniform over the table, d* uniform between
    the smallest tabulated distance and 99.9 % of the rupture distance. Returns ({'max', 'rms'}
    relative errors of (F*, V*, delta1)), build seconds).
    """
    import time

    start = time.perf_counter()
    table = BridgeTable.build(contact_angle, (radius_ratio,), n_suction, n_distance, suction_max)
    seconds = time.perf_counter() - start
    rng = np.random.default_rng(seed)
    errors = []
    theta = math.radians(contact_angle)
    for _ in range(n_samples):
        suction = table.suction_scale * math.expm1(rng.uniform(0.0, math.log1p(suction_max / table.suction_scale)))
        d_rupture = rupture_point(radius_ratio, theta, suction)[1]
        exact_low = solve_bridge(radius_ratio, contact_angle, suction, 90.0 - contact_angle).distance
        distance = rng.uniform(max(0.0, exact_low), 0.999 * d_rupture)
        exists, force, volume, delta1, _ = table.lookup(radius_ratio, suction, distance)
        exact = bridge_at_distance(radius_ratio, contact_angle, suction, distance)
        if not exists:
            raise AssertionError(f"the table finds no bridge at u* = {suction}, d* = {distance}")
        errors.append((force / exact.force - 1.0, volume / exact.volume - 1.0, delta1 / exact.delta1 - 1.0))
    return _summary(errors), seconds


def volume_table_interpolation_error(n_volume, n_distance, contact_angle=0.0, radius_ratio=1.0, n_samples=200, seed=0):
    """Lookups of a one-radius-ratio VolumeBridgeTable against bridge_with_volume at random points.

    Points: ln V* uniform over the table, d* uniform between contact and 99.9 % of the rupture
    distance. Returns ({'max', 'rms'} relative errors of (F*, u*, delta1)), build seconds).
    """
    import time

    start = time.perf_counter()
    table = VolumeBridgeTable.build(contact_angle, (radius_ratio,), n_volume, n_distance, workers=1)
    seconds = time.perf_counter() - start
    rng = np.random.default_rng(seed)
    low, high = table.volume_axes[0]
    errors = []
    for _ in range(n_samples):
        volume = math.exp(rng.uniform(low, high))
        contour = volume_contour(radius_ratio, contact_angle, volume)
        distance = rng.uniform(contour.contact_distance, contour.rupture_distance - 1e-3 * (
            contour.rupture_distance - contour.contact_distance))
        exists, force, suction, delta1, _ = table.lookup(radius_ratio, volume, distance)
        exact = bridge_with_volume(radius_ratio, contact_angle, volume, distance)
        if not exists:
            raise AssertionError(f"the table finds no bridge at V* = {volume}, d* = {distance}")
        # the suction crosses zero along the family: its error is relative to max(|u*|, 1)
        errors.append((
            force / exact.force - 1.0,
            (suction - exact.suction) / max(abs(exact.suction), 1.0),
            delta1 / exact.delta1 - 1.0,
        ))
    return _summary(errors), seconds


def exact_suction_for_toroidal(filling_angle, contact_angle, separation):
    """u* of the exact stable bridge between equal spheres with filling angle alpha at gap H/R.

    Returns (u*, None) or (None, reason): 'u* < 0' where the exact bridge with that filling
    angle and gap needs a liquid pressure above the gas pressure, 'unstable' where that filling
    angle is below the rupture one at every suction for which the gap is reachable.
    """
    theta, alpha = math.radians(contact_angle), math.radians(filling_angle)

    def stable_delta1(log_suction):
        suction = math.expm1(log_suction)
        delta1_rupture, d_rupture = rupture_point(1.0, theta, suction)
        return stable_filling_angle(1.0, theta, suction, separation, delta1_rupture, d_rupture)

    high = math.log1p(1e5)
    at_zero = stable_delta1(0.0)
    if not at_zero == at_zero:
        return None, "unstable"
    if at_zero < alpha:
        return None, "u* < 0"
    # stable delta1 decreases with suction until the gap reaches the rupture distance (NaN beyond)
    low = 0.0
    while True:
        middle = 0.5 * (low + high)
        value = stable_delta1(middle)
        if value == value and value > alpha:
            low = middle
        else:
            high = middle
        if high - low < 1e-13:
            break
    if not abs(stable_delta1(low) - alpha) < 1e-9:
        return None, "unstable"
    return math.expm1(low), None


def toroidal_errors(filling_angles=(5, 10, 20, 30, 40), contact_angles=(0, 20, 40), separations=(0.0, 0.05, 0.1, 0.2)):
    """Rows (alpha, theta, H/R, u*_toroidal, u*_exact or reason, relative errors of u*, V*, F* or None)."""
    rows = []
    for theta in contact_angles:
        for separation in separations:
            for alpha in filling_angles:
                if alpha + theta >= 90:
                    continue
                try:
                    approximate = toroidal_bridge(alpha, theta, separation)
                except ValueError:
                    rows.append((alpha, theta, separation, None, "toroidal neck <= 0", None, None, None))
                    continue
                suction, reason = exact_suction_for_toroidal(alpha, theta, separation)
                if suction is None:
                    rows.append((alpha, theta, separation, approximate.suction_star, reason, None, None, None))
                    continue
                exact = bridge_at_distance(1.0, theta, suction, separation)
                rows.append((
                    alpha, theta, separation, approximate.suction_star, suction,
                    approximate.suction_star / suction - 1.0,
                    approximate.volume / exact.volume - 1.0,
                    approximate.force / exact.force - 1.0,
                ))
    return rows


def main():
    worst = solver_accuracy()
    print("## Solver against reference_bridge (largest relative difference)")
    for name, (error, where) in worst.items():
        theta, r, suction, delta1 = where
        print(f"| {name} | {error:.2e} | theta={theta:.1f}, r={r:.2f}, u*={suction:.3g}, delta1={delta1:.2f} |")
    print("\n## Suction table, r = 1, theta = 0: relative error (max / rms) of F*, V*, delta1")
    for n_suction, n_distance in ((50, 20), (100, 40), (200, 80), (350, 80), (700, 160)):
        errors, seconds = table_interpolation_error(n_suction, n_distance)
        cells = " | ".join(f"{m:.1e} / {r:.1e}" for m, r in zip(errors["max"], errors["rms"]))
        print(f"| {n_suction} x {n_distance} | {cells} | {seconds:.1f} s |")
    print("\n## Volume table, r = 1, theta = 0: relative error (max / rms) of F*, u* (scale max(|u*|,1)), delta1")
    for n_volume, n_distance in ((20, 20), (40, 40), (80, 80)):
        errors, seconds = volume_table_interpolation_error(n_volume, n_distance)
        cells = " | ".join(f"{m:.1e} / {r:.1e}" for m, r in zip(errors["max"], errors["rms"]))
        print(f"| {n_volume} x {n_distance} | {cells} | {seconds:.1f} s |")
    print("\n## Toroidal approximation against the exact bridge (same alpha, theta, H/R)")
    print("| alpha | theta | H/R | u* toroidal | u* exact | error u* | error V* | error F* |")
    for alpha, theta, separation, approximate, exact, e_u, e_v, e_f in toroidal_errors():
        if e_u is None:
            shown = "-" if approximate is None else f"{approximate:.4g}"
            print(f"| {alpha} | {theta} | {separation} | {shown} | {exact} | - | - | - |")
        else:
            print(f"| {alpha} | {theta} | {separation} | {approximate:.4g} | {exact:.4g} | "
                  f"{100 * e_u:+.1f} % | {100 * e_v:+.1f} % | {100 * e_f:+.1f} % |")


if __name__ == "__main__":
    main()
