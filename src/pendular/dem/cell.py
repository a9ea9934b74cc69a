"""A periodic cell: the sample's box without walls (YADE's O.periodic with a diagonal velocity
gradient; LAMMPS's deforming periodic box).

The cell is [0, L] on each axis. A particle leaving through a face comes back through the
opposite one: positions are wrapped into the cell at every neighbour-list rebuild, and
``wraps`` counts how many periods each particle has crossed (its unwrapped position is
position + wraps * L). A pair interacts through the image of j nearest to i
(pendular.dem.neighbors.branch_vector). The cell deforms by stretching its axes: a control sets
``rate`` [1/s] (L' / L, extension positive) and the integrator moves every particle with the
homogeneous velocity rate * x on top of its own (fluctuating) velocity, so the contact law adds
rate * l to the relative velocity of a pair of branch vector l (YADE's periodic scheme).

The cell also shears in the x-z plane (Lees–Edwards boundaries, as LAMMPS's ``fix deform`` of
a tilt or YADE's Cell under a velocity gradient with an xz term): at ``shear_rate`` gamma_dot
[1/s] the homogeneous velocity gains gamma_dot * z along x, the image of the cell above in z
is displaced by ``shear_offset`` delta along x, and the branch vector through image (ix, iy,
iz) is x_j - x_i + (ix Lx + iz delta, iy Ly, iz Lz). The offset follows the velocity gradient,
delta' = (L'_x / L_x) delta + gamma_dot Lz (``follow``), and is brought back into
[-Lx/2, Lx/2) at each neighbour-list rebuild (the lattice of images is periodic in delta
modulo Lx); a particle wrapped through a z face shifts x by -+delta. ``shear_strain`` gamma
is the shear imposed, the integral of gamma_dot dt (delta = gamma Lz at a constant height). A
sheared cell's ``period`` and ``affine_rate`` hold a fourth entry, delta and gamma_dot, which
the kernels read behind a test of the arrays' shapes: a cell never sheared (and walls) runs
the code of before, bit for bit.

With no walls, the stress of the cell is the Love–Weber average of every pair force over the
cell volume (Eq. 3.41 over contacts and, in a wet scene, bridges): ``after_forces`` computes it
each step from the particles' forces and the face terms that the forces' gathers add to
``virial_blocks`` (pendular.dem.virial); forces that are not pair forces (liquid clusters)
give their own sum of x (x) F (``virial``). The
stress servo reads the cell's stiffness S_a = (1/V) sum kn (l_a n_a)^2 [Pa per
unit strain] as a wall servo reads the stiffness of the wall's contacts; the servo refreshes it
(``update_stiffness``) when it refreshes its own.
"""

import math
from dataclasses import dataclass, field

import numba
import numpy as np

from pendular.dem.neighbors import branch_vector
from pendular.dem.state import Box, _box_position, _check_box, period_layout
from pendular.utils.validate import check_array, check_range
from pendular.dem.virial import (SUM_BLOCKS, ZERO9, add_outer, add_to_block, block_bounds,
    sum_blocks)

#: Largest rate a boundary is driven at [1/s]: the walls' strain rate
#: (pendular.dem.walls.ConstantStrainRate), the cell's shear rate (ConstantShearRate).
MAX_STRAIN_RATE = 1e6


@numba.njit(cache=True, parallel=True)
def pair_virial(position, row_start, pair_j, image, period, pair_force):
    """(9,) sum over the pairs of l_a f_b [N m] (row a, column b; l the branch vector i -> j,
    f = ``pair_force`` the force on j from i), pair by pair."""
    count = len(row_start) - 1
    sums = np.zeros((SUM_BLOCKS, 9))
    for block in numba.prange(SUM_BLOCKS):
        start, stop = block_bounds(count, block)
        total = ZERO9
        for i in range(start, stop):
            for k in range(row_start[i], row_start[i + 1]):
                l0, l1, l2 = branch_vector(position, i, pair_j[k], image, k, period)
                total = add_outer(total, l0, l1, l2, pair_force[k, 0], pair_force[k, 1],
                                  pair_force[k, 2])
        add_to_block(sums, block, total)
    return sum_blocks(sums)


