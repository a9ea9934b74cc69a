"""Simulation state in contiguous arrays: particles and the box (six axis-aligned walls; the
periodic cell of pendular.dem.cell shares the Box interface)."""

from dataclasses import dataclass, field

import numpy as np

from pendular.utils.validate import check_array, check_positive


@dataclass
class Particles:
    """Spheres as a structure of arrays (SI units).

    position, velocity, angular_velocity, force, torque: (N, 3) float64 [m, m/s, rad/s, N, N m];
    radius, mass, inertia: (N,) float64 [m, kg, kg m^2]; density [kg/m^3].
    """

    position: np.ndarray
    radius: np.ndarray
    density: float
    velocity: np.ndarray = None
    angular_velocity: np.ndarray = None
    mass: np.ndarray = field(init=False)
    inertia: np.ndarray = field(init=False)
    force: np.ndarray = field(init=False)
    torque: np.ndarray = field(init=False)

    def __post_init__(self):
        self.position = check_array("position", self.position, (3,))
        if len(self.position) == 0:
            raise ValueError("position holds no sphere: valid range at least 1 particle")
        self.radius = check_array("radius", self.radius, positive=True, length=len(self.position))
        self.density = check_positive("density", self.density, "kg/m^3")
        count = len(self.radius)
        self.velocity = (np.zeros((count, 3)) if self.velocity is None
                         else check_array("velocity", self.velocity, (3,), length=count))
        self.angular_velocity = (np.zeros((count, 3)) if self.angular_velocity is None
                                 else check_array("angular_velocity", self.angular_velocity, (3,),
                                                  length=count))
        self.force = np.zeros((count, 3))
        self.torque = np.zeros((count, 3))
        self.mass = np.empty(count)
        self.inertia = np.empty(count)
        self.update_mass()

    def __len__(self):
        return len(self.radius)

    def update_mass(self):
        """Recompute mass (rho 4/3 pi R^3) and moment of inertia (2/5 m R^2) from the radii."""
        np.multiply(self.density * 4.0 / 3.0 * np.pi, self.radius ** 3, out=self.mass)
        np.multiply(0.4 * self.mass, self.radius ** 2, out=self.inertia)

    def solid_volume(self):
        """Total volume of the spheres [m^3]."""
        return float(4.0 / 3.0 * np.pi * np.sum(self.radius ** 3))


#: Wall k sits on axis k // 2; k % 2 == 0 is the low wall (normal +axis), 1 the high wall.
WALL_NAMES = ("x-", "x+", "y-", "y+", "z-", "z+")


class Box:
    """The sample's box [lo, hi], shared by its two kinds (``Walls``, ``PeriodicCell``).

    position: (6,) face coordinates along their axes [m], ordered as WALL_NAMES. A kind
    also provides ``period`` (3,) [m]: what a pair's periodic image shifts its branch vector
    by per image (Contacts.image; zeros for walls), ``affine_rate`` (3,) [1/s]: the
    homogeneous stretching rate that carries the particles (zeros for walls),
    ``virial_blocks`` (SUM_BLOCKS, 9) [N m]: where the pair forces' gathers add the face
    terms of their Love–Weber sums when ``period`` is not zero (pendular.dem.virial; walls: empty,
    never written),
    ``wrap(particles)`` (positions brought back into the box at a neighbour-list rebuild),
    ``after_forces(sim)`` (what the box measures once the step's forces are known) and
    ``follow(dt)`` (what the box does as the integrator moves the particles). A sheared
    periodic cell's ``period`` and ``affine_rate`` hold a fourth entry, its offset and shear
    rate (pendular.dem.cell).
    """

    periodic = False

    @property
    def lo(self):
        return self.position[0::2]

    @property
    def hi(self):
        return self.position[1::2]

    def lengths(self):
        """Box edge lengths (3,) [m]."""
        return self.position[1::2] - self.position[0::2]

    def volume(self):
        """Volume of the box [m^3]."""
        return float(np.prod(self.lengths()))

    def areas(self):
        """Area of each face (6,) [m^2]: the product of the two other edge lengths."""
        lengths = self.lengths()
        face = np.array([lengths[1] * lengths[2], lengths[0] * lengths[2], lengths[0] * lengths[1]])
        return np.repeat(face, 2)


