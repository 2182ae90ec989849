"""Before/after check for restructurings: the same commands give the same outputs.

    python -m tools.compare_outputs capture DIR     # run the five commands, outputs in DIR
    python -m tools.compare_outputs compare OLD NEW  # field by field; exit 1 on a difference
    python -m tools.compare_outputs compare OLD NEW --renamed sim.cases=sim.scenario.cases
    python -m tools.compare_outputs compare-ncap A B  # two `monopic ncap` output folders

`capture` runs, with the installed `monopic` command (so it works on any layout):

- the demo sweep (scenarios/sweeps/demo.toml, failed runs recorded);
- `monopic dataset scenarios/datasets/cases-heldout.toml`;
- `monopic closed-loop` on two small-robot families (a collision and a near miss) at a
  fixed latency (the measured one is a timing, not a result);
- `monopic record 5`;
- `monopic ncap --quick` with the car file's declared latency (the Euro NCAP rating).

`compare` matches sweep runs by their scenario parameters (file, params, seed), not by
line order, and leaves out what is allowed to differ: the code digest, measured times
(`timing`, `*Ms` columns, "ms"/"seconds" figures) and the machine. Dataset images and
masks are compared by their decoded pixels, recordings by every component row that
rerun's own reader gives back (recording ids and wall-clock times excluded). Euro NCAP
runs are matched by run id, each row without its measured times and measured per-frame
latencies (with a declared latency nothing else depends on the host), and the score
table of its report.md line by line. `compare-ncap` compares two `monopic ncap` output
folders that way, e.g. the same command run twice, once under load.
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import io
import json
import math
import os
import re
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
CLOSED_LOOP_FILES = (
    "scenarios/families/small/cpna25.toml",
    "scenarios/families/small/nearmiss_kerb_stop.toml",
)
# Keys that hold the code, measured times or the machine, never a result. A dataset run's
# "bytes" counts its features CSV, whose timing columns change width from run to run.
VOLATILE_KEYS = {
    "code",
    "timing",
    "wall_s",
    "seconds",
    "machine",
    "host",
    "created",
    "date",
    "bytes",
    # A closed-loop or Euro NCAP run's measured pipeline latencies (applied only when a
    # run asked for the measured latency; `latency` says which was applied, and is kept).
    "latencies_ms",
    "latency_ms_median",
}


def volatile(key: str | None) -> bool:
    """A key or column that holds the code, a measured time or the machine."""
    return key in VOLATILE_KEYS or key == "ms" or (key or "").endswith("Ms")


# Lines of text outputs that carry times, machines or the code digest.
VOLATILE_LINE = re.compile(r"Ran on:|ran on|code [0-9a-f]{12}|\bms\b|seconds|[0-9.]+ s\b", re.I)


def monopic(*args: str, log: Path) -> None:
    exe = Path(sys.executable).with_name("monopic")
    start = time.perf_counter()
    with log.open("a") as fh:
        fh.write(f"$ monopic {' '.join(args)}\n")
        fh.flush()
        proc = subprocess.run([str(exe), *args], cwd=ROOT, stdout=fh, stderr=fh)
    print(f"  monopic {args[0]}: rc {proc.returncode}, {time.perf_counter() - start:.0f} s")
    if proc.returncode != 0:
        raise SystemExit(f"monopic {' '.join(args)} failed (rc {proc.returncode}); see {log}")


def capture(out: Path) -> None:
    out = out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    log = out / "commands.log"
    env_note = {"MUJOCO_GL": os.environ.get("MUJOCO_GL", "")}
    (out / "captured.json").write_text(json.dumps({"started": time.time(), **env_note}))
    monopic(
        "sweep", "scenarios/sweeps/demo.toml", "--out", str(out / "demo.jsonl"), "--restart",
        log=log,
    )  # fmt: skip
    monopic("dataset", "scenarios/datasets/cases-heldout.toml", "--out", str(out / "ds"), log=log)
    monopic(
        "closed-loop", *CLOSED_LOOP_FILES, "--robot-speeds", "1,2", "--latency-ms", "60",
        "--policies", "none,truth,rules/ground", "--out", str(out / "closed_loop.md"), log=log,
    )  # fmt: skip
    monopic("record", "5", "--out", str(out / "case5.rrd"), log=log)
    monopic("ncap", "--quick", "--restart", "--out", str(out / "ncap"), log=log)


# --- comparison ---------------------------------------------------------------------------


def scrub(value: Any) -> Any:
    """The value without volatile keys (recursively)."""
    if isinstance(value, dict):
        return {k: scrub(v) for k, v in value.items() if not volatile(k)}
    if isinstance(value, list):
        return [scrub(v) for v in value]
    return value


def diff(a: Any, b: Any, where: str, out: list[str], limit: int = 20) -> None:
    """Field-by-field differences of two JSON-like values, as 'where: a != b' lines."""
    if len(out) >= limit:
        return
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b), key=str):
            if k not in a or k not in b:
                out.append(f"{where}.{k}: only in {'new' if k in b else 'old'}")
            else:
                diff(a[k], b[k], f"{where}.{k}", out, limit)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{where}: length {len(a)} != {len(b)}")
        for i, (x, y) in enumerate(zip(a, b, strict=False)):
            diff(x, y, f"{where}[{i}]", out, limit)
    elif isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return
    elif a != b:
        out.append(f"{where}: {a!r} != {b!r}")


def run_key(row: dict[str, Any]) -> str:
    return json.dumps([row.get("file"), row.get("params"), row.get("seed")], sort_keys=True)


def jsonl(path: Path) -> dict[str, dict[str, Any]]:
    rows = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    return {run_key(r): r for r in rows}


def compare_sweep(old: Path, new: Path) -> list[str]:
    a, b = jsonl(old / "demo.jsonl"), jsonl(new / "demo.jsonl")
    out: list[str] = []
    if set(a) != set(b):
        out.append(f"sweep: runs differ: {len(set(a) ^ set(b))} unmatched of {len(a)}/{len(b)}")
    for key in sorted(set(a) & set(b)):
        diff(scrub(a[key]), scrub(b[key]), f"sweep[{a[key].get('id')}]", out)
    rec_a = sorted(p.relative_to(old) for p in (old / "demo_rrd").rglob("*.rrd"))
    rec_b = sorted(p.relative_to(new) for p in (new / "demo_rrd").rglob("*.rrd"))
    if rec_a != rec_b:
        out.append(f"sweep recordings: {[str(p) for p in rec_a]} != {[str(p) for p in rec_b]}")
    print(f"  sweep: {len(a)} runs, {len(rec_a)} recordings compared")
    return out


def pixels(path: Path) -> str:
    import cv2

    image = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if image is None:
        return "unreadable"
    return hashlib.sha256(image.tobytes()).hexdigest()


def csv_rows(path: Path) -> list[dict[str, str]]:
    rows = list(csv.DictReader(io.StringIO(path.read_text())))
    return [{k: v for k, v in r.items() if not volatile(k)} for r in rows]


RENAMED: list[tuple[str, str]] = []  # (old, new) module names, from --renamed


def text_lines(path: Path, renamed: bool = False) -> list[str]:
    """Lines without times, machines or code digests; table columns headed in ms dropped."""
    out: list[str] = []
    timed: set[int] = set()
    text = path.read_text()
    if renamed:
        for old, new in RENAMED:
            text = re.sub(rf"\b{re.escape(old)}(?![_a-zA-Z])", new, text)
    for line in text.splitlines():
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip("|").split("|")]
            if any("(ms)" in c for c in cells):  # a header row names the timed columns
                timed = {i for i, c in enumerate(cells) if "(ms)" in c}
            out.append(" | ".join(c for i, c in enumerate(cells) if i not in timed))
        elif not VOLATILE_LINE.search(line):
            out.append(line)
            timed = set()
    return out


def compare_file(a: Path, b: Path, where: str, out: list[str]) -> None:
    suffix = a.suffix.lower()
    if suffix in (".jpg", ".png"):
        if pixels(a) != pixels(b):
            out.append(f"{where}: pixels differ")
    elif suffix == ".json":
        diff(scrub(json.loads(a.read_text())), scrub(json.loads(b.read_text())), where, out)
    elif suffix == ".jsonl":
        la = [scrub(json.loads(x)) for x in a.read_text().splitlines() if x.strip()]
        lb = [scrub(json.loads(x)) for x in b.read_text().splitlines() if x.strip()]
        diff(la, lb, where, out)
    elif suffix == ".csv":
        diff(csv_rows(a), csv_rows(b), where, out)
    elif suffix == ".rrd":
        diff(rrd_rows(a), rrd_rows(b), where, out)
    else:
        diff(text_lines(a, renamed=True), text_lines(b), where, out)


def files_below(folder: Path) -> Iterator[Path]:
    for p in sorted(folder.rglob("*")):
        if p.is_file():
            yield p.relative_to(folder)


def compare_dataset(old: Path, new: Path) -> list[str]:
    out: list[str] = []
    fa, fb = set(files_below(old / "ds")), set(files_below(new / "ds"))
    if fa != fb:
        out.append(f"dataset: files differ: {sorted(str(p) for p in fa ^ fb)[:10]}")
    for rel in sorted(fa & fb):
        compare_file(old / "ds" / rel, new / "ds" / rel, f"dataset/{rel}", out)
    print(f"  dataset: {len(fa & fb)} files compared")
    return out


def rrd_rows(path: Path) -> dict[str, list[Any]]:
    """Every component column per entity, as rerun's reader gives it back, row order free.

    rerun batches rows into chunks as time passes, so the same log can come back in
    another chunk order: temporal rows are sorted by their frame. The wall-clock parts
    (log_time, the recording's start time, row ids) and the measured stage times
    (latency/*) are left out.
    """
    from rerun.chunk import RrdReader

    columns: dict[str, list[Any]] = {}
    for chunk in RrdReader(str(path)).stream().to_chunks():
        if chunk.entity_path.startswith("/latency"):  # measured stage times
            continue
        batch = chunk.to_record_batch().to_pydict()
        frames = batch.get("frame", [None] * chunk.num_rows)
        for name, values in batch.items():
            if name in ("frame", "time", "log_time") or "RowId" in name:
                continue
            if name == "RecordingInfo:start_time":
                continue
            kind = "static" if chunk.is_static else "temporal"
            key = f"{chunk.entity_path}:{kind}:{name}"
            columns.setdefault(key, []).extend(zip(frames, values, strict=True))
    return {
        k: [v for _, v in sorted(rows, key=lambda r: (r[0] is not None, r[0] or 0, repr(r[1])))]
        for k, rows in sorted(columns.items())
    }


def compare_record(old: Path, new: Path) -> list[str]:
    out: list[str] = []
    a, b = rrd_rows(old / "case5.rrd"), rrd_rows(new / "case5.rrd")
    diff(a, b, "record/case5.rrd", out)
    print(f"  record: {len(a)} columns, {sum(len(v) for v in a.values())} values compared")
    return out


def ncap_rows(path: Path) -> dict[str, dict[str, Any]]:
    """A `monopic ncap` results file's rows by run id."""
    rows = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    return {r["id"]: r for r in rows}


def score_table(report: Path) -> list[str]:
    """The table of a `monopic ncap` report's "## Points" section, one string per line."""
    lines = report.read_text().splitlines()
    try:
        start = lines.index("## Points (the calculator's compute-score)")
    except ValueError:
        return []
    table: list[str] = []
    for line in lines[start + 1 :]:
        if line.startswith("## "):
            break
        if line.startswith("|"):
            table.append(line.strip())
        elif table:
            break
    return table


def compare_ncap(old: Path, new: Path, where: str = "ncap") -> list[str]:
    """Two `monopic ncap` output folders: results row by row (by run id), the score table."""
    out: list[str] = []
    for folder in (old, new):
        for name in ("results.jsonl", "report.md"):
            if not (folder / name).is_file():
                return [f"{where}: {folder / name} is missing"]
    a, b = ncap_rows(old / "results.jsonl"), ncap_rows(new / "results.jsonl")
    if set(a) != set(b):
        only = sorted(set(a) ^ set(b))
        out.append(f"{where}: runs differ: {len(only)} unmatched of {len(a)}/{len(b)} ({only[0]})")
    for key in sorted(set(a) & set(b)):
        diff(scrub(a[key]), scrub(b[key]), f"{where}[{key}]", out)
    ta, tb = score_table(old / "report.md"), score_table(new / "report.md")
    if not ta:
        out.append(f"{where}: no score table in {old / 'report.md'}")
    diff(ta, tb, f"{where}/report.md score table", out)
    print(f"  ncap: {len(set(a) & set(b))} runs and the score table ({len(ta)} lines) compared")
    return out


def report(problems: list[str], what: str) -> int:
    if problems:
        print(f"DIFFERENT: {len(problems)} difference(s), first ones:")
        for line in problems[:40]:
            print(f"  {line}")
        return 1
    print(f"IDENTICAL: {what} match field by field")
    return 0


def compare(old: Path, new: Path) -> int:
    problems: list[str] = []
    problems += compare_sweep(old, new)
    problems += compare_dataset(old, new)
    closed: list[str] = []
    compare_file(old / "closed_loop.md", new / "closed_loop.md", "closed_loop.md", closed)
    print("  closed loop: table compared")
    problems += closed
    problems += compare_record(old, new)
    problems += compare_ncap(old / "ncap", new / "ncap")
    return report(problems, "sweep, dataset, closed loop, recording and Euro NCAP rating")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="verb", required=True)
    sub.add_parser("capture").add_argument("out", type=Path)
    p = sub.add_parser("compare")
    p.add_argument("old", type=Path)
    p.add_argument("new", type=Path)
    p.add_argument("--renamed", action="append", default=[], metavar="OLD=NEW")
    p = sub.add_parser("compare-ncap", help="two `monopic ncap` output folders")
    p.add_argument("old", type=Path)
    p.add_argument("new", type=Path)
    args = parser.parse_args()
    for pair in getattr(args, "renamed", []):
        old, _, new = pair.partition("=")
        RENAMED.append((old, new))
    if args.verb == "capture":
        capture(args.out)
        return 0
    if args.verb == "compare-ncap":
        return report(compare_ncap(args.old, args.new), "Euro NCAP runs and score table")
    return compare(args.old, args.new)


if __name__ == "__main__":
    sys.exit(main())
