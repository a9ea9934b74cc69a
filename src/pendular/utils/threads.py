"""Numba's threading settings of a run, applied where a run starts (``Simulation``, the command
line, a campaign's worker), never on import.

Numba's OpenMP threading layer is preferred (it had the lowest launch overhead of the three on
the 2-core machine, docs/performance.md); Numba falls back to the next layer where OpenMP is
not available.

OpenMP threads wait for the next parallel region by spinning; with libgomp's default spin
(GOMP_SPINCOUNT 300,000) a two-thread run on a machine with one busy core ran several times
slower than on a quiet one. Unless the environment says otherwise, ``configure`` sets
GOMP_SPINCOUNT to 5,000 before OpenMP starts (docs/performance.md has the measurements).
``OPENMP_DEFAULTS`` holds what was set, so that programs started from here (YADE) run with
their own defaults.
"""

import os

import numba

#: Threading layers in the order Numba tries them.
THREADING_LAYERS = ["omp", "tbb", "workqueue"]
#: OpenMP settings pendular applied because the environment had none (name -> value).
OPENMP_DEFAULTS = {}


def configure():
    """Apply the threading settings (module docstring) if Numba has not started its threads
    yet; later calls change nothing. Call before the first parallel kernel of a run."""
    if numba.np.ufunc.parallel._is_initialized:
        return
    numba.config.THREADING_LAYER_PRIORITY = list(THREADING_LAYERS)
    if not OPENMP_DEFAULTS and not {"GOMP_SPINCOUNT", "OMP_WAIT_POLICY"} & set(os.environ):
        OPENMP_DEFAULTS["GOMP_SPINCOUNT"] = "5000"
        os.environ.update(OPENMP_DEFAULTS)


def use_threads(threads):
    """``configure``, then run Numba's parallel kernels on ``threads`` threads (an int in
    [1, NUMBA_NUM_THREADS])."""
    configure()
    numba.set_num_threads(threads)
