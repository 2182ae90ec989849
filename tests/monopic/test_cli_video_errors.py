"""`monopic video` on bad input: one clear line, non-zero exit, no partial output."""

import subprocess
import sys

from tests.clips import tiny_clip


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


def test_spin_without_threads_to_spin(tmp_path):
    r = run("x.mp4", "--spin", cwd=tmp_path)
    assert r.returncode == 2 and "--spin needs --threads 2 or more" in r.stderr
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
    clip = tiny_clip(tmp_path)
    r = run(str(clip), "--mode", "ground", cwd=tmp_path)
    assert r.returncode == 2 and "--fov" in r.stderr


def test_no_output_asked_for_is_refused_before_any_frame(tmp_path):
    """It used to run the whole video and write nothing, saying only a frame count."""
    clip = tiny_clip(tmp_path)
    r = run(str(clip), cwd=tmp_path)
    assert r.returncode == 2 and r.stdout == ""
    (line,) = r.stderr.strip().splitlines()
    assert (
        "nothing to write: give --out VIDEO.mp4, --csv FRAMES.csv, --tracks TRACKS.txt "
        "and/or --rrd" in line
    )


def test_outputs_go_into_folders_made_as_needed(tmp_path):
    """The one rule for output paths: a missing folder is created (mkdir -p)."""
    clip = tiny_clip(tmp_path)
    out = tmp_path / "new" / "deeper" / "frames.csv"
    r = run(str(clip), "--csv", str(out), cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert out.is_file() and out.read_text().startswith("frameNumber,")
    (tmp_path / "file").write_text("x")
    r = run(str(clip), "--csv", str(tmp_path / "file" / "frames.csv"), cwd=tmp_path)
    assert r.returncode == 2
    (line,) = r.stderr.strip().splitlines()
    assert line.endswith(f"--csv {tmp_path / 'file'}: a file is in the way of this folder")


def test_an_unknown_window_detector_is_named_with_the_choices(tmp_path):
    r = run("x.mp4", "--window-detector", "fp16", cwd=tmp_path)
    assert r.returncode == 2 and "fp16" in r.stderr and "int8" in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_int8_models_on_a_cpu_without_vnni_are_one_line_and_write_nothing(
    tmp_path, monkeypatch, capsys
):
    """Where onnxruntime's int8 kernels saturate, the int8 choices are refused up front
    (run in-process, so the CPU's flags can be those of an AVX2 machine on any host)."""
    import monopic.pose.sessions as sessions
    from monopic.cli.main import main

    monkeypatch.setattr(sessions, "x86_cpu_flags", lambda: frozenset({"avx", "avx2"}))
    clip = tiny_clip(tmp_path)
    for option, value in (("--model", "full-int8"), ("--window-detector", "int8")):
        out = tmp_path / "frames.csv"
        assert main(["video", str(clip), "--csv", str(out), option, value]) == 2
        (line,) = capsys.readouterr().err.strip().splitlines()
        assert line.startswith(f"monopic video: error: {option} {value}: ") and "VNNI" in line
        assert not out.exists()


def test_people_options_out_of_range_or_contradictory_are_one_line(tmp_path):
    clip = tiny_clip(tmp_path)
    csv = str(tmp_path / "f.csv")
    for args, says in (
        (("--max-people", "0"), "--max-people: must be >= 1"),
        (("--budget", "0"), "--budget: must be >= 1"),
        (("--max-people", "1", "--budget", "1"), "--budget 1: the one-pedestrian tracker"),
        (("--max-people", "2", "--budget", "3"), "--budget 3: more landmark runs than people"),
    ):
        r = run(str(clip), "--csv", csv, *args, cwd=tmp_path)
        lines = r.stderr.strip().splitlines()
        assert r.returncode == 2 and len(lines) == 1 and says in lines[0], (args, r.stderr)
        assert not (tmp_path / "f.csv").exists()
