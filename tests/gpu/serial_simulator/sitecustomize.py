"""Numba's CUDA simulator made faster for the GPU tests, loaded at the start of every process
the tests run under it (tests/gpu/simulator.py puts this folder first on PYTHONPATH).

The simulator runs each CUDA thread of a block as a Python thread polled by a busy loop, and
calls a device function through a wrapper that scans the function's module globals at every
call, and reads each element of a device array through two wrappers. pendular's kernels use
no block synchronisation (no syncthreads, no shared memory: each thread reads and writes
global memory alone, integer atomics aside), so a block's threads run here one after the
other in the process's own thread on the NumPy arrays the device arrays wrap, and a device
function that uses no CUDA API (no ``cuda`` in its code) is called as the plain Python
function it is: a kernel runs as a copy of its function whose globals name, instead of each
such device function, that function's own copy made the same way (as
pendular.gpu.cuda.device_twin makes a twin), so that a call costs what a Python call costs.
Results are the same bit for bit, several times sooner. A kernel that did synchronise its
block would fail at once (the main thread has no ``syncthreads``), not run wrong.
"""

import os

if os.environ.get("NUMBA_ENABLE_CUDASIM") == "1":
    import threading
    import types

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

    def _names(code):
        """The global names that ``code`` and the code nested in it (comprehensions, inner
        functions) read."""
        names = set(code.co_names)
        for constant in code.co_consts:
            if isinstance(constant, types.CodeType):
                names |= _names(constant)
        return names

    def _plain_device(value):
        """Whether ``value`` is a device function that uses no CUDA API."""
        return (isinstance(value, _kernel.FakeCUDAKernel) and value._device
                and "cuda" not in _names(value.fn.__code__))

    class _PlainCalls:
        """A kernel's function as a copy whose globals name, instead of each device function
        without CUDA calls, that function's own copy, made the same way down the call tree;
        each copy's other globals read from the original's at each launch (``current``), as
        the simulator's kernel reads its module's."""

        def __init__(self, kernel):
            #: (a copy's globals, the original's, the names read from them, the device
            #: functions replaced in them by name).
            self.links = []
            self.kernel = self._copy(kernel, {})

        def _copy(self, function, made):
            if function in made:
                return made[function]
            made[function] = function       # a call cycle ends here
            original = function.__globals__
            read = _names(function.__code__)
            devices = {name: original[name] for name in read
                       if _plain_device(original.get(name))}
            if not devices:
                return function
            scope = dict(original)
            scope.update({name: self._copy(device.fn, made) for name, device in devices.items()})
            made[function] = types.FunctionType(function.__code__, scope, function.__name__,
                                                function.__defaults__, function.__closure__)
            made[function].__kwdefaults__ = function.__kwdefaults__
            self.links.append((scope, original, sorted(read - devices.keys()), devices))
            return made[function]

        def current(self):
            """Whether the device functions replaced are still those the originals' globals
            name; if so, each copy's other globals read again from the original's."""
            for scope, original, names, devices in self.links:
                if any(original.get(name) is not device for name, device in devices.items()):
                    return False
                for name in names:
                    if name in original:
                        scope[name] = original[name]
                    else:
                        scope.pop(name, None)
            return True

    #: kernel function -> its _PlainCalls.
    _PLAIN_CALLS = {}

    def _run_block_serially(self, grid_point, *args):
        """BlockManager.run: the block's threads one after the other in this thread, reading
        and writing the device arrays as plain NumPy arrays, the kernel's device functions
        called plainly (_PlainCalls)."""
        thread = threading.current_thread()
        thread.blockIdx = Dim3(*grid_point)
        args = [_plain(argument) for argument in args]
        plain = _PLAIN_CALLS.get(self._f)
        if plain is None or not plain.current():
            plain = _PLAIN_CALLS[self._f] = _PlainCalls(self._f)
        for block_point in np.ndindex(*self._block_dim):
            thread.threadIdx = Dim3(*block_point)
            plain.kernel(*args)

    _call = _kernel.FakeCUDAKernel.__call__

    def _call_plainly(self, *args):
        """FakeCUDAKernel.__call__, a device function without CUDA calls called directly."""
        if self._device and "cuda" not in self.fn.__code__.co_names:
            return self.fn(*args)
        return _call(self, *args)

    _kernel.BlockManager.run = _run_block_serially
    _kernel.FakeCUDAKernel.__call__ = _call_plainly
