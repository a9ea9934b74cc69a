"""Campaigns: many runs of configurations, in parallel processes or on a Dask cluster.

A campaign is a list of runs, each a folder name and the configuration of a laboratory command
(pendular.studies.run_kinds.PROCEDURES: triaxial, oedometer, isotropic, cyclic, simple-shear,
path, tension, swcc), built e.g. with ``dataclasses.replace``::

    base = TriaxialConfig(sample=PrepareConfig(particles=300), shear=ShearConfig(0.02))
    runs = [Run(f"s{s:g}", dataclasses.replace(base, bridges=BridgeConfig(s))) for s in (1e4, 3e4)]
    result = Campaign(runs).run("runs/mine", jobs=2)      # result.summaries["s10000"] ...

``Campaign.run(out, options)`` runs each into ``out/runs/<name>/`` (its outputs, and log.txt
with its progress bars) with its command's test (run_kinds.Procedure), as the
pendular.procedures.run_options.RunOptions ``options`` say (or their fields one by one, as
above): ``threads`` Numba threads per run (1 by default), in ``jobs`` spawned processes (at most
JOBS_PER_CPU per CPU) or on the Dask cluster of ``scheduler``, on ``device``. It does not lock
``out``: a command holds it as its pendular.io.outputs.OutputFolder around the campaign, so that
a second campaign into it is refused. A run whose folder holds a finished result of an equal
configuration (``pendular.procedures.config.same_config`` of the configuration stored with it:
in sample.h5 of a laboratory test, in tension.json or swcc.json) is reused, so an interrupted
campaign goes on where it stopped; so is a shared sample (``samples``) saved with an equal
PrepareConfig. The campaign's progress bar shows each running run's own progress. A run that
fails does not stop the others: ``CampaignResult.failed`` names it with its error. A run's
summary is the scalars of its result (run_kinds.Procedure.summary): a laboratory test's
summary.json, the first case of a tension run (give each run one void ratio and one water
content), the key figures of an SWCC (run_kinds.swcc_summary).

``sweep_from_table(path)`` reads a TOML parameter table (``pendular campaign TABLE.toml``)::

    command = "triaxial"            # or any key of PROCEDURES
    [fixed]                         # options of the command, underscores for dashes
    particles = 300
    max_strain = 0.02
    [sweep]                         # lists: every combination (cartesian product)
    suction = [0, 30000]
    confining = [250, 750]
    # or explicit rows instead of [sweep] (a row's values override [fixed]):
    # [[runs]]
    # name = "loose"                # optional folder name
    # prep_friction = 3

Any option of the command's configuration can be fixed or swept, and ``force`` (Run.force) of a
laboratory test; each run's configuration is built by
pendular.procedures.registry.config_from_options, as the command line builds it, so it is
validated as there. Flags take true/false, a list option a list or its comma text
(``table_resolution = [350, 80]``, ``stresses = "500,1000"``); relative ``sample``, ``psd``
and ``table`` (a path table) paths are relative to the table's folder. A table must set at
least one option (an empty table, ``[sweep]`` or ``runs = []`` is refused: it would run the
command's default test) and hold at most MAX_RUNS runs. Every refusal names the table and the
key, with its section (``[fixed]``, ``[sweep]``, ``row 2 of [[runs]]``).
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import csv
import itertools
import json
import math
import multiprocessing
import numbers
import os
import re
import threading
import traceback
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any, Callable

from tqdm import tqdm

from pendular.utils.atomic import replacing
from pendular.procedures.preparation import PrepareConfig, prepare_sample
from pendular.dem.sample import save_sample
from pendular.dem.simulation import check_device
from pendular.utils.threads import use_threads
from pendular.utils.toml_file import read_toml
from pendular.utils.validate import check_int

from pendular.procedures.config import config_to_dict, sample_made_with
from pendular.procedures.registry import config_from_options, options_of
from pendular.procedures.laboratory import Interrupted
from pendular.procedures.run_options import RunOptions
from pendular.studies.run_kinds import PROCEDURES, RunConfig, procedure_of, run_options_of

#: Seconds between updates of the campaign's progress bar.
PROGRESS_PERIOD = 5.0
#: Options a parameter table cannot set: the campaign decides them.
CAMPAIGN_OPTIONS = ("out", "quiet", "threads", "resume", "stop_after", "vtk_prep", "device")
#: Options of a table that are paths, relative to the table's folder.
PATH_OPTIONS = ("sample", "psd", "table")
#: Most runs in a table: each is a DEM test of minutes to hours, so more is a mistake (an extra
#: swept list), and its cartesian product would fill the memory before anything runs.
MAX_RUNS = 10000
#: Most local processes per CPU (--jobs): each run is compute-bound with its own interpreter,
#: Numba runtime and sample in memory, so beyond the CPUs processes only share them; a few per
#: CPU leave room for runs waiting on their files, more only multiply the memory.
JOBS_PER_CPU = 4
@dataclass
class Run:
    """One run of a campaign: its folder name under ``out/runs`` and its configuration (of
    a command of PROCEDURES); ``force``: run a laboratory test refused as not quasi-static or
    too long (pendular.procedures.feasibility.check_feasible)."""

    name: str
    config: RunConfig
    force: bool = False

    def __post_init__(self):
        if (not isinstance(self.name, str) or self.name in ("", ".", "..")
                or os.sep in self.name or (os.altsep and os.altsep in self.name)):
            raise ValueError(f"run name {self.name!r} is not a folder name (valid: a non-empty "
                             "name without path separators)")
        procedure_of(self.config)


class RunRefused(ValueError):
    """A run of a campaign refused before anything runs (its message starts with the run)."""


@dataclass
class CampaignResult:
    """What ``Campaign.run`` did: ``summaries`` {name: summary dict} of the finished runs (run
    now or reused), ``reused`` the names of the reused ones, ``failed`` {name: error text} (the
    traceback is in the run's log.txt)."""

    runs: list[Run]
    summaries: dict[str, dict] = field(default_factory=dict)
    reused: list[str] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)

    def check(self) -> None:
        """ValueError naming every failed run and its error (nothing when none failed)."""
        if self.failed:
            raise ValueError(f"{len(self.failed)} of {len(self.runs)} runs failed: " + "; ".join(
                f"{name}: {error}" for name, error in self.failed.items()))


