"""Campaigns: many runs of configurations, in parallel processes or on a Dask cluster.

A campaign is a list of ``Run`` (a name and a TriaxialConfig or TensionConfig built with
``dataclasses.replace``). ``run_campaign(runs, out, ...)`` runs each into ``out/runs/<name>/``
(its outputs, and log.txt with its progress bar), one Numba thread per run, and reuses a run
whose folder holds a finished result of an equal configuration (``pendular.config.config_json``
of the configuration stored with it), so an interrupted campaign goes on where it stopped. The
campaign's progress bar shows each running run's own progress.

``sweep_from_table(path)`` reads a TOML parameter table (``pendular campaign TABLE.toml``):

    command = "triaxial"            # or "tension"
    [fixed]                         # options of the command, underscores for dashes
    particles = 300
    max_strain = 0.02
    [sweep]                         # lists: every combination (cartesian product)
    suction = [0, 30000]
    confining = [250, 750]
    # or explicit rows:  [[runs]]  suction = 0  confining = 250

Any option of the command can be fixed or swept; each run's configuration is built by the
command's own option parser, so it is validated as on the command line.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import csv
import itertools
import json
import multiprocessing
import os
import re
from dataclasses import dataclass

from tqdm import tqdm

from dem.atomic import replacing
from dem.preparation import prepare_sample
from dem.sample import save_sample

from .config import TriaxialConfig, config_json, config_to_dict

#: Seconds between updates of the campaign's progress bar.
PROGRESS_PERIOD = 5.0


@dataclass
class Run:
    """One run of a campaign: its folder name under ``out/runs`` and its configuration."""

    name: str
    config: object


def _tension():
    from . import tension          # the tension test, imported where a campaign needs it
    return tension


# ---------------------------------------------------------------- workers (top level: picklable)

def run_one(config, folder):
    """Worker: the test of ``config`` into ``folder`` with one Numba thread, its output and
    progress bar in ``folder``/log.txt; returns its summary (dict)."""
    import numba

    from .triaxial import TriaxialTest

    numba.set_num_threads(1)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "log.txt"), "w") as log, \
            contextlib.redirect_stdout(log), contextlib.redirect_stderr(log):
        if isinstance(config, TriaxialConfig):
            return TriaxialTest(config).run(folder, threads=1)
        return tension_summary(_tension().TensionTest(config).run(folder))


def prepare_one(sample, path):
    """Worker: prepare the sample of ``sample`` (a PrepareConfig) and save it at ``path`` with
    its configuration (``{"sample": config_to_dict(sample)}``)."""
    import numba

    numba.set_num_threads(1)
    sim, report = prepare_sample(sample, progress=False, threads=1)
    save_sample(path, sim, report, {"sample": config_to_dict(sample)},
                identity={"seed": sample.seed})
    return path


def tension_summary(result):
    """One summary row of a tension run: its first case's scalars (a campaign run holds one
    void ratio and one water content)."""
    case = result["cases"][0]
    return {k: v for k, v in case.items() if isinstance(v, (int, float, str, bool))}


# ---------------------------------------------------------------- reuse

def stored_config(path, key):
    """The configuration dict stored under ``key`` in the config attribute of a pendular HDF5
    file (sample.h5), or None when absent or unreadable."""
    import h5py

    if not os.path.isfile(path):
        return None
    try:
        with h5py.File(path, "r") as handle:
            return json.loads(handle.attrs["config"]).get(key)
    except (OSError, KeyError, ValueError):
        return None


def sample_made_with(path, sample):
    """Whether the saved sample ``path`` was prepared with the PrepareConfig ``sample``."""
    stored = stored_config(path, "sample")
    return stored is not None and json.dumps(stored, sort_keys=True) == config_json(sample)


def finished_summary(config, folder):
    """The summary of a run of ``folder`` that finished with an equal configuration, or None."""
    if isinstance(config, TriaxialConfig):
        summary_path = os.path.join(folder, "summary.json")
        stored = stored_config(os.path.join(folder, "sample.h5"), "config")
    else:
        summary_path = os.path.join(folder, "tension.json")
        stored = None
        if os.path.isfile(summary_path):
            with open(summary_path) as handle:
                stored = json.load(handle).get("config")
    if stored is None or not os.path.isfile(summary_path):
        return None
    if json.dumps(stored, sort_keys=True) != config_json(config):
        return None
    with open(summary_path) as handle:
        summary = json.load(handle)
    if isinstance(config, TriaxialConfig):
        return summary if summary.get("completed", True) else None
    return tension_summary(summary)


# ---------------------------------------------------------------- execution

@contextlib.contextmanager
def executor(jobs, scheduler=None):
    """Where the runs go: None (here, one after the other), a spawn process pool of ``jobs``
    workers, or the concurrent.futures executor of the Dask cluster at ``scheduler``."""
    if scheduler is not None:
        try:
            from dask.distributed import Client
        except ImportError:
            raise ValueError("--scheduler needs dask.distributed: pip install "
                             "'pendular[dask]'") from None
        with Client(scheduler) as client:
            pool = client.get_executor(pure=False)
            try:
                yield pool
            finally:
                pool.shutdown()
    elif jobs == 1:
        yield None
    else:
        # fresh interpreters (no fork of a running Numba threading layer)
        with concurrent.futures.ProcessPoolExecutor(
                jobs, mp_context=multiprocessing.get_context("spawn")) as pool:
            yield pool


def run_progress(folder):
    """The last progress a run's log.txt shows ('shear 42%', 'wet 1234step'), or ''."""
    try:
        with open(os.path.join(folder, "log.txt"), "rb") as handle:
            handle.seek(0, os.SEEK_END)
            handle.seek(max(0, handle.tell() - 4096))
            tail = handle.read().decode(errors="replace")
    except OSError:
        return ""
    for line in reversed(re.split(r"[\r\n]+", tail)):
        match = re.match(r"\s*(\w[\w ]*?):\s*(\d+%|\d+step)", line)
        if match:
            return f"{match.group(1)} {match.group(2)}"
    return ""


