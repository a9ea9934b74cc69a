"""Strength envelope: drained triaxial compressions at each of --confining (at least two), run as
one campaign, and the Mohr–Coulomb line fitted to their peaks in net and in effective stresses
(Eq. 3.43), with the standard errors of phi and c (pendular.studies.envelope):

    pendular envelope --confining 250,500,1000,2000 --particles 300 --suction 30000

Every other option is the triaxial's (``pendular triaxial --help``), the same for each test.
Writes into --out: summary.json (phi_deg and cohesion in net stresses, phi_effective_deg and
cohesion_effective, each with its standard error ``*_error``, and ``tests``, one per confining
stress with its peak and run folder), mohr_circles.png (Mohr circles at the peaks and the
envelope),
peaks_pq.png (p-q and p'-q' peaks and the failure line), campaign.csv and runs/confining<S>/
(each test's outputs). The tests run in --jobs local processes with --threads Numba threads
each, or on an existing Dask cluster with --scheduler; started again, finished tests with equal
configurations are reused.
"""

from pendular.cli import (add_declared_options, add_executor_options, declared_values,
    print_summary, start_executor_run)
from pendular.studies.envelope import envelope, envelope_options, envelope_runs

#: A worked example: (command line, what it gives).
EXAMPLE = ("pendular envelope --confining 250,500,1000,2000 --particles 300 --suction 30000 "
           "--out runs/envelope --jobs 2",
           "four wet drained triaxial compressions, two at a time, and the Mohr–Coulomb line "
           "fitted to their peaks: phi and c with their standard errors, net and effective, in "
           "summary.json; mohr_circles.png, peaks_pq.png, campaign.csv")

#: Summary keys printed at the end.
SHOWN = ("phi_deg", "phi_error_deg", "cohesion", "cohesion_error", "phi_effective_deg",
         "phi_effective_error_deg", "cohesion_effective", "cohesion_effective_error",
         "phi_through_origin_deg", "phi_effective_through_origin_deg")

#: Columns of the tests' table printed at the end.
COLUMNS = ("confining", "peak_q", "p_at_peak", "peak_q_effective", "p_effective_at_peak",
           "axial_strain_at_peak", "peak_reached", "run")


def add_arguments(parser):
    add_declared_options(parser, envelope_options())
    parser.add_argument("--out", default="runs/envelope", help="output folder")
    parser.add_argument("--force", action="store_true",
                        help="run settings refused as not quasi-static or too long (experts)")
    add_executor_options(parser)


def run(args):
    run_options = start_executor_run(args)       # before the output folder is made
    options = envelope_options()
    declared_values(options, args)       # every option read and checked before anything runs
    runs = envelope_runs({option.key: getattr(args, option.key) for option in options},
                         force=args.force)
    summary, reused = envelope(runs, args.out, run_options)
    print_summary(summary, SHOWN + ("tests",), args.quiet, columns=COLUMNS)
    if not args.quiet:                   # --quiet: the JSON alone, for scripts
        print(f"envelope: {len(runs)} triaxial tests ({reused} reused); outputs in {args.out} "
              "(summary.json, mohr_circles.png, peaks_pq.png, campaign.csv, runs/)")
    return 0
