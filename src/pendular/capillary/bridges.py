"""Liquid bridges in the DEM: the capillary operations of wet scenes (thesis Ch. 5, docs/physics.md
'The bridge model').

Two operations, one per control, share their tables, kernels and measures (``CapillaryBridges``,
their base): ``SuctionBridges`` at an imposed suction (the thesis's Ch. 5), ``VolumeBridges`` of
constant volume. ``CapillaryBridges(suction, ..., control=...)`` builds the one of that control
(``control`` "suction", the default, or "volume"; each refuses the other's options), so that a
scene, a configuration or a test names the bridges one way and finds them with
``sim.operation(CapillaryBridges)``. What depends on the control, on ``persist`` and on the
liquid model is chosen once, when the operation is built or the liquid closed: the kernel each
step calls, how its forces are gathered, which tables it reads.

A wet scene lists the bridges among its forces after the contact law and the wall springs
(``sim.forces.append(bridges)``; YADE's order: InteractionLoop,
Law2_ScGeom_CapillaryPhys_Capillarity, TriaxialStressController, NewtonIntegrator); a dry scene
never builds them. Bridges that persist across gaps declare how far the neighbour list must
reach (``reach(sim)``, their largest rupture distance). Each step:

1. per pair (parallel over pairs): a bridge forms when the spheres touch (overlap > 0, from
   the contact law of the same step) and breaks when contact is lost (the thesis's choice) or,
   with ``persist``, where no bridge exists at that gap: the table says no solution (suction
   control), or the volume-controlled rupture distance is passed (volume control). Its force
   F [N] acts along the branch vector, attractive: the force on j from i is -F n (n unit i -> j);
2. the forces are gathered per particle, -f to i and +f to j, each particle summing its own
   pairs in a fixed order (deterministic for any thread count, no atomics).

The kernels are pendular.capillary.bridge_kernels. Suction control, bridges only at contact
(the default): ``contact_bridges`` only reads overlap and the bridge state and looks a bridge up
when it forms; the contact law's gather then adds the cached magnitudes along its normals with
the contact forces, in the same pass over the pairs (``joins_contact_gather``,
pendular.dem.contact_law.ContactForces.gather; ``gather_contact_bridges`` when the scene has no
contact law). Bridges across gaps (``persist``, volume control): ``suction_bridges`` /
``volume_bridges`` write per-pair force vectors ``pair_force``, gathered by
``pendular.dem.neighbors.gather_pair_forces``.

The capillary force is added on top of the mechanical contact force and does not enter the
Coulomb cap |Fs| <= Fn tan(phi): in YADE, Law2_ScGeom_FrictPhys_CundallStrack caps the shear
force with ``phys->normalForce`` (the spring's force only), and
Law2_ScGeom_CapillaryPhys_Capillarity adds fCap separately through ``scene->forces.addForce``
(YADE 2023 sources, pkg/dem/ElasticContactLaw.cpp and
pkg/dem/Law2_ScGeom_CapillaryPhys_Capillarity.cpp). Sphere-wall bridges are optional
(SuctionBridges' ``wall_bridges``, pendular.capillary.wall_bridges; YADE's capillary law skips
pairs of different shapes), and ``contacts.force`` stays the mechanical force, so that pendular.homogenize.contact_stress is Eq. 3.41's contact stress.

Lookups (the units of docs/units.md): r = R2/R1 with R2 the larger radius, u* = s R2 / gamma,
d* = max(gap, 0) / R2 (overlaps read the table's contact values, as YADE does), F = F* 2 pi gamma
R2, V = V* R2^3, filling angles delta1 on the smaller sphere and delta2 on the larger one. At
d* = 0 a bridge's force, volume and filling angles depend only on the radii (suction control)
or on the radii and its volume (volume control): they are looked up once when the bridge forms
(or comes back into contact) and cached in its per-pair arrays, so a bridge at contact costs
no lookup per step; only bridges across a gap (``persist``, volume control) are looked up
each step.

Per-pair state: pendular.capillary.bridge_state.BridgeState, the arrays of its declared
``FIELDS`` (state, volume, force, filling_i, filling_j, suction; the operations'
``pair_state``), kept in ``sim.contacts.extra`` and carried across neighbour-list rebuilds.

Volume control: a bridge forms at contact with the volume of the suction-controlled bridge at
contact at ``suction`` (the formation suction, the same for bridges that form later), then keeps
that volume; its force and suction follow from (V*, d*) and it ruptures at the
volume-controlled rupture distance (capillary.VolumeBridgeTable). Bridges persist across gaps.

The liquid of volume-controlled bridges (``liquid``; docs/hydro_mechanical.md):
"reservoir" (default): new contacts take their bridge's liquid from outside, a ruptured
bridge's goes back there (a sample in contact with a water supply, the wetting phase);
"shared" and "lost": the amount is closed (a fixed water content). On rupture, "shared" gives
half of the bridge's liquid to each of its two grains, split equally among that grain's
remaining bridges, or held on the grain as film when it has none (Mani, Kadau & Herrmann
2012; MercuryDPM's liquid migration); "lost" removes it, counted in ``liquid_lost``. A new
contact forms a bridge only from the films of its two grains. ``close_liquid`` switches a
reservoir-wetted sample to a closed model; then bridges + films + lost = the liquid at closing
(``liquid_balance``) to round-off.
"""