@numba.njit(cache=True, inline="always")
def pair_stiffness(k, i, radius, pair_j, normal, normal_force, overlap):
    """Pair k's (of particle i) (kn (l_0 n_0)^2, kn (l_1 n_1)^2, kn (l_2 n_2)^2) [N m]
    (contact_stiffness; nothing from a pair apart: no normal force)."""
    length = radius[i] + radius[pair_j[k]] - overlap[k]
    spring_overlap = overlap[k] if overlap[k] > 0.0 else 1.0
    weight = normal_force[k] * length * length / spring_overlap
    s0 = normal[k, 0] * normal[k, 0]
    s1 = normal[k, 1] * normal[k, 1]
    s2 = normal[k, 2] * normal[k, 2]
    return weight * (s0 * s0), weight * (s1 * s1), weight * (s2 * s2)


@numba.njit(cache=True, parallel=True)
def contact_stiffness(radius, row_start, pair_j, normal, normal_force, overlap):
    """(3,) sum over the touching pairs of kn (l_a n_a)^2 = kn |l|^2 n_a^4 [N m], with
    kn = normal_force / overlap the spring stiffness, n the contact normal of the last
    evaluation and |l| = r_i + r_j - overlap the branch length. Pairs apart have no normal
    force and add nothing (no branch: half the pairs touch, at random)."""
    count = len(row_start) - 1
    sums = np.zeros((SUM_BLOCKS, 3))
    for block in numba.prange(SUM_BLOCKS):
        start, stop = block_bounds(count, block)
        k0 = k1 = k2 = 0.0
        for i in range(start, stop):
            for k in range(row_start[i], row_start[i + 1]):
                s0, s1, s2 = pair_stiffness(k, i, radius, pair_j, normal, normal_force, overlap)
                k0 += s0
                k1 += s1
                k2 += s2
        sums[block, 0] = k0
        sums[block, 1] = k1
        sums[block, 2] = k2
    return sum_blocks(sums)


