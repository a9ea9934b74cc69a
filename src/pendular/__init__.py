"""pendular: discrete elements for wet granular media in the pendular regime.

One namespace; its sub-packages are layers, each importing only those to its left:
``pendular.dem`` (the engine) <- ``pendular.capillary`` (liquid bridges) <-
``pendular.homogenize`` (effective stress) <- the procedures, studies and command line of
``pendular`` itself <- scenarios. The public names below are imported on first use:

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

from importlib import import_module

#: Public name -> the module that defines it. Imported on first use, so that ``import
#: pendular.dem`` (or the command line) loads only what it needs.
_EXPORTS = {
    "CapillaryBridges": "pendular.capillary",
    "ContactForces": "pendular.dem.contact_law",
    "Integrator": "pendular.dem.integrate",
    "NeighborList": "pendular.dem.neighbors",
    "PrepareConfig": "pendular.dem.preparation",
    "prepare_sample": "pendular.dem.preparation",
    "HistoryRecorder": "pendular.dem.record",
    "Simulation": "pendular.dem.simulation",
    "Particles": "pendular.dem.state",
    "Walls": "pendular.dem.state",
    "ConstantStrainRate": "pendular.dem.walls",
    "StressServo": "pendular.dem.walls",
    "WallForces": "pendular.dem.walls",
    "Campaign": "pendular.campaign",
    "Run": "pendular.campaign",
    "BridgeConfig": "pendular.config",
    "ShearConfig": "pendular.config",
    "SwccConfig": "pendular.config",
    "TensionConfig": "pendular.config",
    "TriaxialConfig": "pendular.config",
    "read_history": "pendular.io",
    "read_summary": "pendular.io",
    "SwccTest": "pendular.swcc",
    "TensionTest": "pendular.tension",
    "TriaxialShear": "pendular.triaxial",
    "TriaxialTest": "pendular.triaxial",
    "equilibrate": "pendular.triaxial",
    "summarize": "pendular.triaxial",
    "wet": "pendular.triaxial",
}

__all__ = sorted([*_EXPORTS, "__version__"])


def __getattr__(name):
    if name == "__version__":
        from importlib.metadata import PackageNotFoundError, version

        try:
            value = version("pendular")
        except PackageNotFoundError:      # a source tree that was not installed
            value = "0+unknown"
    elif name in _EXPORTS:
        value = getattr(import_module(_EXPORTS[name]), name)
    else:
        raise AttributeError(f"module 'pendular' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__():
    return __all__