import math

import numba
import numpy as np

from pendular.capillary.bridge_kernels import (LiquidExchange, bridges_across_gaps,
    contact_bridges, exchange_liquid, gather_contact_bridges, gather_contact_bridges_virial,
    pair_geometry, particle_pairs, pendular_overlap_counts, refresh_contact_bridges,
    serial_contact_bridges, suction_bridges, suction_interfaces, volume_bridges,
    volume_interfaces)
from pendular.capillary.bridge_state import FIELDS, OWNER, BridgeState
from pendular.capillary.radius_ratios import sample_radius_ratios, table_radius_ratios
from pendular.capillary.table import BridgeTable
from pendular.capillary.validation import (check_bridge_stiffness, check_contact_angle,
    check_pendular_suction)
from pendular.capillary.volume_table import VolumeBridgeTable
from pendular.capillary.wall_bridges import WallBridges
from pendular.dem.contact_law import ContactForces
from pendular.dem.neighbors import gather_pair_forces, gather_pair_forces_virial
from pendular.dem.protocols import state_array
from pendular.utils.validate import check_int, check_positive, check_range

#: Surface tension of water [N/m] (thesis Ch. 5, Table 5.2); the default everywhere.
SURFACE_TENSION = 0.073
#: Bridge models: exact Young–Laplace tables, or the toroidal approximation (Appendix A).
BRIDGE_MODELS = ("exact", "toroidal")
#: How bridges are controlled: imposed suction (SuctionBridges), or constant volume
#: (VolumeBridges).
CONTROLS = ("suction", "volume")
#: Where the liquid of volume-controlled bridges comes from and goes (``liquid``): an outside
#: reservoir, or a closed amount shared among the grains' bridges on rupture, or lost on rupture.
LIQUID_MODELS = ("reservoir", "shared", "lost")
#: Largest meniscus separation of touching spheres H / R2 (a rough grain's, thesis Ch. 4) that
#: volume-controlled bridges take: ``roughness`` in [0, MAX_ROUGHNESS].
MAX_ROUGHNESS = 0.5


class _ByControl(type):
    """Calling ``CapillaryBridges`` itself builds the operation of the ``control`` asked for
    (``bridges_by_control``); calling a subclass builds that subclass."""

    def __call__(cls, *args, **kwargs):
        if cls is CapillaryBridges:
            return bridges_by_control(*args, **kwargs)
        return super().__call__(*args, **kwargs)


