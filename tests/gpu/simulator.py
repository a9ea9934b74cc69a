"""What the GPU tests share: scripts and commands run under Numba's CUDA simulator in a
process of their own (``simulated``, ``simulated_commands``, ``histories_on_both``), the
samples the command tests load (``prepared_sample``), the relative difference they judge
(``relative``) and a count of the state's copies back from the device (``counted_copies``).
The simulator runs there with the serial block runner of serial_simulator/sitecustomize.py
(the same results, sooner). Run as a script, this module runs the commands it is given
(``simulated_commands``).

Nothing here imports pendular.gpu when the module loads: the tests are collected where the
gpu extra (numba-cuda) is not installed, and skip there.
"""

import contextlib
import json
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
#: The repository (the scripts run from it).
ROOT = os.path.dirname(os.path.dirname(HERE))
#: The folder whose sitecustomize.py makes the simulator run a block's threads serially.
SERIAL_SIMULATOR = os.path.join(HERE, "serial_simulator")
#: Longest wait for one check of a script run under the simulator [s]: a bound on a hung
#: process, far beyond a check's run on a loaded machine.
CHECK_TIMEOUT = 900
#: The tests' folder (its support package).
TESTS = os.path.dirname(HERE)


def environment():
    """This process's environment with Numba's CUDA simulator on and its serial runner loaded
    (SERIAL_SIMULATOR first on PYTHONPATH, then TESTS)."""
    path = os.pathsep.join(filter(None, [SERIAL_SIMULATOR, TESTS, os.environ.get("PYTHONPATH")]))
    return dict(os.environ, NUMBA_ENABLE_CUDASIM="1", PYTHONPATH=path)


def _run(argv, timeout):
    """stdout of ``argv`` run under the simulator from ROOT; the test fails with its error when
    it fails."""
    done = subprocess.run(argv, capture_output=True, text=True, env=environment(), cwd=ROOT,
                          timeout=timeout)
    assert done.returncode == 0, done.stderr[-3000:]
    return done.stdout


#: The argument of a script of checks after which come, in JSON, the commands it runs first.
COMMANDS = "--commands"


def simulated(script, *arguments, commands=(), timeout=None):
    """The JSON object that ``script`` (a file of tests/gpu, or a path) prints last, run with
    ``arguments`` under the simulator in a process of its own. A script of checks
    (``run_checks``) given several names runs them all in that one process, after the
    ``commands``, (command, argv) pairs each run as ``pendular command *argv`` (``timeout``
    [s]: by default CHECK_TIMEOUT per check and command)."""
    if timeout is None:
        timeout = CHECK_TIMEOUT * max(1, len(arguments) + len(commands))
    if commands:
        arguments = (*arguments, COMMANDS, json.dumps([[command, [str(a) for a in argv]]
                                                       for command, argv in commands]))
    stdout = _run([sys.executable, os.path.join(HERE, script), *arguments], timeout)
    return json.loads(stdout.strip().splitlines()[-1])


def run_checks(checks):
    """The main of a script of checks run under the simulator: print one JSON object, each
    check named on the command line -> its measurements (``checks``: name -> function), after
    running the commands given after COMMANDS (simulated's ``commands``; the script fails
    with the first that fails)."""
    names, commands = sys.argv[1:], []
    if COMMANDS in names:
        names, commands = names[:names.index(COMMANDS)], json.loads(names[-1])
    unknown = [name for name in names if name not in checks]
    if unknown or not (names or commands):
        raise SystemExit(f"checks: {', '.join(checks)} (unknown or none: {unknown})")
    if commands:
        from pendular.cli import run_command

        for command, argv in commands:
            if run_command(command, argv) != 0:
                raise SystemExit(f"pendular {command} {' '.join(argv)} failed")
    print(json.dumps({name: checks[name]() for name in names}, default=float))


def simulated_commands(*commands, timeout=600):
    """Run each (command, argv) of ``commands`` as ``pendular command *argv`` under the
    simulator, all in one process of their own (this script's, with no checks)."""
    simulated("simulator.py", commands=commands, timeout=timeout)