# ---------------------------------------------------------------- workers (top level: picklable)

def run_one(config: RunConfig, folder: str, options: RunOptions, force: bool = False) -> dict:
    """Worker: the test of ``config`` into ``folder`` as ``options`` say (its Numba threads and
    device), its output and progress bars in ``folder``/log.txt (with the traceback if it
    fails); its summary (Procedure.run)."""
    use_threads(options.threads)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "log.txt"), "w", encoding="utf-8") as log, \
            contextlib.redirect_stdout(log), contextlib.redirect_stderr(log):
        try:
            return procedure_of(config).run(config, folder, options, force)
        except BaseException:
            traceback.print_exc()
            raise


#: A campaign's run by default: one Numba thread, on the CPU.
ONE_THREAD = RunOptions(threads=1)


def prepare_one(sample: PrepareConfig, path: str, options: RunOptions = ONE_THREAD) -> str:
    """Worker: prepare the sample of ``sample`` (a PrepareConfig) with the Numba threads and on
    the device of ``options`` and save it at ``path`` with its configuration (``{"sample":
    config_to_dict(sample)}``)."""
    use_threads(options.threads)
    sim, report = prepare_sample(sample, progress=False, threads=options.threads,
                                 device=options.device)
    save_sample(path, sim, report, {"sample": config_to_dict(sample)},
                identity={"seed": sample.seed})
    return path


# ---------------------------------------------------------------- reuse

def finished_summary(config: RunConfig, folder: str) -> dict | None:
    """The summary of a run of ``folder`` that finished with an equal configuration, or None
    (also for a damaged summary: the run is done again); Procedure.finished."""
    return procedure_of(config).finished(config, folder)


# ---------------------------------------------------------------- execution

def max_jobs() -> int:
    """The most local processes (--jobs) on this machine: JOBS_PER_CPU per CPU."""
    return JOBS_PER_CPU * (os.cpu_count() or 1)


def check_jobs(jobs: int) -> int:
    """``jobs`` (--jobs) as an int in [1, max_jobs()]; ValueError naming --jobs and the range."""
    high = max_jobs()
    valid = (f"valid range [1, {high}] ({JOBS_PER_CPU} processes per CPU of this machine; "
             "more only slow every run down)")
    if isinstance(jobs, bool) or not isinstance(jobs, numbers.Integral):
        raise ValueError(f"--jobs {jobs!r} is not an integer; {valid}")
    if not 1 <= jobs <= high:
        raise ValueError(f"--jobs {jobs} is outside the {valid}")
    return int(jobs)


