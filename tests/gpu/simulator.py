"""What the GPU tests share: a script run under Numba's CUDA simulator in a process of its own
(``simulated``), the relative difference they judge (``relative``) and a count of the state's
copies back from the device (``counted_copies``).

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


def simulated(script, *arguments, timeout=600):
    """The JSON object that ``script`` (a file of tests/gpu, or a path) prints last, run with
    ``arguments`` under the simulator (NUMBA_ENABLE_CUDASIM=1) in a process of its own; the
    test fails with the script's error when it fails."""
    environment = dict(os.environ, NUMBA_ENABLE_CUDASIM="1")
    done = subprocess.run([sys.executable, os.path.join(HERE, script), *arguments],
                          capture_output=True, text=True, env=environment, cwd=ROOT,
                          timeout=timeout)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


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
