"""The one place that imports the CUDA target (numba-cuda; a switch to numba-cuda-mlir is the
import line below: ``from numba_cuda_mlir import cuda``).

Everything in pendular.gpu reaches CUDA through this module and uses only the kernel API both
packages share: ``cuda.jit`` (kernels and ``device=True`` functions), ``cuda.grid``,
``cuda.atomic.add`` on integers, ``cuda.to_device``, ``cuda.device_array``,
``copy_to_host``. A kernel's arguments are arrays, numbers and booleans: numba-cuda compiles
a kernel for a None argument but cannot launch it on a GPU (the simulator would). With
``NUMBA_ENABLE_CUDASIM=1`` the same code runs in Numba's CUDA simulator (Python per thread:
slow, for tests on tens of spheres).

One source for both targets (``device_twin``): the GPU runs the CPU's own laws (the contact
law, the bridge table's lookup, ...), compiled from the CPU functions' code. A device function
can call device functions only, not the CPU's Numba dispatchers, so the twin of a CPU function
is its Python code object in a new function whose globals name, instead of each CPU
dispatcher the code calls, that dispatcher's own twin (made the same way, once each): the
device compiles the whole call tree from the CPU's source, and a change to a CPU law changes
the GPU's. A CPU function meant for both targets keeps to what both compile (``math`` on
scalars rather than NumPy's ufuncs, which the CUDA target lacks on scalars); its checks
(``raise``) compile too, and on the device end the thread quietly (no debug build), so the
host checks the ranges once before a run.
"""

import os
import types

from numba import cuda
from numba.core.registry import CPUDispatcher

#: Threads per block of every launch over particles (fewer when there are fewer items: the
#: simulator runs one Python thread per thread of a block).
THREADS = 128

#: CPU dispatcher -> its device twin (device_twin), each made once.
_TWINS = {}


def device(function):
    """``function`` (plain Python math over scalars and arrays) as a CUDA device function."""
    return cuda.jit(device=True)(function)


def device_twin(cpu_function):
    """The device function compiled from the source of ``cpu_function`` (a Numba CPU
    dispatcher, ``numba.njit``), the CPU dispatchers it calls by global name replaced by their
    own twins (module docstring); the same twin for the same function. Its globals are those
    of the CPU function's module when the twin is made; a dispatcher reached otherwise (a
    module's attribute) is not replaced, and the device compiler rejects the call."""
    twin = _TWINS.get(cpu_function)
    if twin is None:
        source = cpu_function.py_func
        names = dict(source.__globals__)
        for name in source.__code__.co_names:
            if isinstance(names.get(name), CPUDispatcher):
                names[name] = device_twin(names[name])
        clone = types.FunctionType(source.__code__, names, source.__name__,
                                   source.__defaults__, source.__closure__)
        clone.__doc__ = source.__doc__
        twin = _TWINS[cpu_function] = device(clone)
    return twin


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