@contextlib.contextmanager
def executor(jobs: int, scheduler: str | None = None):
    """Where the runs go: None (here, one after the other), a spawn process pool of ``jobs``
    workers (check_jobs), or the concurrent.futures executor of the Dask cluster at
    ``scheduler``. On an exception (Ctrl-C) the runs not started are cancelled."""
    jobs = check_jobs(jobs)
    if scheduler is not None:
        try:
            from dask.distributed import Client
        except ImportError:
            raise ValueError("--scheduler needs dask.distributed: pip install "
                             "'pendular[dask]'") from None
        try:
            client = Client(scheduler)
        except (OSError, ValueError) as error:
            raise ValueError(f"--scheduler {scheduler!r}: cannot connect ({error})") from None
        with client:
            pool = client.get_executor(pure=False)
            try:
                yield pool
            finally:
                pool.shutdown()
    elif jobs == 1:
        yield None
    else:
        # fresh interpreters (no fork of a running Numba threading layer)
        pool = concurrent.futures.ProcessPoolExecutor(
            jobs, mp_context=multiprocessing.get_context("spawn"))
        try:
            yield pool
        except BaseException:
            pool.shutdown(wait=True, cancel_futures=True)
            raise
        pool.shutdown(wait=True)


def run_progress(folder: str) -> str:
    """The last progress a run's log.txt shows: 'shear 42%', or for an open-ended phase its
    steps and what it waits for ('wet 1200step unbalanced=0.02/0.01'); '' if none."""
    try:
        with open(os.path.join(folder, "log.txt"), "rb") as handle:
            handle.seek(0, os.SEEK_END)
            handle.seek(max(0, handle.tell() - 4096))
            tail = handle.read().decode(errors="replace")
    except OSError:
        return ""
    for line in reversed(re.split(r"[\r\n]+", tail)):
        match = re.match(r"\s*(\w[\w ]*?):\s*(\d+%|\d+step)(.*)", line)
        if match:
            text = f"{match.group(1)} {match.group(2)}"
            if match.group(2).endswith("step"):
                waits = re.findall(r"(\w+=[^,\]\s]+)", match.group(3))
                text += "".join(" " + item for item in waits[:2])
            return text
    return ""


def map_tasks(pool, function: Callable, tasks: Sequence[tuple], *, description: str,
              folders: Sequence[str] | None = None, quiet: bool = False):
    """``function(*task)`` for every task (in ``pool`` or here) with a progress bar whose status
    shows each running task's own progress (the log.txt of its folder in ``folders``).
    Returns (results in the order of ``tasks``, {index: error text} of the tasks that failed)."""
    results: list = [None] * len(tasks)
    errors: dict[int, str] = {}
    if not tasks:
        return results, errors
    names = [os.path.basename(str(f)) for f in folders] if folders else [""] * len(tasks)

    def status(indices):
        if not folders:
            return ""
        return ", ".join(f"{names[i]} {p}".strip() for i in indices
                         for p in [run_progress(folders[i])])

    with tqdm(total=len(tasks), desc=description, unit="run", disable=quiet) as bar:
        if pool is None:
            for index, task in enumerate(tasks):
                bar.set_postfix_str(names[index])
                with _watching(bar, lambda i=index: status([i]), quiet):
                    try:
                        results[index] = function(*task)
                    except Interrupted:          # Ctrl-C in a run here stops the campaign
                        raise KeyboardInterrupt from None
                    except Exception as error:   # noqa: BLE001 - reported per run
                        errors[index] = _error_text(error)
                bar.update()
            return results, errors
        pending = {pool.submit(function, *task): i for i, task in enumerate(tasks)}
        try:
            while pending:
                done, _ = concurrent.futures.wait(pending, timeout=PROGRESS_PERIOD,
                                                  return_when=concurrent.futures.FIRST_COMPLETED)
                for future in done:
                    index = pending.pop(future)
                    try:
                        results[index] = future.result()
                    except Exception as error:   # noqa: BLE001 - reported per run
                        errors[index] = _error_text(error)
                    bar.update()
                bar.set_postfix_str(status(sorted(pending.values())))
        except BaseException:
            for future in pending:
                future.cancel()
            raise
    return results, errors


def _error_text(error: BaseException) -> str:
    text = str(error).strip().splitlines()
    return f"{type(error).__name__}: {text[-1] if text else ''}".rstrip(": ")


