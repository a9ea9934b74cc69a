"""Mixed stress conditions: a control that sets, each step, the targets of the stress servos of
the axes it holds from the box's stresses now (pendular.procedures.loading's stages with a
constant mean stress or a constant b; the GPU runs the same law, pendular.gpu.walls).

Stresses compression positive [Pa], sigma_1 on z, sigma_3 on x:

- a constant mean stress p alone: each free axis gets (3 p - the other axes' stresses) /
  (number of free axes);
- b = (sigma_2 - sigma_3) / (sigma_1 - sigma_3) alone: sigma_y = sigma_3 + b (sigma_z -
  sigma_3), sigma_3 x's given stress;
- both: sigma_3 = (3 p - (1 + b) sigma_z) / (2 - b) on x and sigma_y as above.

A target below zero would need walls that pull: the control raises StageFailed.
"""

from pendular.dem.walls import AXES
from pendular.utils.validate import check_positive, check_range

#: The axes by name, in order (x, y lateral; z axial).
AXIS_NAMES = tuple(AXES)


class StageFailed(ValueError):
    """A stage of a loading cannot go on: a mixed condition needs walls to pull, or
    (pendular.procedures.loading) its end was not reached within its limit."""


def _axis(name, letter):
    """The index of the axis ``letter``; ValueError naming ``name`` otherwise."""
    if letter not in AXIS_NAMES:
        raise ValueError(f"{name} = {letter!r} is not one of {AXIS_NAMES}")
    return AXES[letter]


class MixedStress:
    """A control, run before the servos it sets, holding a constant mean stress and/or a
    constant b (module docstring) on the axes ``free`` (letters, e.g. "xy").

    servos: {axis index: the StressServo of that axis}, one for each free axis;
    mean_stress: p [Pa] (None: not held); b [-] in [0, 1] (None: not held); stress: {axis
    letter: the stress given to a servoed axis [Pa]} (an axis given none enters with its
    stress now).
    """

    def __init__(self, servos, free, *, mean_stress=None, b=None, stress=None):
        self.servos = servos
        self.mean_stress, self.b, self.stress, self.free = self._condition(
            mean_stress, b, {} if stress is None else stress, free)

    def _condition(self, mean, b, given, free):
        """(mean_stress, b, {axis index: Pa}, free axis indices) checked; ValueError naming
        the first value out of range."""
        mean = None if mean is None else check_positive("mean_stress", mean, "Pa")
        b = None if b is None else check_range("b", b, 0.0, 1.0)
        if mean is None and b is None:
            raise ValueError("mean_stress and b are both None; valid: one of them or both")
        if not isinstance(given, dict):
            raise ValueError(f"stress holds {type(given).__name__}; valid: axis -> Pa")
        stress = {_axis("stress axis", a): check_range(f"stress/{a}", value, 0.0, unit="Pa")
                  for a, value in given.items()}
        axes = tuple(_axis("free axis", a) for a in free)
        unserved = [AXIS_NAMES[a] for a in axes if a not in self.servos]
        if not axes or unserved:
            raise ValueError(f"free = {free!r}: valid: axes of this scene's servos "
                             f"({''.join(AXIS_NAMES[a] for a in sorted(self.servos))})")
        if b is not None and axes != ((1,) if mean is None else (0, 1)):
            raise ValueError(f"free = {free!r} with b = {b:g}: valid: "
                             f"{'y' if mean is None else 'xy'} (b sets y from x's stress, "
                             "and with mean_stress x too)")
        return mean, b, stress, axes

    def state_dict(self):
        """The condition its stage set: ``mean_stress`` [Pa] and ``b`` (None: not held),
        ``stress`` ({axis letter: stress given [Pa]}) and ``free`` (the letters of the axes it
        sets); its servos are the scene's."""
        return {"mean_stress": self.mean_stress, "b": self.b,
                "stress": {AXIS_NAMES[a]: value for a, value in self.stress.items()},
                "free": "".join(AXIS_NAMES[a] for a in self.free)}

    def load_state(self, state):
        self.mean_stress, self.b, self.stress, self.free = self._condition(
            state["mean_stress"], state["b"], state["stress"], state["free"])

    def targets(self, sigma):
        """{axis index: target [Pa]} of the free axes for the stresses ``sigma`` (3,) [Pa]."""
        given = {a: self.stress.get(a, sigma[a]) for a in range(3)}
        if self.b is None:
            others = sum(given[a] for a in range(3) if a not in self.free)
            share = (3.0 * self.mean_stress - others) / len(self.free)
            return {a: share for a in self.free}
        axial = sigma[2]
        if self.mean_stress is None:
            minor = given[0]
            return {1: minor + self.b * (axial - minor)}
        minor = (3.0 * self.mean_stress - (1.0 + self.b) * axial) / (2.0 - self.b)
        return {0: minor, 1: minor + self.b * (axial - minor)}

    def failure(self, step, axis, target, axial):
        """The StageFailed of a ``target`` [Pa] below zero (or not a number) on ``axis``
        (index) at ``step``, sigma_z being ``axial`` [Pa]."""
        condition = ("the mean stress" if self.b is None else "b") + " condition"
        return StageFailed(
            f"{condition} cannot be held at step {step}: it needs {target:.4g} Pa on "
            f"{AXIS_NAMES[axis]} with sigma_z = {axial:.4g} Pa, and walls cannot pull; end the "
            "shear earlier (--max-strain) or raise the confining stress")

    def apply(self, sim):
        sigma = sim.walls.stress()
        for axis, target in self.targets(sigma).items():
            if not target >= 0.0:
                raise self.failure(sim.step, axis, target, sigma[2])
            self.servos[axis].target = target
