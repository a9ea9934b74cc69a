"""Numba's CUDA simulator made faster for the GPU tests, loaded at the start of every process
the tests run under it (tests/gpu/simulator.py puts this folder first on PYTHONPATH).

The simulator runs each CUDA thread of a block as a Python thread polled by a busy loop, and
calls a device function through a wrapper that scans the function's module globals at every
call, and reads each element of a device array through two wrappers. pendular's kernels use
no block synchronisation (no syncthreads, no shared memory: each thread reads and writes
global memory alone, integer atomics aside), so a block's threads run here one after the
other in the process's own thread on the NumPy arrays the device arrays wrap, and a device
function that uses no CUDA API (no ``cuda.`` in its code) is called as the plain Python
function it is. Results are the same bit for bit, several times sooner. A kernel that did
synchronise its block would fail at once (the main thread has no ``syncthreads``), not run
wrong.
"""

import os

if os.environ.get("NUMBA_ENABLE_CUDASIM") == "1":
    import threading

    import numpy as np
    from numba.cuda.simulator import kernel as _kernel
    from numba.cuda.simulator.cudadrv.devicearray import (FakeCUDAArray,
                                                          FakeWithinKernelCUDAArray)
    from numba.cuda.simulator.kernelapi import Dim3

    def _plain(argument):
        """A kernel's argument with the simulator's device arrays as the NumPy arrays they
        wrap (the same memory), in tuples (bundles of arrays) too."""
        if isinstance(argument, FakeWithinKernelCUDAArray):
            argument = argument._item
        if isinstance(argument, FakeCUDAArray):
            return argument._ary
        if isinstance(argument, tuple):
            values = [_plain(value) for value in argument]
            return type(argument)(*values) if hasattr(argument, "_fields") else tuple(values)
        return argument

    def _run_block_serially(self, grid_point, *args):
        """BlockManager.run: the block's threads one after the other in this thread, reading
        and writing the device arrays as plain NumPy arrays."""
        thread = threading.current_thread()
        thread.blockIdx = Dim3(*grid_point)
        args = [_plain(argument) for argument in args]
        for block_point in np.ndindex(*self._block_dim):
            thread.threadIdx = Dim3(*block_point)
            self._f(*args)

    _call = _kernel.FakeCUDAKernel.__call__

    def _call_plainly(self, *args):
        """FakeCUDAKernel.__call__, a device function without CUDA calls called directly."""
        if self._device and "cuda" not in self.fn.__code__.co_names:
            return self.fn(*args)
        return _call(self, *args)

    _kernel.BlockManager.run = _run_block_serially
    _kernel.FakeCUDAKernel.__call__ = _call_plainly
