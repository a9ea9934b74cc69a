"""One collision of a sphere with an identical sphere or a rigid wall, to check a material's
contact law: its peak force and overlap, contact duration, restitution and rebound
(pendular.procedures.impact, docs/impact.md).

With --target sphere two identical spheres approach each other, each at --velocity; with
--target wall one sphere hits a flat wall at --velocity, rigid by default: the limit of an
infinitely stiff wall (Hertz: E* = E / (1 - nu^2), G* = G / (2 - nu), R* = R; linear:
kn = E R); --wall-young, --wall-poisson, --wall-friction, --wall-restitution,
--wall-rolling-friction and --wall-twisting-friction give the wall a material of its own,
mixed with the sphere's (docs/physics.md 'Materials and mixing rules'). --angle tilts the
velocity from the normal, --spin turns the sphere about the axis normal to the plane of
incidence (a target sphere the other way); --rolling-friction and --twisting-friction resist
the relative rotation of the spheres, or of the sphere on the wall (R* = R). The engine's
own simulation runs it with the chosen --contact law, at 2,000 steps per closed-form contact
duration. Writes DIR/summary.json, DIR/history.h5 (time,
overlap, normal_force, tangential_force, angular_velocity) and DIR/impact.png (force against
time and against overlap).
"""

from __future__ import annotations

from pendular.cli import add_declared_options, declared_values, print_summary
from pendular.procedures.impact import OPTIONS, write_impact

#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular impact --target wall --contact hertz-mindlin --radius 0.01 --young 2e11 "
           "--poisson 0.3 --density 7800 --velocity 1 --restitution 0.5 --out runs/steel",
           "a steel sphere dropped on a rigid wall at 1 m/s with Hertz–Mindlin contacts: "
           "Hertz's peak force, overlap and contact time, a rebound at half the impact speed, "
           "in summary.json; force against time and overlap in impact.png")

#: Summary keys printed at the end.
SHOWN = ("effective_modulus", "contact_restitution", "max_normal_force", "max_overlap",
         "contact_duration", "normal_restitution", "tangential_restitution",
         "rebound_angular_velocity", "rebound_angle_deg", "dt", "rayleigh_timestep")


def add_arguments(parser):
    add_declared_options(parser, OPTIONS)
    parser.add_argument("--out", default="runs/impact", metavar="DIR", help="output folder")
    parser.add_argument("--quiet", action="store_true",
                        help="the summary as JSON, values unrounded (without --quiet: one line "
                             "per result, to 4 significant figures, with units)")


def run(args):
    summary = write_impact(declared_values(OPTIONS, args), args.out)
    print_summary(summary, SHOWN, args.quiet)
    if not args.quiet:
        print(f"outputs in {args.out} (summary.json, history.h5, impact.png)")
    return 0
