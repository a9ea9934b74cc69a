"""Bayesian calibration of a laboratory command's parameters to a measured curve.

    pendular calibrate --data CURVE.csv --test triaxial --particles 500 --confining 500
        --max-strain 0.12 --fit friction=10:50 [--fit ...] [--iterations K] [--samples M]
        [--scheduler ADDRESS] [--out DIR]

--test names the laboratory command; its own options (those of 'pendular TEST --help') fix
what is not fitted; each --fit NAME=LOW:HIGH names one of its numeric options, in that
option's units, with its prior range. CURVE.csv has a header naming its columns (compression
positive, SI units, strains as fractions): triaxial axial_strain,q[,volumetric_strain];
oedometer axial_stress,void_ratio; isotropic mean_stress,void_ratio; simple-shear
shear_strain,shear_stress; swcc suction,saturation; tension water_content,tensile_strength.
Each run is compared with the data at the data's control points. GrainLearning's iterative Bayesian
filter draws --samples runs per iteration (pip install 'pendular[calibrate]'); each
iteration's runs are one campaign in --jobs local processes or on the Dask cluster of
--scheduler, so a calibration started again reuses its finished runs.

Writes into --out: posterior.csv (every sample of every iteration: its parameters, weight and
error to the data), summary.json (each parameter's posterior mean, std, best value and unit,
the best run's folder and error), calibration.png (data, ensemble and best run),
posterior.png (each parameter's posterior, and pairs), errors.png (error per iteration) and
the runs under runs/ (docs/calibration.md).
"""

import argparse
import os
import sys

from pendular.cli import UsageError, add_executor_options, start_executor_run, positive_int
from pendular.io.outputs import OutputFolder

#: A worked example: the command line, and what it gives (--help and docs/commands.md).
EXAMPLE = ("pendular calibrate --data curve.csv --test triaxial --particles 500 --confining 500 "
           "--max-strain 0.12 --fit friction=5:40 --iterations 3 --samples 12 --jobs 2 "
           "--out runs/calibrate",
           "the contact friction angle whose drained triaxial reproduces curve.csv "
           "(axial_strain,q): 3 iterations of 12 runs, two at a time, each a campaign; its "
           "posterior mean and std in summary.json, every run's weight and error in "
           "posterior.csv, calibration.png, posterior.png, errors.png")

#: The laboratory commands calibrate can run.
TESTS = ("triaxial", "oedometer", "isotropic", "cyclic", "simple-shear", "tension", "swcc")


def _test_options():
    """{key: Option} of every option of the TESTS, by key (the first declaration of a key)."""
    from pendular.procedures.registry import options_of

    return {option.key: option for test in TESTS for option in options_of(test)
            if not option.positional}


def add_arguments(parser):
    parser.add_argument("--data", required=True, metavar="CURVE.csv",
                        help="the measured curve: a CSV with a header naming its columns")
    parser.add_argument("--test", required=True, choices=TESTS,
                        help="the laboratory command run for each sample")
    parser.add_argument("--fit", action="append", required=True, metavar="NAME=LOW:HIGH",
                        help="an option of the test to fit and its prior range, in its units "
                             "(e.g. friction=10:50); repeat for several")
    parser.add_argument("--iterations", type=positive_int("--iterations", 1), default=3,
                        help="iterations of the Bayesian filter")
    parser.add_argument("--samples", type=positive_int("--samples", 2), default=12,
                        help="runs per iteration")
    parser.add_argument("--out", default="runs/calibrate", help="output folder")
    add_executor_options(parser)
    tests = parser.add_argument_group(
        "the test's own options", "any option of 'pendular TEST --help' (parsed and checked "
                                  "by that command's declarations)")
    for option in _test_options().values():
        if option.kind is bool:
            tests.add_argument(option.flag, action="store_true", default=argparse.SUPPRESS,
                               help=argparse.SUPPRESS)
        else:
            tests.add_argument(option.flag, metavar=option.metavar or "VALUE",
                               default=argparse.SUPPRESS, help=argparse.SUPPRESS)


def _log(message):
    print(f"calibrate: {message}", file=sys.stderr, flush=True)


def run(args):
    from pendular.procedures.registry import options_of
    from pendular.studies.calibration import (Calibration, parse_fit, read_curve,
                                              write_posterior, write_summary, DATA_COLUMNS)
    from pendular.studies.calibration_figures import write_figures

    options = start_executor_run(args)
    if args.test not in DATA_COLUMNS:
        raise UsageError(f"--test {args.test}: calibrate compares curves of "
                         f"{', '.join(DATA_COLUMNS)} (no measured curve of {args.test} yet)")
    own = {option.key for option in options_of(args.test)}
    given = {key: value for key, value in vars(args).items() if key in _test_options()}
    foreign = sorted(key for key in given if key not in own)
    if foreign:
        raise UsageError(f"--{foreign[0].replace('_', '-')} is not an option of {args.test}; "
                         f"see 'pendular {args.test} --help'")
    curve = read_curve(args.data, args.test)
    fits = [parse_fit(text, args.test) for text in args.fit]
    calibration = Calibration(args.test, given, fits, curve, iterations=args.iterations,
                              samples=args.samples)
    try:
        import grainlearning  # noqa: F401
    except ImportError:
        raise UsageError("calibrate needs GrainLearning: pip install 'pendular[calibrate]' "
                         "(docs/calibration.md)") from None
    # keep: the finished runs of an interrupted calibration are reused
    with OutputFolder(args.out, ["calibrate", *sys.argv[1:]], keep=True) as folder:
        paths = {name: folder.claim(name) for name in
                 ("posterior.csv", "summary.json", "calibration.png", "posterior.png",
                  "errors.png")}
        summary = calibration.run(os.path.abspath(args.out), options, log=_log)
        write_posterior(paths["posterior.csv"], summary["rows"], fits)
        write_figures(calibration, summary, os.path.abspath(args.out), paths)
        data = write_summary(paths["summary.json"], summary, fits)
    for name, values in data["parameters"].items():
        note = "" if values["constrained"] else " (unconstrained: the data do not pin it)"
        print(f"  {name}  {values['mean']:.4g} ± {values['std']:.2g} {values['unit']}, best "
              f"{values['best']:.4g}{note}")
    print(f"calibrate: {data['runs']} runs, best error {data['best_error']:.3g} "
          f"({data['best_run']}); outputs in {args.out}")
    return 0
