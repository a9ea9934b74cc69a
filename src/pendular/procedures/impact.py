"""One collision, to check a material's contact law: ``pendular impact`` (docs/impact.md).

A sphere of ``radius``, ``young``, ``poisson``, ``density`` hits a target at ``velocity``,
``angle`` degrees from the normal, spinning at ``spin`` about the axis normal to the plane of
incidence (positive: rolling forward); with target "sphere" an identical sphere comes the
other way (its position and velocity the mirror image through the contact point) spinning the
other way (-spin: at normal incidence the two roll on each other without sliding, their
relative rotation the rolling resistance's, ``rolling_friction`` and ``twisting_friction``,
pendular.dem.rolling), with "wall" a flat wall of its own material (``wall_material``:
``wall_young``, ``wall_poisson``, ``wall_friction``, ``wall_restitution``,
``wall_rolling_friction`` and ``wall_twisting_friction``: the rolling resistance of
pendular.dem.wall_rolling, R* = R), mixed with the
sphere's by pendular.dem.material's rules; rigid by default, the limit of an infinitely stiff
wall, E* = E / (1 - nu^2), G* = G / (2 - nu), R* = R, m* = m
(pendular.dem.hertz_mindlin.ViscoelasticWallForces; linear: kn = E R). The engine's own
Simulation runs it with the chosen contact law, without local damping or gravity, at a step of
1/STEPS_PER_CONTACT of the contact's closed-form duration (Hertz's, or pi sqrt(m* / kn)); an
impact whose closed-form peak overlap exceeds MAX_OVERLAP of the radius is refused.

The summary holds the contact's E* (Hertz–Mindlin) and restitution, the peak normal force
and overlap, the contact's duration (while the normal force is positive), the restitution
of the sphere's centre velocity along the initial normal and along the incident tangent
(signed; None at normal incidence), its angular velocity after the contact and its rebound
angle from the normal.
"""

import math
import os

import numpy as np

from pendular.dem.hertz_mindlin import (DampedLinearForces, HertzMindlinForces,
    ViscoelasticWallForces)
from pendular.dem.integrate import Integrator
from pendular.dem.material import Material, effective_modulus, pair_restitution
from pendular.dem.neighbors import NeighborList
from pendular.dem.protocols import state_array
from pendular.dem.rolling import RollingResistance
from pendular.dem.simulation import Simulation
from pendular.dem.state import Particles, Walls
from pendular.dem.timestep import rayleigh_timestep
from pendular.dem.wall_rolling import wall_resistance
from pendular.io.history import write_history
from pendular.io.outputs import OutputFolder
from pendular.io.plots import pyplot, save_figure
from pendular.io.schema import summary_units
from pendular.procedures.preparation import PrepareConfig
from pendular.utils.atomic import write_json
from pendular.utils.parameters import Option, OptionError, Parameter, option_from, option_of

#: Steps in the closed-form duration of the contact: the peak force sampled within 1e-6 of
#: its value, the duration within 1/STEPS_PER_CONTACT.
STEPS_PER_CONTACT = 2000
#: Most steps of a run, in contact durations (a damped contact ends sooner than an elastic one).
MAX_CONTACT_DURATIONS = 20
#: The largest peak overlap / radius of an impact (closed form, elastic_impact).
MAX_OVERLAP = 0.1
#: Files the impact writes in its folder.
OUTPUTS = ("summary.json", "history.h5", "impact.png")