@contextlib.contextmanager
def _watching(bar, status: Callable[[], str], quiet: bool):
    """While a task runs here, refresh ``bar``'s status from ``status()`` every
    PROGRESS_PERIOD seconds (a reader thread; the run keeps the main thread and Ctrl-C)."""
    if quiet:
        yield
        return
    stop = threading.Event()

    def watch():
        while not stop.wait(PROGRESS_PERIOD):
            bar.set_postfix_str(status())

    watcher = threading.Thread(target=watch, daemon=True)
    watcher.start()
    try:
        yield
    finally:
        stop.set()
        watcher.join()


class Campaign:
    """Runs (``Run`` or (name, config) pairs, names unique) and the shared samples they start
    from (``samples``: (PrepareConfig, path) pairs, prepared first unless saved with an equal
    configuration); ``run(out)`` (module docstring)."""

    def __init__(self, runs: Iterable[Run | tuple[str, RunConfig]],
                 samples: Iterable[tuple[PrepareConfig, str]] = ()):
        self.runs = [run if isinstance(run, Run) else Run(*run) for run in runs]
        names = [run.name for run in self.runs]
        repeated = sorted({name for name in names if names.count(name) > 1})
        if repeated:
            raise ValueError(f"run names must be unique: {', '.join(repeated)} repeated")
        self.samples = [(sample, os.fspath(path)) for sample, path in samples]
        for sample, _ in self.samples:
            if not isinstance(sample, PrepareConfig):
                raise TypeError(f"samples: a PrepareConfig expected, got "
                                f"{type(sample).__name__}")

    def folder(self, out: str, name: str) -> str:
        """The folder of run ``name``."""
        return os.path.join(out, "runs", name)

    def run(self, out: str, options: RunOptions | None = None, **settings) -> CampaignResult:
        """Run every run into ``out``/runs/<name> (reusing finished ones) as ``options`` say
        (RunOptions; ``settings``: its fields one by one): ``threads`` Numba threads each
        (None: 1), in ``jobs`` local processes (check_jobs) or on the Dask cluster at
        ``scheduler`` (its workers must see ``out`` at the same path), the preparations and
        the runs on ``device`` ("cpu" or "gpu"; a run option: not part of a run's identity,
        so a finished run is reused whichever device ran it), the campaign's progress bar
        unless ``progress`` is False (each run's bars go to its log.txt), each run's figures
        unless ``plots`` is False. Every
        configuration still to run is checked here first (its test: quasi-static, duration,
        bridge tables), and the device, so a bad one is refused before anything runs. The
        caller holds ``out`` (an OutputFolder, module docstring)."""
        options = RunOptions.of(options, **settings)
        jobs, scheduler, device = check_jobs(options.jobs), options.scheduler, options.device
        threads = check_int("threads", 1 if options.threads is None else options.threads,
                            low=1)
        quiet = not options.progress
        # a run's, bars into its log
        each = RunOptions(device=device, threads=threads, plots=options.plots)
        out = os.path.abspath(os.fspath(out))       # workers elsewhere see the same paths
        result = CampaignResult(self.runs)
        todo = []
        for run in self.runs:
            summary = finished_summary(run.config, self.folder(out, run.name))
            if summary is None:
                todo.append(run)
            else:
                result.summaries[run.name] = summary
                result.reused.append(run.name)
        check_device(device)
        for run in todo:
            try:
                procedure_of(run.config).start(run.config, run.force)
            except ValueError as error:
                raise RunRefused(f"run {run.name}: {error}") from None
        preparations = [(sample, path) for sample, path in self.samples
                        if not sample_made_with(path, sample)]
        for _, path in preparations:
            os.makedirs(os.path.dirname(path), exist_ok=True)
        with executor(jobs, scheduler) as pool:
            _, errors = map_tasks(pool, prepare_one,
                                  [(sample, path, each) for sample, path in preparations],
                                  description="prepare", quiet=quiet)
            unprepared = {os.path.abspath(preparations[i][1]): text
                          for i, text in errors.items()}
            for run in list(todo):
                path = getattr(run.config, "sample_path", None)
                if path is not None and os.path.abspath(path) in unprepared:
                    todo.remove(run)
                    result.failed[run.name] = (f"its sample {path} could not be prepared: "
                                               f"{unprepared[os.path.abspath(path)]}")
            folders = [self.folder(out, run.name) for run in todo]
            results, errors = map_tasks(
                pool, run_one, [(run.config, folder, each, run.force)
                                for run, folder in zip(todo, folders)],
                description="runs", folders=folders, quiet=quiet)
        for index, (run, summary) in enumerate(zip(todo, results)):
            if index in errors:
                result.failed[run.name] = (f"{errors[index]} (log: "
                                           f"{os.path.join(folders[index], 'log.txt')})")
            else:
                result.summaries[run.name] = summary
        return result


