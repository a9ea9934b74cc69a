"""The liquid clusters of a wet DEM scene: the operation that holds which pore units are filled,
applies the clusters' forces and hands bridges' liquid to them (docs/liquid_clusters.md).

``LiquidClusters(bridges)`` joins a scene whose liquid is at one imposed suction: the
suction-controlled bridges that persist across gaps (capillary.SuctionBridges, ``persist``),
listed before it among the scene's forces. ``set_suction(sim, s)`` is the quasi-static step
of the model (pendular.capillary.pore_filling): the packing is decomposed into pore units
again, the filled state carried over unit by unit (a unit is its four grains), the units
whose filling suction is at least s fill, then the Haines jumps empty those the gas reaches.
Until the next ``set_suction`` (a stage of a path run to equilibrium) the clusters' forces are
those of the packing at that moment (pendular.capillary.cluster_forces), added to the grains
each step, and a bridge on an edge of filled units keeps only the share of its force and
liquid that lies in empty units (its force is taken off in the share the filled units hold:
the cluster's pressure and menisci replace it there). Between walls, or in a periodic cell
(sheared too): there the units are cut from the grains' images (pendular.capillary.pores), a
unit's forces act at the images it sees, and ``virial`` hands the cell's stress their sum of
x (x) F (pendular.dem.cell.PeriodicCell.after_forces). The model runs on the host; between
walls a device adds the forces each step from what it reads here (``cluster_force``,
``absorbed_shares``, new at each ``version``: pendular.gpu.clusters).

With the liquid closed (a water content), ``hold_volume(sim, V)`` is the model's step instead:
the suction is the one at which the bridges and the filled units hold V
(pendular.capillary.closed_liquid), imposed on the bridges; the units at the front of a jump
hold a fraction of their pore volume (their forces and absorbed shares in that fraction), and
what a bridge broken at that suction leaves stays on the grains as film.

``state_dict``/``load_state`` keep all of this (the pore units of the last step of the model,
the filled state, the closed liquid, where the forces act), so that a checkpointed run
resumes bit for bit.
"""

import math

import numpy as np

from pendular.capillary.bridge_state import BridgeState
from pendular.capillary.closed_liquid import ClosedLiquid, HeldLiquid, solve_closed_liquid
from pendular.capillary.cluster_forces import (UnitForces, cluster_forces, cluster_stress,
    partial_forces)
from pendular.capillary.clusters import find_clusters
from pendular.capillary.pore_filling import (drain, filling_thresholds, imbibe,
    liquid_account, unit_edges)
from pendular.capillary.pores import (PoreUnits, decompose, into_cell, nearest_images,
    search_rows)
from pendular.capillary.throats import check_entry_estimate
from pendular.capillary.trimers import find_trimers
from pendular.dem.cell import pair_virial
from pendular.dem.neighbors import branch_vectors, gather_pair_forces
from pendular.dem.protocols import state_array


