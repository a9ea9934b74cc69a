# YADE driver: drained triaxial shear of a sphere packing, timed (a YADE script, not pendular).
#
#   yade -n -x -j THREADS triaxial.py CONFIG.json
#
# (YADE 2023.02a, Debian package ``yade``: -n no GUI, -x exit when the script ends, -j OpenMP
# threads; arguments after the script land in sys.argv[1:]). Exit status 1 on any error.
# Shipped with pendular as a file, run by YADE's own Python, never imported:
# ``pendular.interop.yade.runner.run_yade_triaxial`` finds it (pendular.interop.yade.runner.DRIVER) and runs it.
# YADE is only a cross-check: pendular never imports it.
#
# CONFIG.json (SI units, stresses compression positive, angles in degrees):
#   spheres       sphere file, yade.export.textExt 'x_y_z_r' layout (dem.yade_io.write_spheres)
#   box_lo/box_hi inner faces of the six walls [m] (default: the '# box_lo ... box_hi ...' line)
#   young         FrictMat.young E [Pa]: kn = 2 E R1 R2 / (R1 + R2), E R against a wall
#   poisson       FrictMat.poisson, read by Ip2_FrictMat_FrictMat_FrictPhys as ks / kn (0.3);
#                 with contact "hertz-mindlin" the grains' Poisson ratio
#   friction_deg  sphere friction angle (walls: 0, frictionless)
#   density       [kg/m^3];  damping: NewtonIntegrator.damping (Cundall local damping)
#   dt            fixed time step [s]
#   confining     lateral stress on the x and y walls [Pa]
#   strain_rate   axial (z) compression rate [1/s], > 0 compresses
#   steps, warmup_steps, record_every, output, history (optional, plot.saveDataTxt file)
# Optional, with defaults: skin (Verlet skin [m], 0.3 R_min; YADE verletDist = skin / 2: YADE's
#   faster of 0.1 and 0.3 R, docs/performance.md; pendular's own is 0.1 R),
#   stress_damping 0.25 (TriaxialStressController.stressDamping, YADE's default),
#   strain_damping 0.0 (TriaxialStressController.strainDamping; YADE's default 0.99 ramps the
#   axial rate up geometrically, 0 imposes it at once as pendular does),
#   contact "linear" (Ip2_FrictMat_FrictMat_FrictPhys, Law2_ScGeom_FrictPhys_CundallStrack) or
#   "hertz-mindlin" (Ip2_FrictMat_FrictMat_MindlinPhys, Law2_ScGeom_MindlinPhys_Mindlin: Hertz
#   normal force 4/3 E* sqrt(R*) delta^1.5, shear stiffness 4 G sqrt(R* delta) / (2 - nu),
#   undamped; dry, six walls only),
#   wall_poisson (the walls' FrictMat.poisson; default poisson: with Hertz-Mindlin the value
#   that makes YADE's wall contact pendular's rigid plane,
#   pendular.studies.crosscheck.yade_wall_poisson),
#   max_vel 1.0 m/s (TriaxialStressController.max_vel, YADE's default; YADE scales it per axis
#   by 3 L_a / (L_x + L_y + L_z)), stiffness_update_interval 10
#   (TriaxialStressController.stiffnessUpdateInterval, YADE's default; the wall stiffness is
#   also refreshed at each of the first 100 iterations).
#   periodic (optional, default false): a periodic cell [0, L] (O.periodic, O.cell.setBox to
#     box_hi; box_lo must be 0) instead of six walls, driven by PeriTriaxController (below);
#     stress_damping is then its growDamping (below 0 amplifies the controller's stiffness
#     term: pendular.studies.crosscheck.cell_grow_damping), max_vel caps the lateral strain rates at
#     2 max_vel / L_a (pendular's per-step cap on both faces of the cell), glob_update its
#     globUpdate (YADE's default 5: steps between evaluations of the cell's stress and
#     stiffness, predicted in between).
#   capillary (optional, wet test): {"suction": s [Pa], "files": folder holding the capillary
#     files M(r=1) ... M(r=10) (pendular.interop.yade.capillary_files), "surface_tension": 0.073 N/m,
#     "persist": false, "detection_factor": 1.0}. Adds YADE's capillary law
#     (Law2_ScGeom_CapillaryPhys_Capillarity, Scholtes et al. 2009) after the InteractionLoop with
#     Ip2_FrictMat_FrictMat_CapillaryPhys; menisci form at contact (createDistantMeniscii=False)
#     and, by default, vanish with the interaction when contact is lost (CundallStrack erases
#     it). persist: bridges live to their rupture distance (neverErase=True, interactions
#     detected within detection_factor times the radii: aabbEnlargeFactor and
#     interactionDetectionFactor). The law reads its files from the working directory, so
#     the driver changes into ``files``.
#
# Engine list, one step (YADE order, as pendular's shear phase):
#   ForceResetter -> InsertionSortCollider -> InteractionLoop(Ig2 sphere-sphere & box-sphere ScGeom,
#   Ip2_FrictMat_FrictMat_FrictPhys, Law2_ScGeom_FrictPhys_CundallStrack, or the Mindlin pair)
#   [-> Law2_ScGeom_CapillaryPhys_Capillarity (wet test)]
#   -> TriaxialStressController (x, y servoed at -confining, z at strain rate -strain_rate)
#   -> NewtonIntegrator(damping) [-> PyRunner recording the history]
# Periodic: no walls (no box bounds nor box-sphere geometry), and PeriTriaxController(dynCell=
#   False, stressMask=0b011, goal=(-confining, -confining, z strain goal)) instead of the
#   TriaxialStressController. x, y: the cell's velocity gradient is set each step from the
#   stress error (goal - stress) * area / mean contact stiffness / dt, then
#   (1 - growDamping) * that + 0.8 * previous, clipped to maxStrainRate. z is a strain goal
#   (log(L / L0)) beyond the final strain, so its rate stays at maxStrainRate = strain_rate (the
#   true strain rate, on the current length) for all ``steps``. The cell's stress is
#   utils.getStress() (Love-Weber over the cell, tension positive, negated here).
#
# History (plot.saveDataTxt columns, a row every record_every iterations, from iteration 0 (its
# wall forces are those of the initial packing) if record_initial (default false), and the final
# state): i, t, eps_axial (1 - L_z / L_z0), sx, sy, sz [Pa], lx, ly, lz (inner box or cell
# lengths [m]), porosity, unbalanced; the wet test adds saturation and menisci (as in the output
# JSON).
#
# Output JSON: particles, steps, wall_time_s, particle_steps_per_s, threads, yade_version,
# sigma_wall [sx, sy, sz] Pa (compression positive, force on each wall pair / current face
# area; periodic: the cell's stress), porosity, coordination (2 Nc / N over sphere-sphere
# contacts), unbalanced_force (utils.unbalancedForce), and the settings used; wet test: menisci
# (count), water_volume [m^3] and saturation (water / (box volume - solid volume)).

