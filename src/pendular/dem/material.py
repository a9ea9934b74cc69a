"""Materials of the grains and of the walls, and the rules that give an unlike pair its
contact's parameters (docs/physics.md 'Materials and mixing rules').

A ``Material`` holds young E [Pa], poisson nu, density [kg/m^3], friction_deg phi [deg],
rolling_friction mu_r, restitution e and twisting_friction mu_t. A wall is driven, never moved
by its contacts: its density is infinite, and its E is infinite for a rigid wall (the default:
the limit of an infinitely stiff wall). A sphere–wall contact takes:

- elastic moduli: Hertz's E*, 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (Johnson 1985,
  Eq. 4.22), and Mindlin's G*, 1/G* = (2 - nu1)/G1 + (2 - nu2)/G2 (Mindlin 1949), a rigid
  body's terms 0;
- friction: the wall's own angle. A DEM user states the friction of each pair of materials
  (LIGGGHTS's ``coefficientFriction`` is a matrix over the pairs of atom types, its
  grain–wall entry the wall's); YADE's min(phi1, phi2) would make frictional walls under
  frictionless grains frictionless, and a wall's friction (a rough platen, a lubricated one)
  is a property of the wall's surface. Rolling and twisting friction likewise, the wall's
  own (pendular.dem.wall_rolling: the EPSD springs of the pairs on a sphere and a plane);
- restitution: the arithmetic mean (e1 + e2) / 2, YADE's rule for two materials' values when
  no value is given for their pair (its MatchMaker's default algorithm, 'avg'): exact where
  the two are equal, as the mean of two equal doubles is that double.
"""

import math
from dataclasses import dataclass

from pendular.utils.validate import check_range

#: The valid Poisson ratios: (-1, 0.5), open at both ends (an incompressible 0.5 has no shear
#: stiffness to spare: G* and the Rayleigh step stay finite, but the law is meant for solids).
POISSON_RANGE = (-1.0, 0.5)
#: The valid coefficients of restitution: (0, 1].
RESTITUTION_RANGE = (0.0, 1.0)


def check_poisson(poisson, name="poisson"):
    """``poisson`` as float, ValueError naming ``name`` outside (-1, 0.5)."""
    return check_range(name, poisson, *POISSON_RANGE, low_inclusive=False,
                       high_inclusive=False)


def check_restitution(restitution, name="restitution"):
    """``restitution`` as float, ValueError naming ``name`` outside (0, 1]."""
    return check_range(name, restitution, *RESTITUTION_RANGE, low_inclusive=False)


def _positive_or_infinite(name, value, unit):
    """``value`` as float in (0, inf], inf meaning rigid (or immovable); ValueError naming
    ``name`` otherwise."""
    number = float(value)
    if number == math.inf:
        return number
    return check_range(name, number, 0.0, math.inf, low_inclusive=False, unit=unit)


@dataclass(frozen=True)
class Material:
    """A body's material (module docstring): ``young`` [Pa] in (0, inf] (inf: rigid),
    ``poisson`` in (-1, 0.5), ``density`` [kg/m^3] in (0, inf] (inf: a driven wall),
    ``friction_deg`` [deg] in [0, 90), ``rolling_friction`` >= 0, ``restitution`` in (0, 1],
    ``twisting_friction`` >= 0. ValueError naming the field outside its range."""

    young: float
    poisson: float = 0.3
    density: float = math.inf
    friction_deg: float = 0.0
    rolling_friction: float = 0.0
    restitution: float = 1.0
    twisting_friction: float = 0.0

    def __post_init__(self):
        checked = {
            "young": _positive_or_infinite("young", self.young, "Pa"),
            "poisson": check_poisson(self.poisson),
            "density": _positive_or_infinite("density", self.density, "kg/m^3"),
            "friction_deg": check_range("friction_deg", self.friction_deg, 0.0, 90.0,
                                        high_inclusive=False, unit="deg"),
            "rolling_friction": check_range("rolling_friction", self.rolling_friction, 0.0),
            "restitution": check_restitution(self.restitution),
            "twisting_friction": check_range("twisting_friction", self.twisting_friction, 0.0)}
        for name, value in checked.items():
            object.__setattr__(self, name, value)

    @property
    def rigid(self):
        """Whether the body does not deform (E infinite)."""
        return self.young == math.inf


def rigid_wall(restitution=1.0, friction_deg=0.0):
    """The default wall: rigid, frictionless unless ``friction_deg`` [deg], of ``restitution``
    (the grains', so that a sphere–wall contact rebounds as a sphere–sphere one)."""
    return Material(math.inf, 0.0, math.inf, friction_deg, 0.0, restitution)


def shear_modulus(young, poisson):
    """G = E / (2 (1 + nu)) [Pa]."""
    return young / (2.0 * (1.0 + poisson))


def effective_modulus(young_1, poisson_1, young_2=math.inf, poisson_2=0.0):
    """Hertz's effective modulus E* [Pa], 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (Johnson
    1985, Eq. 4.22); a second body of infinite E (the default) is rigid."""
    return 1.0 / ((1.0 - poisson_1 ** 2) / young_1 + (1.0 - poisson_2 ** 2) / young_2)


def effective_shear_modulus(young_1, poisson_1, young_2=math.inf, poisson_2=0.0):
    """Mindlin's effective shear modulus G* [Pa], 1/G* = (2 - nu1)/G1 + (2 - nu2)/G2 (Mindlin
    1949; kt = 8 G* a); a second body of infinite E is rigid."""
    return 1.0 / ((2.0 - poisson_1) / shear_modulus(young_1, poisson_1)
                  + (2.0 - poisson_2) / shear_modulus(young_2, poisson_2))


def pair_restitution(restitution_1, restitution_2):
    """The coefficient of restitution of a contact between bodies of ``restitution_1`` and
    ``restitution_2``: their arithmetic mean (module docstring)."""
    return 0.5 * (restitution_1 + restitution_2)


def wall_contact(young, poisson, restitution, wall):
    """(E* [Pa], G* [Pa], e, friction angle [deg]) of a grain of ``young`` [Pa], ``poisson``
    and ``restitution`` on the ``wall`` (a Material), by the module docstring's rules."""
    return (effective_modulus(young, poisson, wall.young, wall.poisson),
            effective_shear_modulus(young, poisson, wall.young, wall.poisson),
            pair_restitution(restitution, wall.restitution), wall.friction_deg)