class LiquidClusters:
    """Liquid clusters beside persisting suction-controlled ``bridges`` (module docstring).
    ``saturated``: the pore units start filled (a sample drying from saturation) or empty
    (bridges alone, a sample wetted from dry). ``entry``: the throats' entry estimate, one of
    pendular.capillary.throats.ENTRY_ESTIMATES (pore_filling.filling_thresholds)."""

    def __init__(self, bridges, saturated=True, entry="inscribed"):
        if bridges.control != "suction" or not bridges.persist:
            raise ValueError("liquid = 'clusters' needs suction-controlled bridges that persist "
                             "across gaps (control = 'suction', persist = True)")
        self.bridges = bridges
        self.saturated = bool(saturated)
        self.entry = check_entry_estimate(entry)
        self.suction = None
        self.units = None
        self.filled = None
        self.found = None
        self._unit_forces = None
        self._radius = None           # (N,) [m] the grains' radii
        self._vertices = None         # (M, 4, 3) [m] where the units' forces act
        self._edges = None
        self._force = None
        self._contacts = None         # the neighbour list _pair_edge and _share are of
        self._pair_edge = None
        self._share = None
        self.liquid = None            # ClosedLiquid of the last hold_volume (None: imposed)
        self._own_virial = None       # (the forces, their sum of x (x) F [N m]) (virial)
        self.version = 0              # counts the changes of the forces apply adds (_set_forces)

    # ---------------------------------------------------------------- checkpoints
    def state_dict(self):
        """The clusters as the last step of the model left them, their forces following the
        grains (follow_packing), so that the next steps are those of a run never stopped:
        ``suction`` [Pa] (None before the first step of the model), ``saturated``; then (None
        before the first step) ``units`` the pore units (pendular.capillary.pores.PoreUnits:
        positions [m], volumes [m^3], solid angles [sr], areas [m^2], indices), ``radius``
        (N,) [m] the grains', ``filled`` (M,) bool, ``vertices`` (M, 4, 3) [m] where the
        units' forces act, and ``liquid`` the closed liquid (ClosedLiquid less its
        ``filled``: ``suction`` [Pa], ``front`` (M,) bool, ``front_fraction``, ``weight``
        (M,), ``bridges``, ``clusters``, ``film`` [m^3]; None at an imposed suction)."""
        state = {"suction": self.suction, "saturated": self.saturated, "units": None,
                 "radius": None, "filled": None, "vertices": None, "liquid": None}
        if self.units is None:
            return state
        state.update(units={name: getattr(self.units, name) for name in _UNIT_ARRAYS},
                     radius=self._radius, filled=self.filled, vertices=self._vertices)
        if self.liquid is not None:
            state["liquid"] = {name: getattr(self.liquid, name) for name in _LIQUID_STATE}
        return state

    def load_state(self, state):
        """Take back a ``state_dict``: the units, filled state, suction and closed liquid as
        saved, their forces computed again where the saved ``vertices`` put the grains
        (follow_packing's, bit for bit). ValueError naming the key of a value that does not
        fit, nothing changed then."""
        suction = state["suction"]
        if suction is not None and not (isinstance(suction, float) and suction > 0):
            raise ValueError(f"suction = {suction!r}: a suction > 0 [Pa] or None expected")
        saturated = bool(state["saturated"])
        if state["units"] is None:
            self.__init__(self.bridges, saturated, self.entry)     # the scene's entry kept
            self.suction = suction
            return
        if suction is None:
            raise ValueError("suction = None: the saved pore units need the suction they hold")
        radius = state_array(state, "radius", np.float64, (None,))
        if (radius <= 0.0).any():
            raise ValueError(f"radius[{int(np.argmax(radius <= 0.0))}] = "
                             f"{radius[radius <= 0.0][0]} m; valid: > 0")
        units = _units_of(state["units"], len(radius))
        filled = state_array(state, "filled", bool, (units.count,))
        vertices = state_array(state, "vertices", np.float64, (units.count, 4, 3))
        liquid = None if state["liquid"] is None else _liquid_of(state["liquid"], filled)
        self.__init__(self.bridges, saturated, self.entry)
        self.units, self.filled, self.suction, self.liquid = units, filled, suction, liquid
        self._radius, self._vertices = radius, vertices
        self._edges = unit_edges(units)
        self.found = find_clusters(units, filled)
        unit_forces = UnitForces(units.vertices, radius[units.grains])
        held = np.flatnonzero(self._held())
        if len(held):
            unit_forces = unit_forces.moved(held, vertices[held], radius[units.grains[held]])
        self._set_forces(len(radius), unit_forces)

    # ---------------------------------------------------------------- the model's step
    def set_suction(self, sim, suction):
        """Impose ``suction`` [Pa] on the clusters of ``sim``'s packing now (module docstring):
        decompose, carry, fill, drain; the forces of the stage that follows."""
        units, thresholds, carried = self._decompose(sim)
        filled = drain(units, thresholds, imbibe(thresholds, carried, suction), suction)
        self.liquid = None
        self._set_state(sim, units, filled, suction)

    def hold_volume(self, sim, volume, max_gap=0.0):
        """Hold the closed liquid ``volume`` [m^3] in ``sim``'s packing now (module docstring):
        decompose, carry, find the suction at which the bridges there (and those that form at
        contact; with ``max_gap`` [m] > 0, at the wetting, those that form across every gap
        of the neighbour list up to it) and the filled units hold it, impose it on the
        bridges; the forces of the stage that follows. Returns the ClosedLiquid. Call it
        after a step (or sim.evaluate_forces()), whose neighbour list and bridges it reads."""
        units, thresholds, carried = self._decompose(sim)
        contacts, radius = sim.contacts, sim.particles.radius
        # the gaps the next step's bridges will see (through the cell's images)
        gap = (np.linalg.norm(branch_vectors(sim.particles.position, contacts, sim.walls.period),
                              axis=1)
               - radius[contacts.pair_i] - radius[contacts.pair_j])
        held = self.bridges.state(sim).mask() | (gap < 0.0)
        if max_gap > 0.0:
            held |= gap <= max_gap
        pair_i, pair_j = contacts.pair_i[held], contacts.pair_j[held]
        larger = np.maximum(radius[pair_i], radius[pair_j])
        pairs = (larger, larger / np.minimum(radius[pair_i], radius[pair_j]),
                 np.maximum(gap[held], 0.0) / larger)
        edges = unit_edges(units)
        liquid = solve_closed_liquid(volume, HeldLiquid(
            pairs, edges.of_pairs(pair_i, pair_j), edges, units, thresholds, carried,
            self.bridges.suction_table, self.bridges.surface_tension))
        self.bridges.set_suction(liquid.suction)
        if max_gap > 0.0:
            self.bridges.form_across_gaps(sim, max_gap)
        self.liquid = liquid
        self._set_state(sim, units, liquid.filled, liquid.suction, edges)
        return liquid

    def _decompose(self, sim):
        """(pore units, thresholds, the filled state carried over) of ``sim``'s packing (in a
        periodic cell, its grains brought into the cell and cut with their images)."""
        sim.fetch("particles")
        particles = sim.particles
        previous = self._filled_grains()
        if sim.walls.periodic:
            period = np.array(sim.walls.period)
            units = decompose(into_cell(particles.position, period), particles.radius, period)
        else:
            units = decompose(particles.position, particles.radius)
        if previous is None:
            carried = np.full(units.count, self.saturated)
        else:
            carried = _carry(units.grains, previous)
        thresholds = filling_thresholds(units, particles.radius, self.bridges.surface_tension,
                                        self.bridges.contact_angle, self.entry)
        return units, thresholds, carried

    def _set_state(self, sim, units, filled, suction, edges=None):
        """Take ``filled`` at ``suction`` [Pa] (and the closed liquid's front, ``liquid``):
        clusters, forces."""
        self.units, self.filled, self.suction = units, filled, float(suction)
        self._edges = unit_edges(units) if edges is None else edges
        self.found = find_clusters(units, filled)
        self._vertices = units.vertices
        self._radius = sim.particles.radius.copy()
        self._set_forces(len(sim.particles),
                         UnitForces(units.vertices, sim.particles.radius[units.grains]))
        self._contacts = None

    def _set_forces(self, grain_count, unit_forces):
        """The clusters' forces on ``grain_count`` grains of the filled units (and the closed
        liquid's front) with the coefficients ``unit_forces`` (UnitForces)."""
        units = self.units
        self._unit_forces = unit_forces
        self._force = cluster_forces(units, self._unit_forces, self.filled, self.suction,
                                     grain_count)
        if self.liquid is not None and self.liquid.front_fraction > 0.0:
            self._force += partial_forces(units, self._unit_forces,
                                          np.flatnonzero(self.liquid.front),
                                          self.liquid.front_fraction, self.suction,
                                          grain_count)
        self.version += 1

    def follow_packing(self, sim):
        """The forces of the filled units with their grains where they are now, the filled
        units, the suction and the liquid as they are (no decomposition, filling or drainage:
        between two steps of the model, the forces follow the grains as the packing moves);
        each face keeps the side its normal had at the decomposition, so that the forces still
        sum to zero where a flat unit has turned inside out. Only the units that hold liquid
        move: an empty unit's coefficients stay those of the decomposition, unused."""
        if self.units is None:
            return
        sim.fetch("particles")
        particles = sim.particles
        held = self._held()
        grains = self.units.grains[held]
        vertices = self._vertices.copy()
        vertices[held] = self._grain_images(sim, grains, vertices[held])
        self._vertices = vertices
        self._set_forces(len(particles), self._unit_forces.moved(
            np.flatnonzero(held), vertices[held], particles.radius[grains]))

    def _held(self):
        """(M,) bool: the units that hold liquid, filled or at the closed liquid's front."""
        return self.filled if self.liquid is None else self.filled | (self.liquid.weight > 0.0)

    def _grain_images(self, sim, grains, near):
        """(..., 3) [m] where ``grains`` are now as the units see them: their positions, or in
        a periodic cell their images nearest ``near`` (..., 3) [m], the units' vertices of
        before (the grains and the cell move little between two updates)."""
        position = sim.particles.position[grains]
        if not sim.walls.periodic:
            return position
        return nearest_images(position, near, np.array(sim.walls.period))

    def _filled_grains(self):
        """(F, 4) the grains of the filled units so far (None before the first step of the
        model)."""
        if self.units is None:
            return None
        return self.units.grains[self.filled]

    # ---------------------------------------------------------------- every step
    def apply(self, sim):
        self._add_forces(sim, sim.particles.force)

    def grain_forces(self, sim):
        """(N, 3) [N] the forces ``apply`` adds to the grains at ``sim``'s state: the
        clusters' own, less the shares of the bridges' forces they absorb."""
        sim.fetch("contacts")           # all of a device run's state (Simulation.fetch)
        force = np.zeros_like(sim.particles.position)
        self._add_forces(sim, force)
        return force

    def _add_forces(self, sim, force):
        """Add to ``force`` (N, 3) [N] the clusters' forces and take off the shares of the
        bridges' forces they absorb (nothing while no unit holds liquid)."""
        if not self.adds_forces(sim):
            return
        force += self._force
        absorbed = self._absorbed(sim)
        if absorbed is not None:
            contacts = sim.contacts
            gather_pair_forces(absorbed, contacts.row_start, contacts.second_start,
                               contacts.second_pair, force)

    def _absorbed(self, sim):
        """(K, 3) [N] minus the shares of the bridges' pair forces (on j from i) that the
        filled units absorb, over ``sim``'s neighbour list; None where there is none, or where
        the bridges' forces are not yet of this list."""
        share = self.pair_share(sim.contacts)
        pair_force = self.bridges.pair_force
        if len(share) and len(pair_force) == len(share):
            return -share[:, None] * pair_force
        return None

    def adds_forces(self, sim):
        """Whether ``apply`` adds any force to ``sim``'s grains now: whether a unit holds
        liquid (without, a periodic cell's stress stays the gathered sum of the pair forces,
        pendular.dem.cell.PeriodicCell.after_forces)."""
        return self.holds_liquid

    @property
    def holds_liquid(self):
        """Whether a unit holds liquid now (``apply`` adds forces)."""
        return self._force is not None and bool(self.filled.any() or self._front_held())

    @property
    def cluster_force(self):
        """(N, 3) [N] the clusters' own forces on the grains that ``apply`` adds each step
        (None before the model's first step; read only: it changes with ``version``)."""
        return self._force

    def pair_share(self, contacts):
        """(K,) the share of each pair's bridge that the filled units hold (and the closed
        liquid's front, in its fraction); kept until the neighbour list or the filled units
        change (read only)."""
        edge = self.pair_edge(contacts)
        if self._share is None:
            share = self._edge_share()
            self._share = np.where(edge >= 0, share[np.maximum(edge, 0)], 0.0)
        return self._share

    def absorbed_shares(self, count):
        """(keys, shares): the units' edges of which the filled units hold a share, each as
        the key i * ``count`` + j of its grains i < j (of ``count`` grains), sorted (E,)
        int64, and that share (E,) [-], ``pair_share``'s by grain pair rather than by a
        neighbour list's pair (a device matches its own pairs to it: pendular.gpu.clusters);
        it changes with ``version``."""
        share = self._edge_share()
        held = share > 0.0
        pair = self._edges.pair[held].astype(np.int64)
        keys = pair[:, 0] * count + pair[:, 1]
        order = np.argsort(keys, kind="stable")
        return keys[order], share[held][order]

    def _edge_share(self):
        """(E,) the share of each edge of the units that the filled units hold (and the
        closed liquid's front, in its fraction)."""
        if self._front_held():
            return self._edges.share(self.liquid.weight)
        return self._edges.filled_share(self.filled)

    def pair_edge(self, contacts):
        """(K,) the edge of the pore units each pair of the neighbour list ``contacts`` is
        (UnitEdges.of_pairs, -1: none); kept until the neighbour list or the units change."""
        if contacts is not self._contacts:
            self._pair_edge = self._edges.of_pairs(contacts.pair_i, contacts.pair_j)
            self._share = None
            self._contacts = contacts
        return self._pair_edge

    def _front_held(self):
        """Whether the closed liquid's front holds liquid."""
        return self.liquid is not None and self.liquid.front_fraction > 0.0

    # ---------------------------------------------------------------- measures
    def account(self, sim):
        """LiquidAccount (pendular.capillary.pore_filling) of the liquid now [m^3]."""
        sim.fetch("contacts")
        contacts = sim.contacts
        volume = BridgeState.of(contacts).volume
        edge = self.pair_edge(contacts)
        if self.liquid is None:
            return liquid_account(self.units, self._edges, self.found, volume, edge)
        return liquid_account(self.units, self._edges, self.found, volume, edge,
                              weight=self.liquid.weight, film=self.liquid.film)

    def trimers(self, sim):
        """Trimers (pendular.capillary.trimers) of the bridges now around the throats of the
        units that hold no liquid."""
        sim.fetch("contacts")
        contacts = sim.contacts
        return find_trimers(self.units, self._edges, self._held(), BridgeState.of(contacts),
                            contacts.pair_i, contacts.pair_j, self.pair_edge(contacts))

    def _units_liquid(self, sim, account):
        """[m^3] the liquid inside the pore units: the filled units, and the bridges' shares in
        the empty ones (their dihedral angles there over 2 pi; a bridge between grains that
        share no unit, across a gap, all)."""
        contacts = sim.contacts
        volume = BridgeState.of(contacts).volume
        edge = self.pair_edge(contacts)
        inside = self._edges.filled_share(np.ones(self.units.count, bool))
        inside = np.where(edge >= 0, inside[np.maximum(edge, 0)], 1.0)
        return account.clusters + float(np.sum(volume * inside)) - account.absorbed

    def saturation(self, sim):
        """Degree of saturation: the liquid held over the voids (the box, or the periodic cell,
        less the solid: a cell holds each grain once, whole)."""
        voids = sim.walls.volume() - sim.particles.solid_volume()
        return self.account(sim).total / voids

    def stress(self, sim):
        """(3, 3) [Pa] the clusters' share of the complete capillary stress over the box or the
        cell (cluster_forces.cluster_stress), with the grains where their forces act (in a
        periodic cell, the images each unit sees)."""
        return self._stress_over(sim.walls.volume())

    def _stress_over(self, volume):
        """``stress`` over ``volume`` [m^3]."""
        if self._front_held():
            weight = self.liquid.weight
            return cluster_stress(self.units, self._unit_forces, weight > 0.0, self.suction,
                                  volume, weight, self._vertices)
        return cluster_stress(self.units, self._unit_forces, self.filled, self.suction,
                              volume, vertices=self._vertices)

    def virial(self, sim):
        """(3, 3) [N m] sum x (x) F of the forces ``apply`` adds to the grains of ``sim``, the
        Love–Weber sum of the cell's stress (pendular.dem.cell.PeriodicCell.after_forces,
        compression positive): the clusters' own, unit by unit over each unit's
        self-equilibrated set at the images it sees where its forces were last computed
        (-V ``stress``: translation-invariant, a unit across a face counts as one inside the
        cell), and the shares of the bridges' forces they take off, over their pairs' branch
        vectors (pendular.dem.neighbors.branch_vector)."""
        total = np.zeros((3, 3))
        if not self.adds_forces(sim):
            return total
        sim.fetch("contacts")           # all of a device run's state (Simulation.fetch)
        if self._own_virial is None or self._own_virial[0] is not self._force:
            self._own_virial = (self._force, -self._stress_over(1.0))
        total += self._own_virial[1]
        absorbed = self._absorbed(sim)
        if absorbed is not None:
            contacts = sim.contacts
            total += pair_virial(sim.particles.position, contacts.row_start, contacts.pair_j,
                                 contacts.image, sim.walls.period, absorbed).reshape(3, 3)
        return total

    def statistics(self, sim, account=None):
        """The clusters' figures of a stage row: their number, the filled and all pore units,
        the liquid fractions in bridges, in clusters and in the largest cluster, the number of
        trimers and the fraction of the liquid in their bridges (``trimers``; their shares
        outside filled units, a part of the bridges' fraction), whether the largest cluster
        percolates along x, y, z (in a periodic cell: wraps around it,
        pendular.capillary.clusters), the saturation (over the voids of the box or cell, and over
        the pore units' void alone) and the clusters' stress (``account``: ``account(sim)``
        if already measured)."""
        account = self.account(sim) if account is None else account
        sim.fetch("particles")          # all of a device run's state (Simulation.fetch)
        fractions = account.fractions()
        voids = sim.walls.volume() - sim.particles.solid_volume()
        in_units = self._units_liquid(sim, account) / float(np.sum(self.units.pore_volume))
        trimers = self.trimers(sim)
        in_trimers = trimers.liquid(BridgeState.of(sim.contacts).volume,
                                    self.pair_share(sim.contacts))
        return {"clusters": int(self.found.count),
                "filled_units": int(np.count_nonzero(self.filled)),
                "pore_units": int(self.units.count),
                "liquid_in_bridges": fractions["bridges"],
                "liquid_in_clusters": fractions["clusters"],
                "liquid_in_largest_cluster": fractions["largest"],
                "trimers": trimers.count,
                "liquid_in_trimers": in_trimers / account.total if account.total > 0 else 0.0,
                "largest_cluster_percolates": [bool(v) for v in self.found.percolates],
                "saturation": account.total / voids,
                "saturation_pore_units": in_units,
                "psi_clusters": self.stress(sim).tolist()}


