"""Effective stress of the live DEM state (thesis Eqs. 3.43-3.46, 3.51-3.54, 4.5), when a recorder asks.

The discrete sums of pendular.homogenize.bridge_tensors taken over the liquid bridges of a simulation,
read through capillary.BridgeState (``state`` != NO_BRIDGE marks a bridge; ``volume`` [m^3];
``filling_i`` and ``filling_j`` [deg], the caps on particles pair_i and pair_j, each with its
own radius: delta1 sits on the smaller sphere, delta2 on the larger, and A, B' of each cap use
that sphere's radius; checked for two sizes against a hand computation of Eqs. 3.44-3.49 and
3.53 in tests/integration/test_unequal_bridges.py).
Each bridge's normal is its current branch vector x_j - x_i, unit (valid for bridges at contact
and across a gap alike; ``contacts.normal`` is the contact law's and lags for gap pairs).

    chi_ij    = (V_w / V) delta_ij + (1/V) sum_bridges [Rot A(R_i, delta_i) + Rot A(R_j, delta_j)]  (Eq. 3.44)
    B_ij      = (1/V) sum_bridges [Rot B'(R_i, delta_i) + Rot B'(R_j, delta_j)]                      (Eq. 3.45)
    psi_ij    = chi_ij s + B_ij                                                                     (Eq. 3.46)
    sigma'_ij = (sigma_ij - u_a delta_ij) + psi_ij                                                  (Eq. 3.43)
    F^LB_ij   = (1/N_LB) sum_bridges n_i n_j, a_LB = 5/2 (F_z - F_x) / tr F                        (Eqs. 3.53-3.54)
    a_psi     = 5/2 (psi_z - psi_x) / tr psi                                                        (Eq. 4.5)
    I_ij      = (gamma/V) sum_bridges ∫_interface (delta_ij - n_i n_j) dS      (liquid-gas interface)
    sigma'^c  = (sigma_ij - u_a delta_ij) + psi_ij + I_ij                     (complete effective stress)

with V_w the water volume (sum of the bridge volumes, V_w / V = n Sr) and V the volume
homogenised over (the box inside the walls for a recorder). In the triaxial the total stress
sigma_ij is the wall stress diag(sigma_x, sigma_y, sigma_z) and u_a = 0. SI units, angles in
degrees, stresses compression positive.

Sign of B (Eq. 3.45 with Eq. 3.49 as restated in docs/physics.md 'Effective stress'). In
Love-Weber form, compression positive, forces f acting on a particle at points x of its surface
(x from its centre) contribute -(1/V) sum x_i f_j to the stress: a force pushing the particle
inward is compressive. A bridge acts on each of its particles through the water pressure u_w =
-s on the wetted cap (the force s n dGamma pulls the surface outward: contribution -(s/V) A_ij)
and through the surface tension gamma e dl along the contact line, e pointing along the
liquid-gas interface, i.e. toward the other particle (attraction: contribution -(1/V) B'_ij);
the water itself adds u_w n Sr delta_ij.
The total stress is then sigma = sigma' - chi s - B, i.e. Eq. 3.43 with a plus sign for
both terms, provided B'_ij = ∫ R gamma n_i e_j dl with e the direction of the surface-tension
force ON the particle. That is how Eq. 3.49 reads: in the bridge frame n_z = cos(alpha) and
e_z = sin(alpha + theta) > 0 at the contact line, so B'_zz = pi R^2 gamma sin(2 alpha)
sin(alpha + theta) > 0, compressive along the bridge like the suction term, while
B'_xx = B'_yy = -pi R^2 gamma sin^2(alpha) cos(alpha + theta) < 0 (the lateral pull of the
meniscus ring, e_x = -cos(alpha + theta) at azimuth 0). Hence, at theta = 0 and s > 0, tr B = 0
(B is deviatoric and vanishes for an isotropic bridge fabric), chi s is positive definite, the
diagonal of psi is positive for the near-isotropic bridge fabrics of packings and triaxial
samples, and the capillary terms add to the net stress: sigma' = sigma_net + psi.

Volume-controlled bridges carry their own suction (``BridgeState.suction``): psi is the sum of
each bridge's s_k [V_k delta_ij + Rot A] over V plus B, which equals chi s + B when every
bridge has the suction s; chi is Eq. 3.44 either way.

The complete capillary stress (docs/capillary.md "The complete capillary stress"). Eq. 3.46
sums the water pressure on the wetted caps and the surface tension along the contact lines,
but not the tension carried by the liquid-gas interface itself. Averaging the stress of every
phase (solids, water, air and the interface as a membrane of tension gamma) over V adds
-(gamma/V) ∫ (delta - n n) dS to the total stress, so that psi + I is exactly, bridge by bridge,
the Love–Weber stress of the capillary forces with its sign reversed, (1/V) d F n n (d the
centre distance, F the attraction; Duriez et al. 2018, YADE's MeasureCapStress; checked against
the exact solver and in a static packing in tests/integration/test_complete_capillary_stress.py). Then
sigma'^c = sigma_net + psi + I is the stress the contacts carry. I is taken from the exact
tables (nn11, nn33 at each bridge's suction and gap); the toroidal model has none.

``homogenized(sim)`` gives the homogenised quantities of a simulation's state, named as the
history's columns, wherever the state is held: reduced on the device when a device run holds
it (its ``homogenized()``, pendular.gpu.homogenize: no particle state comes back), else
measured here by the CPU's own functions (HostMeasures). A wet scene's recorder builds
``CapillaryHomogenization(bridges)`` from its bridge operation; a dry scene never does.
"""

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from pendular.capillary.bridge_state import BridgeState
from pendular.capillary.bridges import CapillaryBridges
from pendular.dem.measure import coordination, largest_overlap, unbalanced_force
from pendular.dem.neighbors import branch_vectors
from pendular.utils.validate import check_positive
from pendular.homogenize.bridge_tensors import (capillary_stress, capillary_stress_anisotropy,
    effective_stress_parameter, interface_stress, surface_tension_stress, wetted_caps_sum)
