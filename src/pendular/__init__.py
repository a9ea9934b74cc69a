"""pendular: discrete elements for wet granular media in the pendular regime.

The public face of the engine (layers, each importing only those to its left:
dem <- capillary <- homogenize <- pendular <- scenarios):

- scenes: ``Simulation`` (state plus the declared step pipeline), ``Particles``, ``Walls``,
  ``NeighborList``, ``ContactForces``, ``WallForces``, ``StressServo``, ``ConstantStrainRate``,
  ``Integrator``, ``HistoryRecorder``, ``CapillaryBridges``;
- preparation: ``PrepareConfig``, ``prepare_sample``;
- test procedures: ``TriaxialConfig``, ``ShearConfig``, ``BridgeConfig``, ``TriaxialTest``,
  with the building blocks ``equilibrate``, ``wet``, ``TriaxialShear``, ``summarize``;
  ``TensionConfig``, ``TensionTest``; ``SwccConfig``, ``SwccTest`` (drying and wetting
  paths); campaigns of runs: ``Campaign``, ``Run``;
- results: ``read_history``, ``read_summary``.

Units are SI, stresses compression positive.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("pendular")
except PackageNotFoundError:      # a source tree that was not installed
    __version__ = "0+unknown"

from capillary import CapillaryBridges
from dem.contact_law import ContactForces
from dem.integrate import Integrator
from dem.neighbors import NeighborList
from dem.preparation import PrepareConfig, prepare_sample
from dem.record import HistoryRecorder
from dem.simulation import Simulation
from dem.state import Particles, Walls
from dem.walls import ConstantStrainRate, StressServo, WallForces

from .campaign import Campaign, Run
from .config import BridgeConfig, ShearConfig, SwccConfig, TensionConfig, TriaxialConfig
from .io import read_history, read_summary
from .swcc import SwccTest
from .tension import TensionTest
from .triaxial import TriaxialShear, TriaxialTest, equilibrate, summarize, wet

__all__ = [
    "BridgeConfig", "Campaign", "CapillaryBridges", "ConstantStrainRate", "ContactForces",
    "HistoryRecorder", "Integrator", "NeighborList", "Particles", "PrepareConfig", "Run",
    "ShearConfig", "Simulation", "StressServo", "SwccConfig", "SwccTest", "TensionConfig",
    "TensionTest",
    "TriaxialConfig", "TriaxialShear", "TriaxialTest", "WallForces", "Walls", "__version__",
    "equilibrate", "prepare_sample", "read_history", "read_summary", "summarize", "wet",
]
