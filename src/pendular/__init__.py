"""pendular: discrete elements for wet granular media in the pendular regime.

One namespace; its sub-packages are layers, each importing only those to its left:
``pendular.dem`` (the engine) <- ``pendular.capillary`` (liquid bridges) <-
``pendular.homogenize`` (effective stress) <- the procedures, studies and command line of
``pendular`` itself <- scenarios. The public names below are imported on first use:

- scenes: ``Simulation`` (state plus the declared step pipeline), ``Particles``, ``Walls``,
  ``NeighborList``, ``ContactForces``, ``WallForces``, ``StressServo``, ``ConstantStrainRate``,
  ``ConstantVolume``, ``Integrator``, ``HistoryRecorder``, ``CapillaryBridges``;
- preparation: ``PrepareConfig``, ``prepare_sample``;
- loading paths: ``Stage`` (per-axis stress or strain-rate control, ends at a ``Strain``, a
  ``Stress`` or ``Static``), ``LoadingPath``; ``OedometerConfig``, ``OedometerTest``,
  ``IsotropicConfig``, ``IsotropicTest``;
- test procedures: ``TriaxialConfig``, ``ShearConfig``, ``BridgeConfig``, ``TriaxialTest``,
  with the building blocks ``equilibrate``, ``wet``, ``TriaxialShear``, ``summarize``;
  ``TensionConfig``, ``TensionTest``; ``SwccConfig``, ``SwccTest`` (drying and wetting
  paths); campaigns of runs: ``Campaign``, ``Run``;
- results: ``read_history``, ``read_summary``, ``read_vtk`` (a ParaView series).

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
    "PrepareConfig": "pendular.procedures.preparation",
    "prepare_sample": "pendular.procedures.preparation",
    "HistoryRecorder": "pendular.dem.record",
    "Simulation": "pendular.dem.simulation",
    "Particles": "pendular.dem.state",
    "Walls": "pendular.dem.state",
    "ConstantShearRate": "pendular.dem.cell",
    "ConstantStrainRate": "pendular.dem.walls",
    "ConstantVolume": "pendular.dem.walls",
    "StressServo": "pendular.dem.walls",
    "WallForces": "pendular.dem.walls",
    "Campaign": "pendular.studies.campaign",
    "Run": "pendular.studies.campaign",
    "BridgeConfig": "pendular.procedures.config",
    "ShearConfig": "pendular.procedures.config",
    "SwccConfig": "pendular.procedures.swcc",
    "TensionConfig": "pendular.procedures.tension",
    "TriaxialConfig": "pendular.procedures.triaxial",
    "IsotropicConfig": "pendular.procedures.isotropic",
    "OedometerConfig": "pendular.procedures.oedometer",
    "CyclicConfig": "pendular.procedures.cyclic",
    "TablePathConfig": "pendular.procedures.path",
    "SimpleShearConfig": "pendular.procedures.simple_shear",
    "LoadingPath": "pendular.procedures.loading",
    "Stage": "pendular.procedures.loading",
    "Static": "pendular.procedures.loading",
    "Strain": "pendular.procedures.loading",
    "Stress": "pendular.procedures.loading",
    "ShearStrain": "pendular.procedures.loading",
    "IsotropicTest": "pendular.procedures.isotropic",
    "OedometerTest": "pendular.procedures.oedometer",
    "CyclicTest": "pendular.procedures.cyclic",
    "PathTest": "pendular.procedures.path",
    "SimpleShearTest": "pendular.procedures.simple_shear",
    "read_history": "pendular.io.history",
    "read_summary": "pendular.io.history",
    "read_vtk": "pendular.io.vtk",
    "SwccTest": "pendular.procedures.swcc",
    "TensionTest": "pendular.procedures.tension",
    "TriaxialShear": "pendular.procedures.triaxial",
    "TriaxialTest": "pendular.procedures.triaxial",
    "equilibrate": "pendular.procedures.equilibrium",
    "summarize": "pendular.procedures.triaxial",
    "wet": "pendular.procedures.equilibrium",
}

__all__ = sorted([*_EXPORTS, "__version__"])


def __getattr__(name):
    if name == "__version__":
        from pendular.utils.version import software_version

        value = software_version()
    elif name in _EXPORTS:
        value = getattr(import_module(_EXPORTS[name]), name)
    else:
        raise AttributeError(f"module 'pendular' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__():
    return __all__
