"""A recording appears whole or not at all: used as a context manager, an error drops it."""

import time
from pathlib import Path

import pytest
import rerun as rr

from monopic.recording import RunRecording
from tests.rrd import rows_per_entity


def test_recording_appears_only_when_the_run_ends_without_an_error(tmp_path: Path) -> None:
    good, bad = tmp_path / "good.rrd", tmp_path / "bad.rrd"
    with RunRecording(good):
        pass
    with pytest.raises(RuntimeError), RunRecording(bad):
        raise RuntimeError("the run broke")
    assert good.exists() and good.stat().st_size > 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["good.rrd"]  # no temporary left


def test_a_close_interrupted_before_the_rename_leaves_no_temporary(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Ctrl-C while the finished file is flushed: neither the file nor its temporary stays.
    rec = RunRecording(tmp_path / "run.rrd")
    rec.rec.log("features/phi", rr.Scalars(1.0))
    release = rec._release

    def interrupted() -> None:
        release()
        raise KeyboardInterrupt

    monkeypatch.setattr(rec, "_release", interrupted)
    with pytest.raises(KeyboardInterrupt):
        rec.close()
    assert list(tmp_path.iterdir()) == []


def _threads() -> int:
    """This process's threads once the short-lived ones are gone: the fewest seen over
    0.3 s (rerun's flush threads end a moment after a recording closes; a full-suite run
    once read [9, 8, 9, 9, 8, 9]). A leaked thread stays, so it is still counted."""
    seen = []
    for _ in range(30):
        status = Path("/proc/self/status").read_text().splitlines()
        seen.append(int(next(ln for ln in status if ln.startswith("Threads:")).split()[1]))
        time.sleep(0.01)
    return min(seen)


def test_dropped_recordings_free_their_threads(tmp_path: Path) -> None:
    # rerun keeps a dropped stream's batcher threads and buffers until a cleanup pass; a
    # sweep worker records every run and drops most of them, so each must be freed. The
    # first recordings may start threads rerun then keeps for all (a full-suite run once
    # read [8, 9, 9, 9]): the count must not grow after them.
    counts = []
    for k in range(6):
        rec = RunRecording(tmp_path / f"r{k}.rrd")
        rec.abort()
        counts.append(_threads())
    assert counts[-1] <= counts[1], counts
    assert not list(tmp_path.iterdir())
    # Kept ones too, blueprint included (rerun makes a stream for it).
    counts = []
    for k in range(6):
        rec = RunRecording(tmp_path / f"k{k}.rrd")
        rec.rec.log("features/phi", rr.Scalars(float(k)))
        rec.close()
        counts.append(_threads())
    assert counts[-1] <= counts[1], counts
    assert rows_per_entity(tmp_path / "k3.rrd") == {"/features/phi": 1}  # whole, readable
