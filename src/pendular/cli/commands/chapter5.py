"""Thesis Chapter 5 campaign (Table 5.3): drained triaxial tests at every suction and confining
stress, from one sample per confining stress; campaign.json, report.md (every Table 5.3 cell
and Sr beside the thesis's, Mohr–Coulomb envelopes in net and effective stress) and plots/
(Figs. 5.3-5.8). The default grid is the table pendular/campaigns/chapter5.toml; options
override it. Finished runs with equal configurations are reused. Each run has --threads Numba
threads (one by default) and its own log.txt with its progress."""

from pendular.studies.campaign import check_jobs
from pendular.studies.chapter5 import Chapter5Grid, chapter5_campaign
from pendular.cli import UsageError, add_executor_options, set_threads


def _values(name):
    def parse(text):
        try:
            values = [float(v) for v in text.split(",") if v.strip()]
        except ValueError:
            raise UsageError(f"--{name} {text!r}: comma-separated numbers expected") from None
        return values
    return parse


def add_arguments(parser):
    parser.add_argument("--particles", type=int, default=None,
                        help="number of spheres (table: 10000)")
    parser.add_argument("--suctions", "--suction", dest="suctions", default=None,
                        help="matric suctions [Pa], comma-separated, 0: dry (table: "
                             "0,15000,30000,300000)")
    parser.add_argument("--confining", default=None,
                        help="lateral stresses [Pa], comma-separated (table: 250,500,750,1000)")
    parser.add_argument("--out", default="runs/chapter5", help="output folder")
    parser.add_argument("--seed", type=int, default=None, help="random seed of every sample "
                                                               "(table: 0)")
    parser.add_argument("--max-strain", type=float, default=None,
                        help="final axial strain [-] (table: 0.25)")
    parser.add_argument("--inertial-number", type=float, default=None,
                        help="target inertial number setting the strain rate [-] (table: 3e-4)")
    parser.add_argument("--prep-friction", type=float, default=None,
                        help="contact friction during the radius growth [deg] (table: 0.5; "
                             "higher gives looser samples)")
    add_executor_options(parser)


def run(args):
    if args.out == "":
        raise UsageError("--out '': an output folder is required")
    set_threads(args.threads)
    check_jobs(args.jobs)                # before the output folder is made
    grid = Chapter5Grid.from_table(
        suctions=None if args.suctions is None else _values("suctions")(args.suctions),
        confining=None if args.confining is None else _values("confining")(args.confining),
        particles=args.particles, seed=args.seed, max_strain=args.max_strain,
        inertial_number=args.inertial_number, prep_friction=args.prep_friction)
    campaign, reused = chapter5_campaign(grid, args.out, jobs=args.jobs,
                                         scheduler=args.scheduler, threads=args.threads,
                                         quiet=args.quiet)
    runs = len(campaign["runs"])
    if reused:
        print(f"chapter5: {reused} finished runs in {args.out} reused, {runs - reused} run")
    print(f"chapter5: {runs} runs; outputs in {args.out} (campaign.json, report.md, plots/)")
    return 0
