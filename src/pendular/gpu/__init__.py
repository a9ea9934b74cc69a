"""The GPU engine: a walled scene's step on one GPU with Numba's CUDA target
(numba-cuda, ``pip install -e '.[gpu]'``; the CUDA import lives in pendular.gpu.cuda alone).

``Simulation(..., device="gpu")`` runs a pendular.dem.simulation.Simulation's scene on the
device through ``GpuSimulation(sim).run(steps)`` (pendular.gpu.simulation says what runs
there so far); docs/gpu.md tells how it is checked. Importing pendular.gpu needs numba-cuda
and registers the device "gpu" with pendular.dem.simulation, which imports it by name when a
Simulation first asks for it (the layers' one plug-in point, docs/architecture.md); nothing
else in pendular imports it.
"""

from pendular.dem.simulation import register_device
from pendular.gpu.cuda import unavailable
from pendular.gpu.simulation import GpuSimulation, check_scene

register_device("gpu", GpuSimulation, unavailable)

__all__ = ["GpuSimulation", "check_scene"]
