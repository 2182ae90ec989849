"""`monopic video` on bad input: one clear line, non-zero exit, no partial output."""

import subprocess
import sys


def run(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "monopic", "video", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_unreadable_input(tmp_path):
    bad = tmp_path / "not_a_video.mp4"
    bad.write_bytes(b"this is not a video at all" * 10)
    out = tmp_path / "out.mp4"
    r = run(str(bad), "--out", str(out), "--csv", str(tmp_path / "f.csv"), cwd=tmp_path)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "not_a_video.mp4" in lines[0], r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["not_a_video.mp4"]


def test_missing_input(tmp_path):
    r = run(str(tmp_path / "nope.mp4"), cwd=tmp_path)
    assert r.returncode == 2 and "nope.mp4: no such video file" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_unknown_variant_and_bad_horizon(tmp_path):
    r = run("x.mp4", "--variant", "teleport", cwd=tmp_path)
    assert r.returncode == 2 and "teleport" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    for bad in ("0", "-1", "nan", "soon"):
        r = run("x.mp4", "--horizon", bad, cwd=tmp_path)
        assert r.returncode == 2 and "--horizon" in r.stderr, bad
        assert len(r.stderr.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_ground_mode_needs_camera_geometry(tmp_path):
    import cv2
    import numpy as np

    clip = tmp_path / "c.mp4"
    w = cv2.VideoWriter(str(clip), cv2.VideoWriter_fourcc(*"mp4v"), 15, (64, 48))
    for _ in range(3):
        w.write(np.zeros((48, 64, 3), np.uint8))
    w.release()
    r = run(str(clip), "--mode", "ground", cwd=tmp_path)
    assert r.returncode == 2 and "--fov" in r.stderr
