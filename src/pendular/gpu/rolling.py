"""Rolling and twisting resistance on the device: the CPU's own per-pair body
(pendular.dem.rolling._pair_moment, compiled by device_twin) over each particle's row of pairs,
after the contact law's pair forces and their gather, whose per-pair arrays it reads; then each
particle's pair moments added to its torque by the CPU's sum (_sum_moments: its own pairs,
then those in which it is the second member, as the CPU's gather_moments).

The springs (pendular.dem.rolling.FIELDS) are one (K, COLUMNS) float64 array ``rolling`` of
pendular.gpu.state, carried across the device's rebuilds as the bridges' columns are
(pendular.gpu.neighbors), with each pair's moment of the last step, ``pair_moment`` (K, 3)
[N m] (RollingResistance.moment on the host).
"""

import numpy as np

from pendular.dem.neighbors import carry_pair_array
from pendular.dem.protocols import pair_key
from pendular.dem.rolling import FIELDS, OWNER, RollingResistance, _pair_moment, _sum_moments
from pendular.gpu.cuda import cuda, device_twin
from pendular.gpu.operations import DeviceSide, device_side

pair_moment = device_twin(_pair_moment)
sum_moments = device_twin(_sum_moments)

#: (first column, components) of each of FIELDS in the device's ``rolling``, in order.
LAYOUT = tuple((sum(int(np.prod(f.shape)) for f in FIELDS[:index]), int(np.prod(field.shape)))
               for index, field in enumerate(FIELDS))
#: Columns of the device's ``rolling`` (rolling moment, twisting moment, last normal).
COLUMNS = sum(size for _, size in LAYOUT)


@cuda.jit
def pair_moments(radius, mass, inertia, angular_velocity, pairs, springs, moment,
                 coefficients, dt):
    """Every pair of particle p's row (one thread per particle): the CPU's update of its
    springs (``rolling_moment`` (K, 3), ``twisting_moment`` (K,), ``last_normal`` (K, 3): the
    columns of the device's ``rolling``) and its ``moment`` (K, 3) [N m] on p
    (pendular.dem.rolling.pair_moments); ``pairs`` pendular.gpu.forces.Pairs, ``springs``
    the three (columns), ``coefficients`` the operation's (rolling, twisting, damping_ratio)."""
    pair_count, pair_j, normal, overlap, normal_force = (pairs.count, pairs.second,
                                                         pairs.normal, pairs.overlap,
                                                         pairs.normal_force)
    rolling_moment, twisting_moment, last_normal = springs
    rolling, twisting, damping_ratio = coefficients
    p = cuda.grid(1)
    n = radius.shape[0]
    if p >= n:
        return
    for s in range(pair_count[p]):
        k = s * n + p
        pair_moment(k, p, pair_j[k], radius, mass, inertia, angular_velocity, normal, overlap,
                    normal_force, rolling_moment, twisting_moment, last_normal, moment,
                    rolling, twisting, damping_ratio, dt)


@cuda.jit
def gather_moments(pair_count, second_count, second_pair, moment, torque):
    """Add particle p's pair moments to its torque (N, 3) [N m] by the CPU's sum
    (pendular.dem.rolling.gather_moments over the device's rows)."""
    p = cuda.grid(1)
    n = torque.shape[0]
    if p >= n:
        return
    t0, t1, t2 = sum_moments(moment, second_pair, range(p, p + pair_count[p] * n, n),
                             range(p, p + second_count[p] * n, n))
    torque[p, 0] += t0
    torque[p, 1] += t1
    torque[p, 2] += t2


def columns(rolling):
    """The views of ``rolling`` (K, COLUMNS), the device's or a host copy, that are FIELDS'
    arrays (rolling_moment (K, 3), twisting_moment (K,), last normal (K, 3))."""
    return tuple(rolling[:, first:first + size] if field.shape else rolling[:, first]
                 for (first, size), field in zip(LAYOUT, FIELDS))


def host_columns(contacts):
    """The springs that ``contacts`` (a host Contacts) keeps in its ``extra`` as one (K,
    COLUMNS) array in its pair order (zeros for a list without them)."""
    values = np.zeros((len(contacts), COLUMNS))
    for view, field in zip(columns(values), FIELDS):
        array = contacts.extra.get(pair_key(OWNER, field))
        if array is not None:
            view[...] = array
    return values


def host_fields(values):
    """``extra`` entries (key -> array) of the springs in ``values`` (K, COLUMNS), a host copy
    of the device's ``rolling`` in the host list's order."""
    return {pair_key(OWNER, field): np.ascontiguousarray(view, dtype=field.dtype)
            for view, field in zip(columns(values), FIELDS)}


@device_side(RollingResistance)
class Resistance(DeviceSide):
    """A RollingResistance's side: its launches after the contact law's gather, its pairs'
    moments back into the operation."""

    family = "force"
    role = "rolling"

    def check(self, scene):
        """It reads the contact law's pairs of the same step: listed after the law."""
        if scene.index(self) < scene.index(scene.force("contact law")):
            raise ValueError("device='gpu' runs a RollingResistance listed after the contact "
                             "law only (it reads the contact law's pairs of the same step)")

    def launches(self, state, dt):
        """(kernel, items, arguments) of a step's rolling resistance (its coefficients now;
        ``state`` a DeviceState, ``dt`` [s]), to run after the gather."""
        s = state
        op = self.op
        n = s.count
        return [(pair_moments, n, (s.radius, s.mass, s.inertia, s.angular_velocity, s.pairs(),
                                   columns(s.rolling), s.pair_moment,
                                   (op.rolling, op.twisting, op.damping_ratio), dt)),
                (gather_moments, n, (s.pair_count, s.second_count, s.second_pair,
                                     s.pair_moment, s.torque))]

    def pairs_to_host(self, sim, state, index):
        """The device's pair moments into the operation's ``moment``, carried to the host
        list's pairs (``index``: pendular.dem.neighbors.previous_pair_index)."""
        self.op.moment = carry_pair_array(state.pair_moments(), index)