import json
import math
import os
import sys
import time

from yade import O, plot, utils, ymport
from yade import (Bo1_Box_Aabb, Bo1_Sphere_Aabb, ForceResetter, FrictMat, Ig2_Box_Sphere_ScGeom,
                  Ig2_Sphere_Sphere_ScGeom, InsertionSortCollider, InteractionLoop,
                  Ip2_FrictMat_FrictMat_CapillaryPhys, Ip2_FrictMat_FrictMat_FrictPhys,
                  Ip2_FrictMat_FrictMat_MindlinPhys, Law2_ScGeom_CapillaryPhys_Capillarity,
                  Law2_ScGeom_FrictPhys_CundallStrack, Law2_ScGeom_MindlinPhys_Mindlin,
                  NewtonIntegrator, PeriTriaxController, PyRunner, TriaxialStressController)
import yade.config

REQUIRED = ("spheres", "young", "poisson", "friction_deg", "density", "damping", "dt",
            "confining", "strain_rate", "steps", "warmup_steps", "record_every", "output")


def fail(message):
    raise SystemExit("triaxial.py (YADE driver): " + message)


def load_config(path):
    with open(path) as source:
        config = json.load(source)
    missing = [key for key in REQUIRED if key not in config]
    if missing:
        fail(f"{path}: missing keys {missing}")
    for key in ("young", "density", "dt"):
        if not config[key] > 0:
            fail(f"{key} = {config[key]!r} must be > 0")
    for key in ("steps", "warmup_steps", "record_every"):
        if int(config[key]) != config[key] or config[key] < (1 if key != "warmup_steps" else 0):
            fail(f"{key} = {config[key]!r} must be a positive integer")
    if not 0 <= config["damping"] < 1:
        fail(f"damping = {config['damping']!r} must lie in [0, 1)")
    if config["confining"] < 0:
        fail(f"confining = {config['confining']!r} Pa must be >= 0")
    contact = config.setdefault("contact", "linear")
    if contact not in ("linear", "hertz-mindlin"):
        fail(f"contact = {contact!r} must be 'linear' or 'hertz-mindlin'")
    if contact == "hertz-mindlin" and (config.get("capillary") or config.get("periodic")):
        fail("contact 'hertz-mindlin' is dry, in six walls (no capillary, not periodic)")
    return config


