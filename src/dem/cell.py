"""A periodic cell: the sample's box without walls (YADE's O.periodic with a diagonal velocity
gradient; LAMMPS's deforming periodic box).

The cell is [0, L] on each axis. A particle leaving through a face comes back through the
opposite one: positions are wrapped into the cell at every neighbour-list rebuild, and
``wraps`` counts how many periods each particle has crossed (its unwrapped position is
position + wraps * L). A pair interacts through the image of j nearest to i
(dem.neighbors.branch_vector). The cell deforms by stretching its axes: a control sets
``rate`` [1/s] (L' / L, extension positive) and the integrator moves every particle with the
homogeneous velocity rate * x on top of its own (fluctuating) velocity, so the contact law adds
rate * l to the relative velocity of a pair of branch vector l (YADE's periodic scheme).

With no walls, the stress of the cell is the Love–Weber average of every pair force over the
cell volume (Eq. 3.41 over contacts and, in a wet scene, bridges): ``after_forces`` computes it
each step, with the cell's stiffness S_a = (1/V) sum kn (l_a n_a)^2 [Pa per unit strain] that
the stress servo uses as a wall servo uses the stiffness of the wall's contacts.
"""

from dataclasses import dataclass, field

import numba
import numpy as np

from .contact_law import ContactForces
from .neighbors import branch_vector
from .state import Box, _box_position, _check_box
from .validate import check_array

_NONE = np.zeros((0, 3))

#: Fixed blocks of particles summed apart then together: a sum in the same order for any
#: thread count (results thread-independent).
SUM_BLOCKS = 64


