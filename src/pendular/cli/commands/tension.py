"""Direct tension of wet sand at fixed water content (Kim 2001; thesis Table 4.5).

Without --void-ratio / --water-content it runs Kim's six cases (F-75 sand, R = 0.11 mm,
e = 0.72 and 0.58, three water contents each): a sample per void ratio (core void ratio reached
by tuning the growth friction), wetted with volume-controlled bridges to the gravimetric water
content, pulled apart by grips at its z walls. Writes tension.json, report.md, plots/ and
cases/<case>/history.h5 and vtk/ (pendular.procedures.tension), with --checkpoint-every N
checkpoint.h5; --resume DIR continues an interrupted run bit for bit. --device gpu runs the
preparations, wettings and pulls on the GPU, or refuses in one line, before anything is made,
what the GPU does not run yet (docs/gpu.md).
"""

from __future__ import annotations

import argparse
import sys

from pendular.cli import (INTERRUPTED, add_command_options, add_device_option,
    add_run_options, command_config, declared_values, print_summary, set_threads)
from pendular.cli.commands.triaxial import add_resume_options, check_resume_options, run_options
from pendular.procedures.tension import TensionConfig
from pendular.procedures.options import CHECKPOINT_EVERY
from pendular.procedures.registry import COMMANDS
from pendular.dem.simulation import check_device
from pendular.procedures.tension import TensionTest
from pendular.procedures.laboratory import Interrupted

#: Options that watch a run rather than make it: not recorded in tension.json's arguments.
WATCHING = ("checkpoint_every", "resume", "stop_after")
#: The command's declaration (pendular.procedures.registry).
COMMAND = COMMANDS["tension"]
EXAMPLE = COMMAND.example



def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_command_options(parser, "tension")
    parser.add_argument("--out", default=COMMAND.out, help="output folder")
    add_run_options(parser, threads_default=1)
    add_device_option(parser, "the preparations, the wettings and the pulls")
    add_resume_options(parser)


def config_from(args: argparse.Namespace) -> TensionConfig:
    """The TensionConfig of parsed options (ValueError naming the option)."""
    return command_config("tension", args)


def run(args: argparse.Namespace) -> int:
    set_threads(args.threads)
    try:
        if args.resume is not None:
            check_resume_options(args, add_arguments)
            output = TensionTest.resume(args.resume, run_options(args))
            args.out = args.resume
        else:
            config = config_from(args)
            check_device(args.device)                   # before anything is made
            every = declared_values((CHECKPOINT_EVERY,), args)["checkpoint_every"]
            arguments = {k: v for k, v in vars(args).items() if k not in WATCHING}
            output = TensionTest(config).run(args.out, run_options(
                args, checkpoint_every=every, arguments=arguments))
    except Interrupted as stop:
        print(f"{stop}", file=sys.stderr)
        return INTERRUPTED
    print_summary(output, COMMAND.shown, args.quiet, columns=COMMAND.columns)
    # with --quiet, stdout holds the JSON alone
    print(f"done in {output['wall_time_s']:.0f} s; outputs in {args.out}",
          file=sys.stderr if args.quiet else sys.stdout)
    return 0
