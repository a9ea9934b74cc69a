"""Content checksums and identities of the HDF5 files pendular writes and reads back.

A stamped file carries two attributes on its root:

    identity   JSON object: what made the file (``kind``, software version, schema or format
               version, configuration hash, seed, ...), chosen by the writer
    checksum   "sha256:<hex>": SHA-256 over every group, dataset (name, dtype, shape, bytes) and
               attribute (name, value) of the file in a canonical order (sorted names, depth
               first), the ``checksum`` attribute itself excepted

Writers call ``stamp(handle, identity)`` last, inside the block that writes the file under a
temporary name (pendular.utils.atomic.replacing), so a file on disk is either complete and stamped or
absent. Readers call ``verify(path, expected_identity, kind)`` before reading: an edited or
damaged file (checksum mismatch), a file made by another run or configuration (identity
mismatch) and a file without a checksum (written by pendular before CHECKSUMS_SINCE) are
refused with a ValueError naming the path and the reason.
"""

import dataclasses
import hashlib
import json
import os
from contextlib import contextmanager

import h5py
import numpy as np

from pendular.utils.version import software_version

from pendular.utils.validate import reading

#: The first pendular version whose files carry a checksum; older files are refused.
CHECKSUMS_SINCE = "0.2"

CHECKSUM = "checksum"
IDENTITY = "identity"
ALGORITHM = "sha256"
_ABSENT = object()

#: What to do with a file of each kind that has no checksum (written before CHECKSUMS_SINCE).
_REMEDY = {
    "sample": "prepare the sample again with this pendular",
    "checkpoint": "start the run again without resuming (a checkpoint written by an older "
                  "pendular cannot be resumed)",
    "table cache": "delete the file; it is rebuilt on the next run",
}




def _plain(value):
    """json.dumps ``default``: numpy scalars and arrays, dataclasses, tuples and paths as JSON."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return dataclasses.asdict(value)
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, (set, frozenset)):
        return sorted(value)
    raise TypeError(f"{type(value).__name__} is not JSON serializable")


def canonical_json(data):
    """Compact JSON with sorted keys: equal data give equal text."""
    return json.dumps(data, sort_keys=True, separators=(",", ":"), default=_plain)


def config_hash(config):
    """SHA-256 (hex) of a configuration (dict, or dataclass) in canonical JSON: stable across
    runs, key order and Python sessions; equal configurations give equal hashes."""
    if dataclasses.is_dataclass(config) and not isinstance(config, type):
        config = dataclasses.asdict(config)
    return hashlib.sha256(canonical_json(config).encode()).hexdigest()


class _Digest:
    """SHA-256 of a sequence of length-prefixed tokens (so that no two sequences collide by
    concatenation)."""

    def __init__(self):
        self.hash = hashlib.new(ALGORITHM)

    def token(self, data):
        if isinstance(data, str):
            data = data.encode("utf-8")
        view = memoryview(data).cast("B")
        self.hash.update(len(view).to_bytes(8, "little"))
        self.hash.update(view)


def _value(digest, value):
    """Feed an attribute value or a dataset's contents: type, dtype, shape, then the bytes."""
    if isinstance(value, h5py.Empty):
        digest.token("empty")
        digest.token(str(value.dtype))
        return
    if isinstance(value, str):
        digest.token("str")
        digest.token(value)
        return
    if isinstance(value, bytes):
        digest.token("bytes")
        digest.token(value)
        return
    array = np.asarray(value)
    digest.token("array")
    digest.token(str(array.shape))
    if array.dtype.kind == "O":         # variable-length strings or bytes
        digest.token("object")
        for item in array.reshape(-1):
            _value(digest, item)
        return
    array = np.ascontiguousarray(array)
    digest.token(array.dtype.str if array.dtype.fields is None else str(array.dtype.descr))
    digest.token(array.reshape(-1).view(np.uint8) if array.size else b"")


def _attributes(digest, obj, root):
    for name in sorted(obj.attrs):
        if root and name == CHECKSUM:
            continue
        digest.token("attribute")
        digest.token(name)
        _value(digest, obj.attrs[name])