@numba.njit(cache=True)
def store_cell_stress(virial_blocks, position, force, cell_position, stress_tensor):
    """``stress_tensor`` (3, 3) [Pa] = (sum_p x_p (x) F_p + the face terms the gathers left in
    ``virial_blocks``) over the volume of the cell of faces ``cell_position`` (6,) [m]
    (pendular.dem.virial): every force being a pair force, ``force`` (N, 3) [N] is the resultant of
    the pair forces. One compiled call, in particle order: each NumPy operation after the
    step's large kernels costs several microseconds. Nine scalar sums and no allocation: 2.3 us
    at 1,000 spheres, against 3.2 us with a tuple of sums (pendular.dem.virial.add_outer) and
    sum_blocks' array (same results, bit for bit)."""
    volume = cell_position[1] * cell_position[3] * cell_position[5]
    s00 = s01 = s02 = s10 = s11 = s12 = s20 = s21 = s22 = 0.0
    for p in range(position.shape[0]):
        x0, x1, x2 = position[p, 0], position[p, 1], position[p, 2]
        f0, f1, f2 = force[p, 0], force[p, 1], force[p, 2]
        s00 += x0 * f0
        s01 += x0 * f1
        s02 += x0 * f2
        s10 += x1 * f0
        s11 += x1 * f1
        s12 += x1 * f2
        s20 += x2 * f0
        s21 += x2 * f1
        s22 += x2 * f2
    totals = (s00, s01, s02, s10, s11, s12, s20, s21, s22)
    for c in range(9):
        faces = 0.0             # the blocks in order, as pendular.dem.virial.sum_blocks (no allocation)
        for block in range(virial_blocks.shape[0]):
            faces += virial_blocks[block, c]
        stress_tensor[c // 3, c % 3] = (totals[c] + faces) / volume


@numba.njit(cache=True)
def servo_cell(position, rate, stress_tensor, cell_stiffness, stiffness, previous, axes,
               target, gain, memory, max_velocity, scale_max_velocity, refresh, dt):
    """One step of the stress servo for the axes ``axes`` of a periodic cell, in place: each
    length changes by dL_n = gain * clip(L (sigma - target) / S, +-cap) + memory * dL_n-1
    (pendular.dem.walls.StressServo's law with the cell's stiffness S [Pa] for K_wall / area, and
    cap = 2 max_velocity dt: both faces of the box), and ``rate`` becomes dL / (L dt).
    ``stiffness[slot]`` holds S of axis ``axes[slot]``, refreshed from ``cell_stiffness``
    when ``refresh``."""
    lx = position[1] - position[0]
    ly = position[3] - position[2]
    lz = position[5] - position[4]
    for slot in range(len(axes)):
        axis = axes[slot]
        length = lx if axis == 0 else (ly if axis == 1 else lz)
        cap = 2.0 * max_velocity * dt
        if scale_max_velocity:
            cap = cap * (3.0 * length / (lx + ly + lz))
        if refresh:
            stiffness[slot] = cell_stiffness[axis]
        if stiffness[slot] > 0.0:
            shift = length * (stress_tensor[axis, axis] - target) / stiffness[slot]
            shift = min(max(shift, -cap), cap)
        else:
            shift = -cap
        previous[slot] = gain * shift + memory * previous[slot]
        position[2 * axis + 1] += previous[slot]
        rate[axis] = previous[slot] / (length * dt)


def _gathered(op, sim):
    """Whether the force operation ``op`` leaves the gathered stress of ``sim``'s cell exact
    (PeriodicCell.after_forces): a pair force, or one that adds no force this step."""
    if hasattr(op, "pair_forces"):
        return True
    adds_forces = getattr(op, "adds_forces", None)
    return adds_forces is not None and not adds_forces(sim)


@dataclass
class PeriodicCell(Box):
    """A periodic box [0, L] (module docstring), the counterpart of pendular.dem.state.Walls.

    position: (6,) faces as Walls.position, low faces at 0 [m];
    rate: (3,) stretching rate L' / L of the current step, extension positive [1/s];
    stress_tensor: (3, 3) Love–Weber stress of every force at the last evaluation (the pair
    forces', and the sums the other forces give, ``after_forces``), compression positive
    [Pa]; stiffness: (3,) S_a [Pa] (module docstring);
    wraps: (N, 3) int64 periods crossed by each particle (+1 through a high face);
    virial_blocks: (SUM_BLOCKS, 9) the face terms of the pair forces' sum of l (x) f [N m]
    gathered since the step began (pendular.dem.virial; zeroed with the forces);
    shear_offset: delta [m], the offset along x of the image above in z; shear_rate:
    gamma_dot [1/s] of the current step (x with z, set by a control: ConstantShearRate);
    shear_strain: gamma [-], the integral of gamma_dot dt (module docstring).
    """

    position: np.ndarray
    rate: np.ndarray = field(default_factory=lambda: np.zeros(3))
    stress_tensor: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    stiffness: np.ndarray = field(default_factory=lambda: np.zeros(3))
    wraps: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.int64))
    shear_offset: float = 0.0
    shear_rate: float = 0.0
    shear_strain: float = 0.0

    periodic = True

    def __post_init__(self):
        self.position = _check_box("periodic cell position", self.position)
        if np.any(self.position[0::2] != 0.0):
            raise ValueError(f"periodic cell position = {self.position.tolist()} m: the low "
                             "faces must sit at 0 (valid: [0, L] on every axis)")
        self.rate = check_array("cell rate", self.rate, length=3)
        self.stress_tensor = check_array("cell stress_tensor", self.stress_tensor, (3,),
                                         length=3)
        self.stiffness = check_array("cell stiffness", self.stiffness, length=3)
        self.wraps = np.asarray(self.wraps, dtype=np.int64).reshape(-1, 3)
        self.virial_blocks = np.zeros((SUM_BLOCKS, 9))
        self.shear_offset = check_range("cell shear_offset", self.shear_offset, unit="m")
        self.shear_rate = check_range("cell shear_rate", self.shear_rate, unit="1/s")
        self.shear_strain = check_range("cell shear_strain", self.shear_strain)

    @classmethod
    def box(cls, lo, hi):
        """The cell [lo, hi]; lo must be 0 on every axis."""
        return cls(position=_box_position(lo, hi))

    @property
    def sheared(self):
        """Whether the cell is sheared now: an offset or a shear rate (module docstring)."""
        return self.shear_offset != 0.0 or self.shear_rate != 0.0

    @property
    def period(self):
        """Shift of one periodic image (3,) [m]: the edge lengths (a view of ``position``,
        the low faces being at 0); sheared, (4,): (Lx, Ly, Lz, delta), laid out as the view
        (one compiled version of each kernel)."""
        if not self.sheared:
            return self.position[1::2]
        return period_layout([*self.position[1::2], self.shear_offset])

    def volume(self):
        """Volume of the cell [m^3]."""
        return float(self.position[1] * self.position[3] * self.position[5])

    @property
    def affine_rate(self):
        """Homogeneous stretching rate carrying the particles (3,) [1/s]; sheared, (4,) with
        the shear rate gamma_dot last (the velocity gamma_dot * z along x)."""
        if not self.sheared:
            return self.rate
        return np.array([self.rate[0], self.rate[1], self.rate[2], self.shear_rate])

    def stress(self):
        """Normal stress on each axis (3,) [Pa], compression positive: the diagonal of the
        Love–Weber stress of the last evaluation."""
        return np.diagonal(self.stress_tensor).copy()

    def shear_stress(self):
        """Shear stress tau [Pa] of the x-z plane: -(sigma_xz + sigma_zx) / 2 of the
        Love–Weber stress (compression positive), the stress whose power tau gamma_dot per
        unit volume the shear puts in, positive where it resists a positive shear rate."""
        return float(-0.5 * (self.stress_tensor[0, 2] + self.stress_tensor[2, 0]))

    def wrap(self, particles):
        """Bring every position into [0, L) and count the periods crossed in ``wraps``; a
        sheared cell first brings its offset into [-Lx/2, Lx/2) and its particles through the
        z faces, shifting x by -+ delta (module docstring)."""
        if len(self.wraps) != len(particles):
            self.wraps = np.zeros((len(particles), 3), np.int64)
        lengths = self.lengths()
        if self.sheared:
            self._wrap_sheared(particles.position, lengths)
        crossed = np.floor(particles.position / lengths)
        if crossed.any():
            particles.position -= crossed * lengths
            np.minimum(particles.position, np.nextafter(lengths, 0.0), out=particles.position)
            np.maximum(particles.position, 0.0, out=particles.position)
            self.wraps += crossed.astype(np.int64)

    def _wrap_sheared(self, position, lengths):
        """The offset into [-Lx/2, Lx/2) (whole Lx taken out of it counted in the x wraps of
        the particles wrapped in z, so that ``unwrapped`` is unchanged), then the particles
        through the z faces, x shifted by -+ delta and z clamped into [0, Lz)."""
        turns = math.floor(self.shear_offset / lengths[0] + 0.5)
        if turns:
            self.shear_offset -= turns * lengths[0]
            self.wraps[:, 0] += turns * self.wraps[:, 2]
        crossed = np.floor(position[:, 2] / lengths[2])
        if crossed.any():
            position[:, 0] -= crossed * self.shear_offset
            position[:, 2] -= crossed * lengths[2]
            np.clip(position[:, 2], 0.0, np.nextafter(lengths[2], 0.0), out=position[:, 2])
            self.wraps[:, 2] += crossed.astype(np.int64)

    def unwrapped(self, particles):
        """Positions with the periods crossed added back (N, 3) [m], in the current cell (a
        sheared one's images above in z at +delta along x)."""
        if len(self.wraps) != len(particles):
            return particles.position.copy()
        unwrapped = particles.position + self.wraps * self.lengths()
        if self.shear_offset != 0.0:
            unwrapped[:, 0] += self.wraps[:, 2] * self.shear_offset
        return unwrapped

    def follow(self, dt):
        """Advance the offset over the step ``dt`` [s] with the step's velocity gradient (the
        integrator's affine motion): delta += (rate_x delta + gamma_dot Lz0) dt, Lz0 the
        height at the step's start (the controls have set this step's lengths and rates);
        gamma += gamma_dot dt."""
        if self.sheared:
            height = self.position[5] / (1.0 + self.rate[2] * dt)
            self.shear_offset += (self.rate[0] * self.shear_offset
                                  + self.shear_rate * height) * dt
            self.shear_strain += self.shear_rate * dt

    def after_forces(self, sim):
        """The stress of this step's forces: from the particles' forces and the face terms
        the gathers left in ``virial_blocks`` (store_cell_stress) when every force operation
        is a pair force (has ``pair_forces(sim)``) or adds no force this step (declares
        ``adds_forces(sim)``, false now); otherwise pair by pair over the operations that are
        pair forces, and the sum of x (x) F [N m] that each other operation declaring
        ``virial(sim)`` gives of its forces (liquid clusters,
        pendular.capillary.liquid_clusters). The stretching and shear rates return to zero
        until a control sets them."""
        contacts = sim.contacts
        if all(_gathered(op, sim) for op in sim.forces):
            store_cell_stress(self.virial_blocks, sim.particles.position, sim.particles.force,
                              self.position, self.stress_tensor)
        else:       # a force that is not a pair force: its gather adds no virial
            total = np.zeros(9)
            for op in sim.forces:
                if hasattr(op, "pair_forces") and len(contacts):
                    total += pair_virial(sim.particles.position, contacts.row_start,
                                         contacts.pair_j, contacts.image, self.period,
                                         op.pair_forces(sim))
                elif hasattr(op, "virial"):
                    total += np.ravel(op.virial(sim))
            self.stress_tensor[:] = total.reshape(3, 3) / self.volume()
        self.rate.fill(0.0)
        self.shear_rate = 0.0

    def update_stiffness(self, sim):
        """``stiffness`` (3,) [Pa] of the current contacts, S_a = (1/V) sum kn (l_a n_a)^2
        (what the stress servo reads; a pass over the pairs, so the servo asks for it only
        when it refreshes)."""
        c = sim.contacts
        if c is None or not len(c):
            self.stiffness[:] = 0.0
            return
        self.stiffness[:] = contact_stiffness(sim.particles.radius, c.row_start, c.pair_j,
                                              c.normal, c.normal_force,
                                              c.overlap) / self.volume()

    def stretch(self, axis, shift, dt):
        """Change the length of ``axis`` by ``shift`` [m] over the step ``dt`` [s] (the
        particles follow through ``rate``)."""
        length = self.position[2 * axis + 1]
        self.position[2 * axis + 1] += shift
        self.rate[axis] = shift / (length * dt)


