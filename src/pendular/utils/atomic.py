"""Atomic file replacement: a killed run leaves either the old file or the new one, never a
truncated one."""

import json
import os
from contextlib import contextmanager


def _fsync(path):
    descriptor = os.open(path, os.O_RDONLY)
    try:
        os.fsync(descriptor)
    finally:
        os.close(descriptor)


@contextmanager
def replacing(path, durable=False):
    """Yield a temporary name beside ``path``; when the block ends normally, rename it to
    ``path`` (removing it if the block raised). ``durable`` also flushes the file and the
    folder to disk, so the new file survives a power loss (checkpoints)."""
    folder, name = os.path.split(os.path.abspath(path))
    temporary = os.path.join(folder, f".{name}.tmp{os.getpid()}")
    try:
        yield temporary
        if durable:
            _fsync(temporary)
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.remove(temporary)
        raise
    if durable and os.name == "posix":
        _fsync(folder)


def write_text(path, text):
    """Write ``text`` to ``path`` atomically."""
    with replacing(path) as temporary, open(temporary, "w", encoding="utf-8") as handle:
        handle.write(text)


def write_json(path, data, **options):
    """Write ``data`` as JSON (json.dump ``options``, indent 2 by default) to ``path``
    atomically."""
    options.setdefault("indent", 2)
    with replacing(path) as temporary, open(temporary, "w", encoding="utf-8") as handle:
        json.dump(data, handle, **options)