from pendular.homogenize.contact_stress import contact_stress, pair_stress_sum
from pendular.homogenize.fabric import fabric_tensor, principal_anisotropy
from pendular.homogenize.wall_bridge_stress import with_wall_bridges


@dataclass(frozen=True)
class BridgeStress:
    """Homogenised capillary state of the bridges in a volume.

    bridges: number of bridges counted (N_LB); water_volume: V_w [m^3]; volume: V [m^3];
    chi: chi_ij (3, 3), dimensionless (Eq. 3.44); B: B_ij (3, 3) [Pa] (Eq. 3.45);
    psi: psi_ij (3, 3) [Pa] (Eq. 3.46); fabric: bridge fabric F^LB_ij (3, 3) (Eq. 3.53, zeros
    without bridges); anisotropy: a_LB (Eq. 3.54); a_psi (Eq. 4.5) (both NaN without bridges);
    interface: the liquid-gas interface term I_ij (3, 3) [Pa] (None when not asked for).
    """

    bridges: int
    water_volume: float
    volume: float
    chi: np.ndarray
    B: np.ndarray
    psi: np.ndarray
    fabric: np.ndarray
    anisotropy: float
    a_psi: float
    interface: np.ndarray | None = None


def bridge_mask(contacts):
    """(K,) bool: the pairs holding a liquid bridge (none if no bridge operation ran)."""
    if not BridgeState.present(contacts):
        return np.zeros(len(contacts), dtype=bool)
    return BridgeState.of(contacts).mask()


def _branch(particles, contacts, index, period):
    """Centre distances (B,) and unit branch vectors i -> j (B, 3) of the pairs ``index``
    (``period``: the periodic cell's edges [m], or None inside walls)."""
    branch = branch_vectors(particles.position, contacts,
                            np.zeros(3) if period is None else period, index)
    distance = np.sqrt(np.einsum("ka,ka->k", branch, branch))
    return distance, branch / distance[:, None]


def bridges_in_region(particles, contacts, lo, hi, period=None):
    """(K,) bool: the bridges whose centre lies in the half-open box [lo, hi) [m] (``period``
    [m]: the edges of a periodic cell holding the particles, None inside walls).

    The bridge centre is the middle of the gap (or overlap) on the branch vector,
    x_i + (d + R_i - R_j)/2 n (the contact point at touching; the midpoint for equal spheres).
    Selecting bridges by their centre counts each bridge of a periodic packing once per cell.
    """
    lo = np.asarray(lo, dtype=float)
    hi = np.asarray(hi, dtype=float)
    if lo.shape != (3,) or hi.shape != (3,) or not np.all(hi > lo):
        raise ValueError(f"region [lo, hi) = [{lo.tolist()}, {hi.tolist()}) is not a box: "
                         "expected lo, hi of shape (3,) with hi > lo")
    mask = bridge_mask(contacts)
    index = np.flatnonzero(mask)
    distance, normal = _branch(particles, contacts, index, period)
    radius = particles.radius
    reach = 0.5 * (distance + radius[contacts.pair_i[index]] - radius[contacts.pair_j[index]])
    centre = particles.position[contacts.pair_i[index]] + reach[:, None] * normal
    mask[index] = np.all((centre >= lo) & (centre < hi), axis=1)
    return mask