class CapillaryBridges(metaclass=_ByControl):
    """What the bridge operations of both controls share (docs/physics.md 'The bridge model'):
    parameters, tables, the per-pair state and its neighbour-list reach, formation across gaps
    at wetting, and the measures read at record time. An operation ``apply(sim)``.

    ``CapillaryBridges(suction, surface_tension=0.073, contact_angle=0.0, model="exact",
    control="suction", persist=False, table_options=None, roughness=0.0, liquid="reservoir")``
    builds a SuctionBridges or a VolumeBridges (``bridges_by_control``).

    suction [Pa] >= 0: imposed matric suction (suction control), or the suction at which bridges
        form (volume control);
    surface_tension [N/m] > 0 (thesis Ch. 5: 0.073); contact_angle [deg] in [0, 90);
    model: "exact" (Young–Laplace tables, capillary.BridgeTable) or "toroidal" (thesis
        Appendix A, equal spheres only);
    table_options: keyword arguments of BridgeTable.cached (model 'exact') or
        pendular.capillary.toroidal_table.toroidal_table (model 'toroidal'): resolution, range.

    Add it to a scene's forces after the contact and wall forces; ``reach(sim)`` tells the
    neighbour list how far bridges across gaps reach. Radii must not change while bridges
    exist.
    """

    #: The per-pair quantities the bridges keep (pendular.dem.protocols.PairField), in
    #: ``sim.contacts.extra["bridge.<name>"]``.
    pair_state = FIELDS
    pair_owner = OWNER
    #: "suction" or "volume" (CONTROLS), set by each operation.
    control = None
    #: Whether bridges live across gaps up to their rupture distance.
    persist = False
    #: Meniscus separation of touching spheres / R2 (rough grains; volume control only).
    roughness = 0.0
    #: Where a bridge's liquid comes from and goes (LIQUID_MODELS; volume control only).
    liquid = "reservoir"
    #: The bridges' pair forces are central along the contact normals and join the contact
    #: law's gather (pendular.dem.contact_law.ContactForces.joined_by).
    joins_contact_gather = False

    def __init__(self, suction, surface_tension=SURFACE_TENSION, contact_angle=0.0,
                 model="exact", table_options=None):
        self.suction = check_range("suction", suction, 0.0, unit="Pa")
        self.surface_tension = check_positive("surface_tension", surface_tension, "N/m")
        self.contact_angle = check_contact_angle(contact_angle)
        if model not in BRIDGE_MODELS:
            raise ValueError(f"model = {model!r} is not one of {BRIDGE_MODELS}")
        self.model = model
        self.table_options = dict(table_options or {})
        self.suction_table = None
        self.required_range = 0.0
        self.pair_force = np.zeros((0, 3))
        self._lookup = None              # suction_table.arrays()
        self._contacts = None
        self._bridges = 0
        self._radius_bounds = None
        self._checked_stiffness = False
        self._state = None
        self.walls = None                # sphere-wall bridges (SuctionBridges' wall_bridges)

    # ---------------------------------------------------------------- checkpoints
    def state_dict(self):
        """What the bridges keep besides their per-pair state (``pair_state``, the
        contacts'): ``suction`` [Pa] (imposed, or the formation suction), ``required_range``
        [m] (the reach, which never shrinks: set_suction) and ``bridges`` (their number at
        the last step, which the next neighbour list must carry). The tables are rebuilt from
        the parameters and radii."""
        return {"suction": self.suction, "required_range": self.required_range,
                "bridges": self._bridges}

    def load_state(self, state):
        suction = check_range("suction", state["suction"], 0.0, unit="Pa")
        reach = check_range("required_range", state["required_range"], 0.0, unit="m")
        bridges = check_int("bridges", state["bridges"])
        self.suction, self.required_range, self._bridges = suction, reach, bridges

    # ---------------------------------------------------------------- set-up, once per sample
    def reach(self, sim):
        """Largest gap [m] at which a bridge of this operation may exist (0 unless bridges
        persist): the neighbour list holds every pair closer than that."""
        if sim.contacts is None or sim.contacts is not self._contacts:
            self._prepare(sim)                # radii change only with a rebuild
        return self.required_range

    def _prepare(self, sim):
        """Check the contact stiffness against the bridges (once) and load the tables for the
        scene's radii."""
        if not self._checked_stiffness:
            for contact_law in (op for op in sim.forces if isinstance(op, ContactForces)):
                check_bridge_stiffness(contact_law.young, float(sim.particles.radius.min()),
                                       self.surface_tension)
            self._checked_stiffness = True
        radius = sim.particles.radius
        low, high = float(radius.min()), float(radius.max())
        if self._radius_bounds is not None and self._radius_bounds[:2] == (low, high):
            return
        self.load_tables(low, high, radius_ratios=sample_radius_ratios(radius))

    def load_tables(self, low, high, radius_ratios=None):
        """Check the input against spheres of radii in [low, high] [m] and load (or build and
        cache) the tables; ValueError naming the parameter when out of range.

        radius_ratios: the exact tables' ratio nodes (``sample_radius_ratios`` of the scene's
        radii, which ``reach``/``apply`` pass); default YADE's ratios up to high / low
        (``table_radius_ratios``). table_options' radius_ratios, if given, win.
        """
        low = check_positive("smallest radius", low, "m")
        high = check_range("largest radius", high, low, unit="m")
        if radius_ratios is None and self.model == "exact":
            radius_ratios = table_radius_ratios(high / low)
        if self._radius_bounds == (low, high, radius_ratios):
            return
        ratio = high / low
        options = dict(self.table_options)
        if self.model == "toroidal":
            if ratio > 1.0:
                raise ValueError(f"model='toroidal' needs equal spheres; the radii range from "
                                 f"{low:g} to {high:g} m (use model='exact')")
            from pendular.capillary.toroidal_table import toroidal_table

            suction_star_high = self.suction * high / self.surface_tension
            options.setdefault("suction_max", max(suction_star_high * 1.001, 1e-3))
            self.suction_table = toroidal_table(self.contact_angle, **options)
        else:
            options.setdefault("radius_ratios", radius_ratios)
            self.suction_table = BridgeTable.cached(self.contact_angle, **options)
        self._check_suction(self.suction, low, high)
        if self.walls is not None:
            self.walls.load_table(low, high)
        self._load_control_tables()
        self._lookup = self.suction_table.arrays()
        self._radius_bounds = (low, high, radius_ratios)
        # never shrinks: a lower suction imposed earlier (set_suction) may reach farther
        self.required_range = max(self.required_range, self._rupture_range(low, high))

    def _load_control_tables(self):
        """Load what this control reads besides the suction table (nothing)."""

    def _check_suction(self, suction, low, high):
        """ValueError naming ``suction`` [Pa] unless the loaded table covers it for spheres of
        radii [low, high] [m] and bridges at contact stay pendular."""
        suction_star_high = suction * high / self.surface_tension
        if suction_star_high > self.suction_table.suction_max:
            raise ValueError(
                f"suction = {suction:g} Pa is outside the valid range [0, "
                f"{self.suction_table.suction_max * self.surface_tension / high:g}] Pa for these "
                f"spheres: u* = s R2/gamma = {suction_star_high:g} (R2 = {high:g} m, gamma = "
                f"{self.surface_tension:g} N/m) exceeds the table's "
                f"{self.suction_table.suction_max:g}")
        check_pendular_suction(self.suction_table, suction, low, self.surface_tension)

    def set_suction(self, suction):
        """Impose a new suction [Pa] (suction control only: SuctionBridges.set_suction)."""
        raise ValueError(f"control = {self.control!r}: set_suction needs control = "
                         "'suction' (volume-controlled bridges have their own suctions)")

    def close_liquid(self, sim, liquid="shared"):
        """Close the liquid (volume control only: VolumeBridges.close_liquid)."""
        raise ValueError(f"control = {self.control!r}: a closed amount of liquid needs "
                         "control = 'volume'")

    # ---------------------------------------------------------------- every step
    def _attach(self, sim):
        """Per-pair arrays for a new neighbour list (after a rebuild): create or pick them up."""
        contacts = sim.contacts
        state = BridgeState.of(contacts)
        carried = state.count()
        if carried < self._bridges:
            raise RuntimeError(
                f"{self._bridges - carried} liquid bridge(s) left the neighbour list at a "
                f"rebuild: its reach ({sim.neighbors.interaction_range:g} m plus skin) is "
                f"shorter than the rupture distance ({self.required_range:g} m)")
        self.pair_force = np.zeros((len(contacts) if self.persist else 0, 3))
        self._contacts = contacts
        self._state = state

    def _sync(self, sim):
        """Tables, stiffness check and per-pair arrays for the current radii and neighbour
        list (a device run's state fetched first: every measure reads it through here)."""
        sim.fetch("contacts")
        if sim.contacts is self._contacts:
            return
        self._prepare(sim)
        self._attach(sim)

    def adopt(self, sim):
        """Take sim's neighbour list as it is, its bridges those the next list must carry: a
        state that another engine stepped (the GPU's, brought back) and the CPU goes on from.
        The per-pair arrays are this list's (``pair_force`` zero: the engine sets it)."""
        self._bridges = BridgeState.of(sim.contacts).count()
        self._sync(sim)

    def _gather_pair_forces(self, sim):
        """Add ``pair_force`` to the particles (with the face terms of the cell's stress in a
        periodic cell) and count the bridges the next neighbour list must carry."""
        p, c, box = sim.particles, sim.contacts, sim.walls
        if box.periodic:
            gather_pair_forces_virial(self.pair_force, c.row_start, c.second_start,
                                      c.second_pair, p.force, c.image, c.through_face,
                                      c.face_start, box.period, box.virial_blocks)
        else:
            gather_pair_forces(self.pair_force, c.row_start, c.second_start, c.second_pair,
                               p.force)
        self._bridges = self._state.count()

    def form_across_gaps(self, sim, max_gap):
        """Wetting where the liquid would be (volume control, or suction control with
        ``persist``): besides the bridges that form at contact, give every pair of the
        neighbour list apart by a gap in (0, ``max_gap``] [m] the bridge of the (formation)
        suction at its own gap (bridge_kernels.bridges_across_gaps); returns how many formed.
        Pairs beyond the rupture distance of that suction get none, so the neighbour list
        (``reach``) holds every pair that can."""
        if not self.persist:
            raise ValueError(f"control = {self.control!r}, persist = False: bridges across gaps "
                             "form at wetting with control = 'volume' or persist = True only")
        max_gap = check_positive("max_gap", max_gap, "m")
        self._sync(sim)
        return int(bridges_across_gaps(pair_geometry(sim), self._state, self.suction,
                                       self.surface_tension, self.roughness, max_gap,
                                       self._lookup))

    # ---------------------------------------------------------------- measures (record time)
    def state(self, sim):
        """The BridgeState of the current neighbour list."""
        self._sync(sim)
        return self._state

    def count(self, sim):
        """Number of bridges."""
        return self.state(sim).count()

    def water_volume(self, contacts):
        """Total liquid volume of the bridges of ``contacts`` [m^3], the sphere-wall bridges'
        included (``walls``)."""
        walls = 0.0 if self.walls is None else self.walls.water_volume()
        return float(np.sum(BridgeState.of(contacts).volume)) + walls

    def saturation(self, sim):
        """Degree of saturation Sr = sum(V_bridge) / V_voids, V_voids = box volume minus the
        solid volume."""
        self._sync(sim)
        voids = sim.walls.volume() - sim.particles.solid_volume()
        return self.water_volume(sim.contacts) / voids

    def pair_forces(self, sim):
        """Capillary force on j from i per pair (K, 3) [N] as applied at the last step."""
        self._sync(sim)
        return self.pair_force

    def interfaces(self, sim, index):
        """(B, 2) [m^2]: nn11 and nn33, ∫ n_i n_i dS over the liquid-gas interface of each
        bridge of the pairs ``index``, in its bridge frame (bridge_kernels.suction_interfaces,
        volume_interfaces). ValueError for the toroidal model, whose table holds no interface."""
        if self.model != "exact":
            raise ValueError(f"model = {self.model!r}: the liquid-gas interface is tabulated for "
                             "model = 'exact' only")
        state = self.state(sim)
        return self._interfaces(pair_geometry(sim), state,
                                np.ascontiguousarray(index, dtype=np.int64))

    def pendular_overlaps(self, sim):
        """Number of pairs of overlapping menisci on a same particle, summed over particles."""
        state = self.state(sim)
        return int(np.sum(pendular_overlap_counts(pair_geometry(sim),
                                                  particle_pairs(sim.contacts), state)))