#: The options of ``pendular impact``: the sphere's material from the preparation's fields
#: (declared once there; steel's values by default), the collision's own.
OPTIONS = (
    Option("target", "what the sphere hits: an identical sphere coming the other way, or a "
                     "flat wall (rigid unless --wall-young)", default="wall", kind=str,
           choices=("sphere", "wall")),
    option_of(PrepareConfig, "radius", default=0.01, checked=True, help="sphere radius"),
    option_of(PrepareConfig, "young", default=2e11, checked=True,
              help="Young's modulus E of the spheres (linear: kn = E R)"),
    option_of(PrepareConfig, "poisson", checked=True),
    option_of(PrepareConfig, "density", default=7800.0, checked=True, flag="--density"),
    option_of(PrepareConfig, "friction_deg", checked=True,
              help="contact friction (with the wall too, unless --wall-friction)"),
    option_of(PrepareConfig, "restitution", checked=True),
    option_from(Parameter("m/s", "impact speed of the sphere (with target sphere: of each)",
                          low=0.0, low_inclusive=False, flag="--velocity"), 1.0, checked=True),
    option_from(Parameter("deg", "angle of the velocity from the normal", low=0.0, high=90.0,
                          high_inclusive=False, flag="--angle"), 0.0, checked=True),
    option_from(Parameter("rad/s", "spin about the axis normal to the plane of incidence "
                                   "(positive: rolling forward)", flag="--spin"),
                0.0, checked=True),
    option_of(PrepareConfig, "contact", checked=True),
    option_of(PrepareConfig, "rolling_friction", checked=True,
              help="rolling resistance coefficient mu_r: limit moment mu_r R* Fn "
                   "(pendular.dem.rolling; with the wall too, unless --wall-rolling-friction; "
                   "0: none)"),
    option_of(PrepareConfig, "twisting_friction", checked=True,
              help="twisting resistance coefficient mu_t: limit moment mu_t R* Fn about the "
                   "normal (with the wall too, unless --wall-twisting-friction; 0: none)"),
    option_of(PrepareConfig, "wall_young", checked=True,
              help="Young's modulus of the wall (target wall, Hertz-Mindlin; default: rigid, "
                   "E = inf)"),
    option_of(PrepareConfig, "wall_poisson", checked=True,
              help="Poisson ratio of the wall, with --wall-young (default: the sphere's)"),
    option_of(PrepareConfig, "wall_friction", default=None, checked=True,
              help="friction angle of the wall (target wall; default: the sphere's "
                   "--friction)"),
    option_of(PrepareConfig, "wall_restitution", checked=True,
              help="coefficient of restitution of the wall (target wall): the contact's is the "
                   "mean of the sphere's and the wall's (default: the sphere's)"),
    option_of(PrepareConfig, "wall_rolling_friction", default=None, checked=True,
              help="rolling resistance coefficient of the wall (target wall; limit moment "
                   "mu_r R Fn, pendular.dem.wall_rolling; default: the sphere's "
                   "--rolling-friction)"),
    option_of(PrepareConfig, "wall_twisting_friction", default=None, checked=True,
              help="twisting resistance coefficient of the wall (target wall; default: the "
                   "sphere's --twisting-friction)"),
)
#: The options that set the wall's material.
WALL_OPTIONS = ("wall_young", "wall_poisson", "wall_friction", "wall_restitution",
                "wall_rolling_friction", "wall_twisting_friction")


def wall_material(values):
    """The wall's Material (pendular.dem.material) of ``values`` (OPTIONS, read): rigid
    unless ``wall_young``, the sphere's Poisson ratio, friction, rolling and twisting friction
    and restitution where no wall value is given."""
    def given(key, otherwise):
        return otherwise if values[key] is None else values[key]
    return Material(given("wall_young", math.inf), given("wall_poisson", values["poisson"]),
                    math.inf, given("wall_friction", values["friction"]),
                    given("wall_rolling_friction", values["rolling_friction"]),
                    given("wall_restitution", values["restitution"]),
                    given("wall_twisting_friction", values["twisting_friction"]))


def contact_restitution(values):
    """The coefficient of restitution of the contact of ``values`` (OPTIONS, read): the
    spheres', or the mean of the sphere's and the wall's (pendular.dem.material)."""
    if values["target"] == "sphere":
        return values["restitution"]
    return pair_restitution(values["restitution"], wall_material(values).restitution)


def contact_modulus(values):
    """Hertz's E* [Pa] of the contact of ``values`` (OPTIONS, read): two spheres, or the
    sphere and the wall (rigid unless ``wall_young``)."""
    young, poisson = values["young"], values["poisson"]
    if values["target"] == "sphere":
        return effective_modulus(young, poisson, young, poisson)
    wall = wall_material(values)
    return effective_modulus(young, poisson, wall.young, wall.poisson)


def elastic_impact(values):
    """(duration [s], peak overlap [m]) of the elastic normal impact of ``values`` (OPTIONS,
    read; each sphere at ``velocity`` with target "sphere"), in closed form: Hertz's
    2.868 (m*^2 / (R* E*^2 v))^(1/5) and (15 m* v^2 / (16 E* sqrt(R*)))^(2/5) (Johnson 1985,
    Eqs. 11.23-11.24), v the approach speed, or a linear spring's pi sqrt(m* / kn) and
    v sqrt(m* / kn)."""
    radius, young = values["radius"], values["young"]
    mass = values["density"] * 4.0 / 3.0 * math.pi * radius ** 3
    pair = values["target"] == "sphere"
    mass_star = mass / 2.0 if pair else mass
    approach = 2.0 * values["velocity"] if pair else values["velocity"]
    if values["contact"] == "linear":
        period = math.sqrt(mass_star / (young * radius))
        return math.pi * period, approach * period
    modulus = contact_modulus(values)
    radius_star = radius / 2.0 if pair else radius
    return (2.868 * (mass_star ** 2 / (radius_star * modulus ** 2 * approach)) ** 0.2,
            (15.0 * mass_star * approach ** 2 / (16.0 * modulus * math.sqrt(radius_star)))
            ** 0.4)


