"""The progress of the laboratory procedures' phases, and the plans of whole runs.

Each open-ended phase is measured by the quantity that ends it (pendular.utils.progress):

- radius growth (until the walls hold the preparation stress): ``growth_bar``, the walls' mean
  stress approaching its target [Pa];
- an equilibrium (preparation's friction and final equilibria, wetting, a loaded sample's
  settling, a suction step of the SWCC, a Static loading stage): ``equilibrium_bar``, the decades
  by which the distance to equilibrium has fallen toward 1 (``off_equilibrium``: the larger of
  the unbalanced force over its threshold and the servos' stress errors over their tolerance);
- a loading stage until a stress: ``stress_bar``, that wall stress approaching its target
  [Pa].

Phases of known length count steps: the unload in stages, a loading stage to a strain, the
tension's pull (its step limit is the pull to the largest strain; a rupture ends it earlier).

The plans of whole runs (``laboratory_plan``, ``swcc_plan``, ``tension_plan``; the run's
bar, pendular.utils.progress.whole_run) estimate each phase in steps: the known lengths (the
unload, a loading to a strain, the pull) as they are, an equilibrium OPEN_ENDED_STEPS, the
radius growth GROWTH_STEPS. These are rough; the run's bar refines them as its phases run and
end.
"""

import numpy as np

from pendular.dem.walls import StressServo
from pendular.homogenize.on_the_fly import homogenized
from pendular.utils.progress import Approach, Decades, Phase

#: Estimated steps of an equilibrium (the run bar's share of it) [-].
OPEN_ENDED_STEPS = 5_000
#: Estimated steps of the radius growth (the run bar's share of it) [-].
GROWTH_STEPS = 20_000
#: Estimated preparations of the tension's tuning of a void ratio (the run bar's share) [-].
TUNING_PREPARATIONS = 3


def unbalanced_now(sim):
    """The unbalanced force of ``sim``'s state [-], measured where the state is, as
    pendular.procedures.preparation.static measures it (a device run: there)."""
    return homogenized(sim)["unbalanced_force"]


def off_equilibrium(unbalanced, tolerance):
    """How far ``sim`` is from the equilibrium of pendular.procedures.preparation.static, as a
    function of sim: the larger of the unbalanced force over ``unbalanced`` and each
    StressServo's largest stress error over ``tolerance`` times its target [-]; at most 1 at
    equilibrium."""

    def ratio(sim):
        worst = unbalanced_now(sim) / unbalanced
        for servo in (op for op in sim.peek("controls") if isinstance(op, StressServo)):
            error = np.max(np.abs(sim.fetch("walls").walls.stress()[list(servo.axes)] - servo.target))
            worst = max(worst, error / (tolerance * max(servo.target, 1e-12)))
        return worst

    return ratio


def mean_wall_stress(sim):
    """The walls' mean stress [Pa]."""
    return float(sim.fetch("walls").walls.stress().mean())


def growth_bar(label, target):
    """The bar of a radius growth toward the mean stress ``target`` [Pa]; None without
    ``label``."""
    return label and Phase(label, Approach(mean_wall_stress, target, "Pa"))


def equilibrium_bar(label, unbalanced, tolerance):
    """The bar of an equilibrium until the unbalanced force is at most ``unbalanced`` [-] and
    the servos' stresses within ``tolerance`` (relative) of their targets: the decades by which
    ``off_equilibrium`` falls to 1; None without ``label``."""
    return label and Phase(label, Decades(off_equilibrium(unbalanced, tolerance), 1.0))


def stress_bar(label, axis, target):
    """The bar of a loading stage until the stress of wall axis ``axis`` (0, 1, 2) reaches
    ``target`` [Pa]; None without ``label``."""
    return label and Phase(label, Approach(
        lambda sim: sim.fetch("walls").walls.stress()[axis], target, "Pa"))


def preparation_plan(sample, *, loaded=False):
    """The preparation's phases (label prefix, estimated steps) for a PrepareConfig; a
    ``loaded`` sample only settles ("equilibrate sample")."""
    if loaded:
        return [("equilibrate", OPEN_ENDED_STEPS)]
    return [("grow radii", GROWTH_STEPS), ("set friction", OPEN_ENDED_STEPS),
            ("unload", sample.unload_steps), ("equilibrate", OPEN_ENDED_STEPS)]


def laboratory_plan(config, loading):
    """The plan of a LaboratoryConfig's run whose loading's bars are labelled ``loading``:
    the preparation (or a loaded sample's equilibrium), the wetting if wet, the loading
    (its estimated_steps, or OPEN_ENDED_STEPS when its stages end at a stress)."""
    wetting = [] if config.bridges is None else [("wet", OPEN_ENDED_STEPS)]
    return [*preparation_plan(config.sample, loaded=config.sample_path is not None), *wetting,
            (loading, config.estimated_steps() or OPEN_ENDED_STEPS)]


def swcc_plan(config):
    """The plan of an SwccConfig's run: the preparation, then an equilibrium per suction
    drying and per suction back but the turning point wetting."""
    count = len(config.suctions)
    return [*preparation_plan(config.sample), ("drying", OPEN_ENDED_STEPS * count),
            ("wetting", OPEN_ENDED_STEPS * max(count - 1, 1))]


def tension_plan(config):
    """The plan of a TensionConfig's run: per void ratio the preparations of its tuning (one
    entry for all of them, TUNING_PREPARATIONS estimated), then per case its wetting and its
    pull (TensionConfig.pull_steps)."""
    preparation = preparation_plan(config.sample)
    tuning = (tuple(prefix for prefix, _ in preparation),
              TUNING_PREPARATIONS * sum(steps for _, steps in preparation))
    plan = []
    for void_ratio in dict.fromkeys(e for e, _ in config.cases):
        plan.append(tuning)
        for _ in (w for e, w in config.cases if e == void_ratio):
            plan.extend([("wet", OPEN_ENDED_STEPS), ("pull", config.pull_steps())])
    return plan
