"""pendular as a library: the layers import one way, the public API composes a custom loading
path, configurations round-trip through JSON, and the command line lists its commands."""

import ast
import dataclasses
import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import ROOT

SRC = os.path.join(ROOT, "src")
#: The layers of the package, lowest first: a module may import from its own layer and those
#: below it, never above. "pendular" itself (its __init__) is the public face, above all. The
#: one way up is declared: pendular.dem.simulation imports a device's module (DEVICE_MODULES,
#: e.g. pendular.gpu) by name when a Simulation first asks for that device
#: (test_the_device_registry_is_the_one_plug_in_point).
LAYER_ORDER = ("pendular.utils", "pendular.dem", "pendular.capillary", "pendular.homogenize",
               "pendular.gpu", "pendular.io", "pendular.procedures", "pendular.interop",
               "pendular.studies", "pendular.cli", "pendular")
LAYERS = {layer: set(LAYER_ORDER[:rank + 1]) for rank, layer in enumerate(LAYER_ORDER)}


def _module_name(path):
    """Dotted name of the module at ``path`` under src/ (a package's __init__ is the package)."""
    parts = os.path.relpath(path, SRC)[:-len(".py")].split(os.sep)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _layer(module):
    """The layer of a dotted module name, None outside pendular."""
    if module != "pendular" and not module.startswith("pendular."):
        return None
    return next((layer for layer in LAYER_ORDER if layer != "pendular"
                 and (module == layer or module.startswith(layer + "."))), "pendular")