class SuctionBridges(CapillaryBridges):
    """Suction-controlled bridges: every bridge is the one in equilibrium with the imposed
    ``suction`` [Pa] at its gap (thesis Ch. 5); the liquid comes from and goes to a reservoir.

    persist: False (the thesis's choice, the default): a bridge exists exactly while its
        spheres touch, and the contact law's gather adds its force (``joins_contact_gather``);
        True: bridges live up to the rupture distance instead of breaking when contact is
        lost (thesis Table 5.1), gathered apart.
    wall_bridges: bridges between the spheres and the walls too (``walls``, a
        pendular.capillary.wall_bridges.WallBridges at this suction and ``persist``), applied
        first each step (the scene lists the bridges after the wall forces).
    The other parameters are CapillaryBridges'.
    """

    control = "suction"

    def __init__(self, suction, surface_tension=SURFACE_TENSION, contact_angle=0.0,
                 model="exact", persist=False, table_options=None, wall_bridges=False):
        super().__init__(suction, surface_tension, contact_angle, model, table_options)
        self.persist = bool(persist)
        self._applied_suction = None
        if wall_bridges:
            if model != "exact":
                raise ValueError("wall_bridges needs model='exact' (the sphere-plane bridges "
                                 "are exact Young-Laplace solutions)")
            self.walls = WallBridges(self)

    def state_dict(self):
        """CapillaryBridges' and ``applied_suction`` [Pa], the suction the bridges at contact
        were last looked up at (None before the first step); with wall bridges their state
        (``walls``, WallBridges.state_dict)."""
        walls = {} if self.walls is None else {"walls": self.walls.state_dict()}
        return {**super().state_dict(), "applied_suction": self._applied_suction, **walls}

    def load_state(self, state):
        applied = state["applied_suction"]
        applied = None if applied is None else check_range("applied_suction", applied, 0.0,
                                                           unit="Pa")
        if (self.walls is None) != ("walls" not in state):
            raise ValueError("walls: the checkpoint's bridges and this scene's differ in their "
                             "sphere-wall bridges (--wall-bridges)")
        if self.walls is not None:
            self.walls.load_state(state["walls"])
        super().load_state(state)
        self._applied_suction = applied

    @property
    def joins_contact_gather(self):
        """Whether the contact law's gather adds these bridges' forces
        (pendular.dem.contact_law.ContactForces.joined_by): bridges at contact only (not
        ``persist``) pull along the contact normals, so one pass over the pairs gathers
        both."""
        return not self.persist

    def set_suction(self, suction):
        """Impose a new suction [Pa] from the next step on (a path of drying and wetting):
        bridges at contact are looked up again at it, bridges across a gap (``persist``)
        follow it and rupture where the new rupture distance is shorter than their gap, new
        bridges form at contact only, so drying and wetting differ (hysteresis). The
        neighbour list's reach follows the lowest suction imposed so far, so no persisting
        bridge leaves it. ValueError naming ``suction`` outside the table or the pendular
        regime."""
        suction = check_range("suction", suction, 0.0, unit="Pa")
        if self._radius_bounds is not None:
            low, high = self._radius_bounds[:2]
            self._check_suction(suction, low, high)
        self.suction = suction
        if self._radius_bounds is not None:
            self.required_range = max(self.required_range, self._rupture_range(low, high))

    def _rupture_range(self, low, high):
        """Upper bound of the gap [m] at which a bridge can still exist (0 if none persists).

        The rupture distance d*_rupture(u*) decreases with u*, and u* = s R2/gamma >= s Rmin/gamma,
        so Rmax * max_r d*_rupture(r, s Rmin/gamma) bounds D (5 % margin).
        """
        if not self.persist:
            return 0.0
        table = self.suction_table
        xi = math.log1p(self.suction * low / self.surface_tension / table.suction_scale)
        nodes = np.log1p(table.suction / table.suction_scale)
        return 1.05 * high * max(np.interp(xi, nodes, row) for row in table.distance_rupture)

    def take_new_suction(self):
        """Whether the bridges at contact are to be looked up again at ``suction`` before this
        step (set_suction since the last step), the suction recorded as applied: read once a
        step by the engine that runs it (``apply``, or the GPU path's)."""
        new = self._applied_suction is not None and self._applied_suction != self.suction
        self._applied_suction = self.suction
        return new

    def apply(self, sim):
        self._sync(sim)
        if self.walls is not None:
            self.walls.apply(sim)
        pairs = pair_geometry(sim)
        state = self._state
        if self.take_new_suction():             # set_suction: bridges at contact
            refresh_contact_bridges(pairs, state, self.suction, self.surface_tension,
                                    self._lookup)
        if self.persist:
            suction_bridges(pairs, state, self.pair_force, self.suction, self.surface_tension,
                            self._lookup)
            self._gather_pair_forces(sim)
            return
        follow = contact_bridges if numba.get_num_threads() > 1 else serial_contact_bridges
        follow(pairs, state, self.suction, self.surface_tension, self._lookup)
        contact_law = self._joined_contact_law(sim)
        if contact_law is not None:
            contact_law.gather(sim, state.force)
            return
        p, c, box = sim.particles, sim.contacts, sim.walls
        if box.periodic:
            gather_contact_bridges_virial(state.force, c.normal, c.row_start, c.second_start,
                                          c.second_pair, p.force, c.image, c.through_face,
                                          c.face_start, box.period, box.virial_blocks)
        else:
            gather_contact_bridges(state.force, c.normal, c.row_start, c.second_start,
                                   c.second_pair, p.force)

    def _joined_contact_law(self, sim):
        """The ContactForces of ``sim.forces`` whose gather waits for this operation, or None
        (the bridges gather themselves)."""
        for op in sim.forces:
            if isinstance(op, ContactForces) and op.joined_by(sim) is self:
                return op
        return None

    def mean_suction(self, sim):
        """The imposed suction [Pa]."""
        return self.suction

    def pair_forces(self, sim):
        """Capillary force on j from i per pair (K, 3) [N] as applied at the last step."""
        if self.persist:
            return super().pair_forces(sim)
        return -self.state(sim).force[:, None] * sim.contacts.normal

    def _interfaces(self, pairs, state, index):
        return suction_interfaces(pairs, state, index, self.suction, self.surface_tension,
                                  self._lookup)