def homogenize_bridges(particles, contacts, volume, *, suction, contact_angle, surface_tension,
                       mask=None, interfaces=None, period=None):
    """chi, B, psi, bridge fabric and anisotropies of the bridges of a DEM state (Eqs. 3.44-3.46,
    3.53-3.54, 4.5) over the volume V [m^3]; a BridgeStress.

    suction: s = u_a - u_w [Pa], a scalar (suction control) or one value per pair (K,)
    (volume control: each bridge's own suction); contact_angle [deg]; surface_tension [N/m];
    mask: (K,) bool, the pairs counted (default: every bridge); it must select bridges only;
    interfaces: (B, 2) [m^2], nn11 and nn33 of each counted bridge in pair order
    (capillary.CapillaryBridges.interfaces): adds the interface term (``interface``);
    period: (3,) [m] the edges of a periodic cell (bridges through its faces), None inside walls.
    """
    volume = check_positive("volume", volume, "m^3")
    bridges = bridge_mask(contacts)
    if mask is None:
        mask = bridges
    else:
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != bridges.shape:
            raise ValueError(f"mask has shape {mask.shape}; expected ({len(contacts)},), one per pair")
        if np.any(mask & ~bridges):
            raise ValueError(f"mask selects {int(np.count_nonzero(mask & ~bridges))} pair(s) "
                             "without a bridge; valid: a subset of the bridges")
    index = np.flatnonzero(mask)
    _, normal = _branch(particles, contacts, index, period)
    radius_i = particles.radius[contacts.pair_i[index]]
    radius_j = particles.radius[contacts.pair_j[index]]
    if len(index):
        state = BridgeState.of(contacts)
        filling_i, filling_j = state.filling_i[index], state.filling_j[index]
        bridge_volume = state.volume[index]
    else:
        filling_i = filling_j = bridge_volume = np.zeros(0)
    water_volume = float(np.sum(bridge_volume))
    caps = (normal, radius_i, radius_j, filling_i, filling_j)
    chi = effective_stress_parameter(*caps, water_volume, volume)
    tension = surface_tension_stress(*caps, contact_angle, surface_tension, volume)
    if np.ndim(suction) == 0:
        psi = capillary_stress(chi, tension, float(suction))
    else:
        suction = np.asarray(suction, dtype=float)
        if suction.shape != bridges.shape:
            raise ValueError(f"suction has shape {suction.shape}; expected a scalar or "
                             f"({len(contacts)},), one per pair")
        own = suction[index]
        weighted = wetted_caps_sum(*caps, weight=own)
        psi = (float(np.sum(own * bridge_volume)) * np.eye(3) + weighted) / volume + tension
    interface = None
    if interfaces is not None:
        interfaces = np.asarray(interfaces, dtype=float)
        if interfaces.shape != (len(index), 2):
            raise ValueError(f"interfaces has shape {interfaces.shape}; expected "
                             f"({len(index)}, 2), nn11 and nn33 of each counted bridge")
        interface = interface_stress(normal, interfaces[:, 0], interfaces[:, 1],
                                     surface_tension, volume)
    fabric = fabric_tensor(normal, np.ones(len(index), dtype=bool))
    return BridgeStress(
        bridges=len(index),
        water_volume=water_volume,
        volume=volume,
        chi=chi,
        B=tension,
        psi=psi,
        fabric=fabric,
        anisotropy=principal_anisotropy(fabric),
        a_psi=capillary_stress_anisotropy(psi),
        interface=interface,
    )


def capillary_force_stress(sim, bridges):
    """Love–Weber stress of the capillary forces (1/V) sum l_i f^cap_j [Pa] (3x3) of the bridge
    operation ``bridges`` (capillary.CapillaryBridges), V the box inside the walls, with the
    sign convention of pendular.homogenize.contact_stress (l = x_j - x_i, f on j from i, compression
    positive): attractive bridges give a negative (tensile) stress, and in static equilibrium
    sigma_wall = sigma_contact + sigma_capillary. Sphere-wall bridges (``bridges.walls``) add
    their l f, l from the sphere's centre to the wall, as the walls' contacts add theirs to
    sigma_contact (Walls.moment)."""
    pair_force = bridges.pair_forces(sim)
    c = sim.contacts
    total = pair_stress_sum(sim.particles.position, c.pair_i, c.pair_j, c.image,
                            sim.walls.period, pair_force, BridgeState.of(c).mask())
    if bridges.walls is not None:
        moment = bridges.walls.moment
        total[np.diag_indices(3)] -= moment[0::2] + moment[1::2]
    return total / sim.walls.volume()


