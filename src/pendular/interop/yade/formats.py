"""Text files exchanged with YADE: sphere packings and ``yade.plot`` histories (pure numpy).

YADE is never imported here; these readers and writers only follow its file layouts, so that a
packing prepared by pendular can be loaded by a YADE cross-check script and its results read back.

Sphere files follow ``yade.export.textExt(filename, format='x_y_z_r')`` (YADE 2023.02)::

    #format x_y_z_r
    # box_lo 0 0 0 box_hi 0.0005 0.0005 0.0005      <- optional, pendular's wall box
    x<TAB>y<TAB>z<TAB>r
    ...

``yade.ymport.textExt(filename, format='x_y_z_r')`` reads it back: it takes the format from the
``#format`` line, skips every other line starting with ``#`` and expects no blank line. YADE
writes the numbers with ``%g`` (6 significant digits); we write them with 17 (exact round trip),
which ``ymport`` parses just as well. Units: metres.

Plot histories follow ``yade.plot.saveDataTxt(fileName, vars=None, headers=None)``: optional
header lines ``# key=<TAB>value``, then one line ``# name1<TAB><TAB>name2...`` naming the
columns, then one line per record with ``str(value)`` joined by tabs (``nan`` where a record
lacks a variable). A name ending in ``.gz`` or ``.bz2`` means gzip / bzip2 compression.
"""

import bz2
import gzip
import math
import os

import numpy as np

from pendular.utils.atomic import replacing
from pendular.utils.validate import reading

SPHERE_FORMAT = "x_y_z_r"
_BOX_TAGS = ("box_lo", "box_hi")


# ---------------------------------------------------------------------------------------------
# sphere packings
# ---------------------------------------------------------------------------------------------

def _check_box(box_lo, box_hi):
    """Return (lo, hi) as float arrays, or (None, None); both or neither must be given."""
    if box_lo is None and box_hi is None:
        return None, None
    if box_lo is None or box_hi is None:
        raise ValueError("box_lo and box_hi must be given together (or neither), "
                         f"got box_lo={box_lo!r}, box_hi={box_hi!r}")
    lo = np.asarray(box_lo, dtype=np.float64)
    hi = np.asarray(box_hi, dtype=np.float64)
    for name, corner in (("box_lo", lo), ("box_hi", hi)):
        if corner.shape != (3,):
            raise ValueError(f"{name} must hold 3 coordinates [m], got shape {corner.shape}")
        if not np.all(np.isfinite(corner)):
            raise ValueError(f"{name} = {corner.tolist()} m must be finite")
    if not np.all(hi > lo):
        raise ValueError(f"box_hi = {hi.tolist()} m must exceed box_lo = {lo.tolist()} m "
                         "on every axis")
    return lo, hi


def _number(value):
    """Shortest text that reads back as the same float64."""
    return repr(float(value))


def write_spheres(path, positions, radii, box_lo=None, box_hi=None):
    """Write spheres in YADE's ``export.textExt(format='x_y_z_r')`` layout; return their count.

    positions: (N, 3) centres [m]; radii: (N,) radii [m], > 0; box_lo, box_hi: optional inner
    corners of the wall box [m], recorded in a ``# box_lo ... box_hi ...`` comment line that YADE
    ignores and ``read_spheres`` returns. The file is written to a temporary file in the same
    folder and moved into place, so a reader never sees a partial file.
    """
    position = np.asarray(positions, dtype=np.float64)
    radius = np.asarray(radii, dtype=np.float64)
    if position.ndim != 2 or position.shape[1] != 3:
        raise ValueError(f"positions must have shape (N, 3) [m], got {position.shape}")
    if radius.shape != (position.shape[0],):
        raise ValueError(f"radii must have shape ({position.shape[0]},) to match positions, "
                         f"got {radius.shape}")
    if position.shape[0] == 0:
        raise ValueError("positions holds no sphere: a packing needs at least one")
    bad = np.argwhere(~np.isfinite(position))
    if bad.size:
        i, c = bad[0]
        raise ValueError(f"positions[{i}, {c}] = {position[i, c]} is not finite")
    bad = np.flatnonzero(~(np.isfinite(radius) & (radius > 0.0)))
    if bad.size:
        raise ValueError(f"radii[{bad[0]}] = {radius[bad[0]]} m must be finite and > 0")
    lo, hi = _check_box(box_lo, box_hi)

    lines = [f"#format {SPHERE_FORMAT}\n"]
    if lo is not None:
        lines.append("# box_lo " + " ".join(map(_number, lo))
                     + " box_hi " + " ".join(map(_number, hi)) + "\n")
    lines.extend("\t".join(map(_number, (*x, r))) + "\n" for x, r in zip(position, radius))

    path = os.fspath(path)
    with replacing(path) as temporary, open(temporary, "w", encoding="utf-8") as out:
        out.writelines(lines)
    return position.shape[0]


def _finite_number(path, lineno, label, word):
    """``word`` as a float; ValueError naming the file, the line and ``label`` (what the word
    is) when it is not a finite number."""
    try:
        value = float(word)
    except ValueError:
        raise ValueError(f"{path}, line {lineno}: {label} is not a number") from None
    if not math.isfinite(value):
        raise ValueError(f"{path}, line {lineno}: {label} is not finite")
    return value


