"""Compile every kernel of a dry and a wet step for a real GPU (PTX for compute capability 9.0,
an H100) without one, as a script in its own process: the simulator runs kernels as Python and
would not see code that the CUDA target cannot compile (a NumPy ufunc, a global it cannot
type). Needs NVVM and NVRTC (``pip install nvidia-nvvm nvidia-cuda-nvrtc`` with CUDA_HOME at
their nvidia/cu13 folder); prints {"skip": reason} without them, else {kernel: PTX lines}.

Arrays stay on the host (the kernels' argument types are those of the device arrays), and
device functions are compiled for compute capability 9.0 where numba-cuda would ask a driver.
"""

import json
import sys
import types

import numba
import numpy as np

from numba import cuda
import numba.cuda.dispatcher as dispatcher

from simulated import scene


class HostArray(np.ndarray):
    """A host array standing for a device array (the copies the simulation makes)."""

    def copy_to_device(self, values):
        self[...] = values

    def copy_to_host(self, out=None):
        return np.array(self)


def main():
    try:
        cuda.compile_ptx(lambda a: None, (numba.float64[:],), cc=(9, 0))
    except Exception as error:  # no NVVM or NVRTC here: nothing to check
        print(json.dumps({"skip": f"{type(error).__name__}: {str(error).splitlines()[0]}"}))
        return
    dispatcher.get_current_device = lambda: types.SimpleNamespace(compute_capability=(9, 0))
    cuda.to_device = lambda values: np.array(values, copy=True).view(HostArray)
    from pendular.gpu import GpuSimulation

    compiled = {}
    for wet in (False, True):
        gpu = GpuSimulation(scene(wet=wet))
        gpu._configure()
        for kernel, _, args in gpu._steps:
            signature = tuple(numba.typeof(np.asarray(a) if isinstance(a, np.ndarray) else a)
                              for a in args)
            ptx, _ = cuda.compile_ptx(kernel.py_func, signature, cc=(9, 0))
            compiled[f"{kernel.py_func.__name__}{' wet' if wet else ''}"] = ptx.count("\n")
    print(json.dumps(compiled))


if __name__ == "__main__":
    sys.exit(main())
