"""Time the YADE-equivalent capillary table set: 10 radius ratios x 350 suctions x 80 distances, theta = 0.

Usage: python benchmarks/bench_tables.py [--threads N] [--volume]
Prints seconds for: the BridgeTable (exact stable bridge at every node), the ten YADE files
M(r=1) ... M(r=10) (exact bridges at YADE's 80 distances x 350 suctions), and optionally the
volume-controlled table (10 x 80 volumes x 80 distances). Numba compilation is excluded
(a warm-up build runs first).
"""

import argparse
import tempfile
import time

import numba

from pendular import capillary
from pendular.interop.yade.capillary_files import write_table_files


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS)
    parser.add_argument("--volume", action="store_true", help="also time the volume-controlled table")
    arguments = parser.parse_args()
    numba.set_num_threads(arguments.threads)
    with tempfile.TemporaryDirectory() as folder:
        warm = capillary.BridgeTable.build(0.0, radius_ratios=(1.0,), n_suction=3, n_distance=3)
        write_table_files(warm, folder, n_distance=3)
        start = time.perf_counter()
        table = capillary.BridgeTable.build(0.0)
        built = time.perf_counter()
        write_table_files(table, folder)
        written = time.perf_counter()
    print(f"threads: {arguments.threads}")
    print(f"BridgeTable 10 x 350 x 80 (theta = 0): {built - start:.1f} s")
    print(f"YADE files M(r=1) ... M(r=10), 80 distances x 350 suctions: {written - built:.1f} s")
    print(f"total: {written - start:.1f} s")
    if arguments.volume:
        start = time.perf_counter()
        capillary.VolumeBridgeTable.build(0.0, workers=arguments.threads)
        print(f"VolumeBridgeTable 10 x 80 x 80 (theta = 0): {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()
