"""The output folder of a run: checked, locked, and owning the files it lists.

``OutputFolder(path, command)`` is a context manager that

- refuses, with one ValueError naming the path, an empty path, an existing file or device
  (e.g. /dev/null), a folder that cannot be created or is not writable;
- takes an exclusive lock (fcntl.flock on ``DIR/.pendular.lock``, non-blocking): a second run
  on the same folder is refused while the first runs (the lock dies with its process, kill -9
  included, so a stale lock never blocks);
- keeps a manifest ``DIR/.pendular-outputs.json`` of the files the run owns (``claim``).

A run into a used folder never leaves it with less than it had. At start, the files the
previous manifest lists (and the manifest) are moved aside into ``DIR/.pendular-earlier/``;
the new run writes into the folder itself. When it succeeds (or ``commit`` says its results are
whole) the earlier files are deleted, so a dry run into an old wet run's folder leaves no stale
plots or VTK frames; one line on stderr says so when the run starts. When it
fails or is interrupted and the earlier run had finished, the new run's files are removed and
the earlier ones put back (``earlier_results`` tells the run so beforehand); an earlier run
that had not finished is replaced by the new partial one. A folder left with files aside by a
killed run (kill -9) is put back in order by the next run that enters it: a resume keeps them
aside until it succeeds, a new run first restores them. ``keep=True`` (resume): the files are
kept and stay owned. Files not listed in a manifest (the user's own, or a run older than
manifests) are never touched.

A run that fails or is interrupted with no finished earlier results to fall back on leaves its
partial results, and, if it owns a ``summary.json`` it had not written yet, one that says so:
``completed`` false, the ``phase`` the run had reached (its ``phase`` attribute), and whether
it was ``interrupted`` or the ``error`` that stopped it.
"""

import datetime
import errno
import fcntl
import json
import os
import shutil
import sys

from pendular.utils.atomic import write_json
from pendular.utils.interrupt import deferred_interrupts

LOCK = ".pendular.lock"
MANIFEST = ".pendular-outputs.json"
#: Where the files of the previous run wait while a new run writes (module docstring).
EARLIER = ".pendular-earlier"
#: The summary a failed or interrupted run leaves when it wrote none (module docstring).
SUMMARY = "summary.json"
FORMAT = "pendular-outputs"
VERSION = 1


def _refuse(path, reason):
    return ValueError(f"out = {path!r}: {reason}")


def _relative(path, relpath):
    """``relpath`` normalised, inside the folder and not one of its bookkeeping files."""
    text = os.fspath(relpath)
    name = os.path.normpath(text)
    if (not text or os.path.isabs(text) or name == os.curdir or name == os.pardir
            or name.startswith(os.pardir + os.sep) or name.split(os.sep)[0] in (LOCK, MANIFEST,
                                                                                EARLIER)):
        raise _refuse(path, f"cannot own {text!r}: valid names are relative paths inside the "
                            f"folder other than {LOCK}, {MANIFEST} and {EARLIER}")
    return name


def _move(source, target, name):
    """Move ``name`` from folder ``source`` to folder ``target`` (absent ones are skipped)."""
    origin = os.path.join(source, name)
    if os.path.lexists(origin):
        destination = os.path.join(target, name)
        os.makedirs(os.path.dirname(destination), exist_ok=True)
        _remove(target, name)
        os.replace(origin, destination)


def _manifest(folder):
    """The manifest of ``folder`` (dict), {} if none or unreadable."""
    try:
        with open(os.path.join(folder, MANIFEST)) as handle:
            data = json.load(handle)
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def _remove(folder, name):
    """Remove the owned file or folder ``name`` of ``folder`` (links are removed, not
    followed); absent ones are skipped."""
    target = os.path.join(folder, name)
    if os.path.islink(target) or os.path.isfile(target):
        os.remove(target)
    elif os.path.isdir(target):
        shutil.rmtree(target)