def homogenized(sim):
    """The homogenised quantities of ``sim``'s state, a mapping named as the history's columns
    (module docstring): the device run's reduction when one holds the state
    (Simulation.holder), else HostMeasures(sim). Keys: sigma_contact [Pa] (3, 3),
    coordination, fabric (3, 3), anisotropy, unbalanced_force [-], solid_volume [m^3],
    largest_overlap [-], smallest_radius and largest_radius [m]; wet, bridges,
    pendular_overlaps, water_volume [m^3], chi (3, 3), B, psi, sigma_capillary [Pa] (3, 3),
    fabric_bridges (3, 3), anisotropy_bridges, a_psi [-] and, with the exact model,
    psi_interface [Pa] (3, 3)."""
    run = sim.holder
    return HostMeasures(sim) if run is None else run.homogenized()


def _contact_fabric(sim):
    return fabric_tensor(sim.contacts.normal, sim.contacts.overlap > 0.0)      # Eq. 4.1


#: The host's measure of each dry quantity of ``homogenized``: a function of (sim, the
#: HostMeasures asked).
DRY_MEASURES = {
    "sigma_contact": lambda sim, m: contact_stress(sim.particles, sim.contacts, sim.walls),
    "coordination": lambda sim, m: coordination(sim.contacts, len(sim.particles)),
    "fabric": lambda sim, m: _contact_fabric(sim),
    "anisotropy": lambda sim, m: principal_anisotropy(m["fabric"]),           # Eq. 3.51
    "unbalanced_force": lambda sim, m: unbalanced_force(sim.particles, sim.contacts),
    "solid_volume": lambda sim, m: sim.particles.solid_volume(),
    "largest_overlap": lambda sim, m: largest_overlap(sim),
    "smallest_radius": lambda sim, m: float(sim.particles.radius.min()),
    "largest_radius": lambda sim, m: float(sim.particles.radius.max()),
}
#: The host's measure of each wet quantity: a function of (sim, the HostMeasures asked, the
#: scene's CapillaryBridges).
WET_MEASURES = {
    "bridges": lambda sim, m, op: op.count(sim),
    "pendular_overlaps": lambda sim, m, op: op.pendular_overlaps(sim),
    "water_volume": lambda sim, m, op: op.water_volume(sim.contacts),
    "sigma_capillary": lambda sim, m, op: capillary_force_stress(sim, op),
    "chi": lambda sim, m, op: m.bridge_stress.chi,
    "B": lambda sim, m, op: m.bridge_stress.B,
    "psi": lambda sim, m, op: m.bridge_stress.psi,
    "fabric_bridges": lambda sim, m, op: m.bridge_stress.fabric,
    "anisotropy_bridges": lambda sim, m, op: m.bridge_stress.anisotropy,
    "a_psi": lambda sim, m, op: m.bridge_stress.a_psi,
    "psi_interface": lambda sim, m, op: m.bridge_stress.interface,      # the exact model's
}


class HostMeasures(Mapping):
    """``homogenized`` of a state the host holds: each quantity measured on first read by the
    CPU's function (DRY_MEASURES, WET_MEASURES with the scene's bridge operation), then kept,
    so that the columns of one record share one evaluation (the bridges' sums of
    homogenize_bridges among them)."""

    def __init__(self, sim):
        self.sim = sim
        found = [op for op in sim.forces if isinstance(op, CapillaryBridges)]
        self.bridges = found[0] if found else None
        self._values = {}
        self._bridge_stress = None

    def _names(self):
        if self.bridges is None:
            return tuple(DRY_MEASURES)
        return (*DRY_MEASURES, *(name for name in WET_MEASURES
                                 if name != "psi_interface" or self.bridges.model == "exact"))

    def __getitem__(self, name):
        if name not in self._values:
            if name in DRY_MEASURES:
                self._values[name] = DRY_MEASURES[name](self.sim, self)
            elif name in self._names():
                self._values[name] = WET_MEASURES[name](self.sim, self, self.bridges)
            else:
                raise KeyError(f"{name!r} is not a homogenised quantity of this scene (valid: "
                               f"{', '.join(self._names())})")
        return self._values[name]

    def __iter__(self):
        return iter(self._names())

    def __len__(self):
        return len(self._names())

    @property
    def bridge_stress(self):
        """The BridgeStress of the bridges over the box inside the walls (homogenize_bridges
        with the operation's suction, contact angle and surface tension; volume control:
        each bridge's own suction; the exact model: its interfaces), the sphere-wall bridges'
        share added (pendular.homogenize.wall_bridge_stress)."""
        if self._bridge_stress is None:
            sim, op = self.sim, self.bridges
            suction = (BridgeState.of(sim.contacts).suction if op.control == "volume"
                       else op.suction)
            interfaces = None
            if op.model == "exact":
                interfaces = op.interfaces(sim, np.flatnonzero(bridge_mask(sim.contacts)))
            self._bridge_stress = homogenize_bridges(
                sim.particles, sim.contacts, sim.walls.volume(), suction=suction,
                contact_angle=op.contact_angle, surface_tension=op.surface_tension,
                interfaces=interfaces, period=sim.walls.period)
            if op.walls is not None:        # sphere-wall bridges (--wall-bridges)
                self._bridge_stress = with_wall_bridges(
                    self._bridge_stress, sim, op.walls, op.suction, op.contact_angle,
                    op.surface_tension, sim.walls.volume())
        return self._bridge_stress