def _carry(grains, previous):
    """(M,) bool: the units of ``grains`` (M, 4) that are among ``previous`` (F, 4), each a
    set of four grains."""
    if len(previous) == 0:
        return np.zeros(len(grains), bool)
    table = np.unique(np.sort(np.asarray(previous, np.int64), axis=1), axis=0)
    return search_rows(table, np.sort(grains, axis=1)) >= 0


#: The arrays of the pore units (pendular.capillary.pores.PoreUnits) a checkpoint keeps, with
#: their dtype and shape (M: units, T: throats; ``period`` apart: None, (3,) or (4,) [m]).
_UNIT_ARRAYS = {
    "grains": (np.int64, ("M", 4)), "vertices": (np.float64, ("M", 4, 3)),
    "neighbours": (np.int64, ("M", 4)), "volume": (np.float64, ("M",)),
    "pore_volume": (np.float64, ("M",)), "solid_angle": (np.float64, ("M", 4)),
    "grain_area": (np.float64, ("M", 4)), "protrudes": (bool, ("M",)),
    "throat_radius": (np.float64, ("M", 4)), "throat_units": (np.int64, ("T", 2)),
    "throat_of": (np.int64, ("M", 4)), "throat_shift": (np.int64, ("T", 3)),
    "period": (np.float64, (None,))}

