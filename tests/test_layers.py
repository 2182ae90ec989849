"""The house's floors: the pipeline never reaches the simulator, and light modules stay light.

lint-imports (pyproject.toml) checks import statements floor by floor; these tests also
catch what it cannot see: a sim module loaded by name (importlib, __import__) from the
pipeline, and heavy packages (MuJoCo, highway-env, gymnasium, pygame) loaded by a module
that only does maths or reads files.
"""

from __future__ import annotations

import ast
import os
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


# Import loops allowed to stay: none. A new ring is untangled (a lower module for what both
# sides read, a protocol for what one side only reads), never listed here.
KNOWN_LOOPS: list[frozenset[str]] = []


def import_loops(*packages: str) -> list[frozenset[str]]:
    """The sets of modules that import each other in a ring (strongly connected components
    of the module import graph, every import counted: top level, in functions, for typing)."""
    import grimp

    graph = grimp.build_graph(*packages)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    loops: list[frozenset[str]] = []

    def visit(v: str) -> None:  # Tarjan's algorithm
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.find_modules_directly_imported_by(v):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            ring = set()
            while (w := stack.pop()) != v:
                on_stack.discard(w)
                ring.add(w)
            on_stack.discard(v)
            if ring:
                loops.append(frozenset(ring | {v}))

    for module in sorted(graph.modules):
        if module not in index:
            visit(module)
    return loops


PACKAGES = ("monopic", "sim", "studies", "bench", "tools")  # every package of the tree


def test_no_import_loop_inside_any_package():
    assert sorted(map(sorted, import_loops(*PACKAGES))) == sorted(map(sorted, KNOWN_LOOPS))


def test_the_loop_finder_sees_a_ring(tmp_path):
    ring = tmp_path / "ringpkg"
    ring.mkdir()
    (ring / "__init__.py").write_text("")
    (ring / "a.py").write_text("from ringpkg import b\n")
    (ring / "b.py").write_text("def f():\n    from ringpkg import c\n")
    (ring / "c.py").write_text("import ringpkg.a\n")
    (ring / "d.py").write_text("import ringpkg.a\n")
    # In a child whose import path holds the ring (PYTHONPATH), not by editing ours.
    code = (
        "from tests.test_layers import import_loops\n"
        "print(sorted(map(sorted, import_loops('ringpkg'))))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True,
        env={**os.environ, "PYTHONPATH": str(tmp_path)},
    )  # fmt: skip
    assert out.stdout.strip() == str([["ringpkg.a", "ringpkg.b", "ringpkg.c"]])


SYS_PATH_EDITS = {"insert", "append", "extend", "remove", "pop", "clear"}


def sys_path_edits(path: Path) -> list[str]:
    """Every place a file changes the import path: a call of sys.path's list methods, an
    assignment to sys.path or an item of it, or pytest's monkeypatch.syspath_prepend."""

    def is_sys_path(node: ast.AST) -> bool:
        return (
            isinstance(node, ast.Attribute)
            and node.attr == "path"
            and isinstance(node.value, ast.Name)
            and node.value.id == "sys"
        )

    found: list[tuple[int, str]] = []
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            if node.func.attr in SYS_PATH_EDITS and is_sys_path(node.func.value):
                found.append((node.lineno, f"sys.path.{node.func.attr}"))
            elif node.func.attr == "syspath_prepend":
                found.append((node.lineno, "syspath_prepend"))
        targets = (
            node.targets if isinstance(node, ast.Assign)
            else [node.target] if isinstance(node, ast.AugAssign | ast.AnnAssign)
            else []
        )  # fmt: skip
        for t in targets:
            if is_sys_path(t) or (isinstance(t, ast.Subscript) and is_sys_path(t.value)):
                found.append((node.lineno, "sys.path assigned"))
    return [f"line {line}: {what}" for line, what in sorted(found)]


def test_nothing_in_the_tree_edits_the_import_path():
    # Scripts run as modules from the top folder (`python -m bench.spin`), which puts the
    # top folder on the path: a neighbour is `from bench.history import ...`, never found by
    # editing sys.path, which hides from the import contracts what a file really reads.
    offenders = [
        f"{path.relative_to(ROOT)}: {edit}"
        for folder in (*PACKAGES, "tests")
        for path in sorted((ROOT / folder).rglob("*.py"))
        for edit in sys_path_edits(path)
    ]
    assert not offenders, offenders


def test_the_path_check_sees_every_kind_of_edit(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text(
        "import sys\nsys.path.insert(0, 'x')\nsys.path.append('y')\nsys.path[:0] = ['z']\n"
        "sys.path += ['w']\nsys.path = []\ndef t(monkeypatch):\n"
        "    monkeypatch.syspath_prepend('v')\nprint(sys.path[0], list(sys.path))\n"
    )
    assert sys_path_edits(bad) == [
        "line 2: sys.path.insert",
        "line 3: sys.path.append",
        "line 4: sys.path assigned",
        "line 5: sys.path assigned",
        "line 6: sys.path assigned",
        "line 8: syspath_prepend",
    ]
