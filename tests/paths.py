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
PETS09 = SHARED_DATA / "mot-pets09-s2l1"
needs_pets09 = pytest.mark.skipif(
    not (PETS09 / "gt" / "gt.txt").is_file(),
    reason=f"the PETS09-S2L1 sequence is not at {PETS09} (set MONOPIC_SHARED_DATA)",
)
STREET_CLIP = SHARED_DATA / "street-clips" / "road_walkers_high_angle.mp4"
needs_street_clip = pytest.mark.skipif(
    not STREET_CLIP.is_file(),
    reason=f"the street clip is not at {STREET_CLIP} (set MONOPIC_SHARED_DATA)",
)
ETH_UCY = SHARED_DATA / "eth-ucy-calibration"
needs_eth_ucy = pytest.mark.skipif(
    not (ETH_UCY / "biwi_hotel.txt").is_file(),
    reason=f"the ETH/UCY tracks are not at {ETH_UCY} (set MONOPIC_SHARED_DATA)",
)
