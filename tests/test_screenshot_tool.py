"""tools.view.screenshot without a Vulkan driver: one line naming the package, no viewer."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from tests.paths import ROOT
from tools.view import screenshot

TOOL = [sys.executable, "-m", "tools.view.screenshot"]


def run_tool(tmp_path: Path, *args: str, env: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*TOOL, *args, "--out", str(tmp_path / "shots")],
        capture_output=True, text=True, timeout=60, env={**os.environ, **env}, cwd=ROOT,
    )  # fmt: skip


def test_no_vulkan_driver_is_one_line_naming_the_package(tmp_path: Path) -> None:
    rrd = tmp_path / "x.rrd"
    rrd.write_bytes(b"RRF2" + bytes(12))
    r = run_tool(tmp_path, str(rrd), env={"VK_DRIVER_FILES": str(tmp_path / "none.json")})
    assert r.returncode == 1 and r.stdout == ""
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith("screenshot.py: no Vulkan driver found")
    assert "apt-get install -y mesa-vulkan-drivers" in line
    assert not (tmp_path / "shots" / "viewer.log").exists()  # no viewer was started


def test_a_missing_recording_is_one_line(tmp_path: Path) -> None:
    r = run_tool(tmp_path, "nope.rrd", env={})
    assert r.returncode == 1
    assert r.stderr.strip() == "screenshot.py: nope.rrd: no such recording"


def test_the_drivers_are_found_where_the_vulkan_loader_looks(tmp_path: Path) -> None:
    icd = tmp_path / "lvp_icd.json"
    icd.write_text("{}")
    listed = os.pathsep.join([str(icd), str(tmp_path / "gone.json")])
    assert screenshot.vulkan_drivers({"VK_DRIVER_FILES": listed}) == [icd]
    assert screenshot.vulkan_drivers({"VK_ICD_FILENAMES": str(icd)}) == [icd]
    assert screenshot.vulkan_drivers({"VK_DRIVER_FILES": str(tmp_path / "gone.json")}) == []
