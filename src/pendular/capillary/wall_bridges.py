"""Liquid bridges between the spheres and the box's walls in the DEM (docs/capillary.md
'Sphere–wall bridges'), a part of the scene's suction-controlled bridge operation
(pendular.capillary.bridges.SuctionBridges, ``wall_bridges``).

A sphere of radius R facing wall w across the surface gap D (negative: an overlap) holds a
bridge of the exact sphere–plane family (pendular.capillary.wall_bridge) at the operation's
suction s, looked up each step in a WallBridgeTable at u = s R / gamma and D/R (an overlap reads
the contact values, as the sphere–sphere bridges do):

- formation at contact (D <= 0); rupture when contact is lost, or with ``persist`` beyond the
  rupture distance at the suction, as the operation's sphere–sphere bridges;
- force F = F* 2 pi gamma R, attractive along the wall's normal: -F n on the sphere (n into the
  box), +F n on the wall, so the wall's normal force (``Walls.force``, the servo's and the wall
  stress's) loses F; the stiffness of the wall is its contacts' alone, and its Love–Weber term
  (R + D) F (``moment``, the capillary stress's share of the walls, as ``Walls.moment`` is the
  contacts') is kept apart from the contacts';
- the liquid V = V* R**3 and the filling angle delta1 on the sphere are kept per sphere and
  wall (``exists``, ``volume``, ``force``, ``filling`` (N, 6)) for the liquid balance, the
  saturation and the homogenised stresses (pendular.homogenize.wall_bridge_stress).

Suction control only: the liquid comes from and goes to the reservoir of the imposed suction.
"""

import math

import numba
import numpy as np

from pendular.capillary.wall_bridge import WallBridgeTable, lookup_wall
from pendular.dem.contact_law import wall_gap
from pendular.dem.protocols import state_array

#: Table range of u = s R / gamma of the wall bridges: 0.01 (s = 30 Pa for R = 24 um, gamma =
#: 0.073 N/m) to 1500 (s = 4.6 MPa there), above the pendular range of the sphere–sphere
#: bridges' table (u* = s R2 / gamma up to 15000 over pairs of radius ratio up to 10).
SUCTION_RANGE = (0.01, 1500.0)


@numba.njit(cache=True)
def _sphere_on_walls(p, position, radius, wall_position, suction, surface_tension, persist,
                     suction_axis, distance_low, log_distance_rupture, log_values, exists,
                     volume, force_magnitude, filling, force, moment):
    """Sphere p's bridges with the six walls (wall_bridge_forces' arguments; the GPU runs this
    body too, pendular.gpu.wall_bridges): row p of ``exists``, ``volume``,
    ``force_magnitude`` (its pull on each wall [N], 0 without a bridge) and ``filling`` set,
    its pulls added to ``force[p]``, ``moment`` (6,) set to (centre-to-wall distance) * pull
    [N m] per wall."""
    r = radius[p]
    u = suction * r / surface_tension
    for w in range(6):
        moment[w] = 0.0
        axis, side, gap = wall_gap(p, w, position, radius, wall_position)
        found = gap <= 0.0 or (persist and exists[p, w] != 0)
        if found:
            found, force_star, volume_star, delta1, _ = lookup_wall(
                suction_axis, distance_low, log_distance_rupture, log_values, u,
                max(gap, 0.0) / r)
        if not found:
            exists[p, w] = 0
            volume[p, w] = 0.0
            force_magnitude[p, w] = 0.0
            filling[p, w] = 0.0
            continue
        pull = force_star * 2.0 * math.pi * surface_tension * r
        exists[p, w] = 1
        volume[p, w] = volume_star * r * r * r
        force_magnitude[p, w] = pull
        filling[p, w] = delta1
        force[p, axis] -= side * pull
        moment[w] = (r + gap) * pull


@numba.njit(cache=True)
def wall_bridge_forces(position, radius, wall_position, suction, surface_tension, persist,
                       suction_axis, distance_low, log_distance_rupture, log_values, exists,
                       volume, force_magnitude, filling, force, wall_force, moment):
    """Every sphere's bridges with the six walls (module docstring), in place: ``exists``
    (N, 6) int8, ``volume`` [m^3], ``force_magnitude`` [N] and ``filling`` [deg] (N, 6); the
    forces added to ``force`` (N, 3) and subtracted from the walls' ``wall_force`` (6,);
    ``moment`` (6,) [N m] set to each wall's sum of (centre-to-wall distance) * pull.
    suction [Pa], surface_tension [N/m]; the table's arrays (WallBridgeTable.arrays)."""
    moment[:] = 0.0
    sphere_moment = np.zeros(6)
    for p in range(len(radius)):
        _sphere_on_walls(p, position, radius, wall_position, suction, surface_tension, persist,
                         suction_axis, distance_low, log_distance_rupture, log_values, exists,
                         volume, force_magnitude, filling, force, sphere_moment)
        for w in range(6):
            wall_force[w] -= force_magnitude[p, w]
            moment[w] += sphere_moment[w]


