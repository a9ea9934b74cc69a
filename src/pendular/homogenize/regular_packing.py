"""Regular packings of equal spheres (thesis section 4.2): SCP, BCC (Eqs. 4.2-4.3) and FCP.

Lengths are in units of the particle radius R. Neighbours whose centres lie 2 (1 + H/2) apart
(surface gap H = separation, in units of R) are in "contact": they carry one liquid bridge each
(Tables 4.2-4.4). Cells:

- SCP: cube of side 2 (1 + H/2), one particle; 6 contacts.
- BCC: box L x L x L' (z along L'), particles at the corners and the centre (two per cell);
  the centre touches the 8 corners: l'^2 + 2 l^2 = 16 (1 + H/2)^2 (Eq. 4.2). Geometric limits (Eq.
  4.3 with the erratum in docs/physics.md 'Errata', scaled with 1 + H/2): 1 <= l'/2 and l/2 <=
  sqrt(3/2), i.e. l' in [2, 2 sqrt 2] (1 + H/2). At l' = 2 (1 + H/2) the neighbours along z
  touch too (10 contacts); at l = 4/sqrt 3 (1 + H/2) = l' the packing is isotropic; at the upper
  end, l' = 2 sqrt 2 (1 + H/2), the neighbours along x and y touch (12 contacts): the FCP.
- FCP: the BCC cell with l' = 2 sqrt 2 (1 + H/2), l = 2 (1 + H/2) (section 4.2.3); 12 contacts.

Every particle of these packings has the same set of contact normals, so the fabric of one
particle is the fabric of the packing (Eq. 4.1).
"""

from dataclasses import dataclass
import itertools
import math

import numpy as np

from pendular.utils.validate import finite_number
from pendular.homogenize.fabric import fabric_tensor, principal_anisotropy

KINDS = ("scp", "bcc", "fcp")

_CONTACT_TOLERANCE = 1e-9
"""Relative tolerance on the centre distance 2 (1 + H/2) for two neighbours to be in contact."""


@dataclass(frozen=True)
class RegularPacking:
    """A regular packing of spheres of radius R; lengths and volumes in units of R and R^3.

    kind: "scp", "bcc" or "fcp". l_prime: L'/R (BCC and FCP; None for SCP). separation: H/R.
    cell_size: (3,) cell edges L_x, L_y, L_z / R. particles_per_cell: particles in the cell.
    cell_volume: V / R^3. porosity: n. coordination: contacts per particle.
    normals: (coordination, 3) unit contact normals of one particle (both orientations).
    bridge_normals: (bridges_per_cell, 3) one unit normal per bridge of the cell
    (particles_per_cell * coordination / 2 bridges). fabric: (3, 3) F_ij (Eq. 4.1).
    anisotropy: a = 5/2 (F_z - F_x) / tr F (Eq. 3.51). max_filling_angle: the pendular limit
    [deg], half the smallest angle between two contact normals of a particle, where the wetted
    caps of neighbouring bridges on one particle touch (docs/physics.md 'The bridge model').
    """

    kind: str
    l_prime: float | None
    separation: float
    cell_size: np.ndarray
    particles_per_cell: int
    cell_volume: float
    porosity: float
    coordination: int
    normals: np.ndarray
    bridge_normals: np.ndarray
    fabric: np.ndarray
    anisotropy: float
    max_filling_angle: float

    @property
    def void_ratio(self):
        """e = n / (1 - n)."""
        return self.porosity / (1.0 - self.porosity)

    @property
    def bridges_per_cell(self):
        """Number of bridges (contacts) in the cell, N_LB (docs/physics.md 'Errata', Eq. 3.57)."""
        return len(self.bridge_normals)


def bcc_l_prime_range(separation=0.0):
    """(smallest, largest) l' = L'/R of a BCC packing with gap H/R = separation (Eq. 4.3,
    docs/physics.md 'Errata')."""
    scale = 1.0 + 0.5 * separation
    return 2.0 * scale, 2.0 * math.sqrt(2.0) * scale


