"""tools.compare_outputs on two small `monopic ncap` output folders made by hand.

The reports are written by the command's own renderer (sim.analysis.ncap_report.render),
so the score table the tool reads back is the one `monopic ncap` writes.
"""

from __future__ import annotations

import copy
import json
import subprocess
import sys
from pathlib import Path
from typing import Any

from sim.analysis import ncap_report as rep
from sim.analysis.ncap_score import CalculatorScore, LoadCaseScore
from sim.runs.ncap_grid import DECLARED, LatencySetting
from sim.scenario.ncap import load_car, load_protocol
from tests.paths import ROOT
from tools import compare_outputs

TOOL = [sys.executable, "-m", "tools.compare_outputs"]
PROTOCOL = load_protocol(ROOT / "scenarios" / "ncap" / "protocol.toml")
CAR = load_car(ROOT / "scenarios" / "ncap" / "car.toml")
LATENCY = LatencySetting(DECLARED, 465.0)


def row(role: str, index: int, warning_ttc: float, latencies: list[float]) -> dict[str, Any]:
    return {
        "schema": 1,
        "id": f"rules/ground/cpna/AEB/20kmh/50/{role}{index}-0123abcd",
        "code": "0123456789ab",
        "policy": "rules/ground",
        "role": role,
        "index": index,
        "test": "cpna",
        "function": "AEB",
        "speed_kmh": 20.0,
        "impact": 0.5,
        "load_case": "CPNA day",
        "latency": LATENCY.to_json(),
        "outcome": {
            "contact": False,
            "relative_impact_speed": None,
            "speed_reduction": 5.7,
            "warning_ttc": warning_ttc,
            "brake_time": 2.4,
            "warned_frames": 20,
            "frames": len(latencies),
            "latency_ms_median": sorted(latencies)[len(latencies) // 2],
            "latencies_ms": latencies,
        },
        "wall_s": 4.2,
        "machine": {"cpu": "AMD EPYC", "cores": 2, "host": "vm"},
    }


def scores(cpna: float) -> dict[str, CalculatorScore]:
    lc = LoadCaseScore("CPNA", cpna, 0.0, 0.0, 1.25, 0.5, 0.5)
    return {"rules/ground": CalculatorScore("5.4.9", Path("x.xlsx"), {"CPNA": lc}, cpna, 20.0)}


def write(folder: Path, rows: list[dict[str, Any]], cpna: float = 0.056) -> Path:
    folder.mkdir()
    (folder / "results.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    text = rep.render(
        protocol=PROTOCOL, car=CAR, tests=["cpna"], quick=True, speeds=[20.0], seeds=1,
        rows=rows, points=rep.summarise(rows), scores=scores(cpna), pictures=[],
        command="monopic ncap --quick", machine="AMD EPYC, 2 cores, host vm",
        wall_s=sum(r["wall_s"] for r in rows), ran_now=len(rows), version="5.4.9",
        left_unscored="the rest", out=folder, latency=LATENCY,
    )  # fmt: skip
    (folder / "report.md").write_text(text)
    return folder


def rows() -> list[dict[str, Any]]:
    return [row("grid", 0, 1.92, [30.5, 210.0, 41.0]), row("verify", 1, 2.12, [28.0, 35.5])]


def test_runs_and_scores_that_differ_only_in_times_and_measured_latencies_are_identical(
    tmp_path: Path,
) -> None:
    old = write(tmp_path / "old", rows())
    other = rows()[::-1]  # another order, another host's times and measured latencies
    for r in other:
        r["wall_s"] *= 3
        r["code"] = "ba9876543210"
        r["machine"] = {"cpu": "Intel Xeon", "cores": 4, "host": "ci"}
        r["outcome"]["latencies_ms"] = [v * 2.5 for v in r["outcome"]["latencies_ms"]]
        r["outcome"]["latency_ms_median"] *= 2.5
    new = write(tmp_path / "new", other)
    assert (old / "report.md").read_text() != (new / "report.md").read_text()  # times, latencies
    assert compare_outputs.score_table(old / "report.md")[0].startswith("| policy | CPNA |")
    assert compare_outputs.compare_ncap(old, new) == []
    done = subprocess.run(
        [*TOOL, "compare-ncap", str(old), str(new)],
        capture_output=True, text=True, check=False, cwd=ROOT,
    )  # fmt: skip
    assert done.returncode == 0 and "IDENTICAL" in done.stdout, done.stdout + done.stderr


def test_an_outcome_an_applied_latency_a_run_or_a_score_that_differs_is_named(
    tmp_path: Path,
) -> None:
    old = write(tmp_path / "old", rows())
    later = rows()
    later[0]["outcome"]["warning_ttc"] = 1.87
    problems = compare_outputs.compare_ncap(old, write(tmp_path / "ttc", later))
    assert problems == [f"ncap[{later[0]['id']}].outcome.warning_ttc: 1.92 != 1.87"]

    slower = copy.deepcopy(rows())
    slower[1]["latency"] = {"source": "fixed", "applied_ms": 500.0}
    problems = compare_outputs.compare_ncap(old, write(tmp_path / "fixed", slower))
    assert f"ncap[{slower[1]['id']}].latency.applied_ms: 465.0 != 500.0" in problems
    assert f"ncap[{slower[1]['id']}].latency.source: 'declared' != 'fixed'" in problems

    problems = compare_outputs.compare_ncap(old, write(tmp_path / "one", rows()[:1]))
    assert problems == ["ncap: runs differ: 1 unmatched of 2/1 (" + rows()[1]["id"] + ")"]

    problems = compare_outputs.compare_ncap(old, write(tmp_path / "score", rows(), cpna=0.1))
    assert len(problems) == 1 and problems[0].startswith("ncap/report.md score table[2]: ")
    done = subprocess.run(
        [*TOOL, "compare-ncap", str(old), str(tmp_path / "score")],
        capture_output=True, text=True, check=False, cwd=ROOT,
    )  # fmt: skip
    assert done.returncode == 1 and "DIFFERENT: 1 difference" in done.stdout


def test_a_folder_without_results_or_report_is_named(tmp_path: Path) -> None:
    old = write(tmp_path / "old", rows())
    (tmp_path / "empty").mkdir()
    assert compare_outputs.compare_ncap(old, tmp_path / "empty") == [
        f"ncap: {tmp_path / 'empty' / 'results.jsonl'} is missing"
    ]