def _check_box(name, position):
    position = check_array(name, position, length=6)
    lo, hi = position[0::2], position[1::2]
    if (hi <= lo).any():
        raise ValueError(f"{name} = {position.tolist()} m: each high face must lie above its "
                         f"low face (valid range hi > lo on every axis)")
    return position


def _box_position(lo, hi):
    lo = check_array("box_lo", np.reshape(lo, (1, 3)), (3,))[0]
    hi = check_array("box_hi", np.reshape(hi, (1, 3)), (3,))[0]
    if (hi <= lo).any():
        raise ValueError(f"box_hi {hi.tolist()} must exceed box_lo {lo.tolist()} on every axis")
    return np.array([lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]], dtype=np.float64)


def period_layout(values):
    """``values`` [m] (a cell's (3,) period, or a sheared cell's (4,)) as a new array laid out
    as a periodic cell's ``period``: a strided view of every other element. Walled and
    periodic scenes, and any caller of the kernels that take a period, then pass one array
    type and share one compiled version of each kernel (another layout compiles each again)."""
    values = np.asarray(values, dtype=np.float64)
    laid_out = np.zeros(2 * len(values))[1::2]
    laid_out[:] = values
    return laid_out


_NO_STRETCHING = np.zeros(3)
#: Zeros (3,) laid out as a periodic cell's ``period`` (period_layout).
_NO_PERIOD = period_layout(np.zeros(3))
_NO_VIRIAL = np.zeros((0, 9))


@dataclass
class Walls(Box):
    """Six frictionless axis-aligned planar walls bounding the box [lo, hi].

    position: (6,) wall plane coordinate along its axis [m], ordered as WALL_NAMES;
    velocity: (6,) outward-positive wall speed of the last step [m/s];
    force: (6,) normal force the particles exert on each wall, compression positive [N];
    stiffness: (6,) sum of the normal stiffnesses of the wall's contacts [N/m];
    moment: (6,) sum over the wall's contacts of centre-to-wall distance * force [N m].
    """

    position: np.ndarray
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(6))
    force: np.ndarray = field(default_factory=lambda: np.zeros(6))
    stiffness: np.ndarray = field(default_factory=lambda: np.zeros(6))
    moment: np.ndarray = field(default_factory=lambda: np.zeros(6))

    def __post_init__(self):
        self.position = _check_box("walls position", self.position)
        for name in ("velocity", "force", "stiffness", "moment"):
            setattr(self, name, check_array(f"walls {name}", getattr(self, name), length=6))

    @classmethod
    def box(cls, lo, hi):
        return cls(position=_box_position(lo, hi))

    @property
    def period(self):
        """No periodic images: zeros (3,) [m]."""
        return _NO_PERIOD

    @property
    def affine_rate(self):
        """Walls carry no particle: zeros (3,) [1/s]."""
        return _NO_STRETCHING

    @property
    def virial_blocks(self):
        """Walls gather no virial (period zero): an empty (0, 9) array."""
        return _NO_VIRIAL

    def wrap(self, particles):
        """Nothing to wrap inside walls."""

    def follow(self, dt):
        """Walls move by their own controls, not with the particles."""

    def after_forces(self, sim):
        """The wall forces come from pendular.dem.walls.WallForces among the scene's forces."""

    def stress(self):
        """Mean normal stress on each axis (3,) [Pa], compression positive: both walls' force / area."""
        per_wall = self.force / self.areas()
        return 0.5 * (per_wall[0::2] + per_wall[1::2])