class VolumeBridges(CapillaryBridges):
    """Volume-controlled bridges: each keeps the volume it formed with (at contact, from the
    suction-controlled bridge at the formation ``suction`` [Pa]); its force and suction follow
    from its volume and gap, and it persists across gaps up to its volume-controlled rupture
    distance (capillary.VolumeBridgeTable). Exact tables only.

    roughness: meniscus separation of touching spheres H / R2 in [0, MAX_ROUGHNESS] (rough
        grains, thesis Ch. 4's H/R; 0: smooth spheres, the default);
    liquid: "reservoir" (default), "shared" or "lost" (LIQUID_MODELS, module docstring);
        ``close_liquid`` closes a reservoir-wetted sample's liquid later.
    The other parameters are CapillaryBridges'.
    """

    control = "volume"
    persist = True

    def __init__(self, suction, surface_tension=SURFACE_TENSION, contact_angle=0.0,
                 roughness=0.0, liquid="reservoir", table_options=None):
        super().__init__(suction, surface_tension, contact_angle, "exact", table_options)
        self.roughness = check_range("roughness", roughness, 0.0, MAX_ROUGHNESS)
        self.volume_table = None
        self.liquid_initial = None       # [m^3] at closing (None: open liquid)
        self.liquid_lost = 0.0           # [m^3] since closing
        self.film = None                 # (N,) [m^3] liquid held on each grain
        self._volume_lookup = None       # volume_table.arrays()
        self._released = None
        self._events = None
        self._set_liquid(liquid)

    def state_dict(self):
        """CapillaryBridges' and the liquid's account: ``liquid`` (the model, which
        close_liquid changes), ``liquid_initial`` [m^3] (None while open), ``liquid_lost``
        [m^3] and ``film`` (N,) [m^3] on each grain (None before the first step)."""
        return {**super().state_dict(), "liquid": self.liquid,
                "liquid_initial": self.liquid_initial, "liquid_lost": self.liquid_lost,
                "film": None if self.film is None else self.film.copy()}

    def load_state(self, state):
        if state["liquid"] not in LIQUID_MODELS:
            raise ValueError(f"liquid = {state['liquid']!r} is not one of {LIQUID_MODELS}")
        initial = state["liquid_initial"]
        initial = None if initial is None else check_range("liquid_initial", initial, 0.0,
                                                           unit="m^3")
        lost = check_range("liquid_lost", state["liquid_lost"], 0.0, unit="m^3")
        film = None if state["film"] is None else state_array(state, "film", np.float64,
                                                               (None,))
        if film is not None and (film < 0.0).any():
            index = int(np.argmax(film < 0.0))
            raise ValueError(f"film[{index}] = {film[index]:g} m^3 is outside the valid range "
                             "[0, inf)")
        super().load_state(state)
        self._set_liquid(state["liquid"])
        self.liquid_initial, self.liquid_lost, self.film = initial, lost, film

    def _set_liquid(self, liquid):
        """The liquid model (LIQUID_MODELS) and what it decides each step: whether the amount
        is ``closed`` and whether a ruptured bridge's liquid ``shares`` to its grains."""
        if liquid not in LIQUID_MODELS:
            raise ValueError(f"liquid = {liquid!r} is not one of {LIQUID_MODELS}")
        self.liquid = liquid
        self.closed = liquid != "reservoir"
        self.shares = liquid == "shared"

    def _load_control_tables(self):
        self.volume_table = VolumeBridgeTable.cached(
            self.contact_angle, radius_ratios=self.suction_table.radius_ratios)
        self._volume_lookup = self.volume_table.arrays()

    def _rupture_range(self, low, high):
        """Upper bound of the gap [m] at which a bridge can still exist: the largest volume
        forms at the smallest suction, and d*_rupture grows with the volume (5 % margin)."""
        table = self.suction_table
        volumes = [table.lookup(r, self.suction * low / self.surface_tension, 0.0)[2]
                   for r in table.radius_ratios]
        largest = []
        vtable = self.volume_table
        for index, axis in enumerate(vtable.volume_axes):
            volume_nodes = np.linspace(axis[0], axis[1], vtable.n_volume)
            largest.append(np.interp(math.log(max(volumes)), volume_nodes,
                                     vtable.distance_rupture[index]))
        return 1.05 * high * max(largest)

    def _attach(self, sim):
        super()._attach(sim)
        self._released = np.zeros(len(sim.contacts))
        self._events = np.zeros(len(sim.contacts), np.int8)
        if self.film is None or len(self.film) != len(sim.particles):
            self.film = np.zeros(len(sim.particles))

    def apply(self, sim):
        self._sync(sim)
        pairs = pair_geometry(sim)
        state = self._state
        liquid = LiquidExchange(self.film, self._released, self._events)
        events = volume_bridges(pairs, state, self.pair_force, self.suction,
                                self.surface_tension, self.roughness, self._lookup,
                                self._volume_lookup, liquid, self.closed)
        if events:
            self.liquid_lost += exchange_liquid(
                liquid, particle_pairs(sim.contacts), pairs, state, self.shares,
                *self.volume_table.volume_star_bounds())
        self._gather_pair_forces(sim)

    def close_liquid(self, sim, liquid="shared"):
        """From now on the liquid is a closed amount (``liquid`` "shared" or "lost", module
        docstring): the bridges' liquid now is ``liquid_initial`` [m^3], and every later
        exchange is accounted for (``liquid_balance``)."""
        if liquid not in LIQUID_MODELS[1:]:
            raise ValueError(f"liquid = {liquid!r} is not one of {LIQUID_MODELS[1:]}")
        self._sync(sim)
        self._set_liquid(liquid)
        self.liquid_lost = 0.0
        self.liquid_initial = self.water_volume(sim.contacts) + float(np.sum(self.film))

    def liquid_balance(self, sim):
        """(liquid in bridges, on grains as film, lost) [m^3] and the relative error of
        bridges + film + lost against ``liquid_initial`` (NaN while the liquid is open)."""
        self._sync(sim)
        bridges = self.water_volume(sim.contacts)
        film = 0.0 if self.film is None else float(np.sum(self.film))
        if self.liquid_initial is None:
            return bridges, film, self.liquid_lost, math.nan
        error = abs(bridges + film + self.liquid_lost - self.liquid_initial) / self.liquid_initial
        return bridges, film, self.liquid_lost, error

    def mean_suction(self, sim):
        """The bridges' mean suction [Pa] (NaN without bridges)."""
        state = self.state(sim)
        mask = state.mask()
        if not mask.any():
            return math.nan
        return float(np.mean(state.suction[mask]))

    def _interfaces(self, pairs, state, index):
        return volume_interfaces(pairs, state, index, self.roughness, self._volume_lookup)


