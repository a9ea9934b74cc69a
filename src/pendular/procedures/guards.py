"""Guards: read-only writers that stop a run whose sample has left the bounds of a packing.

A guard is a writer of pendular.dem.simulation.Simulation (``apply(sim)`` after each step, as
pendular.dem.record.HistoryRecorder): every ``period`` steps it measures the state and raises
when a bound is crossed; it changes nothing, so a run within the bounds gives the same results
with or without it. A shear driven past what its walls can hold (a strain no test reaches, a
servo too slow for the strain rate) squeezes the spheres into each other: the linear contact
law then answers with stresses of no physical meaning, and the guard stops it instead.
"""

import math

from pendular.dem.mixed_stress import StageFailed
from pendular.homogenize.on_the_fly import homogenized
from pendular.utils.validate import check_int, check_range

#: Largest overlap of two spheres, or of a sphere and a wall, over the smaller radius [-]. The
#: linear contact law stands for small deformations of the grains: configurations keep the
#: overlaps at the confining stress below about 0.16 (pendular.procedures.preparation
#: .MAX_STRESS_OVER_YOUNG), and the extremes grid's bound of a sound state is 0.25 too.
MAX_OVERLAP_OVER_RADIUS = 0.25
#: Porosity [-] below which equal spheres must overlap: the densest packing's, 1 - pi / sqrt(18)
#: (Kepler's conjecture, proved by Hales 2005).
MIN_POROSITY_EQUAL = 1.0 - math.pi / math.sqrt(18.0)
#: Porosity [-] below which graded spheres (radius ratio at most 10, pendular.dem.grading) must
#: overlap, with a margin: binary mixtures of size ratio 7 pack to 0.14 (McGeary 1961).
MIN_POROSITY_GRADED = 0.1
#: Porosity [-] above which the spheres no longer form a packing that bears a load: the
#: loosest static packings of frictional spheres, wet ones included, stay below about 0.6
#: (random loose packing 0.45; the box's wall layers add a few hundredths).
MAX_POROSITY = 0.7
#: What the error suggests by default: the settings that drive a triaxial shear.
SHEAR_REMEDY = ("lower --max-strain, or the strain rate (--strain-rate / --inertial-number), "
                "or raise --young")


class SampleCrushed(ValueError):
    """A sample's state left the bounds of a packing (overlaps or porosity, SampleGuard)."""


class AxialContactLost(StageFailed):
    """The axial stress fell to 0: the axial walls, which cannot pull, left the sample
    (AxialStressGuard)."""


class AxialStressGuard:
    """A writer: AxialContactLost when the axial (z) stress is 0 or below after a step. The
    axial walls cannot pull: at zero stress they have left the sample (in a periodic cell, the
    sample is in tension), whose response they then no longer measure. ``describe(sim)``:
    where the path stands (text); ``remedy``: what to change (text)."""

    stateless = True

    def __init__(self, describe, remedy):
        self.describe = describe
        self.remedy = remedy

    def apply(self, sim):
        sigma = sim.fetch("walls").walls.stress()[2]
        if not sigma > 0.0:
            raise AxialContactLost(
                f"{self.describe(sim)}: the axial stress fell to {sigma:.4g} Pa at step "
                f"{sim.step} and the axial walls cannot pull; {self.remedy}")


class SampleGuard:
    """Every ``period`` steps, the largest overlap over the smaller radius (sphere pairs and,
    inside walls, sphere-wall contacts) at most ``max_overlap`` [-], and the porosity
    (pendular.dem.measure.porosity) within ``porosity_range`` (low, high) [-] (default
    ``default_porosity_range`` of the radii); otherwise SampleCrushed naming the bound crossed,
    the step, ``describe(sim)`` (text, e.g. the axial strain) when given, and ``remedy``: the
    options to change."""

    stateless = True

    def __init__(self, period, *, max_overlap=MAX_OVERLAP_OVER_RADIUS, porosity_range=None,
                 describe=None, remedy=SHEAR_REMEDY):
        self.period = check_int("guard period", period, low=1)
        self.max_overlap = check_range("max_overlap", max_overlap, 0.0, 1.0,
                                       low_inclusive=False)
        if porosity_range is not None:
            bounds = [check_range("porosity_range", value, 0.0, 1.0) for value in porosity_range]
            if len(bounds) != 2 or bounds[0] >= bounds[1]:
                raise ValueError(f"porosity_range = {porosity_range!r}: valid is (low, high) "
                                 "with 0 <= low < high <= 1")
            porosity_range = tuple(bounds)
        self.porosity_range = porosity_range
        if describe is not None and not callable(describe):
            raise TypeError(f"describe = {describe!r} is not a function of sim")
        self.describe = describe
        self.remedy = remedy

    def apply(self, sim):
        if sim.step % self.period == 0:
            self.check(sim)

    def check(self, sim):
        """Measure the state now; SampleCrushed when a bound is crossed, else (largest overlap
        over the radius, porosity)."""
        sim.fetch("walls")
        state = homogenized(sim)    # where the state is held: no particle comes back
        overlap = state["largest_overlap"]
        measured = 1.0 - state["solid_volume"] / sim.walls.volume()   # dem.measure.porosity
        radii = (state["smallest_radius"], state["largest_radius"])
        low, high = self.porosity_range or default_porosity_range(*radii)
        if not overlap <= self.max_overlap:
            self._crushed(sim, f"an overlap of {overlap:.3g} of the radius, beyond the bound "
                               f"{self.max_overlap:g} of a packing of grains")
        if not low <= measured <= high:
            self._crushed(sim, f"porosity {measured:.3g}, outside the range [{low:.3g}, "
                               f"{high:.3g}] of a packing of these spheres")
        return overlap, measured

    def _crushed(self, sim, what):
        where = f" ({self.describe(sim)})" if self.describe is not None else ""
        raise SampleCrushed(f"the sample is crushed at step {sim.step}{where}: {what}; "
                            f"{self.remedy}")


def default_porosity_range(smallest, largest):
    """(least, largest) porosity [-] of a packing of spheres of radii from ``smallest`` to
    ``largest`` [m]: equal or graded (MIN_POROSITY_EQUAL or MIN_POROSITY_GRADED), and
    MAX_POROSITY."""
    equal = smallest == largest
    return (MIN_POROSITY_EQUAL if equal else MIN_POROSITY_GRADED), MAX_POROSITY
