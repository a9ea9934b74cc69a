"""Compile every kernel of a dry and a wet step (and a radius growth's, a periodic cell's
dry and wet, a simple shear's, the grips', the rolling resistance's and gravity's, the walls'
springs and rolling resistance, the liquid clusters') for a real GPU (PTX,
by default for compute capability 9.0, an H100) without one, as a script in its own process:
the simulator runs kernels as Python and would not see code that the CUDA target cannot
compile (a NumPy ufunc, a global it cannot type).

It needs NVVM and NVRTC. The gpu extra installs CUDA 13's (the wheels nvidia-nvvm and
nvidia-cuda-nvrtc, in site-packages/nvidia/cu13), which numba-cuda finds there itself
(through cuda-pathfinder; no CUDA_HOME needed). Where those wheels are installed, a compiler
is expected: any failure to compile, the first small kernel's included, ends the script with
an error. Without them it tries a CUDA toolkit found otherwise (CUDA_HOME, the system's) and
prints {"skip": reason} when there is none. Else it prints {"wheels": the wheels' folder (or
null), "kernels": {kernel: PTX lines}}.

``python compile_ptx.py [MAJOR.MINOR]`` compiles for another compute capability.

Arrays stay on the host (the kernels' argument types are those of the device arrays), and
device functions are compiled for the compute capability asked where numba-cuda would ask a
driver. NVVM compiles without its optimisation passes (``opt=False``, NVVM's -opt=0): code
that Numba's CUDA target or NVVM rejects is rejected at every level, and the passes, which a
GPU's own run applies to code that compiles, are most of NVVM's time.
"""

import json
import sys
import types
from importlib.metadata import PackageNotFoundError, distribution
from pathlib import Path

import numpy as np

#: The gpu extra's compiler wheels (pyproject.toml), both in site-packages/nvidia/cu13.
COMPILER_WHEELS = ("nvidia-nvvm", "nvidia-cuda-nvrtc")


def extra_compiler_folder():
    """The folder (lib/, nvvm/) of the gpu extra's NVVM, or None unless both of its compiler
    wheels are installed."""
    try:
        nvvm, _ = (distribution(name) for name in COMPILER_WHEELS)
    except PackageNotFoundError:
        return None
    return Path(nvvm.locate_file("nvidia/cu13"))


class HostArray(np.ndarray):
    """A host array standing for a device array (the copies the simulation makes)."""

    def copy_to_device(self, values):
        self[...] = values

    def copy_to_host(self, out=None):
        return np.array(self)


def plain(argument):
    """``argument`` with its host arrays as plain ndarrays, in tuples (a kernel's bundles of
    arrays) too."""
    if isinstance(argument, np.ndarray):
        return np.asarray(argument)
    if isinstance(argument, tuple):
        values = [plain(value) for value in argument]
        return type(argument)(*values) if hasattr(argument, "_fields") else tuple(values)
    return argument


def signature(arguments):
    """The Numba types of a kernel's ``arguments``."""
    import numba

    return tuple(numba.typeof(plain(argument)) for argument in arguments)


def compile_step_kernels(cuda, capability):
    """{kernel (and " wet"): PTX lines} of every kernel of a dry and a wet step, and of the
    homogenisation at a record step (pendular.gpu.homogenize). A kernel reached again with
    the same argument types (a dry and a wet step's leapfrog) is compiled once."""
    import numba.cuda.dispatcher as dispatcher

    lines = {}

    def ptx_lines(kernel, args):
        """The lines of ``kernel``'s PTX for the types of ``args``."""
        key = (kernel.py_func, signature(args))
        if key not in lines:
            ptx, _ = cuda.compile_ptx(kernel.py_func, key[1], cc=capability, opt=False)
            lines[key] = ptx.count("\n")
        return lines[key]

    dispatcher.get_current_device = lambda: types.SimpleNamespace(
        compute_capability=capability)
    cuda.to_device = lambda values: np.array(values, copy=True).view(HostArray)
    from pendular.gpu import GpuSimulation
    from pendular.gpu.homogenize import COLUMNS, launches
    from simulated import scene

    compiled = {}
    for wet in (False, True):
        gpu = GpuSimulation(scene(wet=wet))
        gpu.configure()
        reduction = launches(gpu, np.zeros((2, COLUMNS)), np.zeros(COLUMNS))
        # wet, the bridges' refresh at a new suction (a suction path, between runs)
        refresh = (gpu.bridges.refresh_step(gpu.state),) if wet else ()
        for kernel, _, args in (*gpu.steps, *reduction, *refresh):
            compiled[f"{kernel.py_func.__name__}{' wet' if wet else ''}"] = ptx_lines(kernel,
                                                                                  args)
    # the kernels a radius growth adds to a dry step (growth_checks.py's scene), those of a
    # dry and a wet step in a periodic cell (periodic_checks.py's), of a simple shear
    # (shear_checks.py's), the grips' (grips_checks.py's), volume-controlled bridges'
    # liquid exchange (volume_checks.py's), the rolling resistance and gravity
    # (rolling_checks.py's), the sphere-wall bridges (wall_bridges_checks.py's), the walls'
    # springs and rolling resistance (wall_friction_checks.py's), the liquid clusters'
    # (clusters_checks.py's)
    from clusters_checks import scene as clusters_scene
    from grips_checks import scene as grips_scene
    from growth_checks import scene as growth_scene
    from periodic_checks import scene as periodic_scene
    from rolling_checks import scene as rolling_scene
    from shear_checks import scene as shear_scene
    from volume_checks import scene as volume_scene
    from wall_bridges_checks import scene as wall_bridges_scene
    from wall_friction_checks import scene as wall_friction_scene

    for sim, label in ((growth_scene(), ""), (periodic_scene(), " periodic"),
                       (periodic_scene(wet=True), " periodic wet"),
                       (shear_scene(), " sheared"),
                       (grips_scene(wet=False)[0], ""), (volume_scene()[0], " volume"),
                       (rolling_scene(), ""), (wall_bridges_scene(), ""),
                       (wall_friction_scene(rolling=True), ""), (clusters_scene()[0], "")):
        gpu = GpuSimulation(sim)
        gpu.configure()
        for kernel, _, args in gpu.steps:
            name = kernel.py_func.__name__
            if name not in compiled and f"{name}{label}" not in compiled:
                compiled[f"{name}{label}"] = ptx_lines(kernel, args)
    return compiled


def main(arguments):
    capability = tuple(int(part) for part in (arguments[0] if arguments else "9.0").split("."))
    folder = extra_compiler_folder()
    import numba
    from numba import cuda

    try:
        cuda.compile_ptx(lambda a: None, (numba.float64[:],), cc=capability)
    except Exception as error:
        if folder is not None:      # the gpu extra's compiler is installed: a failure
            raise
        print(json.dumps({"skip": f"{type(error).__name__}: {str(error).splitlines()[0]}"}))
        return 0
    print(json.dumps({"wheels": None if folder is None else str(folder),
                      "kernels": compile_step_kernels(cuda, capability)}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