def map_tasks(pool, function, tasks, description, quiet=False):
    """``function(*task)`` for every task (in ``pool`` or here) with a progress bar whose status
    shows each running run's own progress (tasks whose last item is a folder); the results in
    the order of ``tasks``."""
    results = [None] * len(tasks)
    if not tasks:
        return results
    with tqdm(total=len(tasks), desc=description, unit="run", disable=quiet) as bar:
        if pool is None:
            for index, task in enumerate(tasks):
                bar.set_postfix_str(os.path.basename(str(task[-1])))
                results[index] = function(*task)
                bar.update()
            return results
        pending = {pool.submit(function, *task): i for i, task in enumerate(tasks)}
        while pending:
            done, _ = concurrent.futures.wait(pending, timeout=PROGRESS_PERIOD,
                                              return_when=concurrent.futures.FIRST_COMPLETED)
            for future in done:
                results[pending.pop(future)] = future.result()
                bar.update()
            running = (tasks[i][-1] for i in sorted(pending.values()))
            bar.set_postfix_str(", ".join(f"{os.path.basename(str(f))} {p}" for f in running
                                          for p in [run_progress(f)] if p))
    return results


def run_campaign(runs, out, *, jobs=1, scheduler=None, quiet=False, samples=()):
    """Run every ``Run`` into ``out``/runs/<name> (reusing finished ones); ``samples``: (sample
    PrepareConfig, path) pairs to prepare first unless already there. Returns ({name:
    summary}, number of runs reused)."""
    folders = {run.name: os.path.join(out, "runs", run.name) for run in runs}
    summaries = {run.name: finished_summary(run.config, folders[run.name]) for run in runs}
    todo = [run for run in runs if summaries[run.name] is None]
    preparations = [(sample, path) for sample, path in samples
                    if not sample_made_with(path, sample)]
    for _, path in preparations:
        os.makedirs(os.path.dirname(path), exist_ok=True)
    with executor(jobs, scheduler) as pool:
        map_tasks(pool, prepare_one, preparations, "prepare", quiet)
        results = map_tasks(pool, run_one, [(run.config, folders[run.name]) for run in todo],
                            "runs", quiet)
    summaries.update({run.name: result for run, result in zip(todo, results)})
    return summaries, len(runs) - len(todo)


# ---------------------------------------------------------------- parameter tables