def _imports(path):
    """Absolute names of the modules a Python file imports, relative imports resolved."""
    tree = ast.parse(open(path).read(), path)
    name = _module_name(path)
    package = name if path.endswith("__init__.py") else name.rpartition(".")[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from (alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package.split(".")
            if node.level:
                base = base[:len(base) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module
            # "from pendular import capillary" imports the sub-package
            yield from (f"{module}.{alias.name}" for alias in node.names)


def _python_files(folder):
    for base, _, names in os.walk(folder):
        yield from (os.path.join(base, n) for n in names if n.endswith(".py"))


def test_the_import_rule_resolves_relative_imports():
    here = os.path.join(SRC, "pendular", "dem", "simulation.py")
    assert _module_name(here) == "pendular.dem.simulation"
    assert "pendular.dem.state.Particles" in set(_imports(here))
    assert _layer("pendular.procedures.triaxial.TriaxialTest") == "pendular.procedures"
    assert _layer("pendular.__version__") == "pendular"
    assert _layer("pendular.capillary.bridges") == "pendular.capillary"
    assert _layer("numpy") is None


def test_no_module_imports_a_layer_above_it():
    wrong = []
    for path in _python_files(os.path.join(SRC, "pendular")):
        if os.sep + "scripts" + os.sep in path:      # YADE's driver, never imported
            continue
        layer = _layer(_module_name(path))
        source = open(path).read()
        for module in _imports(path):
            target = _layer(module)
            if target is not None and target not in LAYERS[layer]:
                wrong.append(f"{path}: imports {module} (layer {target})")
        if "sys.modules" in source or "sys.path" in source:
            wrong.append(f"{path}: uses sys.modules or sys.path")
    for path in _python_files(os.path.join(ROOT, "scenarios")):
        if "sys.path" in open(path).read():
            wrong.append(f"{path}: edits sys.path")
    assert not wrong, "\n".join(wrong)


def test_the_device_registry_is_the_one_plug_in_point():
    """Below the command line, only pendular.dem.simulation imports a module by name: a
    device's (DEVICE_MODULES), from a layer above pendular.dem, which registers its run
    (register_device) when imported (docs/architecture.md)."""
    from pendular.dem.simulation import DEVICE_MODULES

    by_name = sorted(_module_name(path) for path in _python_files(os.path.join(SRC, "pendular"))
                     if _layer(_module_name(path)) not in ("pendular.cli", "pendular")
                     and any(word in open(path).read()
                             for word in ("import_module(", "__import__(")))
    assert by_name == ["pendular.dem.simulation"]
    devices = {name: module for name, module in DEVICE_MODULES.items() if module is not None}
    assert devices == {"gpu": "pendular.gpu"}
    for name, module in devices.items():
        assert LAYER_ORDER.index(_layer(module)) > LAYER_ORDER.index("pendular.dem")
        source = open(os.path.join(SRC, *module.split("."), "__init__.py")).read()
        assert f'register_device("{name}"' in source


def test_only_pendular_is_installed_and_importing_it_changes_no_setting():
    code = ("import os, sys, numba, pendular.dem, pendular.capillary, pendular.homogenize; "
            "import pendular.dem.simulation, pendular.procedures.triaxial; "
            "print(numba.config.THREADING_LAYER_PRIORITY, 'GOMP_SPINCOUNT' in os.environ)")
    environment = {k: v for k, v in os.environ.items()
                   if k not in ("GOMP_SPINCOUNT", "OMP_WAIT_POLICY")}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=environment, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["['tbb',", "'omp',", "'workqueue']", "False"]
    for name in ("dem", "capillary", "homogenize"):
        missing = subprocess.run([sys.executable, "-c", f"import {name}"], capture_output=True,
                                 text=True, cwd=ROOT)
        assert missing.returncode != 0, f"'import {name}' works: only pendular is installed"


def test_scenarios_are_thin_wrappers():
    for path in _python_files(os.path.join(ROOT, "scenarios")):
        lines = len(open(path).read().splitlines())
        assert lines <= 200, f"{path} has {lines} lines"


def test_custom_loading_path_in_a_few_lines():
    """The custom loading path of docs/tutorials/plot_3_custom_loading_path.py: isotropic
    compression to 2 kPa, unload to 500 Pa, then shear."""
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
    history = shear.recorder.arrays()
    result = summarize(history)
    assert result["lateral_stress"] == pytest.approx(500.0, rel=0.03)
    # the peak is that of q = sigma_z - (sigma_x + sigma_y) / 2 of the recorded wall stresses
    sigma = history["sigma_wall"]
    q = sigma[:, 2] - 0.5 * (sigma[:, 0] + sigma[:, 1])
    assert result["peak_q"] == q.max() and result["peak_q"] > 0.3 * 500.0
    assert history["axial_strain"][-1] == pytest.approx(0.01, rel=0.02)


def test_configurations_round_trip_through_json():
    from pendular.procedures.config import (BridgeConfig, ShearConfig, config_from_dict, config_json,
        config_to_dict)
    from pendular.procedures.triaxial import TriaxialConfig
    from pendular.procedures.preparation import PrepareConfig

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


def test_no_module_below_the_command_line_parses_arguments():
    """Options become configurations in the library (pendular.procedures.options); only the
    command line parses a command line."""
    parsing = [path for path in _python_files(os.path.join(SRC, "pendular"))
               if _layer(_module_name(path)) not in ("pendular.cli", "pendular")
               and os.sep + "scripts" + os.sep not in path
               and any(module == "argparse" or module.startswith("argparse.")
                       for module in _imports(path))]
    assert not parsing


def test_a_campaign_table_builds_its_configurations_without_the_command_line(tmp_path):
    table = tmp_path / "t.toml"
    table.write_text('[fixed]\nparticles = 300\nmax_strain = 0.02\n'
                      '[sweep]\nsuction = [0, 30000]\n')
    code = ("import sys; from pendular.studies.campaign import sweep_from_table; "
            f"command, runs = sweep_from_table({str(table)!r}); "
            "print(command, [run.config.suction for run in runs], "
            "sorted(m for m in sys.modules if m.startswith('pendular.cli')))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=ROOT)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["triaxial", "[0.0,", "30000.0]", "[]"]


def test_pendular_command_lists_its_commands_and_version(capsys):
    """``python -m pendular.cli --version`` in its own process (the module's entry point); the
    two help texts from pendular.cli.main, which that entry point calls, in this one."""
    from pendular.cli import main

    def printed(argv):
        with pytest.raises(SystemExit) as stop:
            main(argv)
        assert stop.value.code == 0
        return capsys.readouterr().out

    listing = printed(["--help"])
    for command in ("triaxial", "tension", "chapter5", "campaign"):
        assert command in listing
    version = subprocess.run([sys.executable, "-m", "pendular.cli", "--version"],
                             capture_output=True, text=True, check=True)
    import pendular
    assert version.stdout.strip() == f"pendular {pendular.__version__}"
    triaxial = printed(["triaxial", "--help"])
    assert "(default: 750.0)" in triaxial and "[Pa]" in triaxial