class CapillaryHomogenization:
    """The capillary state of a wet scene, evaluated when a recorder asks.

    bridges: the scene's capillary.CapillaryBridges operation (its suction, contact angle and
    surface tension, and its per-pair BridgeState). The volume is the box inside the walls; the
    total stress of Eq. 3.43 is the wall stress diag(sigma_x, sigma_y, sigma_z), u_a = 0. One
    ``homogenized`` serves every column of a record (kept for the state's step, contact list
    and holder). The exact model adds the interface term and the complete effective stress.
    """

    def __init__(self, bridges):
        self.bridges = bridges
        self._key = None
        self._measured = None

    def measured(self, sim):
        """homogenized(sim), once per state (step, time, contact list and holder)."""
        key = (sim.step, sim.time, sim.peek("contacts"), sim.holder)
        if (self._key is None or key[:2] != self._key[:2]
                or any(a is not b for a, b in zip(key[2:], self._key[2:]))):
            self._key, self._measured = key, homogenized(sim)
        return self._measured

    def sigma_capillary(self, sim):
        return self.measured(sim)["sigma_capillary"]

    def saturation(self, sim):
        measured = self.measured(sim)
        return measured["water_volume"] / (sim.walls.volume() - measured["solid_volume"])

    def count(self, sim):
        return self.measured(sim)["bridges"]

    def pendular_overlaps(self, sim):
        return self.measured(sim)["pendular_overlaps"]

    def chi(self, sim):
        return self.measured(sim)["chi"]

    def B(self, sim):
        return self.measured(sim)["B"]

    def psi(self, sim):
        return self.measured(sim)["psi"]

    def sigma_effective(self, sim):
        return np.diag(sim.walls.stress()) + self.measured(sim)["psi"]    # Eq. 3.43, u_a = 0

    def psi_interface(self, sim):
        return self.measured(sim)["psi_interface"]

    def sigma_effective_complete(self, sim):
        return self.sigma_effective(sim) + self.psi_interface(sim)

    def fabric_bridges(self, sim):
        return self.measured(sim)["fabric_bridges"]

    def anisotropy_bridges(self, sim):
        return self.measured(sim)["anisotropy_bridges"]

    def a_psi(self, sim):
        return self.measured(sim)["a_psi"]

    def quantities(self):
        """Recorded columns of a wet scene, name -> function of sim (bound methods, so that a
        deep-copied recorder follows its copy): the bridges' saturation, suction [Pa],
        sigma_capillary [Pa], bridges, pendular_overlaps, then chi, B, psi, sigma_effective,
        fabric_bridges, anisotropy_bridges, a_psi (Eqs. 3.43-3.46, 3.53-3.54, 4.5), and with
        the exact model psi_interface and sigma_effective_complete."""
        op = self.bridges
        columns = {
            "saturation": self.saturation,
            "suction": op.mean_suction,
            "sigma_capillary": self.sigma_capillary,
            "bridges": self.count,
            "pendular_overlaps": self.pendular_overlaps,
            "chi": self.chi,
            "B": self.B,
            "psi": self.psi,
            "sigma_effective": self.sigma_effective,
            "fabric_bridges": self.fabric_bridges,
            "anisotropy_bridges": self.anisotropy_bridges,
            "a_psi": self.a_psi,
        }
        if op.model == "exact":
            columns.update({"psi_interface": self.psi_interface,
                            "sigma_effective_complete": self.sigma_effective_complete})
        return columns
