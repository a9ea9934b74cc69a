"""Angle of repose of a pile poured under gravity onto a rough floor (docs/validation.md,
'Angle of repose').

``pour_pile(PileConfig(...))`` drops a loose column of equal spheres (random, non-overlapping,
in a vertical cylinder above the middle of the floor) under ``gravity`` along -z onto a
floor of fixed spheres (a square lattice of the same spheres, spacing ``floor_spacing``
diameters, slightly jittered: a rough floor whatever the walls' friction), inside six walls
far enough apart that the heap never reaches the side walls. The scene is pendular's dry
one (pendular.procedures.preparation.dry_simulation: the contact law, restitution, rolling
and twisting resistance, Cundall damping and gravity of the PrepareConfig), with the floor
spheres held in place (``HeldParticles``). It runs until the grains are at rest (their largest
speed below ``rest_speed`` sqrt(g R)) or ``max_time``.

The angle is read from the heap's surface (``repose_angle``): the grains' tops z + R, binned
by the distance r from the heap's axis (bins of one diameter) and by azimuth (``SECTORS``
sectors); the highest top of each cell, averaged over the sectors of a bin that hold a
grain, gives the surface height h(r); a straight line fitted to h(r) over the flank (from
``FLANK`` of the heap's radius, where h first falls below one diameter above the floor)
gives tan(theta).

Stresses and lengths SI; angles in degrees.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from pendular.dem.state import Particles, Walls
from pendular.procedures.preparation import PrepareConfig, dry_simulation, pwave_step
from pendular.utils.parameters import spec_of
from pendular.utils.validate import check_int, check_range

#: The gravity of a pile [m/s^2]: the sample's, above 0 (a pile needs its weight).
PILE_GRAVITY = dataclasses.replace(spec_of(PrepareConfig, "gravity"), low_inclusive=False)

#: Azimuthal sectors of the surface profile.
SECTORS = 8
#: The flank over which the surface is fitted, as fractions of the heap's radius.
FLANK = (0.3, 0.9)


@dataclasses.dataclass(frozen=True)
class PileConfig:
    """A poured pile: ``grains`` free spheres of the ``material`` (a PrepareConfig: radius,
    density, contact law and its E, nu, restitution, friction_deg, rolling_friction,
    damping, gravity > 0), poured from a cylinder of ``column_radius`` radii at solid fraction
    ``column_fraction`` onto a floor of side ``floor_side`` radii; ``seed`` of the column's
    and the floor's random positions; at most ``max_time`` [s]; at rest below ``rest_speed``
    sqrt(g R)."""

    material: PrepareConfig
    grains: int = 800
    column_radius: float = 8.0
    column_fraction: float = 0.25
    floor_side: float = 70.0
    floor_spacing: float = 1.05
    seed: int = 0
    max_time: float = 1.5
    rest_speed: float = 0.02

    def __post_init__(self):
        check_int("grains", self.grains, low=10)
        check_range("column_fraction", self.column_fraction, 0.0, 0.3, low_inclusive=False)
        check_range("floor_spacing", self.floor_spacing, 1.0, 1.5)
        if not self.material.gravity > 0.0:
            raise ValueError(f"gravity = {self.material.gravity:g} m/s^2: a pile needs its "
                             f"weight; valid range {PILE_GRAVITY.valid_range()}")
        if self.column_radius < 2.0 or self.floor_side < 2.0 * self.column_radius + 4.0:
            raise ValueError(f"column_radius = {self.column_radius:g}, floor_side = "
                             f"{self.floor_side:g} radii: valid: column_radius >= 2 and "
                             "floor_side >= 2 column_radius + 4")


class HeldParticles:
    """Hold the particles ``indices`` in place: their force, torque, velocity and spin set to
    zero after every other force, so that the integrator leaves them where they are (the
    last of a scene's forces)."""

    stateless = True

    def __init__(self, indices):
        self.indices = np.asarray(indices, dtype=np.int64)

    def apply(self, sim):
        p = sim.particles
        for array in (p.force, p.torque, p.velocity, p.angular_velocity):
            array[self.indices] = 0.0


def floor_lattice(side, radius, spacing, rng):
    """Centres [m] of a square lattice of spheres of ``radius`` [m] covering a floor of
    ``side`` [m] from the origin, ``spacing`` diameters apart, each jittered in x, y by up to
    (spacing - 1) / 2 radii (never touching), at height ``radius``."""
    pitch = 2.0 * radius * spacing
    count = int(side // pitch)
    offset = 0.5 * (side - (count - 1) * pitch)
    grid = offset + pitch * np.arange(count)
    x, y = np.meshgrid(grid, grid, indexing="ij")
    jitter = (spacing - 1.0) * radius * rng.uniform(-1.0, 1.0, size=(x.size, 2))
    return np.column_stack([x.ravel() + jitter[:, 0], y.ravel() + jitter[:, 1],
                            np.full(x.size, radius)])


def column_cloud(count, radius, column_radius, fraction, centre, base, rng):
    """``count`` random non-overlapping centres [m] of spheres of ``radius`` [m] in a vertical
    cylinder of ``column_radius`` [m] about the axis through ``centre`` (x, y) [m], from
    ``base`` [m] up, at solid fraction ``fraction`` (random sequential addition)."""
    inner = column_radius - radius
    height = count * 4.0 / 3.0 * math.pi * radius ** 3 / (fraction * math.pi * column_radius ** 2)
    placed = np.empty((count, 3))
    n = 0
    cell = 2.0 * radius
    grid = {}
    attempts = 0
    while n < count:
        attempts += 1
        if attempts > 200 * count:
            raise RuntimeError(f"column_cloud: {n} of {count} spheres placed; give a lower "
                               "column_fraction")
        r = inner * math.sqrt(rng.uniform())
        angle = rng.uniform(0.0, 2.0 * math.pi)
        point = np.array([centre[0] + r * math.cos(angle), centre[1] + r * math.sin(angle),
                          base + radius + rng.uniform(0.0, height)])
        key = tuple((point // cell).astype(int))
        near = [grid[(key[0] + a, key[1] + b, key[2] + c)]
                for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)
                if (key[0] + a, key[1] + b, key[2] + c) in grid]
        if any(np.dot(placed[m] - point, placed[m] - point) < cell * cell
               for cells in near for m in cells):
            continue
        placed[n] = point
        grid.setdefault(key, []).append(n)
        n += 1
    return placed


def surface_profile(position, radius, axis, floor_top):
    """(bin centres r [m], surface heights h [m] above ``floor_top``) of the heap of spheres
    at ``position`` (N, 3) [m] of ``radius`` (N,) [m] about the vertical ``axis`` (x, y) [m]:
    bins of one mean diameter, h the mean over the sectors holding a grain of each sector's
    highest top (module docstring; a bin without a grain: 0)."""
    top = position[:, 2] + radius - floor_top
    dx = position[:, 0] - axis[0]
    dy = position[:, 1] - axis[1]
    width = 2.0 * float(np.mean(radius))
    radial = (np.hypot(dx, dy) // width).astype(int)
    sector = ((np.arctan2(dy, dx) + math.pi) / (2.0 * math.pi) * SECTORS).astype(int) % SECTORS
    highest = np.full((int(radial.max()) + 1, SECTORS), -np.inf)
    np.maximum.at(highest, (radial, sector), top)
    filled = np.isfinite(highest)
    height = np.where(filled, highest, 0.0).sum(axis=1) / np.maximum(filled.sum(axis=1), 1)
    return (np.arange(len(height)) + 0.5) * width, height


def flank_angle(centre, height):
    """(angle [deg], the heap's radius [m]) of the surface profile (surface_profile): the
    heap ends where h first falls below one bin width (a grain's diameter: the grains that
    roll out onto the floor lie in its hollows, a monolayer about 0.7 diameter high), and a
    straight line fitted to h over the FLANK fractions of that radius gives tan(angle)."""
    width = centre[1] - centre[0]
    low = np.flatnonzero(height < width)
    edge = centre[low[0]] if len(low) else centre[-1]
    flank = (centre >= FLANK[0] * edge) & (centre <= FLANK[1] * edge)
    if np.count_nonzero(flank) < 3:
        raise ValueError(f"repose_angle: {np.count_nonzero(flank)} bins on the flank (heap "
                         f"radius {edge:g} m, bins of {width:g} m); valid: at least 3")
    slope = np.polyfit(centre[flank], height[flank], 1)[0]
    return math.degrees(math.atan(-slope)), float(edge)


def repose_angle(position, radius, axis, floor_top):
    """(angle [deg], the profile's bin centres r [m] and heights h [m] above ``floor_top``,
    the heap's radius [m]) of the heap of spheres at ``position`` (N, 3) [m] of ``radius``
    (N,) [m] about the vertical ``axis`` (x, y) [m] (surface_profile, flank_angle)."""
    centre, height = surface_profile(position, radius, axis, floor_top)
    angle, edge = flank_angle(centre, height)
    return angle, centre, height, edge


def pile_scene(config):
    """(Simulation, indices of the free grains, floor top z [m], the pile's axis (x, y) [m])
    of ``config`` (a PileConfig), not yet run."""
    material = config.material
    radius = material.radius
    rng = np.random.default_rng(config.seed)
    side = config.floor_side * radius
    floor = floor_lattice(side, radius, config.floor_spacing, rng)
    axis = (0.5 * side, 0.5 * side)
    cloud = column_cloud(config.grains, radius, config.column_radius * radius,
                         config.column_fraction, axis, 2.0 * radius, rng)
    position = np.vstack([floor, cloud])
    particles = Particles(position, np.full(len(position), radius), material.density)
    height = cloud[:, 2].max() + 2.0 * radius
    walls = Walls.box((0.0, 0.0, 0.0), (side, side, height))
    dt = pwave_step(particles.radius, material)
    sim = dry_simulation(particles, walls, material, dt,
                         material.skin_factor * radius, material.friction_deg, [], threads=1)
    sim.forces.append(HeldParticles(np.arange(len(floor))))
    free = np.arange(len(floor), len(position))
    return sim, free, 2.0 * radius, axis


def pour_pile(config, progress=None):
    """Pour the pile of ``config`` (a PileConfig) until at rest; return its summary: angle
    [deg], heap radius and height [m], the profile (r, h [m]), time [s], steps, whether it
    came to rest, the largest grain speed at the end [m/s] and the grains' count."""
    sim, free, floor_top, axis = pile_scene(config)
    material = config.material
    speed_scale = math.sqrt(material.gravity * material.radius)

    def at_rest(s):
        speed = np.linalg.norm(s.particles.velocity[free], axis=1).max()
        return s.time > 0.05 and speed < config.rest_speed * speed_scale

    steps = sim.run(int(config.max_time / sim.dt), until=at_rest, check_every=500,
                    progress=progress)
    position = sim.particles.position[free]
    angle, centre, height, edge = repose_angle(position, sim.particles.radius[free], axis,
                                               floor_top)
    return {"angle_deg": angle, "heap_radius": edge, "heap_height": float(height.max()),
            "profile_r": centre.tolist(), "profile_h": height.tolist(),
            "time": sim.time, "steps": steps, "dt": sim.dt, "at_rest": bool(at_rest(sim)),
            "max_speed": float(np.linalg.norm(sim.particles.velocity[free], axis=1).max()),
            "grains": len(free), "floor_spheres": len(sim.particles) - len(free)}