def bridges_by_control(suction, surface_tension=SURFACE_TENSION, contact_angle=0.0,
                       model="exact", control="suction", persist=False, table_options=None,
                       roughness=0.0, liquid="reservoir", wall_bridges=False):
    """The bridge operation of ``control`` ("suction": SuctionBridges, "volume":
    VolumeBridges, which always persist) with these parameters (CapillaryBridges and the two
    classes); ValueError naming a parameter the control does not take: ``roughness`` > 0 and
    ``liquid`` other than "reservoir" need volume control, volume control needs the exact
    model."""
    if control not in CONTROLS:
        raise ValueError(f"control = {control!r} is not one of {CONTROLS}")
    if control == "volume":
        if wall_bridges:
            raise ValueError("wall_bridges needs control='suction' (volume-controlled "
                             "sphere-wall bridges are not implemented)")
        if model != "exact":
            raise ValueError("volume-controlled bridges need model='exact'")
        return VolumeBridges(suction, surface_tension, contact_angle, roughness=roughness,
                             liquid=liquid, table_options=table_options)
    roughness = check_range("roughness", roughness, 0.0, MAX_ROUGHNESS)
    if roughness > 0.0:
        raise ValueError(f"roughness = {roughness:g} needs control='volume' (suction-"
                         "controlled bridges are between smooth spheres: roughness 0)")
    if liquid not in LIQUID_MODELS:
        raise ValueError(f"liquid = {liquid!r} is not one of {LIQUID_MODELS}")
    if liquid != "reservoir":
        raise ValueError(f"liquid = {liquid!r} needs control='volume' (suction-controlled "
                         "bridges exchange liquid with a reservoir at the imposed suction)")
    return SuctionBridges(suction, surface_tension, contact_angle, model, persist=persist,
                          table_options=table_options, wall_bridges=wall_bridges)