# ---------------------------------------------------------------- parameter tables

def read_table(path: str | os.PathLike) -> dict:
    """The TOML table at ``path`` as a dict; ValueError naming the path (and the line of a
    TOML or UTF-8 error) when it is not a readable TOML file."""
    return read_toml(path, f"table = {os.fspath(path)!r}")


def table_rows(table: dict, source: str) -> tuple[str, list[dict], list[list[str]]]:
    """(command, [options dict per run], [the keys each run varies]) of a parameter table
    (module docstring); ValueError starting with ``source``."""
    valid = "valid: [fixed] options with [sweep] lists or [[runs]] rows"
    if not table:
        raise ValueError(f"{source} is empty; {valid}")
    unknown = set(table) - {"command", "fixed", "sweep", "runs"}
    if unknown:
        raise ValueError(f"{source}: unknown table key(s) {', '.join(sorted(unknown))}; valid: "
                         "command, fixed, sweep, runs")
    command = table.get("command", "triaxial")
    if not isinstance(command, str) or command not in PROCEDURES:
        raise ValueError(f"{source}: command = {command!r} is not one of "
                         f"{', '.join(map(repr, PROCEDURES))}")
    for key in ("fixed", "sweep"):
        if not isinstance(table.get(key, {}), dict):
            raise ValueError(f"{source}: {key} must be a table ([{key}])")
    fixed = dict(table.get("fixed", {}))
    sweep = table.get("sweep", {})
    explicit = table.get("runs", [])
    if not isinstance(explicit, list) or not all(isinstance(r, dict) for r in explicit):
        raise ValueError(f"{source}: runs must be an array of tables ([[runs]])")
    if "sweep" in table and not sweep:
        raise ValueError(f"{source}: [sweep] is empty; valid: a non-empty list per swept "
                         "option, e.g. suction = [0, 30000]")
    if "runs" in table and not explicit:
        raise ValueError(f"{source}: runs = [] holds no run; valid: one [[runs]] table per run")
    if sweep and explicit:
        raise ValueError(f"{source}: give [sweep] or [[runs]], not both")
    for name, values in sweep.items():
        if not isinstance(values, list) or not values:
            raise ValueError(f"{source}: sweep.{name} = {values!r} is not a non-empty list")
    both = sorted(set(fixed) & set(sweep))
    if both:
        raise ValueError(f"{source}: {', '.join(both)} both in [fixed] and in [sweep]")
    count = math.prod(len(values) for values in sweep.values()) if sweep else len(explicit)
    if count > MAX_RUNS:
        sizes = " x ".join(f"{len(values)} {name}" for name, values in sweep.items())
        raise ValueError(f"{source}: {count} runs ({sizes or '[[runs]] rows'}); valid: at "
                         f"most {MAX_RUNS} runs in a table")
    if sweep:
        names = list(sweep)
        own = [dict(zip(names, combination))
               for combination in itertools.product(*(sweep[n] for n in names))]
    else:
        own = [dict(row) for row in explicit] or [{}]
    rows = [{**fixed, **row} for row in own]
    if not any(set(row) - {"name"} for row in rows):
        raise ValueError(f"{source} sets no option, so each run would be the {command} "
                         f"command's default test; {valid}")
    return command, rows, [list(row) for row in own]


def run_name(row: dict, varied: Sequence[str]) -> str:
    """Folder name of a run: its ``name`` key, else its varied options, e.g.
    'suction30000_confining250' ('run' when nothing varies)."""
    if "name" in row:
        return str(row["name"])
    keys = [key for key in varied if key != "name"]
    if not keys:
        return "run"
    return "_".join(f"{key}{_text(row[key])}" for key in keys)


def _text(value: Any) -> str:
    if isinstance(value, list):
        return "-".join(_text(v) for v in value)
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return re.sub(r"[^\w.+-]", "-", str(value))


def _mentions(text: str, key: str) -> bool:
    """Whether the error ``text`` names the option ``key`` (as --key-with-dashes or key)."""
    flag = "--" + key.replace("_", "-")
    return re.search(rf"(?<![\w-])({re.escape(flag)}|{re.escape(key)})(?![\w-])",
                     text) is not None


