"""The studies run end to end, as modules from the checkout's top folder, on real runs:
a four-run sweep of two intent families (the sweep replays), nine two-frame clips (the
found share) and the shipped families' labels (truth only). Each checks the figure its
answer page relies on, not only that a file was written."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from monopic.cli.main import main
from tests.paths import ROOT, SCENARIOS

SPEC = """
name = "studies"
ablation = false
[[include]]
files = ["{families}/cpna25.toml", "{families}/nearmiss_kerb_stop.toml"]
sampling = "random"
runs = 2
seed = 3
[include.parameters]
"pedestrian.behaviour.model" = ["human"]
"""


def study(module: str, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", module, *args],
        capture_output=True, text=True, cwd=ROOT, timeout=600,
        env={**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")},
    )  # fmt: skip


@pytest.fixture(scope="module")
def results(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("sweep")
    spec = folder / "spec.toml"
    spec.write_text(SPEC.format(families=SCENARIOS / "families" / "small"))
    out = folder / "runs.jsonl"
    assert main(["sweep", str(spec), "--out", str(out), "--workers", "1", "--record", "none"]) == 0
    assert len(out.read_text().splitlines()) == 4
    return out


@pytest.mark.slow
def test_the_replay_reproduces_the_sweeps_own_warnings(results: Path) -> None:
    r = study("studies.ground_motion.estimators", str(results))
    assert r.returncode == 0, r.stderr
    shipped = next(line for line in r.stdout.splitlines() if "Kalman track (shipped)" in line)
    agreement = shipped.split("|")[2].strip()
    assert agreement == "100.0 %"  # the track that made the file, replayed: every frame


@pytest.mark.slow
def test_crossfit_ceiling_and_foot_noise_write_their_pages(results: Path, tmp_path: Path) -> None:
    crossfit = study(
        "studies.intent.crossfit", str(results), "--folds", "2", "--depth", "2",
        "--min-rows", "5", "--out", str(tmp_path / "crossfit.md"),
        "--plot", str(tmp_path / "crossfit.png"),
    )  # fmt: skip
    assert crossfit.returncode == 0, crossfit.stderr
    page = (tmp_path / "crossfit.md").read_text()
    assert page.startswith(f"4 runs of `{results}` (cpna-25-small 2, nearmiss-kerb-stop-small 2)")
    assert (tmp_path / "crossfit.png").read_bytes()[:4] == b"\x89PNG"

    ceiling = study("studies.intent.ceiling", str(results), "--out", str(tmp_path / "ceil.md"))
    assert ceiling.returncode == 0, ceiling.stderr
    rows = [line for line in (tmp_path / "ceil.md").read_text().splitlines() if "| all |" in line]
    assert any(r.startswith("| true future point | all |") for r in rows)

    noise = study("studies.intent.foot_noise", str(results), "--out", str(tmp_path / "noise.md"))
    assert noise.returncode == 0, noise.stderr
    assert re.search(
        r"^\| small \| \d+-\d+ px \| \d+ \|", (tmp_path / "noise.md").read_text(), re.M
    )


@pytest.mark.slow
def test_the_found_share_finds_the_walker_at_6_m_in_every_case() -> None:
    r = study("studies.detection.found_share", "--frames", "2", "--distances", "6")
    assert r.returncode == 0, r.stderr
    cases = [line for line in r.stdout.splitlines() if re.match(r"\| \d [a-z]", line)]
    assert len(cases) == 9  # the eight cases and "still, facing away"
    assert all("100.0 %" in line for line in cases)  # the body at 1/6-1/4: every frame found


def test_the_label_sequences_are_those_docs_intent_features_md_quotes() -> None:
    r = study("studies.intent.check", "labels", "cpna25", "look_no_cross")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    # features.md: cpna25, rail "start crossing 0.07-1.60 s, then keep going", human
    # "start crossing 0-0.80 s, then keep going"; look_no_cross "keep going" throughout.
    assert re.match(r"cpna25 \[rail\]: 0.00 s keep going .* -> 0.07 s start crossing .* -> "
                    r"1.60 s keep going", lines[0])  # fmt: skip
    assert re.match(r"cpna25 \[human\]: 0.00 s start crossing .* -> 0.80 s keep going", lines[1])
    assert lines[2].count(" -> ") == 0 and "keep going" in lines[2]
    assert lines[3].count(" -> ") == 0 and "keep going" in lines[3]