def _parse_box(path, lineno, words):
    """Parse the words after '#' of a ``box_lo x y z box_hi x y z`` line."""
    if len(words) != 8 or words[0] != _BOX_TAGS[0] or words[4] != _BOX_TAGS[1]:
        raise ValueError(f"{path}, line {lineno}: box line must read "
                         f"'# box_lo x y z box_hi x y z', got {' '.join(words)!r}")
    corners = [np.array([_finite_number(path, lineno, f"box coordinate {word!r}", word)
                         for word in words[offset:offset + 3]]) for offset in (1, 5)]
    try:
        return _check_box(*corners)
    except ValueError as error:
        raise ValueError(f"{path}, line {lineno}: {error}") from None


def read_spheres(path):
    """Read a YADE ``x_y_z_r`` sphere file -> (positions (N, 3), radii (N,), box_lo, box_hi).

    All in metres, float64. box_lo and box_hi are the arrays of the ``# box_lo ... box_hi ...``
    line written by ``write_spheres``, or None when the file has none (e.g. from YADE itself).
    A missing ``#format`` line means ``x_y_z_r`` (as in ``ymport.textExt``). Raises ValueError
    naming the file and line for another format, a wrong column count, a value that is not a
    finite number, a radius <= 0, or a file without spheres. Blank lines are skipped.
    """
    path = os.fspath(path)
    rows = []
    box_lo = box_hi = None
    with reading(path, "YADE x_y_z_r sphere file"), open(path) as source:
        for lineno, line in enumerate(source, start=1):
            words = line.split()
            if not words:
                continue
            if words[0].startswith("#"):
                words[0] = words[0][1:]
                if not words[0]:
                    words = words[1:]
                if words and words[0] == "format":
                    if len(words) != 2 or words[1] != SPHERE_FORMAT:
                        raise ValueError(f"{path}, line {lineno}: unsupported sphere format "
                                         f"{' '.join(words[1:])!r}, expected {SPHERE_FORMAT!r}")
                elif words and words[0] == _BOX_TAGS[0]:
                    box_lo, box_hi = _parse_box(path, lineno, words)
                continue
            if len(words) != 4:
                raise ValueError(f"{path}, line {lineno}: expected 4 columns (x y z r), "
                                 f"got {len(words)}: {line.strip()!r}")
            values = [_finite_number(path, lineno, f"{name} = {word!r}", word)
                      for name, word in zip("xyzr", words)]
            if values[3] <= 0.0:
                raise ValueError(f"{path}, line {lineno}: radius r = {words[3]} must be > 0")
            rows.append(values)
    if not rows:
        raise ValueError(f"{path}: no sphere found")
    data = np.array(rows, dtype=np.float64)
    return np.ascontiguousarray(data[:, :3]), np.ascontiguousarray(data[:, 3]), box_lo, box_hi


# ---------------------------------------------------------------------------------------------
# yade.plot histories
# ---------------------------------------------------------------------------------------------

def _open_text(path):
    """Open for reading as text, decompressing as ``saveDataTxt`` compressed (by extension)."""
    if path.endswith(".bz2"):
        return bz2.open(path, "rt")
    if path.endswith(".gz"):
        return gzip.open(path, "rt")
    return open(path)


def _read_plot_file(path):
    """Return (headers dict, column names, rows as lists of strings, first data line number)."""
    path = os.fspath(path)
    comments = []
    names = None
    rows = []
    with reading(path, "yade.plot.saveDataTxt file"), _open_text(path) as source:
        for lineno, line in enumerate(source, start=1):
            text = line.rstrip("\r\n")
            if not text.strip():
                continue
            if names is None and text.lstrip().startswith("#"):
                comments.append((lineno, text.lstrip()[1:]))
                continue
            if names is None:
                if not comments:
                    raise ValueError(f"{path}, line {lineno}: expected a '# name1 name2 ...' "
                                     "line naming the columns before the data")
                names = comments.pop()[1].split()
                if not names:
                    raise ValueError(f"{path}: the column line holds no column name")
                if len(set(names)) != len(names):
                    raise ValueError(f"{path}: repeated column names in {names}")
            fields = text.split("\t")  # saveDataTxt joins values with tabs
            if len(fields) != len(names):
                fields = text.split()
            if len(fields) != len(names):
                raise ValueError(f"{path}, line {lineno}: expected {len(names)} values "
                                 f"({' '.join(names)}), got {len(fields)}: {text.strip()!r}")
            rows.append(fields)
    if names is None:
        if not comments:
            raise ValueError(f"{path}: empty file, expected a '# name1 name2 ...' column line")
        names = comments.pop()[1].split()
    headers = {}
    for lineno, comment in comments:
        key, sep, value = comment.partition("=")
        if not sep or not key.strip():
            raise ValueError(f"{path}, line {lineno}: header line must read '# key=value', "
                             f"got {'#' + comment!r}")
        headers[key.strip()] = value.strip()
    return headers, names, rows


def read_plot_data(path):
    """Read a ``yade.plot.saveDataTxt`` file -> dict column name -> numpy array (file order).

    Numeric columns (``nan``/``inf`` included, as ``addData`` pads missing values with nan) come
    back as float64; a column holding any value that is not a number comes back as an array of
    str. ``.gz`` / ``.bz2`` files are decompressed. Raises ValueError naming the file and line
    for a missing column line or a row with the wrong number of values.
    """
    _, names, rows = _read_plot_file(path)
    columns = {}
    for c, name in enumerate(names):
        values = [row[c] for row in rows]
        try:
            columns[name] = np.array([float(v) for v in values], dtype=np.float64)
        except ValueError:
            columns[name] = np.array(values, dtype=str)
    return columns


def read_plot_headers(path):
    """Return the ``headers`` given to ``saveDataTxt`` as a dict of str -> str (maybe empty)."""
    headers, _, _ = _read_plot_file(path)
    return headers
