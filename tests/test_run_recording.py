"""A recording appears whole or not at all: used as a context manager, an error drops it."""

from pathlib import Path

import pytest

from monopic.recording import RunRecording


def test_recording_appears_only_when_the_run_ends_without_an_error(tmp_path: Path) -> None:
    good, bad = tmp_path / "good.rrd", tmp_path / "bad.rrd"
    with RunRecording(good):
        pass
    with pytest.raises(RuntimeError), RunRecording(bad):
        raise RuntimeError("the run broke")
    assert good.exists() and good.stat().st_size > 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["good.rrd"]  # no temporary left
