"""Drained triaxial compression (thesis Ch. 5.2.3): lateral walls servoed, axial walls strained.

Stresses are compression positive [Pa]; q = sigma_axial - sigma_lateral,
p = (sigma_axial + 2 sigma_lateral) / 3; strains compression positive, volumetric strain
positive in contraction (SPEC §1).
"""

from dataclasses import dataclass

import numpy as np

from homogenize import contact_stress, fabric_tensor, principal_anisotropy
from homogenize.on_the_fly import capillary_quantities

from .measure import coordination, porosity, unbalanced_force
from .record import HistoryRecorder
from .validate import check_int, check_positive, check_range
from .walls import ConstantStrainRate, StressServo


@dataclass
class ShearConfig:
    """Shear-phase parameters. ``strain_rate`` [1/s] defaults to the one giving
    ``inertial_number`` I = rate * 2R * sqrt(rho / confining).

    Wall control options, pendular's choice by default; ``YADE_CHOICES`` holds YADE's
    (TriaxialStressController, docs/yade_crosscheck.md):
    rate_on_current_length: the axial rate acts on the current height (true strain rate)
        instead of the initial one (engineering strain rate);
    servo_max_velocity: speed cap of the lateral walls [m/s] (None: the one of the preparation
        servo); servo_scale_max_velocity: scale it per axis by 3 L_a / (L_x + L_y + L_z);
    servo_stiffness_every: refresh the walls' stiffness every this many steps (and at each of
        the first 100) instead of every step.
    """

    confining: float = 750.0
    max_strain: float = 0.25
    inertial_number: float = 3e-4
    strain_rate: float = None
    records: int = 500
    rate_on_current_length: bool = False
    servo_max_velocity: float = None
    servo_scale_max_velocity: bool = False
    servo_stiffness_every: int = 1

    def __post_init__(self):
        self.confining = check_positive("confining", self.confining, "Pa")
        self.max_strain = check_range("max_strain", self.max_strain, 0.0, 0.9,
                                      low_inclusive=False)
        self.inertial_number = check_range("inertial_number", self.inertial_number, 0.0, 1.0,
                                           low_inclusive=False)
        if self.strain_rate is not None:
            self.strain_rate = check_positive("strain_rate", self.strain_rate, "1/s")
        self.records = check_int("records", self.records, low=2)
        if self.servo_max_velocity is not None:
            self.servo_max_velocity = check_positive("servo_max_velocity",
                                                     self.servo_max_velocity, "m/s")
        self.servo_stiffness_every = check_int("servo_stiffness_every",
                                               self.servo_stiffness_every, low=1)

    def rate(self, radius, density):
        """Axial strain rate [1/s]: the given one, or the one of the target inertial number."""
        if self.strain_rate is not None:
            return self.strain_rate
        return self.inertial_number / (2.0 * radius * np.sqrt(density / self.confining))


#: ShearConfig options that reproduce YADE's TriaxialStressController (stiffnessUpdateInterval 10).
YADE_CHOICES = {"rate_on_current_length": True, "servo_scale_max_velocity": True,
                "servo_stiffness_every": 10}


def inertial_number(strain_rate, radius, density, pressure):
    """I = strain_rate * d * sqrt(rho / p), d = 2R (GDR MiDi 2004)."""
    return strain_rate * 2.0 * radius * np.sqrt(density / pressure)


def _contact_fabric(sim):
    return fabric_tensor(sim.contacts.normal, sim.contacts.overlap > 0.0)