class ConstantShearRate:
    """Shear the periodic cell at ``rate`` gamma_dot [1/s], x with z (the velocity
    gamma_dot * z along x on top of the particles' own; module docstring): a control, set each
    step (the cell's rate returns to zero after the forces). Walls cannot shear a sample:
    ValueError on a walled scene."""

    #: Largest shear rate [1/s].
    MAX_RATE = MAX_STRAIN_RATE

    def __init__(self, rate):
        self.rate = check_range("shear_rate", rate, -self.MAX_RATE, self.MAX_RATE, unit="1/s")

    def state_dict(self):
        """The ``rate`` [1/s] its stage set."""
        return {"rate": self.rate}

    def load_state(self, state):
        self.rate = check_range("rate", state["rate"], -self.MAX_RATE, self.MAX_RATE,
                                unit="1/s")

    def steps_to(self, strain, dt, start=0.0):
        """Steps [-] of ``dt`` [s] to bring the shear strain from ``start`` to ``strain`` [-];
        ValueError unless the rate is non-zero and of the sign of the change."""
        change = strain - start
        if self.rate == 0.0 or change / self.rate <= 0.0:
            raise ValueError(f"shear strain = {strain!r} cannot be reached from {start!r} at "
                             f"shear_rate = {self.rate!r} 1/s: the rate must be non-zero and of "
                             "the sign of the change")
        return int(np.ceil(change / (self.rate * dt)))

    def apply(self, sim):
        box = sim.walls
        if not box.periodic:
            raise ValueError(f"shear_rate = {self.rate:g} 1/s needs a periodic cell "
                             "(--periodic): walls cannot shear a sample")
        box.shear_rate = self.rate
