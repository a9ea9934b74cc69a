"""The output folder of a run: checked, locked, and owning the files it lists.

``OutputFolder(path, command)`` is a context manager that

- refuses, with one ValueError naming the path, an empty path, an existing file or device
  (e.g. /dev/null), a folder that cannot be created or is not writable;
- takes an exclusive lock (fcntl.flock on ``DIR/.pendular.lock``, non-blocking): a second run
  on the same folder is refused while the first runs (the lock dies with its process, kill -9
  included, so a stale lock never blocks);
- keeps a manifest ``DIR/.pendular-outputs.json`` of the files the run owns (``claim``).

A run into a used folder clears what the previous run owned: at start, every file the
previous manifest lists is removed (a dry run into an old wet run's folder leaves no stale
plots or VTK frames), unless ``keep=True`` (resume: the files are kept and stay owned). Files
not listed in a manifest (the user's own, or a run older than manifests) are never touched.
"""

import datetime
import errno
import fcntl
import json
import os
import shutil

from pendular.dem.atomic import write_json

LOCK = ".pendular.lock"
MANIFEST = ".pendular-outputs.json"
FORMAT = "pendular-outputs"
VERSION = 1


def _refuse(path, reason):
    return ValueError(f"out = {path!r}: {reason}")


def _relative(path, relpath):
    """``relpath`` normalised, inside the folder and not one of its bookkeeping files."""
    text = os.fspath(relpath)
    name = os.path.normpath(text)
    if (not text or os.path.isabs(text) or name == os.curdir or name == os.pardir
            or name.startswith(os.pardir + os.sep) or name in (LOCK, MANIFEST)):
        raise _refuse(path, f"cannot own {text!r}: valid names are relative paths inside the "
                            f"folder other than {LOCK} and {MANIFEST}")
    return name


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
    its full path; ``files`` lists what the run owns. ValueError naming the path for a path
    that cannot be an output folder or a folder in use by another run.
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
        self._lock = None

    # ------------------------------------------------------------ entering
    def _create(self):
        path = self.path
        if os.path.exists(path) and not os.path.isdir(path):
            kind = "a file" if os.path.isfile(path) else "not a folder (a device or special file)"
            raise _refuse(path, f"exists and is {kind}; valid: a folder, or a path where one "
                                "can be created")
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

    def _previous(self):
        """Files owned by the previous run (its manifest), [] if none or unreadable."""
        try:
            with open(os.path.join(self.path, MANIFEST)) as handle:
                data = json.load(handle)
            files = data["files"]
        except (OSError, ValueError, KeyError, TypeError):
            return []
        owned = []
        for name in files if isinstance(files, list) else []:
            try:
                owned.append(_relative(self.path, name))
            except (ValueError, TypeError):      # never follow a name outside the folder
                continue
        return owned

    def __enter__(self):
        self._create()
        self._acquire()
        try:
            previous = self._previous()
            if self.keep:
                self.files = sorted(set(previous))
            else:
                for name in previous:
                    _remove(self.path, name)
                    self.removed.append(name)
                self.files = []
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

    def _write(self, finished):
        write_json(os.path.join(self.path, MANIFEST), {
            "format": FORMAT, "version": VERSION, "command": self.command, "pid": os.getpid(),
            "updated": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "finished": finished, "files": self.files}, default=str)

    # ------------------------------------------------------------ leaving
    def _release(self):
        if self._lock is not None:
            fcntl.flock(self._lock, fcntl.LOCK_UN)
            os.close(self._lock)
            self._lock = None

    def __exit__(self, kind, value, traceback):
        try:
            self._write(finished=kind is None)
        finally:
            self._release()
        return False
