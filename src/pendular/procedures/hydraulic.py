"""The water of a loading path's stage: a new suction, stepped or ramped, or a new water content.

A stage of pendular.procedures.loading may change what the capillary bridges hold while its
walls do what the stage says (docs/loading_paths.md, 'Constant volume, suction and water content in a stage'):

- ``suction`` [Pa], suction-controlled bridges (a sample wetted at a suction): imposed at the
  stage's first step (a step; the stage's end, e.g. static, is the equilibrium after it), or
  with ``suction_rate`` [Pa/s] ramped linearly to it (``SuctionChange``, a control);
- ``water_content`` [%, of the grains' mass, as --water-content], volume-controlled bridges
  holding a closed amount of liquid (a sample wetted at a water content): liquid added to or
  taken from every bridge and film in proportion to its volume at the stage's first step
  (``WaterContentChange``, a control; ``set_water_content``), the bridges' suctions
  following from their new volumes.

Each control is ``done`` once the water is where its stage says, and a stage's end is checked
only then (pendular.procedures.loading.LoadingPath).

Drying raises the suction (or lowers the water content), wetting lowers it (raises it); the
collapse on wetting is the compression of a sample at a held stress as its capillary forces
fall.
"""

from __future__ import annotations

import numpy as np

from pendular.capillary.bridge_state import ACROSS_GAP, AT_CONTACT
from pendular.procedures.config import WATER_DENSITY
from pendular.utils.validate import check_positive, check_range


class SuctionChange:
    """Bring the suction of the suction-controlled ``bridges`` (capillary.SuctionBridges, among
    the scene's forces) to ``target`` [Pa]: at its first call (``rate`` None, a step), or
    linearly at ``rate`` [Pa/s] > 0 (the sign is the change's), each step by at most rate dt
    and ending exactly at the target. A control; ``done`` once the target is reached."""

    def __init__(self, bridges, target, rate=None):
        if getattr(bridges, "control", None) != "suction":
            raise ValueError(f"suction = {target!r} Pa needs a sample wetted at a suction "
                             "(--suction: suction-controlled bridges); at --water-content "
                             "give water_content")
        self.bridges = bridges
        self.target = check_positive("suction", target, "Pa")
        self.rate = None if rate is None else check_positive("suction_rate", rate, "Pa/s")

    def state_dict(self):
        """The ``target`` [Pa] and ``rate`` [Pa/s, 0: a step] its stage set (the suction
        reached is the bridges' own state)."""
        return {"target": self.target, "rate": 0.0 if self.rate is None else self.rate}

    def load_state(self, state):
        target = check_positive("target", state["target"], "Pa")
        rate = check_range("rate", state["rate"], 0.0, unit="Pa/s")
        self.target, self.rate = target, rate or None

    @property
    def done(self):
        """Whether the suction is at its target."""
        return self.bridges.suction == self.target

    def apply(self, sim):
        now = self.bridges.suction
        if now == self.target:
            return
        change = self.target - now
        if self.rate is None or abs(change) <= self.rate * sim.dt:
            self.bridges.set_suction(self.target)
        else:
            self.bridges.set_suction(now + float(np.copysign(self.rate * sim.dt, change)))


class WaterContentChange:
    """Bring the closed liquid of the volume-controlled ``bridges`` to the water content
    ``percent`` [%] at its first call (``set_water_content``). A control; ``done`` once
    applied (its state, so that a resumed stage does not add the liquid twice)."""

    def __init__(self, bridges, percent):
        if getattr(bridges, "control", None) != "volume":
            raise ValueError(f"water_content = {percent!r} % needs a sample wetted at a water "
                             "content (--water-content: volume-controlled bridges holding a "
                             "closed amount of liquid); at --suction give suction")
        self.bridges = bridges
        self.percent = check_range("water_content", percent, 0.0, 100.0, low_inclusive=False,
                                   unit="%")
        self.done = False

    def state_dict(self):
        """The ``percent`` [%] its stage set and whether it was applied (``done``)."""
        return {"percent": self.percent, "done": self.done}

    def load_state(self, state):
        percent = check_range("percent", state["percent"], 0.0, 100.0, low_inclusive=False,
                              unit="%")
        self.percent, self.done = percent, bool(state["done"])

    def apply(self, sim):
        if not self.done:
            set_water_content(sim, self.bridges, self.percent)
            self.done = True


def unit_water_volume(particles):
    """Water volume [m^3] of a gravimetric water content of 1 (100 %) for ``particles``: the
    grains' mass over the density of water, Gs V_s (Gs = rho_s / WATER_DENSITY)."""
    return particles.density / WATER_DENSITY * particles.solid_volume()


def water_content(sim, bridges):
    """Gravimetric water content [%] held by the volume-controlled ``bridges`` of ``sim``: the
    liquid of the bridges and the grains' films over Gs V_s (unit_water_volume)."""
    held, film, _, _ = bridges.liquid_balance(sim)
    return 100.0 * (held + film) / unit_water_volume(sim.particles)


def set_water_content(sim, bridges, percent):
    """Bring the closed liquid of the volume-controlled ``bridges`` of ``sim`` to the water
    content ``percent`` [%, of the grains' mass]: every bridge and film scaled by one factor
    (new / present liquid), the closed amount (``liquid_initial``) changed by the liquid added
    or taken, and the bridges at contact looked up again at their new volume at the next step.
    ValueError naming ``water_content`` with its valid range: without closed liquid, or when a
    bridge would leave the volume table (capillary.VolumeBridgeTable.volume_star_bounds)."""
    percent = check_range("water_content", percent, 0.0, 100.0, low_inclusive=False, unit="%")
    if bridges is None or getattr(bridges, "liquid_initial", None) is None:
        raise ValueError(f"water_content = {percent:g} % needs a sample wetted at a water "
                         "content (--water-content: volume-controlled bridges holding a closed "
                         "amount of liquid)")
    state = bridges.state(sim)
    held, film, _, _ = bridges.liquid_balance(sim)
    present = held + film
    target = percent / 100.0 * unit_water_volume(sim.particles)
    mask = state.mask()
    radius = sim.particles.radius
    larger = np.maximum(radius[sim.contacts.pair_i[mask]], radius[sim.contacts.pair_j[mask]])
    volume_star = state.volume[mask] / larger ** 3
    low, high = bridges.volume_table.volume_star_bounds()
    now = 100.0 * present / unit_water_volume(sim.particles)
    most = now * high / volume_star.max() if mask.any() else now
    least = now * low / volume_star.min() if mask.any() else now
    if not mask.any() or not least <= percent <= most:
        raise ValueError(f"water_content = {percent:g} % is outside the valid range "
                         f"[{least:.4g}, {most:.4g}] % of this sample's bridges (now "
                         f"{now:.4g} %): liquid scaled in every bridge must keep each within "
                         "the volume table")
    factor = target / present
    state.volume[mask] *= factor
    state.state[state.state == AT_CONTACT] = ACROSS_GAP    # looked up again at contact
    bridges.film *= factor
    bridges.liquid_initial += target - present
    return factor