def check_impact(values):
    """OptionError naming --velocity and --young when the impact of ``values`` would overlap
    the spheres by more than MAX_OVERLAP of their radius (elastic_impact), naming a wall's
    material with a sphere target, --wall-young with the linear law (its wall is a sphere of
    the grains' springs, kn = E R) and --wall-poisson without it."""
    walled = [key for key in WALL_OPTIONS if values[key] is not None]
    if walled and values["target"] == "sphere":
        raise OptionError(lambda name: (
            f"{', '.join(map(name, walled))} set(s) the wall's material; valid with "
            f"{name('target')} wall only"))
    if values["wall_young"] is not None and values["contact"] != "hertz-mindlin":
        raise OptionError(lambda name: (
            f"{name('wall_young')} = {values['wall_young']:g} Pa applies to Hertz-Mindlin "
            f"contacts; valid: none with {name('contact')} linear (its wall is a sphere of "
            "the grains' springs, kn = E R)"))
    if values["wall_poisson"] is not None and values["wall_young"] is None:
        raise OptionError(lambda name: (
            f"{name('wall_poisson')} = {values['wall_poisson']:g} needs "
            f"{name('wall_young')}: a rigid wall's Poisson ratio plays no part"))
    overlap = elastic_impact(values)[1] / values["radius"]
    if overlap > MAX_OVERLAP:
        stiffer = "young" if values["wall_young"] is None else "wall_young"
        raise OptionError(lambda name: (
            f"{name('velocity')} = {values['velocity']:g} m/s with {name(stiffer)} = "
            f"{values[stiffer]:g} Pa overlaps the spheres by {overlap:.3g} of their radius at "
            f"the peak; valid: at most {MAX_OVERLAP:g} (the contact laws hold for small "
            f"overlaps): lower {name('velocity')} or raise {name(stiffer)}"))


class ImpactRecorder:
    """Records every step of an impact: the sphere's overlap with its target [m], the normal
    and tangential forces on it [N] (along the normal from the target to the sphere, and the
    incident tangent), its angular velocity about the axis normal to the plane of incidence
    [rad/s]; ``ended``: whether the contact has come and gone."""

    def __init__(self, target):
        self.target = target
        self.rows = []
        self.touched = False

    def state_dict(self):
        """The ``rows`` recorded (R, 5): time [s], overlap [m], normal and tangential force [N],
        angular velocity [rad/s]; ``touched``: whether the contact has begun."""
        return {"rows": np.array(self.rows, dtype=np.float64).reshape(-1, 5),
                "touched": self.touched}

    def load_state(self, state):
        rows = state_array(state, "rows", np.float64, (None, 5))
        self.touched = bool(state["touched"])
        self.rows = [tuple(row) for row in rows.tolist()]

    def apply(self, sim):
        p = sim.particles
        normal, overlap = _contact_frame(p, sim.walls, self.target)
        tangent = np.array((normal[2], 0.0, -normal[0]))
        force = p.force[0]
        normal_force = float(force @ normal)
        self.touched |= normal_force > 0.0
        self.rows.append((sim.time, overlap, normal_force, float(force @ tangent),
                          float(p.angular_velocity[0, 1])))

    def ended(self, sim):
        return self.touched and self.rows[-1][2] <= 0.0

    def columns(self):
        """The history's columns (pendular.io.schema)."""
        rows = np.array(self.rows)
        return dict(zip(("time", "overlap", "normal_force", "tangential_force",
                         "angular_velocity"), rows.T))


def _contact_frame(particles, walls, target):
    """(normal from the target to the sphere (3,), overlap [m]) of sphere 0."""
    x = particles.position
    r = particles.radius[0]
    if target == "wall":
        return np.array((0.0, 0.0, 1.0)), float(r - (x[0, 2] - walls.position[4]))
    branch = x[0] - x[1]
    distance = float(np.linalg.norm(branch))
    return branch / distance, 2.0 * r - distance