def read_table(path):
    """The TOML table at ``path`` as a dict (ValueError naming the path when unreadable)."""
    try:
        import tomllib
    except ModuleNotFoundError:        # Python 3.10
        import tomli as tomllib
    try:
        with open(path, "rb") as handle:
            return tomllib.load(handle)
    except (OSError, tomllib.TOMLDecodeError) as error:
        raise ValueError(f"table = {os.fspath(path)!r} is not a readable TOML table: "
                         f"{error}") from None


def table_rows(table, source):
    """(command, [options dict per run]) of a parameter table (module docstring)."""
    unknown = set(table) - {"command", "fixed", "sweep", "runs"}
    if unknown:
        raise ValueError(f"{source}: unknown table key(s) {sorted(unknown)}; valid: command, "
                         "fixed, sweep, runs")
    command = table.get("command", "triaxial")
    if command not in ("triaxial", "tension"):
        raise ValueError(f"{source}: command = {command!r} is not one of 'triaxial', "
                         "'tension'")
    fixed = dict(table.get("fixed", {}))
    sweep = table.get("sweep", {})
    explicit = table.get("runs", [])
    if sweep and explicit:
        raise ValueError(f"{source}: give [sweep] or [[runs]], not both")
    for name, values in sweep.items():
        if not isinstance(values, list) or not values:
            raise ValueError(f"{source}: sweep.{name} = {values!r} is not a non-empty list")
    if sweep:
        names = list(sweep)
        rows = [dict(zip(names, combination))
                for combination in itertools.product(*(sweep[n] for n in names))]
    else:
        rows = [dict(row) for row in explicit] or [{}]
    return command, [{**fixed, **row} for row in rows], [list(row) for row in rows]


def run_name(row, varied):
    """Folder name of a run: its varied options, e.g. 'suction30000_confining250'."""
    if not varied:
        return "run"
    return "_".join(f"{key}{_text(row[key])}" for key in varied)


def _text(value):
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return re.sub(r"[^\w.+-]", "-", str(value))


def options_argv(options):
    """Command-line options of a table row (underscores -> dashes; true flags; lists joined)."""
    argv = []
    for key, value in options.items():
        flag = "--" + key.replace("_", "-")
        if value is True:
            argv.append(flag)
        elif value is False:
            continue
        else:
            argv += [flag, ",".join(map(str, value)) if isinstance(value, list) else str(value)]
    return argv


def sweep_from_table(path):
    """(command, [Run]) of the TOML table at ``path``; each run's configuration is parsed and
    validated by the command's own options (ValueError naming the run and the option)."""
    from .cli import command_parser

    source = f"table = {os.fspath(path)!r}"
    command, rows, varied = table_rows(read_table(path), source)
    parser, module = command_parser(command)
    known = set(vars(parser.parse_args([])))
    runs = []
    for row, keys in zip(rows, varied):
        unknown = sorted(set(row) - known)
        if unknown:
            raise ValueError(f"{source}: {command} has no option(s) "
                             f"{', '.join('--' + k.replace('_', '-') for k in unknown)}")
        name = run_name(row, keys)
        try:
            args = parser.parse_args(options_argv(row))
        except SystemExit:
            raise ValueError(f"{source}: run {name}: options {row} are not valid for "
                             f"{command} (see 'pendular {command} --help')") from None
        try:
            config = module.config_from(args)
        except ValueError as error:
            raise ValueError(f"{source}: run {name}: {error}") from None
        runs.append(Run(name, config))
    return command, runs


def write_campaign_csv(path, runs, summaries):
    """``path``: one row per run with its options (flat) and its summary's scalars."""
    from .triaxial import parameters

    rows = []
    for run in runs:
        options = (parameters(run.config) if isinstance(run.config, TriaxialConfig) else
                   {k: v for k, v in vars(run.config).items() if k != "cases"})
        summary = {k: v for k, v in (summaries.get(run.name) or {}).items()
                   if isinstance(v, (int, float, str, bool)) or v is None}
        rows.append({"run": run.name, **options, **summary})
    columns = list(dict.fromkeys(key for row in rows for key in row))
    with replacing(path) as temporary, open(temporary, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=columns)
        writer.writeheader()
        writer.writerows(rows)
