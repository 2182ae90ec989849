"""Where the tests find the repository, its fixtures, scenario files and shared data."""

import os
from pathlib import Path

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