def _tree(digest, group, root=False):
    _attributes(digest, group, root)
    for name in sorted(group):
        item = group.get(name, getlink=True)
        if isinstance(item, (h5py.SoftLink, h5py.ExternalLink)):
            digest.token("link")
            digest.token(name)
            digest.token(getattr(item, "path", ""))
            digest.token(getattr(item, "filename", ""))
            continue
        item = group[name]
        if isinstance(item, h5py.Group):
            digest.token("group")
            digest.token(name)
            _tree(digest, item)
        else:
            digest.token("dataset")
            digest.token(name)
            digest.token(str(item.dtype))
            digest.token(str(item.shape))
            _value(digest, h5py.Empty(item.dtype) if item.shape is None else item[()])
            _attributes(digest, item, False)
    digest.token("end")


@contextmanager
def _opened(handle_or_path, mode):
    if isinstance(handle_or_path, h5py.File):
        yield handle_or_path
    else:
        with h5py.File(handle_or_path, mode) as handle:
            yield handle


def checksum(handle_or_path):
    """"sha256:<hex>" of the file's content (module docstring), its ``checksum`` excepted."""
    with _opened(handle_or_path, "r") as handle:
        digest = _Digest()
        _tree(digest, handle, root=True)
    return f"{ALGORITHM}:{digest.hash.hexdigest()}"


def stamp(handle_or_path, identity):
    """Store ``identity`` (a JSON-able dict; ``software_version`` added when absent) and then
    the checksum of the whole content as root attributes of the HDF5 file (an open, writable
    h5py.File, or a path opened "r+"). Call it last, after every dataset and attribute is
    written. Returns the checksum."""
    if not isinstance(identity, dict):
        raise TypeError(f"identity must be a dict, got {type(identity).__name__}")
    identity = dict(identity)
    identity.setdefault("software_version", software_version())
    with _opened(handle_or_path, "r+") as handle:
        handle.attrs[IDENTITY] = canonical_json(identity)
        if CHECKSUM in handle.attrs:
            del handle.attrs[CHECKSUM]
        value = checksum(handle)
        handle.attrs[CHECKSUM] = value
    return value


def _text(value):
    return value.decode() if isinstance(value, bytes) else str(value)


def _differences(identity, expected):
    """"key = found in the file, wanted expected" for each key of ``expected`` that differs."""
    plain = json.loads(canonical_json(expected))
    return [f"{key} = {identity[key]!r} in the file, {value!r} expected" if key in identity
            else f"{key} absent from the file, {value!r} expected"
            for key, value in sorted(plain.items()) if identity.get(key, _ABSENT) != value]


def verify(path, expected_identity=None, kind="sample"):
    """Check the file ``path`` written with ``stamp``; return its identity (dict).

    ValueError naming the path and the reason: not a readable HDF5 file (truncated, foreign);
    no checksum (written by pendular before CHECKSUMS_SINCE: the message says what to do for
    this ``kind``: "sample", "checkpoint", "table cache"); checksum mismatch (edited or damaged
    since it was written); identity mismatch (a key of ``expected_identity`` differs, e.g. a
    checkpoint of another run; named with both values). FileNotFoundError for a missing file.
    """
    path = os.fspath(path)
    with reading(path, f"pendular {kind}"), h5py.File(path, "r") as handle:
        stored = handle.attrs.get(CHECKSUM)
        if stored is None:
            version = handle.attrs.get("version")
            version = f" of format version {_text(version)}" if version is not None else ""
            raise ValueError(
                f"path = {path!r} is not a checksummed pendular {kind}: it has no checksum (a "
                f"{kind}{version} written by pendular older than {CHECKSUMS_SINCE}, this is "
                f"{software_version()}, or a foreign file); files without a checksum are not "
                f"read: {_REMEDY.get(kind, 'make the file again with this pendular')}")
        actual = checksum(handle)
        if _text(stored) != actual:
            raise ValueError(
                f"path = {path!r}: checksum mismatch: this {kind} was edited or damaged after it "
                f"was written (stored {_text(stored)}, content {actual}); do not edit pendular "
                f"files by hand: make it again")
        try:
            identity = json.loads(_text(handle.attrs[IDENTITY]))
        except (KeyError, json.JSONDecodeError):
            identity = None
        if not isinstance(identity, dict):
            raise ValueError(f"path = {path!r}: this {kind} has a checksum but no readable "
                             "identity attribute (a JSON object)")
    if expected_identity:
        differences = _differences(identity, expected_identity)
        if differences:
            what = "; ".join(differences)
            raise ValueError(f"path = {path!r}: identity mismatch: {what}: this {kind} was made "
                             "by another run or configuration (or by a pendular whose "
                             "configurations had other fields)")
    return identity
