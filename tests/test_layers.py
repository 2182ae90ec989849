"""The house's floors: the pipeline never reaches the simulator, and light modules stay light.

lint-imports (pyproject.toml) checks import statements floor by floor; these tests also
catch what it cannot see: a sim module loaded by name (importlib, __import__) from the
pipeline, and heavy packages (MuJoCo, highway-env, gymnasium, pygame) loaded by a module
that only does maths or reads files.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

from tests.paths import ROOT

HEAVY = ("mujoco", "highway_env", "gymnasium", "pygame")
# Modules that must load without the simulator's heavy packages.
LIGHT = (
    "sim",  # registers the gymnasium environment only when gymnasium is loaded already
    "sim.geometry.frames",
    "sim.geometry.polygons",
    "sim.scenario.spec",
    "sim.scenario.path",
    "sim.scenario.files",
    "sim.scenario.cases",
    "sim.analysis.metrics",
    "sim.analysis.report",
    "sim.runs.results_file",
    "sim.dataset.spec",
    "monopic.cli.main",
)
LOADERS = {"import_module", "__import__", "find_spec", "spec_from_file_location"}


def _is_sim(name: str) -> bool:
    return name == "sim" or name.startswith("sim.")


def sim_references(path: Path) -> list[str]:
    """Every way a file names a sim module: import statements and loaders called by name."""
    tree = ast.parse(path.read_text(), filename=str(path))
    found: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [f"import {a.name}" for a in node.names if _is_sim(a.name)]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if _is_sim(node.module):
                found.append(f"from {node.module} import ...")
        elif isinstance(node, ast.Call):
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            if name in LOADERS:
                found += [
                    f"{name}({arg.value!r})"
                    for arg in node.args
                    if isinstance(arg, ast.Constant)
                    and isinstance(arg.value, str)
                    and _is_sim(arg.value)
                ]
    return found


def test_the_pipeline_never_names_the_simulator():
    offenders = [
        f"{path.relative_to(ROOT)}: {ref}"
        for path in sorted((ROOT / "monopic").rglob("*.py"))
        for ref in sim_references(path)
    ]
    assert not offenders, offenders


def test_the_check_sees_every_kind_of_reference(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text(
        "import importlib\nimport sim.world\nfrom sim import scene\n"
        "importlib.import_module('sim.runs.runner')\n__import__('sim')\n"
        "importlib.import_module('simplejson')\n"
    )
    assert sim_references(bad) == [
        "import sim.world",
        "from sim import ...",
        "import_module('sim.runs.runner')",
        "__import__('sim')",
    ]


@pytest.mark.parametrize("module", LIGHT)
def test_light_modules_load_no_heavy_package(module):
    code = f"import sys, {module}\nprint(','.join(m for m in {HEAVY!r} if m in sys.modules))"
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == "", f"{module} loads {out.stdout.strip()}"


@pytest.mark.parametrize("registers", ["sim.envs", "sim"])  # `import sim` after gymnasium
def test_the_environment_registers_without_loading_the_world(registers):
    code = (
        f"import sys, gymnasium, {registers}\n"
        "assert 'monopic/PedestrianCrossing-v0' in gymnasium.registry\n"
        "print(','.join(m for m in ('mujoco', 'highway_env', 'pygame') if m in sys.modules))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == ""