#: What a checkpoint keeps of a ClosedLiquid (its ``filled`` is the clusters').
_LIQUID_STATE = ("suction", "front", "front_fraction", "weight", "bridges", "clusters", "film")


def _units_of(state, grain_count):
    """PoreUnits of a LiquidClusters.state_dict's ``units`` over ``grain_count`` grains;
    ValueError naming the array (units/<name>) that does not fit."""
    sizes = {}
    for name, length in (("grains", "M"), ("throat_units", "T")):
        value = state[name]
        sizes[length] = len(value) if isinstance(value, np.ndarray) and value.ndim else -1
    arrays = {}
    try:
        for name, (dtype, shape) in _UNIT_ARRAYS.items():
            if name == "period" and state[name] is None:
                arrays[name] = None
                continue
            arrays[name] = state_array(state, name, dtype, tuple(sizes.get(n, n)
                                                                 for n in shape))
    except ValueError as error:
        raise ValueError(f"units/{error}") from None
    period = arrays["period"]
    if period is not None and (len(period) not in (3, 4) or (period[:3] <= 0.0).any()):
        raise ValueError(f"units/period = {period.tolist()} m; valid: None, or the cell's "
                         "lengths (3,) > 0 (and a sheared cell's offset, (4,))")
    for name, low, high in (("grains", 0, grain_count), ("neighbours", -1, sizes["M"]),
                            ("throat_units", -1, sizes["M"]), ("throat_of", 0, sizes["T"])):
        outside = (arrays[name] < low) | (arrays[name] >= high)
        if outside.any():
            index = [int(i) for i in np.argwhere(outside)[0]]
            raise ValueError(f"units/{name}{index} = {arrays[name][tuple(index)]} is outside "
                             f"the valid range [{low}, {high})")
    return PoreUnits(**arrays)


def _liquid_of(state, filled):
    """ClosedLiquid of a LiquidClusters.state_dict's ``liquid`` with the units ``filled``
    (M,); ValueError naming the value (liquid/<name>) that does not fit."""
    count = len(filled)
    try:
        front = state_array(state, "front", bool, (count,))
        weight = state_array(state, "weight", np.float64, (count,))
    except ValueError as error:
        raise ValueError(f"liquid/{error}") from None
    numbers = {}
    for name in ("suction", "front_fraction", "bridges", "clusters", "film"):
        value = state[name]
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not math.isfinite(value):
            raise ValueError(f"liquid/{name} = {value!r}; valid: a finite number")
        numbers[name] = float(value)
    if not (0.0 <= numbers["front_fraction"] <= 1.0 and (weight >= 0.0).all()
            and (weight <= 1.0).all()):
        raise ValueError("liquid/front_fraction and liquid/weight: valid shares in [0, 1]")
    return ClosedLiquid(filled=filled, front=front, weight=weight, **numbers)