def impact_scene(values):
    """The Simulation of an impact of ``values`` (OPTIONS, read) and its recorder: sphere 0
    above its target, touching it at the origin, approaching along -z."""
    radius = values["radius"]
    angle = math.radians(values["angle"])
    speed = values["velocity"]
    velocity = np.array([[speed * math.sin(angle), 0.0, -speed * math.cos(angle)]])
    position = np.array([[0.0, 0.0, radius]])
    spin = np.array([[0.0, values["spin"], 0.0]])
    wall = values["target"] == "wall"
    if not wall:        # the mirror image through the contact point, spinning the other way
        velocity = np.vstack((velocity, -velocity))
        position = np.vstack((position, -position))
        spin = np.vstack((spin, -spin))
    particles = Particles(position, np.full(len(position), radius), values["density"],
                          velocity=velocity, angular_velocity=spin)
    reach = 40.0 * radius
    walls = Walls.box((-reach, -reach, 0.0 if wall else -reach), (reach, reach, reach))
    if values["contact"] == "hertz-mindlin":
        contact = HertzMindlinForces(values["young"], values["poisson"], values["restitution"],
                                     values["friction"])
    else:
        contact = DampedLinearForces(values["young"], restitution=values["restitution"],
                                     friction_deg=values["friction"])
    forces = [contact]
    if wall:
        forces.append(ViscoelasticWallForces(contact, wall_material(values)))
        forces.extend(wall_resistance(contact, wall_material(values)))
    elif values["rolling_friction"] > 0.0 or values["twisting_friction"] > 0.0:
        forces.append(RollingResistance(values["rolling_friction"],
                                        values["twisting_friction"]))
    duration = elastic_impact(values)[0]
    recorder = ImpactRecorder(values["target"])
    sim = Simulation(particles, walls, duration / STEPS_PER_CONTACT,
                     neighbors=NeighborList(0.1 * radius), forces=forces,
                     integrator=Integrator(0.0), writers=[recorder], threads=1)
    return sim, recorder


def impact_summary(sim, recorder, values):
    """The summary (module docstring; its keys: pendular.io.schema.SUMMARY_KEYS)."""
    history = recorder.columns()
    angle = math.radians(values["angle"])
    speed = values["velocity"]
    normal_in = speed * math.cos(angle)
    tangent_in = speed * math.sin(angle)
    velocity = sim.particles.velocity[0]
    normal_out = float(velocity[2])
    tangent_out = float(velocity[0])
    touching = history["normal_force"] > 0.0
    return {
        "effective_modulus": (contact_modulus(values) if values["contact"] == "hertz-mindlin"
                              else None),
        "contact_restitution": contact_restitution(values),
        "max_normal_force": float(history["normal_force"].max()),
        "max_overlap": float(history["overlap"].max()),
        "contact_duration": float(np.count_nonzero(touching) * sim.dt),
        "normal_restitution": normal_out / normal_in,
        "tangential_restitution": tangent_out / tangent_in if tangent_in > 0.0 else None,
        "rebound_angular_velocity": float(sim.particles.angular_velocity[0, 1]),
        "rebound_angle_deg": math.degrees(math.atan2(tangent_out, normal_out)),
        "dt": sim.dt,
        "rayleigh_timestep": rayleigh_timestep(values["radius"], values["young"],
                                               values["poisson"], values["density"]),
        "units": summary_units("impact"),
    }


def run_impact(values):
    """Run the impact of ``values`` (OPTIONS, read); (summary, history columns)."""
    check_impact(values)
    sim, recorder = impact_scene(values)
    sim.run(MAX_CONTACT_DURATIONS * STEPS_PER_CONTACT, until=recorder.ended, check_every=1)
    if not recorder.ended(sim):
        raise RuntimeError(f"the contact did not end within {MAX_CONTACT_DURATIONS} times "
                           "its closed-form duration")
    return impact_summary(sim, recorder, values), recorder.columns()


def impact_figure(history, contact):
    """Normal and tangential force against time, and normal force against overlap."""
    plt = pyplot()
    figure, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    time_us = history["time"] * 1e6
    left.plot(time_us, history["normal_force"], label="normal")
    left.plot(time_us, history["tangential_force"], label="tangential")
    left.set_xlabel("time [µs]")
    left.set_ylabel("force on the sphere [N]")
    left.legend()
    touching = history["overlap"] > 0.0
    right.plot(history["overlap"][touching] * 1e6, history["normal_force"][touching])
    right.set_xlabel("overlap [µm]")
    right.set_ylabel("normal force [N]")
    figure.suptitle(f"impact, {contact} contact")
    return figure


def write_impact(values, out):
    """Run the impact of ``values`` into the folder ``out`` (summary.json, history.h5,
    impact.png); return the summary."""
    check_impact(values)            # before the folder is made
    with OutputFolder(os.path.abspath(out), "impact") as folder:
        paths = {name: folder.claim(name) for name in OUTPUTS}
        summary, history = run_impact(values)
        write_history(paths["history.h5"], history, {"impact": values})
        write_json(paths["summary.json"], summary)
        save_figure(impact_figure(history, values["contact"]), paths["impact.png"])
    return summary
