"""studies.people.judged: runs paired with and without bystanders, and before against
after judged by one set of rules."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from sim.runs.result import RunResult
from studies.people.judged import main, pair_key, paired_lines, pairs
from tests.sim.test_person_by_person import ADULT, CHILD, N, frames, line


def drawn(row: RunResult, speed: float, bystanders: bool) -> RunResult:
    params = {
        "robot.speed": speed,
        **({"people": "../people/pavement_two.toml"} if bystanders else {}),
    }
    return replace(row, params=params, id=f"{row.id}-{speed}-{bystanders}")


def test_a_pair_shares_every_drawn_value_but_its_people() -> None:
    rows = [
        drawn(line(frames(CHILD, range(10, N))), s, b) for s in (1.0, 2.0) for b in (True, False)
    ]
    rows.append(drawn(line(frames(CHILD, range(10, N))), 3.0, True))  # no twin: not paired
    got = pairs(rows)
    assert len(got) == 2
    for with_, without in got:
        assert pair_key(with_) == pair_key(without)
        assert with_.params["people"] and "people" not in without.params


def test_the_paired_table_counts_the_runs_each_arm_alone_warned_in_time() -> None:
    rows = []
    for s in range(6):  # warned in time in both arms
        rows += [drawn(line(frames(CHILD, range(10, N))), s, b) for b in (True, False)]
    # with bystanders the warning went to the adult: a pair lost
    rows += [drawn(line(frames(ADULT, range(10, N))), 9.0, True),
             drawn(line(frames(CHILD, range(10, N))), 9.0, False)]  # fmt: skip
    table = paired_lines(rows)
    (row,) = [ln for ln in table if ln.startswith("| rules/image |")]
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1:5] == ["7", "6 / 7", "0", "1"]
    assert cells[5] == "-14.3" and cells[7] == "missed"


def test_bad_input_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--judged", str(tmp_path / "none.jsonl")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "none.jsonl" in err
    assert main(["--judged", str(tmp_path / "x"), "--before", str(tmp_path / "b")]) == 2
    assert "go together" in capsys.readouterr().err