def _named(error: Exception, options: dict) -> list[str]:
    """The keys of ``options`` that ``error`` names (its ``keys``, else those its text
    mentions), all of them when it names none."""
    keys = getattr(error, "keys", None)
    named = [key for key in options
             if (key in keys if keys is not None else _mentions(str(error), key))]
    return named or list(options)


def sweep_from_table(path: str | os.PathLike) -> tuple[str, list[Run]]:
    """(command, [Run]) of the TOML table at ``path``; each run's configuration is built and
    validated from its options by pendular.procedures.registry.config_from_options (ValueError
    naming the table, the run and the table key with its section)."""
    source = f"table = {os.fspath(path)!r}"
    table = read_table(path)
    command, rows, varied = table_rows(table, source)
    declared = [option.key for option in options_of(command)]
    own = {option.key: option for option in run_options_of(command)}
    known = set(declared) | set(own)

    def where(index, key):
        """The section of the table that gives run ``index`` its ``key``."""
        if key not in varied[index]:
            return "[fixed]"
        return "[sweep]" if table.get("sweep") else f"row {index + 1} of [[runs]]"

    def setting(index, key):
        return f"{key} = {json.dumps(rows[index][key], default=str)} ({where(index, key)})"

    unknown = {}
    for index, row in enumerate(rows):
        for key in row:
            if key != "name" and key not in known:
                unknown.setdefault(key, index)
    if unknown:
        described = []
        for key, index in unknown.items():
            note = ("set by the campaign" if key in CAMPAIGN_OPTIONS else
                    f"write {key.replace('-', '_')}" if key.replace("-", "_") in known else "")
            described.append(f"{key} ({where(index, key)}{': ' + note if note else ''})")
        raise ValueError(f"{source}: {', '.join(described)}: not an option of {command} in a "
                         f"table; see 'pendular {command} --help'")
    folder = os.path.dirname(os.path.abspath(os.fspath(path)))
    runs = []
    for index, (row, keys) in enumerate(zip(rows, varied)):
        name = run_name(row, keys)
        if "name" in row and (isinstance(row["name"], bool)
                              or not isinstance(row["name"], (str, int))):
            raise ValueError(f"{source}: {setting(index, 'name')}: a folder name (a string) "
                             "expected")
        options = {key: os.path.join(folder, value)
                   if key in PATH_OPTIONS and isinstance(value, str)
                   and not os.path.isabs(value) else value
                   for key, value in row.items() if key != "name"}
        try:
            run_settings = {key: own[key].read(options.pop(key)) for key in own
                            if key in options}
            config = config_from_options(command, options)
        except (ValueError, ArithmeticError) as error:
            named = _named(error, {key: None for key in row if key != "name"})
            raise ValueError(f"{source}: run {name}: "
                             f"{', '.join(setting(index, key) for key in named)}: "
                             f"{error}") from None
        try:
            runs.append(Run(name, config, **run_settings))
        except ValueError as error:
            raise ValueError(f"{source}: "
                             f"{setting(index, 'name') if 'name' in row else 'run ' + name}: "
                             f"{error}") from None
    names = [run.name for run in runs]
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise ValueError(f"{source}: runs {', '.join(repeated)} repeat a folder name: give "
                         "each [[runs]] row a distinct name or distinct values")
    return command, runs


def run_options(config: RunConfig) -> dict:
    """A run's options, flat and named as the command's (campaign.csv columns;
    Procedure.options)."""
    return procedure_of(config).options(config)


def write_campaign_csv(path: str, result: CampaignResult) -> None:
    """``path``: one row per run of ``result``: its name, status (run, reused, failed), its
    options (flat) and its summary's scalars (the error of a failed run)."""
    rows = []
    for run in result.runs:
        summary = {k: v for k, v in (result.summaries.get(run.name) or {}).items()
                   if isinstance(v, (int, float, str, bool)) or v is None}
        status = ("failed" if run.name in result.failed else
                  "reused" if run.name in result.reused else "run")
        row = {"run": run.name, "status": status, **run_options(run.config), **summary}
        if run.name in result.failed:
            row["error"] = result.failed[run.name]
        rows.append(row)
    columns = list(dict.fromkeys(key for row in rows for key in row))
    with replacing(path) as temporary, open(temporary, "w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=columns)
        writer.writeheader()
        writer.writerows(rows)
