"""Numba's CUDA simulator made faster for the GPU tests, loaded at the start of every process
the tests run under it (tests/gpu/simulator.py puts this folder first on PYTHONPATH).

The simulator runs each CUDA thread of a block as a Python thread polled by a busy loop, and
calls a device function through a wrapper that scans the function's module globals at every
call, and reads each element of a device array through two wrappers. pendular's kernels use
no block synchronisation (no syncthreads, no shared memory: each thread reads and writes
global memory alone, integer atomics aside), so a block's threads run here one after the
other in the process's own thread on the NumPy arrays the device arrays wrap, and a device
function that uses no CUDA API (no ``cuda`` in its code) is called as the plain Python
function it is: a kernel runs as a copy of its function whose globals (and closure) name,
instead of each such device function, that function's own plain copy, made the same way
once (as pendular.gpu.cuda.device_twin makes a twin), so that a call costs what a Python call
costs. Results are the same bit for bit, several times sooner. A kernel that did
synchronise its block would fail at once (the main thread has no ``syncthreads``), not run
wrong.
"""

import os

if os.environ.get("NUMBA_ENABLE_CUDASIM") == "1":
    import threading
    import types

    import numpy as np
    from numba.cuda.simulator import kernel as _kernel
    from numba.cuda.simulator.cudadrv.devicearray import (FakeCUDAArray,
                                                          FakeWithinKernelCUDAArray)
    from numba.cuda.simulator.kernelapi import Dim3, FakeCUDAModule

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

    #: function -> its copy calling plain copies of the device functions it names (_flat).
    _FLAT = {}

    def _flat(function):
        """``function`` with each device function without CUDA calls that its globals or its
        closure name replaced by that function's own plain copy (made once; ``function``
        itself when it names none)."""
        flat = _FLAT.get(function)
        if flat is not None:
            return flat
        _FLAT[function] = function          # a call cycle ends here
        names = function.__globals__
        plain = {name: _flat(names[name].fn) for name in _names(function.__code__)
                 if _plain_device(names.get(name))}
        closure = function.__closure__
        if closure is not None and any(_plain_device(_content(cell)) for cell in closure):
            closure = tuple(types.CellType(_flat(_content(cell).fn))
                            if _plain_device(_content(cell)) else cell for cell in closure)
        if plain or closure is not function.__closure__:
            flat = types.FunctionType(function.__code__, {**names, **plain},
                                      function.__name__, function.__defaults__, closure)
            flat.__kwdefaults__ = function.__kwdefaults__
            _FLAT[function] = flat
        return _FLAT[function]

    def _content(cell):
        """What a closure's cell holds (None when empty)."""
        try:
            return cell.cell_contents
        except ValueError:
            return None

    #: kernel -> the names of its globals that a launch sets to the simulated CUDA module.
    _CUDA_NAMES = {}

    def _run_block_serially(self, grid_point, *args):
        """BlockManager.run: the block's threads one after the other in this thread, reading
        and writing the device arrays as plain NumPy arrays, the kernel's plain copy
        (_flat) given the simulated CUDA module that the launch put in the kernel's
        globals."""
        thread = threading.current_thread()
        thread.blockIdx = Dim3(*grid_point)
        args = [_plain(argument) for argument in args]
        kernel = _flat(self._f)
        if kernel is not self._f:
            launched = self._f.__globals__
            names = _CUDA_NAMES.get(self._f)
            if names is None:
                names = _CUDA_NAMES[self._f] = [
                    name for name in _names(self._f.__code__)
                    if isinstance(launched.get(name), FakeCUDAModule)]
            for name in names:
                kernel.__globals__[name] = launched[name]
        for block_point in np.ndindex(*self._block_dim):
            thread.threadIdx = Dim3(*block_point)
            kernel(*args)

    _call = _kernel.FakeCUDAKernel.__call__

    def _call_plainly(self, *args):
        """FakeCUDAKernel.__call__, a device function without CUDA calls called directly."""
        if self._device and "cuda" not in self.fn.__code__.co_names:
            return self.fn(*args)
        return _call(self, *args)

    _kernel.BlockManager.run = _run_block_serially
    _kernel.FakeCUDAKernel.__call__ = _call_plainly