def capillary_settings(wet):
    """The 'capillary' entry of the config, checked, with defaults."""
    settings = {"surface_tension": 0.073, "persist": False, "detection_factor": 1.0, **wet}
    for key in ("suction", "files"):
        if key not in settings:
            fail(f"capillary: missing key {key!r}")
    if not settings["suction"] >= 0:
        fail(f"capillary suction = {settings['suction']!r} Pa must be >= 0")
    if not settings["surface_tension"] > 0:
        fail(f"capillary surface_tension = {settings['surface_tension']!r} N/m must be > 0")
    if not settings["detection_factor"] >= 1:
        fail(f"capillary detection_factor = {settings['detection_factor']!r} must be >= 1")
    missing = [name for name in ("M(r=1)", "M(r=10)")
               if not os.path.exists(os.path.join(settings["files"], name))]
    if missing:  # YADE would silently run with zero capillary forces
        fail(f"capillary files {missing} not found in {settings['files']!r}")
    settings["files"] = os.path.abspath(settings["files"])
    settings["suction"] = float(settings["suction"])
    settings["persist"] = bool(settings["persist"])
    return settings


def box_from_file(path):
    """The '# box_lo x y z box_hi x y z' line written by dem.yade_io.write_spheres, or None."""
    with open(path) as source:
        for line in source:
            words = line.replace("#", " ").split()
            if line.startswith("#") and len(words) == 8 and words[0] == "box_lo":
                return [float(w) for w in words[1:4]], [float(w) for w in words[5:8]]
    return None


def build_scene(config):
    box = (config.get("box_lo"), config.get("box_hi"))
    if box[0] is None or box[1] is None:
        box = box_from_file(config["spheres"])
        if box is None:
            fail("no box_lo/box_hi in the config nor in the sphere file")
    lo, hi = [list(map(float, corner)) for corner in box]
    if not all(h > l for l, h in zip(lo, hi)):
        fail(f"box_hi {hi} must exceed box_lo {lo} on every axis")

    E = float(config["young"])
    sphere_mat = O.materials.append(FrictMat(
        young=E, poisson=float(config["poisson"]), density=float(config["density"]),
        frictionAngle=math.radians(float(config["friction_deg"])), label="spheres"))
    # Same E as the spheres: Ig2_Box_Sphere_ScGeom gives the wall the sphere's radius, so
    # kn_wall = E R (docs/physics.md 'The contact law'); friction angle 0 makes the walls
    # frictionless (Ip2 takes the min).
    wall_mat = O.materials.append(FrictMat(
        young=E, poisson=float(config.get("wall_poisson", config["poisson"])),
        density=float(config["density"]),
        frictionAngle=0.0, label="walls"))

    if config.get("periodic"):
        if any(l != 0.0 for l in lo):
            fail(f"periodic: box_lo {lo} must be 0 (the cell is [0, L])")
        O.periodic = True
        O.cell.setBox(*hi)
        thickness, wall_ids = 0.0, []
    else:
        # aabbWalls puts the inner faces exactly on lo / hi and returns minX, maxX, minY, maxY,
        # minZ, maxZ; appended first they get ids 0..5, TriaxialStressController's default ids.
        thickness = 0.1 * min(h - l for l, h in zip(lo, hi))
        walls = utils.aabbWalls([lo, hi], thickness=thickness, oversizeFactor=1.5,
                                material=wall_mat)
        wall_ids = O.bodies.append(walls)
    spheres = ymport.textExt(config["spheres"], format="x_y_z_r", material=sphere_mat)
    if not spheres:
        fail(f"{config['spheres']}: no sphere read")
    sphere_ids = O.bodies.append(spheres)
    return lo, hi, thickness, wall_ids, sphere_ids


def cell_controller(config, size, confining, rate):
    """PeriTriaxController of the periodic shear: x, y at the confining stress (goals in YADE's
    signs, tension positive), z compressed at the true strain rate ``rate`` [1/s] for the whole
    run (its log-strain goal twice the final one); lateral strain rates capped at
    2 max_vel / L_a [1/s] (``size``: the cell's lengths [m])."""
    dt = float(config["dt"])
    if not 0.0 < rate * dt < 1.0:
        fail(f"strain_rate * dt = {rate * dt!r} must lie in (0, 1) for a periodic cell")
    steps = int(config["warmup_steps"]) + int(config["steps"])
    max_vel = float(config.get("max_vel", 1.0))
    return PeriTriaxController(
        label="triax", dynCell=False, stressMask=0b011,
        goal=(-confining, -confining, 2.0 * steps * math.log1p(-rate * dt)),
        maxStrainRate=(2.0 * max_vel / size[0], 2.0 * max_vel / size[1], rate),
        growDamping=float(config.get("stress_damping", 0.25)),
        globUpdate=int(config.get("glob_update", 5)))