def history(folder):
    """The history.h5 columns of a run folder (name -> array)."""
    import h5py

    with h5py.File(os.path.join(folder, "history.h5")) as handle:
        return {name: data[()] for name, data in handle["history"].items()}


def assert_same_records(cpu, gpu, rows, counts=("coordination",)):
    """Two histories with the same columns, more than ``rows`` rows at the same steps and the
    same ``counts`` columns (bridges: more than 20 at every row)."""
    assert cpu.keys() == gpu.keys() and len(cpu["step"]) > rows
    assert np.array_equal(cpu["step"], gpu["step"])
    for name in counts:
        assert np.array_equal(cpu[name], gpu[name]), name
    if "bridges" in counts:
        assert cpu["bridges"].min() > 20


#: The options of the samples that the command tests load, each prepared on the CPU by
#: ``pendular triaxial`` (prepared_sample): 60 spheres in six walls, in a periodic cell (the
#: simple shear's too: its own preparation gives the same sample).
WALLED_SAMPLE = ("--particles", "60", "--max-strain", "1e-4", "--quiet", "--no-plots")
PERIODIC_SAMPLE = (*WALLED_SAMPLE, "--periodic")

#: options -> the sample.h5 that prepared_sample made in this process.
_SAMPLES = {}


def prepared_sample(folders, options):
    """The sample.h5 of ``pendular triaxial *options`` run on the CPU in this process, once
    for every test module of the process that asks (``folders``: pytest's
    tmp_path_factory)."""
    if options not in _SAMPLES:
        from pendular.cli import run_command

        out = folders.mktemp("sample") / "prep"
        assert run_command("triaxial", [*options, "--out", str(out)]) == 0
        _SAMPLES[options] = out / "sample.h5"
    return _SAMPLES[options]


def command_runs_fixture(options):
    """A test module's fixture ``command_runs``: (the sample.h5 of ``options``, prepared once
    on the CPU by prepared_sample; a folder for the module's command runs)."""
    import pytest

    @pytest.fixture(scope="module")
    def command_runs(tmp_path_factory):
        return prepared_sample(tmp_path_factory, options), tmp_path_factory.mktemp("command")

    return command_runs


def on_the_gpu(command, sample, argv, folder):
    """The (command, argv) of ``pendular command *argv --sample sample --device gpu`` writing
    into ``folder``/gpu, without figures, for simulated's ``commands`` (histories_on_both reads
    its run)."""
    return command, [*map(str, argv), "--sample", str(sample), "--device", "gpu", "--no-plots",
                     "--out", f"{folder}/gpu"]


def histories_on_both(command, sample, argv, folder):
    """(CPU history, GPU history): ``pendular command *argv --sample sample`` run on the CPU
    without figures in this process, in ``folder``/cpu, and the run of ``on_the_gpu(command, sample, argv,
    folder)``, which a simulated process has made."""
    from pendular.cli import run_command

    run = [*map(str, argv), "--sample", str(sample), "--no-plots", "--out", f"{folder}/cpu"]
    assert run_command(command, run) == 0
    return history(f"{folder}/cpu"), history(f"{folder}/gpu")


def relative(a, b):
    """max |a - b| / max |a| [-] (0 for two zero arrays)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = np.max(np.abs(a))
    return float(np.max(np.abs(a - b)) / scale) if scale > 0 else float(np.max(np.abs(b)))


@contextlib.contextmanager
def counted_copies():
    """A list to which each GpuSimulation.copy_back made in the block appends what it copies:
    "all", or "walls" when the walls alone come back."""
    from pendular.gpu import GpuSimulation

    copies = []
    copy_back = GpuSimulation.copy_back

    def counted(self, part=None):
        copies.append(part or "all")
        return copy_back(self, part)

    GpuSimulation.copy_back = counted
    try:
        yield copies
    finally:
        GpuSimulation.copy_back = copy_back


if __name__ == "__main__":
    run_checks({})
