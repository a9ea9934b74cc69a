"""The one place that imports the CUDA target (numba-cuda; a switch to numba-cuda-mlir is the
import line below: ``from numba_cuda_mlir import cuda``).

Everything in pendular.gpu reaches CUDA through this module and uses only the kernel API both
packages share: ``cuda.jit`` (kernels and ``device=True`` functions), ``cuda.grid``,
``cuda.atomic.add`` on integers, ``cuda.to_device``, ``cuda.device_array``,
``copy_to_host``. With ``NUMBA_ENABLE_CUDASIM=1`` the same code runs in Numba's CUDA simulator
(Python per thread: slow, for tests on tens of spheres).
"""

import os

from numba import cuda

#: Threads per block of every launch over particles (fewer when there are fewer items: the
#: simulator runs one Python thread per thread of a block).
THREADS = 128


def device(function):
    """``function`` (plain Python math over scalars and arrays) as a CUDA device function."""
    return cuda.jit(device=True)(function)


def configured(kernel, items):
    """``kernel`` set to run over ``items`` threads (at least one) in blocks of THREADS: call
    it with the kernel's arguments."""
    threads = max(1, min(THREADS, items))
    return kernel[max(1, -(-items // threads)), threads]


def simulated():
    """Whether Numba's CUDA simulator stands in for a GPU (NUMBA_ENABLE_CUDASIM=1)."""
    return os.environ.get("NUMBA_ENABLE_CUDASIM", "0") == "1"


def unavailable():
    """Why the GPU path cannot run here (text), or None: numba-cuda missing (Numba's own,
    deprecated CUDA target in its place), or no GPU visible and not the simulator."""
    if getattr(cuda, "implementation", None) == "Built-in":
        return "numba-cuda is not installed; install it with pip install -e '.[gpu]'"
    if not cuda.is_available():
        return ("no CUDA GPU is visible (numba.cuda.is_available() is False); use the CPU "
                "(device 'cpu'), or Numba's CUDA simulator (NUMBA_ENABLE_CUDASIM=1) for tests")
    return None