def bcc_lateral_size(l_prime, separation=0.0):
    """l = L/R from Eq. 4.2: l'^2 + 2 l^2 = 16 (1 + H/2)^2."""
    return math.sqrt(max(0.0, (16.0 * (1.0 + 0.5 * separation) ** 2 - l_prime**2) / 2.0))


def _contact_normals(cell_size, basis, contact_distance):
    """Unit normals from the particle at the origin to its neighbours at contact_distance."""
    normals = []
    for shift in itertools.product(range(-2, 3), repeat=3):
        for site in basis:
            branch = (np.array(shift) + site) * cell_size
            distance = np.linalg.norm(branch)
            if distance > 0.0 and abs(distance - contact_distance) <= _CONTACT_TOLERANCE * contact_distance:
                normals.append(branch / distance)
    return np.array(normals)


def _first_orientation(normals):
    """Mask selecting, of each pair n, -n, the one whose first nonzero component is positive."""
    leading = np.argmax(np.abs(normals) > 1e-12, axis=1)
    return normals[np.arange(len(normals)), leading] > 0.0


def _smallest_angle(normals):
    """Smallest angle [deg] between two distinct normals."""
    cosines = np.clip(normals @ normals.T, -1.0, 1.0)
    np.fill_diagonal(cosines, -1.0)
    return math.degrees(math.acos(cosines.max()))


def regular_packing(kind, l_prime=None, separation=0.0):
    """The regular packing `kind` ("scp", "bcc", "fcp") with surface gap H/R = separation >= 0.

    l_prime = L'/R applies to "bcc" only: in [2, 2 sqrt 2] (1 + H/2) (Eq. 4.3, docs/physics.md
    'Errata'); None gives the isotropic BCC, l' = 4/sqrt(3) (1 + H/2). Returns a RegularPacking.
    """
    if kind not in KINDS:
        raise ValueError(f"kind = {kind!r} is not a regular packing; valid kinds {KINDS}")
    separation = finite_number("separation", separation, "[0, inf) (H/R)")
    if separation < 0.0:
        raise ValueError(f"separation = {separation} is outside the valid range [0, inf) (H/R)")
    scale = 1.0 + 0.5 * separation
    if kind != "bcc" and l_prime is not None:
        raise ValueError(f"l_prime = {l_prime} applies to kind = 'bcc' only (got kind = {kind!r})")
    if kind == "scp":
        cell_size = np.full(3, 2.0 * scale)
        basis = [np.zeros(3)]
    else:
        if kind == "fcp":
            l_prime = bcc_l_prime_range(separation)[1]
        elif l_prime is None:
            l_prime = 4.0 / math.sqrt(3.0) * scale
        else:
            smallest, largest = bcc_l_prime_range(separation)
            l_prime = finite_number("l_prime", l_prime, f"[{smallest}, {largest}]")
            if not smallest <= l_prime <= largest:
                raise ValueError(
                    f"l_prime = {l_prime} is outside the valid range [{smallest:.6g}, {largest:.6g}] "
                    f"= [2, 2 sqrt 2] (1 + H/2) for separation = {separation} (Eq. 4.3)")
        lateral = bcc_lateral_size(l_prime, separation)
        cell_size = np.array([lateral, lateral, l_prime])
        basis = [np.zeros(3), np.full(3, 0.5)]
    normals = _contact_normals(cell_size, basis, 2.0 * scale)
    cell_volume = float(np.prod(cell_size))
    porosity = 1.0 - len(basis) * (4.0 * math.pi / 3.0) / cell_volume
    bridge_normals = np.tile(normals[_first_orientation(normals)], (len(basis), 1))
    fabric = fabric_tensor(normals, np.ones(len(normals), dtype=bool))
    return RegularPacking(
        kind=kind,
        l_prime=None if kind == "scp" else float(l_prime),
        separation=separation,
        cell_size=cell_size,
        particles_per_cell=len(basis),
        cell_volume=cell_volume,
        porosity=porosity,
        coordination=len(normals),
        normals=normals,
        bridge_normals=bridge_normals,
        fabric=fabric,
        anisotropy=principal_anisotropy(fabric),
        max_filling_angle=0.5 * _smallest_angle(normals),
    )
