"""The one place that calls rerun's private API: a recording stream saved to a file with
a default blueprint whose stream we can free.

Why: rerun-sdk 0.41 (pinned) saves a file with a default blueprint by building a second,
blueprint-only recording stream (rerun.blueprint.api.create_in_memory_blueprint) that it
never frees: each `RecordingStream.save(path, default_blueprint=...)` leaves that stream's
two batcher threads and its buffers behind for the life of the process. A sweep worker
recording every run grew by 4 threads and about 12 MB a run (1300 threads and 1.8 GB
after 340 runs). Here the blueprint stream is built the same way, but kept, so that
`release` can disconnect it with the recording.

The private calls are `RecordingStream._from_native` and `Blueprint._log_to_stream`,
plus the `rerun_bindings` functions rerun's own `save` uses. tests/monopic/
test_rerun_file.py checks that they are there with the arguments used here, that the
public path still leaks (when it stops, this module can go: save with
`rec.save(path, default_blueprint=layout)`), and that this one does not.
"""

from __future__ import annotations

from pathlib import Path

import rerun as rr
import rerun.blueprint as rrb
import rerun_bindings


def save_with_blueprint(
    rec: rr.RecordingStream, path: Path, layout: rrb.Blueprint
) -> rr.RecordingStream:
    """Stream `rec` into the file at `path` with `layout` as its default blueprint (what
    `rec.save(path, default_blueprint=layout)` does); returns the blueprint's own stream,
    to be given to `release`."""
    app = rec.get_application_id() or "monopic"
    blueprint = rr.RecordingStream._from_native(  # noqa: SLF001 - the module docstring
        rerun_bindings.new_blueprint(
            application_id=app, make_default=False, make_thread_default=False
        )
    )
    blueprint.set_time("blueprint", sequence=0)
    layout.to_blueprint()._log_to_stream(blueprint)  # noqa: SLF001
    rerun_bindings.save(
        path=str(path),
        default_blueprint=blueprint.memory_recording().storage,
        recording=rec.to_native(),
        write_footer=True,
    )
    return blueprint


def release(rec: rr.RecordingStream, saving: bool, blueprint: rr.RecordingStream | None) -> None:
    """Free the streams' native side now, not at a cleanup pass that may never come.

    `saving`: `rec` streams into a file (it is then disconnected, which flushes it);
    otherwise its buffer is dropped without the warning a disconnect would print."""
    if saving:
        rec.disconnect()
    else:
        rec.set_sinks()
    if blueprint is not None:
        blueprint.disconnect()
    rerun_bindings.flush_and_cleanup_orphaned_recordings()