class OutputFolder:
    """Context manager over the output folder ``path`` of a run of ``command`` (a string or a
    list of arguments, recorded in the manifest); module docstring.

    ``keep``: keep the files a previous run owned (resume) instead of removing them.
    Inside the block, ``claim(relpath)`` records a file (or folder) the run writes and returns
    its full path; ``files`` lists what the run owns; ``phase``: the phase the run is in (set
    by the run, named by the summary of a run that stops); ``earlier_results``: whether a finished
    earlier run waits aside (it comes back if this run fails); ``commit()``: this run's results
    are whole, the earlier ones go now. ValueError naming the path for a path that cannot be
    an output folder or a folder in use by another run.
    """

    def __init__(self, path, command, keep=False):
        try:
            path = os.fspath(path)
        except TypeError:
            raise ValueError(f"out = {path!r} is not a path: give a folder name") from None
        if not isinstance(path, str):
            path = os.fsdecode(path)
        if not path.strip():
            raise ValueError(f"out = {path!r} is empty: give a folder name (valid: a folder "
                             "that can be created or a writable folder)")
        self.path = path
        self.command = command
        self.keep = bool(keep)
        self.files = []
        self.removed = []
        self.phase = None
        self.earlier_results = False
        self._committed = False
        self._lock = None

    # ------------------------------------------------------------ entering
    def _create(self):
        path = self.path
        if os.path.exists(path) and not os.path.isdir(path):
            kind = "a file" if os.path.isfile(path) else "not a folder (a device or special file)"
            raise _refuse(path, f"exists and is {kind}; valid: a folder, or a path where one "
                                "can be created")
        parent = os.path.dirname(os.path.abspath(path))
        while not os.path.exists(parent):
            parent = os.path.dirname(parent)
        if not os.path.isdir(parent):
            raise _refuse(path, f"cannot create the folder: {parent!r} is a file, not a folder; "
                                "valid: a folder, or a path where one can be created")
        try:
            os.makedirs(path, exist_ok=True)
        except OSError as error:
            raise _refuse(path, f"cannot create the folder: {error.strerror or error}") from None
        if not os.access(path, os.W_OK | os.X_OK):
            raise _refuse(path, "the folder is not writable")

    def _acquire(self):
        lock_path = os.path.join(self.path, LOCK)
        try:
            descriptor = os.open(lock_path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as error:
            raise _refuse(self.path, f"the folder is not writable ({LOCK}: "
                                     f"{error.strerror or error})") from None
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as error:
            holder = ""
            try:
                holder = os.pread(descriptor, 4096, 0).decode(errors="replace").strip()
            except OSError:
                pass
            os.close(descriptor)
            if error.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                raise _refuse(self.path, "the folder is in use by another pendular run"
                                         f"{f' ({holder})' if holder else ''}; wait for it to "
                                         "end or choose another folder") from None
            raise _refuse(self.path, f"cannot lock {LOCK}: {error.strerror or error}") from None
        os.ftruncate(descriptor, 0)
        os.pwrite(descriptor, f"pid {os.getpid()}, command {self._command_text()}\n".encode(), 0)
        self._lock = descriptor

    def _command_text(self):
        if isinstance(self.command, (list, tuple)):
            return " ".join(str(part) for part in self.command)
        return str(self.command)

    def _owned(self, folder):
        """Files the manifest of ``folder`` lists, inside it ([] if none or unreadable)."""
        files = _manifest(folder).get("files")
        owned = []
        for name in files if isinstance(files, list) else []:
            try:
                owned.append(_relative(self.path, name))
            except (ValueError, TypeError):      # never follow a name outside the folder
                continue
        return owned

    def _restore_earlier(self):
        """Put the files set aside back in place of the current ones (module docstring)."""
        aside = os.path.join(self.path, EARLIER)
        for name in self._owned(self.path):
            _remove(self.path, name)
        for name in [*self._owned(aside), MANIFEST]:
            _move(aside, self.path, name)
        shutil.rmtree(aside)

    def _set_aside(self):
        """Move the previous run's files and manifest into EARLIER; returns their names."""
        aside = os.path.join(self.path, EARLIER)
        owned = [name for name in self._owned(self.path)
                 if os.path.lexists(os.path.join(self.path, name))]
        if not owned:
            return []
        self.earlier_results = _manifest(self.path).get("finished") is True
        os.makedirs(aside)
        for name in sorted(owned, key=len):       # a folder before the files it holds
            _move(self.path, aside, name)
        _move(self.path, aside, MANIFEST)
        return owned

    def __enter__(self):
        self._create()
        self._acquire()
        try:
            aside = os.path.isdir(os.path.join(self.path, EARLIER))
            if self.keep:
                self.files = sorted(set(self._owned(self.path)))
            else:
                if aside:                          # left by a killed run
                    self._restore_earlier()
                self.removed = self._set_aside()
                self.files = []
            if self.removed or (self.keep and aside):
                print(f"{self.path}: holds the results of an earlier run; this run replaces "
                      "them when it ends (they stay if it fails)", file=sys.stderr)
            self._write(finished=False)
        except BaseException:
            self._release()
            raise
        return self

    # ------------------------------------------------------------ inside
    def claim(self, relpath):
        """Record ``relpath`` (relative to the folder) as owned by this run; returns its full
        path. The manifest is rewritten at once, so a killed run still lists its files."""
        if self._lock is None:
            raise RuntimeError("OutputFolder.claim outside its with block")
        name = _relative(self.path, relpath)
        if name not in self.files:
            self.files.append(name)
            self.files.sort()
            self._write(finished=False)
        return os.path.join(self.path, name)

    def commit(self):
        """This run's results are whole: the earlier ones set aside are deleted now (a later
        failure, e.g. Ctrl-C while plotting, no longer brings them back)."""
        aside = os.path.join(self.path, EARLIER)
        if os.path.isdir(aside):
            shutil.rmtree(aside)
        self.earlier_results = False
        self._committed = True

    def _write(self, finished):
        write_json(os.path.join(self.path, MANIFEST), {
            "format": FORMAT, "version": VERSION, "command": self.command, "pid": os.getpid(),
            "updated": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "finished": finished, "files": self.files}, default=str)

    # ------------------------------------------------------------ leaving
    def _summarize_stop(self, error):
        """The summary of a run stopped by ``error`` that wrote none (module docstring)."""
        path = os.path.join(self.path, SUMMARY)
        if SUMMARY not in self.files or os.path.exists(path):
            return
        summary = {"completed": False, "phase": self.phase,
                   "interrupted": isinstance(error, KeyboardInterrupt)}
        if not summary["interrupted"]:
            summary["error"] = str(error) or type(error).__name__
        with deferred_interrupts():
            write_json(path, summary)

    def _release(self):
        if self._lock is not None:
            fcntl.flock(self._lock, fcntl.LOCK_UN)
            os.close(self._lock)
            self._lock = None

    def __exit__(self, kind, value, traceback):
        try:
            self._write(finished=kind is None)
            if kind is None:
                self.commit()
            elif self.earlier_results and not self._committed:
                self._restore_earlier()
            else:
                self._summarize_stop(value)
                if not self.keep:
                    shutil.rmtree(os.path.join(self.path, EARLIER), ignore_errors=True)
        finally:
            self._release()
        return False