def controller_settings(triax, periodic):
    """The controller's settings, for the output JSON."""
    if periodic:
        return {"controller": "PeriTriaxController", "dyn_cell": triax.dynCell,
                "stress_mask": triax.stressMask, "goal": list(triax.goal),
                "max_strain_rate": list(triax.maxStrainRate),
                "grow_damping": triax.growDamping, "glob_update": triax.globUpdate}
    return {"controller": "TriaxialStressController", "stress_damping": triax.stressDamping,
            "strain_damping": triax.strainDamping, "max_vel": triax.max_vel,
            "stiffness_update_interval": triax.stiffnessUpdateInterval}


def main(config_path):
    config = load_config(config_path)
    for key in ("spheres", "output", "history"):  # the wet test changes the working directory
        if config.get(key):
            config[key] = os.path.abspath(config[key])
    lo, hi, thickness, wall_ids, sphere_ids = build_scene(config)
    radii = [O.bodies[i].shape.radius for i in sphere_ids]
    skin = float(config.get("skin", 0.3 * min(radii)))
    confining = float(config["confining"])
    rate = float(config["strain_rate"])

    periodic = bool(config.get("periodic"))
    if periodic:
        triax = cell_controller(config, hi, confining, rate)
    else:
        triax = TriaxialStressController(
            label="triax", internalCompaction=False, thickness=thickness,
            wall_left_id=wall_ids[0], wall_right_id=wall_ids[1], wall_bottom_id=wall_ids[2],
            wall_top_id=wall_ids[3], wall_back_id=wall_ids[4], wall_front_id=wall_ids[5],
            # goal1/2/3 act on x/y/z; bit i of stressMask makes goal(i+1) a stress, else a
            # strain rate; YADE's signs are tension positive, so compression is negative.
            stressMask=0b011, goal1=-confining, goal2=-confining, goal3=-rate,
            stressDamping=float(config.get("stress_damping", 0.25)),
            strainDamping=float(config.get("strain_damping", 0.0)),
            max_vel=float(config.get("max_vel", 1.0)),
            stiffnessUpdateInterval=int(config.get("stiffness_update_interval", 10)))
    # a periodic cell has no walls: no box bounds, no box-sphere geometry
    box_bound = [] if periodic else [Bo1_Box_Aabb()]
    box_geometry = [] if periodic else [Ig2_Box_Sphere_ScGeom()]
    wet = config.get("capillary")
    if wet:
        wet = capillary_settings(wet)
        os.chdir(wet["files"])  # Law2_ScGeom_CapillaryPhys_Capillarity reads M(r=...) from here
        factor = wet["detection_factor"]
        O.engines = [
            ForceResetter(),
            InsertionSortCollider([Bo1_Sphere_Aabb(aabbEnlargeFactor=factor)] + box_bound,
                                  verletDist=0.5 * skin),
            InteractionLoop([Ig2_Sphere_Sphere_ScGeom(interactionDetectionFactor=factor)]
                            + box_geometry,
                            [Ip2_FrictMat_FrictMat_CapillaryPhys()],
                            [Law2_ScGeom_FrictPhys_CundallStrack(neverErase=wet["persist"])]),
            Law2_ScGeom_CapillaryPhys_Capillarity(
                capillaryPressure=wet["suction"], surfaceTension=wet["surface_tension"],
                createDistantMeniscii=False, label="capillary"),
            triax,
            NewtonIntegrator(damping=float(config["damping"])),
        ]
    else:
        if config["contact"] == "hertz-mindlin":   # undamped: betan = betas = 0, en, es unset
            physics, law = Ip2_FrictMat_FrictMat_MindlinPhys(), Law2_ScGeom_MindlinPhys_Mindlin()
        else:
            physics, law = Ip2_FrictMat_FrictMat_FrictPhys(), Law2_ScGeom_FrictPhys_CundallStrack()
        O.engines = [
            ForceResetter(),
            InsertionSortCollider([Bo1_Sphere_Aabb()] + box_bound, verletDist=0.5 * skin),
            InteractionLoop([Ig2_Sphere_Sphere_ScGeom()] + box_geometry, [physics], [law]),
            triax,
            NewtonIntegrator(damping=float(config["damping"])),
        ]
    O.dt = float(config["dt"])
    depth0 = hi[2] - lo[2]
    sphere_set = set(sphere_ids)

    def wall_state():
        """Inner box (or cell) lengths [m] and wall (or cell) stresses [Pa, compression
        positive]."""
        if periodic:
            stress = utils.getStress()  # Love-Weber over the cell volume, tension positive
            return list(O.cell.size), [-stress[a, a] for a in range(3)]
        p = [O.bodies[i].state.pos for i in wall_ids]
        lengths = [p[2 * a + 1][a] - p[2 * a][a] - thickness for a in range(3)]
        areas = [lengths[1] * lengths[2], lengths[0] * lengths[2], lengths[0] * lengths[1]]
        sigma = [0.5 * (O.forces.f(wall_ids[2 * a + 1])[a] - O.forces.f(wall_ids[2 * a])[a])
                 / areas[a] for a in range(3)]
        return lengths, sigma

    solid = sum(4.0 / 3.0 * math.pi * r ** 3 for r in radii)

    def porosity(lengths):
        """Porosity of the box (the controller's) or of the cell."""
        if periodic:
            return 1.0 - solid / (lengths[0] * lengths[1] * lengths[2])
        return triax.porosity

    def wet_state(lengths):
        """Menisci between spheres, their water volume [m^3] and the degree of saturation."""
        volumes = [i.phys.vMeniscus for i in O.interactions
                   if i.isReal and i.id1 in sphere_set and i.id2 in sphere_set and i.phys.meniscus]
        water = sum(volumes)
        return {"menisci": len(volumes), "water_volume": water,
                "saturation": water / (lengths[0] * lengths[1] * lengths[2] - solid)}

    def record():
        lengths, sigma = wall_state()
        row = {"i": O.iter, "t": O.time, "eps_axial": 1.0 - lengths[2] / depth0,
               "sx": sigma[0], "sy": sigma[1], "sz": sigma[2], "lx": lengths[0],
               "ly": lengths[1], "lz": lengths[2], "porosity": porosity(lengths),
               "unbalanced": utils.unbalancedForce()}
        if wet:
            state = wet_state(lengths)
            row.update(saturation=state["saturation"], menisci=state["menisci"])
        plot.addData(**row)

    history = config.get("history")
    if history:
        globals()["record_history"] = record
        O.engines = O.engines + [PyRunner(iterPeriod=int(config["record_every"]),
                                          initRun=bool(config.get("record_initial", False)),
                                          command="record_history()")]

    if int(config["warmup_steps"]) > 0:  # O.run(0) would run without end
        O.run(int(config["warmup_steps"]), True)
    steps = int(config["steps"])
    start = time.perf_counter()
    O.run(steps, True)
    wall_time = time.perf_counter() - start

    lengths, sigma = wall_state()
    sphere_contacts = sum(1 for i in O.interactions
                          if i.isReal and i.id1 in sphere_set and i.id2 in sphere_set)
    n = len(sphere_ids)
    result = {
        "particles": n,
        "steps": steps,
        "wall_time_s": wall_time,
        "particle_steps_per_s": n * steps / wall_time,
        "threads": O.numThreads,
        "yade_version": yade.config.version,
        "sigma_wall": sigma,
        "porosity": porosity(lengths),
        "coordination": 2.0 * sphere_contacts / n,
        "unbalanced_force": utils.unbalancedForce(),
        "axial_strain": 1.0 - lengths[2] / depth0,
        "box_lengths": lengths,
        "iterations": O.iter,
        "time": O.time,
        "dt": O.dt,
        "verlet_dist": 0.5 * skin,
        "contact": config["contact"],
        **controller_settings(triax, periodic),
        "engines": [type(e).__name__ for e in O.engines],
    }
    if wet:
        result.update(wet_state(lengths), capillary=dict(wet))
    if history:
        record()  # the final state (PyRunner ran last at the previous multiple of record_every)
        columns = ("i", "t", "eps_axial", "sx", "sy", "sz", "lx", "ly", "lz", "porosity",
                   "unbalanced") + (("saturation", "menisci") if wet else ())
        plot.saveDataTxt(history, vars=columns)
    output = config["output"]
    temporary = output + ".tmp"
    with open(temporary, "w", encoding="utf-8") as out:
        json.dump(result, out, indent=1)
    os.replace(temporary, output)


if len(sys.argv) != 2:
    fail("usage: yade -n -x [-j THREADS] triaxial.py CONFIG.json")
main(sys.argv[1])