class WallBridges:
    """The sphere–wall bridges of a suction-controlled bridge operation (module docstring):
    its suction, surface tension, contact angle and ``persist`` are the operation's
    (``bridges``), read at each step. ``apply(sim)`` after the wall forces, which set the walls'
    totals this step. ``moment`` (6,) [N m]: each wall's sum of (centre-to-wall distance) *
    pull of the last step."""

    def __init__(self, bridges):
        self.bridges = bridges
        self.table = None
        self.exists = np.zeros((0, 6), np.int8)
        self.volume = np.zeros((0, 6))
        self.force = np.zeros((0, 6))
        self.filling = np.zeros((0, 6))
        self.moment = np.zeros(6)

    #: The per-sphere, per-wall arrays a checkpoint keeps: name -> dtype.
    ARRAYS = {"exists": np.int8, "volume": np.float64, "force": np.float64,
              "filling": np.float64}

    def state_dict(self):
        """The bridges of each sphere on each wall: exists (N, 6), volume [m^3], force [N],
        filling [deg]."""
        return {name: getattr(self, name).copy() for name in self.ARRAYS}

    def load_state(self, state):
        loaded = {name: state_array(state, name, dtype, (None, 6))
                  for name, dtype in self.ARRAYS.items()}
        if len({len(array) for array in loaded.values()}) != 1:
            raise ValueError("wall bridges: exists, volume, force and filling have different "
                             "lengths; valid: one row per sphere each")
        for name, array in loaded.items():
            setattr(self, name, array)

    def load_table(self, low, high):
        """The table for spheres of radii in [low, high] [m] at the operation's suction;
        ValueError naming the suction when u = s R / gamma leaves SUCTION_RANGE."""
        b = self.bridges
        smallest, largest = SUCTION_RANGE
        u_low, u_high = b.suction * low / b.surface_tension, b.suction * high / b.surface_tension
        if not smallest <= u_low <= u_high <= largest:
            raise ValueError(
                f"suction = {b.suction:g} Pa is outside the valid range "
                f"[{smallest * b.surface_tension / low:g}, {largest * b.surface_tension / high:g}]"
                f" Pa of sphere-wall bridges for spheres of radii {low:g} to {high:g} m (u = s R "
                f"/ gamma in [{smallest:g}, {largest:g}])")
        if self.table is None or self.table.contact_angle != b.contact_angle:
            self.table = WallBridgeTable.cached(b.contact_angle, suction_min=smallest,
                                                suction_max=largest)

    def apply(self, sim):
        p, box, b = sim.particles, sim.walls, self.bridges
        if len(self.exists) != len(p):
            for name, dtype in self.ARRAYS.items():
                setattr(self, name, np.zeros((len(p), 6), dtype))
        self.load_table(float(p.radius.min()), float(p.radius.max()))
        wall_bridge_forces(p.position, p.radius, box.position, b.suction, b.surface_tension,
                           b.persist, *self.table.arrays(), self.exists, self.volume,
                           self.force, self.filling, p.force, box.force, self.moment)

    def count(self):
        """Number of sphere–wall bridges."""
        return int(np.count_nonzero(self.exists))

    def water_volume(self):
        """Their liquid [m^3]."""
        return float(np.sum(self.volume))

    def bridges_of(self, sim):
        """(sphere, wall) of each bridge, the axis from the sphere's centre to the wall (B, 3),
        the sphere's radius [m] and filling angle [deg], and nn11, nn33 [m^2] of its liquid–gas
        interface (the table's at its suction and gap), in (sphere, wall) order."""
        sphere, wall = np.nonzero(self.exists)
        axis = np.zeros((len(sphere), 3))
        axis[np.arange(len(sphere)), wall // 2] = np.where(wall % 2 == 0, -1.0, 1.0)
        radius = sim.particles.radius[sphere]
        side = np.where(wall % 2 == 0, 1.0, -1.0)
        gap = side * (sim.particles.position[sphere, wall // 2] - sim.walls.position[wall]) \
            - radius
        b = self.bridges
        interfaces = np.array([self.table.interface(b.suction * r / b.surface_tension,
                                                    max(g, 0.0) / r) for r, g in zip(radius, gap)])
        interfaces = interfaces.reshape(-1, 2) * (radius ** 2)[:, None]
        return sphere, wall, axis, radius, self.filling[sphere, wall], interfaces