def triaxial_quantities(axial, reference_volume, operations=()):
    """Recorded columns of the triaxial history (see the scenario's HDF5 layout), plus those of
    every operation that offers ``quantities()`` (name -> function of sim; e.g. the capillary
    bridges' saturation, suction, sigma_capillary, bridges, pendular_overlaps) and, when the
    scene has capillary bridges, the homogenised capillary state
    (homogenize.on_the_fly.CapillaryHomogenization: chi, B, psi, sigma_effective,
    fabric_bridges, anisotropy_bridges, a_psi). A dry scene records no capillary column."""
    columns = {
        "step": lambda s: s.step,
        "time": lambda s: s.time,
        "axial_strain": lambda s: axial.strain(s.walls),
        "volumetric_strain": lambda s: 1.0 - s.walls.volume() / reference_volume,
        "sigma_wall": lambda s: s.walls.stress(),
        "sigma_contact": lambda s: contact_stress(s.particles, s.contacts, s.walls),
        "porosity": lambda s: porosity(s.particles, s.walls),
        "coordination": lambda s: coordination(s.contacts, len(s.particles)),
        "fabric": _contact_fabric,
        "anisotropy": lambda s: principal_anisotropy(_contact_fabric(s)),   # Eq. 3.51
        "unbalanced_force": lambda s: unbalanced_force(s.particles, s.contacts),
    }
    for op in operations:
        if hasattr(op, "quantities"):
            columns.update(op.quantities())
    columns.update(capillary_quantities(operations))
    return columns


def start_shear(sim, config, radius, density):
    """Replace the wall control of a prepared sample with the triaxial one; add a recorder.

    Returns (recorder, steps to reach max_strain, strain rate).
    """
    servo = sim.operation(StressServo)
    rate = config.rate(radius, density)
    axial = ConstantStrainRate("z", rate, sim.walls.lengths()[2],
                               on_current_length=config.rate_on_current_length)
    max_velocity = (servo.max_velocity if config.servo_max_velocity is None
                    else config.servo_max_velocity)
    lateral = StressServo("xy", config.confining, max_velocity, servo.gain, servo.memory,
                          scale_max_velocity=config.servo_scale_max_velocity,
                          stiffness_every=config.servo_stiffness_every)
    index = sim.operations.index(servo)
    if sim.contacts is None:
        # a sample just loaded from disk: evaluate its forces once (the operations before the
        # wall control move nothing) so that the first record sees its contacts
        for op in sim.operations[:index]:
            op.apply(sim)
    sim.operations[index:index + 1] = [lateral, axial]
    steps = axial.steps_to(config.max_strain, sim.dt)
    period = max(1, steps // config.records)
    steps = -(-steps // period) * period     # whole periods: the last step is recorded
    recorder = HistoryRecorder(period, triaxial_quantities(axial, sim.walls.volume(),
                                                           sim.operations))
    recorder.record(sim)
    sim.writers.append(recorder)
    return recorder, steps, rate


def summarize(history):
    """Peak values of a triaxial history (dict of arrays): axial stress, q, p, strain at peak
    (and the degree of saturation there when the history records one). A wet history adds
    ``peak_q_effective`` and ``p_effective_at_peak``: q' = sigma'_z - (sigma'_x + sigma'_y)/2
    and p' = tr sigma' / 3 of the effective stress (Eq. 3.43) at the peak of q (the wall
    stresses' peak, not the largest q')."""
    sigma = history["sigma_wall"]
    lateral = 0.5 * (sigma[:, 0] + sigma[:, 1])
    q = sigma[:, 2] - lateral
    p = (sigma[:, 2] + 2.0 * lateral) / 3.0
    peak = int(np.argmax(q))
    summary = {
        "peak_axial_stress": float(sigma[:, 2].max()),
        "peak_q": float(q[peak]),
        "p_at_peak": float(p[peak]),
        "axial_strain_at_peak": float(history["axial_strain"][peak]),
        "lateral_stress": float(np.mean(lateral)),
        "peak_index": peak,
    }
    if "saturation" in history:
        summary["saturation_at_peak"] = float(history["saturation"][peak])
    if "sigma_effective" in history:
        effective = np.diagonal(history["sigma_effective"][peak])
        summary["peak_q_effective"] = float(effective[2] - 0.5 * (effective[0] + effective[1]))
        summary["p_effective_at_peak"] = float(effective.mean())
    return summary
