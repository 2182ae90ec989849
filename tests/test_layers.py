"""The pipeline (monopic/) never imports the simulator (sim/); only monopic.cli may."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
    return names


def test_pipeline_modules_never_import_sim():
    offenders = []
    for path in (ROOT / "monopic").rglob("*.py"):
        if "cli" in path.relative_to(ROOT / "monopic").parts:
            continue
        bad = {n for n in _imports(path) if n == "sim" or n.startswith("sim.")}
        if bad:
            offenders.append(f"{path.relative_to(ROOT)} imports {sorted(bad)}")
    assert not offenders, offenders


def test_the_contract_check_sees_a_violation(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text("import sim.world\nfrom sim import scene\n")
    assert {"sim.world", "sim"} <= _imports(bad)
