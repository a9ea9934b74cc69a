"""YADE capillary files M(r=...): the data read by Law2_ScGeom_CapillaryPhys_Capillarity.

Layout (YADE's Tableau/TableauD readers, files written by its writesCapFile.m):

- line 1: the radius ratio r = R2/R1; line 2: the number n_D of distance blocks;
- then n_D blocks, in increasing distance. Each block starts with a line whose first number is
  its row count n (the rest of that line is ignored; writesCapFile writes "n 0 0 0 0 0 0 0"),
  followed by n rows of 8 numbers, in increasing suction:
  d* = D/R2, u* = s R2/gamma, V* = V/R2**3, F* = F/(2 pi gamma R2), delta1, delta2 (degrees;
  YADE takes the larger as the angle on the smaller sphere), nn11, nn33.
  All rows of a block share one distance (YADE reads it from the block's last row).
- distances are uniform from 0 to the rupture distance at zero suction; a block lists the
  suctions (from the given list) at which a stable bridge exists at its distance.

YADE loads M(r=1), M(r=1.1), M(r=1.25), M(r=1.5), M(r=1.75), M(r=2), M(r=3), M(r=4), M(r=5),
M(r=10) from its working directory and interpolates linearly in r, d* and u*.
"""

from dataclasses import dataclass
import math
from pathlib import Path

import numba
import numpy as np

from pendular.capillary.meniscus import bridge_kernel
from pendular.capillary.suction_control import rupture_point, stable_filling_angle
from pendular.capillary.table import write_bridge_fields
from pendular.utils.atomic import replacing
from pendular.utils.validate import reading

COLUMNS = ("distance", "suction", "volume", "force", "delta1", "delta2", "nn11", "nn33")


@dataclass(frozen=True)
class YadeCapillaryFile:
    """One capillary file: its radius ratio and its distance blocks, each an (n, 8) array in COLUMNS order."""

    radius_ratio: float
    blocks: tuple

    @property
    def distances(self):
        """d* of each block."""
        return np.array([block[-1, 0] for block in self.blocks])


def yade_file_name(radius_ratio):
    """File name YADE expects for a radius ratio: M(r=1), M(r=1.1), ..., M(r=10)."""
    return f"M(r={radius_ratio:g})"


@numba.njit(cache=True, parallel=True)
def yade_rows(radius_ratio, theta, suction_values, n_distance):
    """Exact stable bridges at YADE's (distance, suction) layout for one radius ratio; theta in rad.

    Returns (distances (n_distance,), rows (n_distance, n_suction, 8) in COLUMNS order, NaN
    where no stable bridge within delta1 <= 90 deg - theta exists).
    """
    n_u = suction_values.size
    largest = 0.5 * math.pi - theta
    delta1_rupture = np.empty(n_u)
    distance_rupture = np.empty(n_u)
    distance_low = np.empty(n_u)
    for k in numba.prange(n_u):
        delta1_rupture[k], distance_rupture[k] = rupture_point(radius_ratio, theta, suction_values[k])
        distance_low[k] = bridge_kernel(radius_ratio, theta, suction_values[k], largest)[0]
    distances = np.linspace(0.0, distance_rupture.max(), n_distance)
    rows = np.full((n_distance, n_u, 8), np.nan)
    for job in numba.prange(n_distance * n_u):
        j = job // n_u
        k = job % n_u
        d = min(distances[j], distance_rupture[k])  # the last block sits exactly at the largest rupture distance
        if distances[j] > distance_rupture[k] * (1.0 + 1e-12) or d < distance_low[k]:
            continue
        u = suction_values[k]
        delta1 = stable_filling_angle(radius_ratio, theta, u, d, delta1_rupture[k], distance_rupture[k])
        row = rows[j, k]
        row[0] = distances[j]
        row[1] = u
        write_bridge_fields(radius_ratio, theta, u, delta1, row[2:])
        row[2], row[3] = row[3], row[2]  # the table's fields start F*, V*; YADE's columns V*, F*
    return distances, rows


def write_yade(folder, contact_angle, radius_ratios, suction_values, n_distance=80):
    """Write one capillary file per radius ratio into folder; returns the paths.

    contact_angle in degrees; suction_values: increasing u* values (YADE's files use 350, from 0);
    n_distance: number of distance blocks (80 in YADE's files).
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    suction_values = np.ascontiguousarray(suction_values, dtype=np.float64)
    if np.any(np.diff(suction_values) <= 0.0) or suction_values[0] < 0.0:
        raise ValueError("suction_values must be non-negative and strictly increasing")
    paths = []
    for radius_ratio in radius_ratios:
        rows = yade_rows(float(radius_ratio), math.radians(contact_angle), suction_values, int(n_distance))[1]
        lines = [f"{radius_ratio:g}", f"{int(n_distance)}"]
        for j in range(int(n_distance)):
            block = rows[j][~np.isnan(rows[j, :, 0])]
            lines.append("\t".join([str(len(block))] + ["0"] * 7))
            lines.extend("\t".join(f"{x:.12g}" for x in row) for row in block)
        path = folder / yade_file_name(radius_ratio)
        with replacing(path) as temporary:
            Path(temporary).write_text("\n".join(lines) + "\n")
        paths.append(path)
    return paths


def write_table_files(table, folder, n_distance=80):
    """Write YADE capillary files M(r=...) for the radius ratios of ``table`` (a
    pendular.capillary.BridgeTable) at its contact angle and suctions (write_yade)."""
    return write_yade(folder, table.contact_angle, table.radius_ratios, table.suction,
                      n_distance)


def read_capillary_file(path):
    """Parse one capillary file as YADE does (whitespace-separated numbers); ValueError naming
    the path for a truncated or corrupt file."""
    with reading(path, "YADE capillary file"):
        numbers = Path(path).read_text().split("\n")
        radius_ratio = float(numbers[0].split()[0])
        n_blocks = int(float(numbers[1].split()[0]))
        blocks = []
        line = 2
        for _ in range(n_blocks):
            n_rows = int(float(numbers[line].split()[0]))
            if n_rows <= 0:
                raise ValueError(f"{path}: block {len(blocks)} has {n_rows} rows; YADE needs at least one")
            rows = [[float(x) for x in numbers[line + 1 + i].split()[:8]] for i in range(n_rows)]
            if any(len(row) != 8 for row in rows) or not np.all(np.isfinite(rows)):
                raise ValueError(f"path = {str(path)!r} is not a readable YADE capillary file: block "
                                 f"{len(blocks)} is not {n_rows} rows of 8 finite numbers")
            rows = np.array(rows)
            blocks.append(rows)
            line += 1 + n_rows
    return YadeCapillaryFile(radius_ratio, tuple(blocks))


def read_yade(folder, radius_ratios=None):
    """Read the capillary files M(r=...) of a folder: {radius_ratio: YadeCapillaryFile}.

    radius_ratios: which files to read (default: every M(r=...) file in the folder).
    """
    folder = Path(folder)
    if radius_ratios is None:
        paths = sorted(folder.glob("M(r=*)"), key=lambda p: float(p.name[4:-1]))
    else:
        paths = [folder / yade_file_name(r) for r in radius_ratios]
    files = [read_capillary_file(path) for path in paths]
    return {f.radius_ratio: f for f in files}
