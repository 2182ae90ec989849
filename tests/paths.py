"""Where the tests find the repository, its fixtures, scenario files, tools and shared data."""

import importlib.util
import os
import sys
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data"
SCENARIOS = ROOT / "scenarios"
# The workspace's real data (the authors' logs, ETH/UCY tracks) is read where it is kept,
# never copied into the project: $MONOPIC_SHARED_DATA, else ../shared/data beside the
# checkout. Tests that need it are skipped, saying so, on a checkout without it.
SHARED_DATA = Path(os.environ.get("MONOPIC_SHARED_DATA") or ROOT.parent / "shared" / "data")
AUTHORS_LOGS = SHARED_DATA / "authors-testdata"
needs_authors_logs = pytest.mark.skipif(
    not (AUTHORS_LOGS / "data0.csv").is_file(),
    reason=f"the authors' logs are not at {AUTHORS_LOGS} (set MONOPIC_SHARED_DATA)",
)


def load_tool(name: str) -> ModuleType:
    """tools/<name>.py as a module (the tools are scripts, not a package). It is registered
    in sys.modules under its name because dataclasses look their module up there."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "tools" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module
