"""Direct tension of wet sand at fixed water content (Kim 2001; thesis Table 4.5).

Without --void-ratio / --water-content it runs Kim's six cases (F-75 sand, R = 0.11 mm,
e = 0.72 and 0.58, three water contents each): a sample per void ratio (core void ratio reached
by tuning the growth friction), wetted with volume-controlled bridges to the gravimetric water
content, pulled apart by grips at its z walls. Writes tension.json, report.md, plots/ and
cases/<case>/history.h5 and vtk/ (pendular.procedures.tension).
"""

from __future__ import annotations

import argparse

from pendular.cli import (UsageError, add_run_options, add_size_options, positive_int,
    print_summary, set_threads, sizes_from)
from pendular.procedures.config import (SPECIFIC_GRAVITY_RANGE, TENSION_SAMPLE, WATER_DENSITY,
    TensionConfig, tension_sample)
from pendular.procedures.reference import KIM_RADIUS, SPECIFIC_GRAVITY
from pendular.procedures.tension import TensionTest, cases_of, report_lines
from pendular.utils.parameters import add_options, fields_from

#: The fields set by their options as they are. By hand: --void-ratio and --water-content
#: (comma lists, the water content in %, making ``cases``), the sample's options (the tension's
#: own defaults, TENSION_SAMPLE, and narrower ranges, check_tension_sample; the density as
#: --specific-gravity), --vtk-every (parsed by positive_int, as the laboratory commands').
OWN = ("roughness", "form_gap", "contact_angle", "surface_tension", "inertial_number",
       "max_strain", "residual", "grip_depth", "void_ratio_tolerance", "vtk_frames")

#: Columns of the cases' table printed at the end (--quiet: report.md's table).
SHOWN_COLUMNS = ("case", "void_ratio", "water_content", "saturation", "bridges",
                 "tensile_strength_pa", "kim_measured_pa", "packing_state_pa")


def _numbers(name, text):
    """Distinct floats of a comma-separated option; UsageError naming it (a value given twice
    would run the same cases twice into one folder)."""
    if text is None:
        return None
    try:
        values = [float(item) for item in text.split(",")]
    except ValueError:
        raise UsageError(f"{name} = {text!r} is not a comma-separated list of numbers") from None
    for k, value in enumerate(values):
        if value in values[:k]:
            raise UsageError(f"{name} = {text!r} repeats {value:g}: give each value once")
    return values


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--void-ratio", default=None,
                        help="void ratio(s) of the core [-], comma separated (default: Kim's 0.72, "
                             "0.58)")
    add_options(parser, TensionConfig, ("roughness",))
    parser.add_argument("--water-content", default=None,
                        help="gravimetric water content(s) [%%], comma separated (default: Kim's "
                             "for his void ratios, else 0.5,1,2)")
    parser.add_argument("--particles", type=int, default=TENSION_SAMPLE["particles"],
                        help="number of spheres [-]")
    add_options(parser, TensionConfig, ("form_gap",))
    add_size_options(parser, KIM_RADIUS)
    add_options(parser, TensionConfig, ("contact_angle", "surface_tension"))
    parser.add_argument("--specific-gravity", type=float, default=SPECIFIC_GRAVITY,
                        help="specific gravity Gs of the grains [-], in "
                             f"[{SPECIFIC_GRAVITY_RANGE[0]:g}, {SPECIFIC_GRAVITY_RANGE[1]:g}]: "
                             f"sets their density, Gs x {WATER_DENSITY:g} kg/m^3, which gives "
                             "their mass (time step, strain rate) and the water volume of a "
                             "water content by mass")
    parser.add_argument("--confining", type=float, default=TENSION_SAMPLE["confining"],
                        help="isotropic stress of preparation and wetting [Pa]")
    parser.add_argument("--friction", type=float, default=18.0,
                        help="contact friction during wetting and pull [deg]")
    parser.add_argument("--young", type=float, default=1e6, help="YADE young E [Pa], kn = E R")
    add_options(parser, TensionConfig, ("inertial_number", "max_strain", "residual",
                                        "grip_depth", "void_ratio_tolerance"))
    frames = parser.add_mutually_exclusive_group()
    add_options(frames, TensionConfig, ("vtk_frames",))
    frames.add_argument("--vtk-every", type=positive_int("--vtk-every"), default=None,
                        help="steps between ParaView frames of the pull, instead of "
                             "--vtk-frames (0: none)")
    parser.add_argument("--seed", type=int, default=0, help="random seed of the samples")
    parser.add_argument("--periodic", action="store_true",
                        help="a periodic cell instead of six walls: no grips, the cell pulled "
                             "along z at zero lateral stress; the void ratio is the whole cell's")
    parser.add_argument("--out", default="runs/direct_tension", help="output folder")
    add_run_options(parser, threads_default=1)


def config_from(args: argparse.Namespace) -> TensionConfig:
    """The TensionConfig of parsed options (ValueError naming the option)."""
    cases = cases_of(_numbers("--void-ratio", args.void_ratio),
                     _numbers("--water-content", args.water_content))
    if args.periodic and args.grip_depth is not None:
        raise UsageError(f"--grip-depth = {args.grip_depth:g} does not apply to --periodic: a "
                         "periodic cell has no walls, so no grips")
    sample = tension_sample(particles=args.particles, **sizes_from(args),
                            density=args.specific_gravity * WATER_DENSITY,
                            confining=args.confining, friction_deg=args.friction,
                            young=args.young, seed=args.seed, periodic=args.periodic)
    return TensionConfig(sample=sample, cases=cases, vtk_every=args.vtk_every,
                         **fields_from(args, TensionConfig, OWN))


def run(args: argparse.Namespace) -> int:
    set_threads(args.threads)
    config = config_from(args)
    output = TensionTest(config).run(args.out, progress=not args.quiet, arguments=vars(args))
    if args.quiet:
        print("\n".join(report_lines(output["cases"], config)))
    else:
        print_summary(output, ("cases",), columns=SHOWN_COLUMNS)
    print(f"done in {output['wall_time_s']:.0f} s; outputs in {args.out}")
    return 0
