"""The GPU engine (issue 38): a walled scene's step on one GPU with Numba's CUDA target
(numba-cuda, ``pip install -e '.[gpu]'``; the CUDA import lives in pendular.gpu.cuda alone).

``GpuSimulation(sim).run(steps)`` runs a pendular.dem.simulation.Simulation's scene on the
device (pendular.gpu.simulation says what runs there so far); docs/gpu.md tells how it is
checked. Importing pendular.gpu needs numba-cuda; nothing else in pendular imports it.
"""

from pendular.gpu.simulation import GpuSimulation, check_scene

__all__ = ["GpuSimulation", "check_scene"]
