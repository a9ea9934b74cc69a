"""pendular as a library: the layers import one way, the public API composes a custom loading
path, configurations round-trip through JSON, and the command line lists its commands."""

import ast
import dataclasses
import os
import subprocess
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: Layer -> the packages it may import (itself and the layers below it).
LAYERS = {"dem": {"dem"}, "capillary": {"dem", "capillary"},
          "homogenize": {"dem", "capillary", "homogenize"},
          "pendular": {"dem", "capillary", "homogenize", "pendular"}}


def _imports(path):
    """Top-level package names a Python file imports (absolute imports only)."""
    tree = ast.parse(open(path).read(), path)
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from (alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            yield node.module.split(".")[0]


def _python_files(folder):
    for base, _, names in os.walk(folder):
        yield from (os.path.join(base, n) for n in names if n.endswith(".py"))


def test_no_module_imports_a_layer_above_it():
    wrong = []
    for layer, allowed in LAYERS.items():
        for path in _python_files(os.path.join(ROOT, "src", layer)):
            source = open(path).read()
            wrong += [f"{path}: imports {name}" for name in _imports(path)
                      if name in LAYERS and name not in allowed]
            if "sys.modules" in source or "sys.path" in source:
                wrong.append(f"{path}: uses sys.modules or sys.path")
    for path in _python_files(os.path.join(ROOT, "scenarios")):
        if "sys.path" in open(path).read():
            wrong.append(f"{path}: edits sys.path")
    assert not wrong, "\n".join(wrong)


def test_scenarios_are_thin_wrappers():
    for path in _python_files(os.path.join(ROOT, "scenarios")):
        lines = len(open(path).read().splitlines())
        assert lines <= 200, f"{path} has {lines} lines"


def test_custom_loading_path_in_a_few_lines():
    """The README's example: isotropic compression to 2 kPa, unload to 500 Pa, then shear."""
    from pendular import (PrepareConfig, ShearConfig, StressServo, TriaxialShear, equilibrate,
                          prepare_sample, summarize)

    sample = PrepareConfig(particles=200, confining=2000.0, seed=3, unload_steps=400)
    sim, report = prepare_sample(sample, progress=False)      # static at 2 kPa
    servo = sim.operation(StressServo)
    for target in np.linspace(2000.0, 500.0, 11)[1:]:          # unload in 10 stages
        servo.target = target
        sim.run(100)
    equilibrate(sim)
    shear = TriaxialShear(sim, ShearConfig(max_strain=0.01, inertial_number=2e-3, records=20),
                          confining=500.0, radius=sample.radius, density=sample.density)
    sim.run(shear.steps)
    result = summarize(shear.recorder.arrays())
    assert result["lateral_stress"] == pytest.approx(500.0, rel=0.03)
    assert result["peak_q"] > 0.0
    assert shear.recorder.arrays()["axial_strain"][-1] == pytest.approx(0.01, rel=0.02)


def test_configurations_round_trip_through_json():
    from pendular.config import (BridgeConfig, ShearConfig, TriaxialConfig, config_from_dict,
                                 config_json, config_to_dict)
    from dem.preparation import PrepareConfig

    config = TriaxialConfig(sample=PrepareConfig(particles=500, confining=250.0),
                            shear=ShearConfig(max_strain=0.1),
                            bridges=BridgeConfig(30000.0, table_resolution=(100, 40)))
    again = config_from_dict(config_to_dict(config))
    assert again == config
    assert config_json(again) == config_json(config)
    variant = dataclasses.replace(config, sample=dataclasses.replace(config.sample, seed=4))
    assert config_json(variant) != config_json(config)
    data = config_to_dict(config)
    data["schema_version"] = 1
    with pytest.raises(ValueError, match="schema_version 1"):
        config_from_dict(data, "old.h5")


def test_pendular_command_lists_its_commands_and_version():
    result = subprocess.run([sys.executable, "-m", "pendular.cli", "--help"],
                            capture_output=True, text=True, check=True)
    for command in ("triaxial", "tension", "chapter5", "campaign"):
        assert command in result.stdout
    version = subprocess.run([sys.executable, "-m", "pendular.cli", "--version"],
                             capture_output=True, text=True, check=True)
    import pendular
    assert version.stdout.strip() == f"pendular {pendular.__version__}"
    triaxial = subprocess.run([sys.executable, "-m", "pendular.cli", "triaxial", "--help"],
                              capture_output=True, text=True, check=True)
    assert "(default: 750.0)" in triaxial.stdout and "[Pa]" in triaxial.stdout