@numba.njit(cache=True, parallel=True)
def pair_virial(position, row_start, pair_j, image, period, pair_force, other_force,
                normal_force, overlap, with_stiffness):
    """(12,) sums over the pairs: [0:9] sum l_a f_b (row a, column b; l the branch vector
    i -> j [m], f the force on j from i [N]: ``pair_force`` plus ``other_force`` unless that
    is empty, (0, 3)) and, with ``with_stiffness``, [9:12] sum over the touching pairs of
    kn (l_a n_a)^2 with kn = normal_force / overlap [N m]."""
    other = len(other_force) > 0
    count = len(row_start) - 1
    sums = np.zeros((SUM_BLOCKS, 12))
    for block in numba.prange(SUM_BLOCKS):
        s00 = s01 = s02 = s10 = s11 = s12 = s20 = s21 = s22 = 0.0
        k0 = k1 = k2 = 0.0
        for i in range(count * block // SUM_BLOCKS, count * (block + 1) // SUM_BLOCKS):
            for k in range(row_start[i], row_start[i + 1]):
                l0, l1, l2 = branch_vector(position, i, pair_j[k], image, k, period)
                f0 = pair_force[k, 0]
                f1 = pair_force[k, 1]
                f2 = pair_force[k, 2]
                if other:
                    f0 += other_force[k, 0]
                    f1 += other_force[k, 1]
                    f2 += other_force[k, 2]
                s00 += l0 * f0
                s01 += l0 * f1
                s02 += l0 * f2
                s10 += l1 * f0
                s11 += l1 * f1
                s12 += l1 * f2
                s20 += l2 * f0
                s21 += l2 * f1
                s22 += l2 * f2
                if with_stiffness and overlap[k] > 0.0:
                    weight = normal_force[k] / (overlap[k] * (l0 * l0 + l1 * l1 + l2 * l2))
                    k0 += weight * l0 ** 4
                    k1 += weight * l1 ** 4
                    k2 += weight * l2 ** 4
        row = sums[block]
        row[0], row[1], row[2], row[3], row[4], row[5] = s00, s01, s02, s10, s11, s12
        row[6], row[7], row[8], row[9], row[10], row[11] = s20, s21, s22, k0, k1, k2
    total = np.zeros(12)
    for block in range(SUM_BLOCKS):
        for c in range(12):
            total[c] += sums[block, c]
    return total


@numba.njit(cache=True)
def servo_cell(position, rate, stress_tensor, cell_stiffness, stiffness, previous, axes,
               target, gain, memory, max_velocity, scale_max_velocity, refresh, dt):
    """One step of the stress servo for the axes ``axes`` of a periodic cell, in place: each
    length changes by dL_n = gain * clip(L (sigma - target) / S, +-cap) + memory * dL_n-1
    (dem.walls.StressServo's law with the cell's stiffness S [Pa] for K_wall / area, and
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


@dataclass
class PeriodicCell(Box):
    """A periodic box [0, L] (module docstring), the counterpart of dem.state.Walls.

    position: (6,) faces as Walls.position, low faces at 0 [m];
    rate: (3,) stretching rate L' / L of the current step, extension positive [1/s];
    stress_tensor: (3, 3) Love–Weber stress of every pair force at the last evaluation,
    compression positive [Pa]; stiffness: (3,) S_a [Pa] (module docstring);
    wraps: (N, 3) int64 periods crossed by each particle (+1 through a high face).
    """

    position: np.ndarray
    rate: np.ndarray = field(default_factory=lambda: np.zeros(3))
    stress_tensor: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    stiffness: np.ndarray = field(default_factory=lambda: np.zeros(3))
    wraps: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.int64))

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

    @classmethod
    def box(cls, lo, hi):
        """The cell [lo, hi]; lo must be 0 on every axis."""
        return cls(position=_box_position(lo, hi))

    @property
    def period(self):
        """Shift of one periodic image (3,) [m]: the edge lengths."""
        return self.lengths()

    @property
    def affine_rate(self):
        """Homogeneous stretching rate carrying the particles (3,) [1/s]."""
        return self.rate

    def stress(self):
        """Normal stress on each axis (3,) [Pa], compression positive: the diagonal of the
        Love–Weber stress of the last evaluation."""
        return np.diagonal(self.stress_tensor).copy()

    def wrap(self, particles):
        """Bring every position into [0, L) and count the periods crossed in ``wraps``."""
        if len(self.wraps) != len(particles):
            self.wraps = np.zeros((len(particles), 3), np.int64)
        lengths = self.lengths()
        crossed = np.floor(particles.position / lengths)
        if crossed.any():
            particles.position -= crossed * lengths
            np.minimum(particles.position, np.nextafter(lengths, 0.0), out=particles.position)
            np.maximum(particles.position, 0.0, out=particles.position)
            self.wraps += crossed.astype(np.int64)

    def unwrapped(self, particles):
        """Positions with the periods crossed added back (N, 3) [m], in the current cell."""
        if len(self.wraps) != len(particles):
            return particles.position.copy()
        return particles.position + self.wraps * self.lengths()

    def after_forces(self, sim):
        """The stress and stiffness of this step's pair forces (every force operation with
        ``pair_forces(sim)``; the contact law's also give the stiffness); the stretching rate
        returns to zero until a control sets it."""
        contacts = sim.contacts
        total = np.zeros(12)
        if contacts is not None and len(contacts):
            period = self.period
            contact, others = None, []
            for op in sim.forces:
                if isinstance(op, ContactForces) and contact is None:
                    contact = op.pair_forces(sim)
                elif hasattr(op, "pair_forces"):
                    others.append(op.pair_forces(sim))
            # one pass for the contacts (with their stiffness) and a first other force
            passes = [(force, _NONE, False) for force in others]
            if contact is not None:
                passes = [(contact, others[0] if others else _NONE, True)] + passes[1:]
            for pair_force, other_force, with_stiffness in passes:
                total += pair_virial(sim.particles.position, contacts.row_start,
                                     contacts.pair_j, contacts.image, period, pair_force,
                                     other_force, contacts.normal_force, contacts.overlap,
                                     with_stiffness)
        volume = self.volume()
        self.stress_tensor[:] = total[:9].reshape(3, 3) / volume
        self.stiffness[:] = total[9:] / volume
        self.rate[:] = 0.0

    def stretch(self, axis, shift, dt):
        """Change the length of ``axis`` by ``shift`` [m] over the step ``dt`` [s] (the
        particles follow through ``rate``)."""
        length = self.position[2 * axis + 1]
        self.position[2 * axis + 1] += shift
        self.rate[axis] = shift / (length * dt)
