"""Screenshots of a .rrd recording as the real rerun viewer draws it, on a headless machine.

    .venv/bin/python -m tools.view.screenshot recordings/case5.rrd --out /tmp/shots \
        --at 1.5 --at 2.6 --at end [--size 1600x1000] [--view NAME] [--small 1400]

What works here (2 cores, no GPU, no display): the native viewer of rerun-sdk 0.41 in its
headless mode (`rerun --headless`: an offscreen egui harness, no window, no X server)
on Mesa's lavapipe, a software Vulkan driver (Debian: `apt-get install -y
mesa-vulkan-drivers`; without a Vulkan driver the tool stops with one line saying so),
driven over gRPC by rerun's ViewerClient: open the file, move the
time cursor to each `--at` (seconds on the `time` timeline, paused; `end` for the last
frame), save a screenshot (of the whole viewer or of one `--view`). It prints what each
view reported as failing to draw. About 5 s for a few screenshots. By hand:

    WGPU_BACKEND=vulkan .venv/lib/python3.11/site-packages/rerun_cli/rerun --headless \
        --port 9877 --window-size 1600x1000 &
    # then, in Python: c = ViewerClient.connect("rerun+http://127.0.0.1:9877/proxy");
    # c.open(rrd); c.set_time("time", duration=2.6, play_state="paused");
    # c.save_screenshot("/tmp/shot.png")

Also seen to work:
- `--web`: rerun's web viewer (`rerun --serve-web FILE`) in headless Chromium with
  SwiftShader WebGL (Debian: `apt-get install -y chromium`); 20-50 s, the time is
  wherever playback got to (the end, usually), the side panels show and the JPEG frames
  may still be decoding (a spinner). A cross-check, not the way. The command it runs:
      chromium --headless=new --no-sandbox --use-angle=swiftshader \
          --enable-unsafe-swiftshader --window-size=1600,1000 \
          --virtual-time-budget=60000 --screenshot=OUT.png \
          "http://127.0.0.1:9091/?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A9878%2Fproxy&renderer=webgl"
- The windowed viewer under Xvfb (`Xvfb :99 &`, then `DISPLAY=:99 WGPU_BACKEND=vulkan
  rerun FILE.rrd --window-size 1600x1000 --screenshot-to out.png`, which saves once the
  file has loaded, wherever playback is). An earlier session's tries there: the GL
  backend on llvmpipe fails ("Adapter does not support drawing to texture format
  R32Float"), and `import -window root` captured black: the viewer's own screenshot is
  the way.

The viewer runs with a home of its own, so no state a viewer persisted in
~/.local/share/rerun (the blueprint a person edited) changes what is shown. A development
tool: nothing in `make test` needs it. `--small W` also writes NAME-small.png, at most W
pixels wide and quantised to 256 colours (about 150 kB at 1600), for docs/images/.
"""

from __future__ import annotations

import argparse
import os
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path
from urllib.parse import quote

from PIL import Image
from rerun.experimental import ViewerClient

ROOT = Path(__file__).resolve().parents[2]


def rerun_executable() -> str:
    """The viewer binary itself (rerun_cli's), not the `rerun` wrapper script.

    The wrapper runs the binary as a child: terminating the wrapper would leave the viewer
    running (and listening on the port the next run wants).
    """
    import rerun_cli

    binary = Path(rerun_cli.__file__).parent / "rerun"
    if not binary.is_file():
        raise FileNotFoundError(f"{binary}: the rerun viewer of rerun-sdk is missing")
    return str(binary)


# Where the Vulkan loader looks for drivers (ICD manifests) when no variable names them.
VULKAN_ICD_DIRS = ("/usr/share/vulkan/icd.d", "/etc/vulkan/icd.d", "/usr/local/share/vulkan/icd.d")
NO_VULKAN = (
    "no Vulkan driver found: rerun's headless viewer draws with Vulkan and finds no graphics "
    "adapter without one; install Mesa's software driver (lavapipe): apt-get install -y "
    "mesa-vulkan-drivers (Debian, Ubuntu), or use --web"
)


def vulkan_drivers(env: dict[str, str] | os._Environ[str] = os.environ) -> list[Path]:
    """The Vulkan driver manifests the loader would find (VK_DRIVER_FILES or
    VK_ICD_FILENAMES when set, as the loader reads them, else its standard folders)."""
    listed = env.get("VK_DRIVER_FILES") or env.get("VK_ICD_FILENAMES")
    if listed:
        return [Path(p) for p in listed.split(os.pathsep) if Path(p).is_file()]
    return sorted(p for d in VULKAN_ICD_DIRS for p in Path(d).glob("*.json"))


def port_free(port: int) -> bool:
    """Nothing listens on 127.0.0.1:`port` (else a client would talk to another viewer)."""
    with socket.socket() as sock:
        return sock.connect_ex(("127.0.0.1", port)) != 0


def start_viewer(port: int, size: str, log: Path) -> subprocess.Popen:
    """A headless viewer on lavapipe Vulkan, listening for control on `port`.

    It runs with a home of its own (beside the log) so that no state a viewer persisted
    (~/.local/share/rerun: a blueprint edited by hand, the catalog setting) changes what
    the recording's own blueprint shows.
    """
    env = viewer_env(log.parent / "viewer-home")
    cmd = [rerun_executable(), "--headless", "--hide-welcome-screen"]
    cmd += ["--port", str(port), "--window-size", size, "--threads", "1"]
    with log.open("w") as out:
        return subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT, env=env)


def connect(port: int, viewer: subprocess.Popen, timeout: float = 60.0) -> ViewerClient:
    """A client once the viewer answers (it takes a few seconds to start)."""
    deadline = time.monotonic() + timeout
    while True:
        if viewer.poll() is not None:
            raise RuntimeError(f"the viewer exited with status {viewer.returncode}")
        try:
            client = ViewerClient.connect(f"rerun+http://127.0.0.1:{port}/proxy")
            client.get_state()
            return client
        except Exception:  # not listening yet
            if time.monotonic() > deadline:
                raise
            time.sleep(0.5)


def open_recording(client: ViewerClient, rrd: Path, timeout: float = 60.0) -> int:
    """Open `rrd` and wait until it has loaded; the end of its `time` timeline, in ns."""
    client.open(str(rrd.resolve()))
    deadline = time.monotonic() + timeout
    while True:
        state = client.get_state()
        recordings = [r for r in state.recordings if r.store_id == state.active_recording]
        timelines = {t.name: t for r in recordings for t in r.timelines}
        if not state.loading and "time" in timelines and timelines["time"].end is not None:
            for view in state.views:
                for report in view.reports:
                    print(f"  view {view.name!r}: {report.severity}: {report.summary}")
            return int(timelines["time"].end)
        if time.monotonic() > deadline:
            raise TimeoutError(f"{rrd}: still loading after {timeout:.0f} s")
        time.sleep(0.5)


def view_id(client: ViewerClient, name: str | None) -> str | None:
    """The id of the view called `name` (None: the whole viewer)."""
    if name is None:
        return None
    views = {v.name: v.view_id for v in client.get_state().views}
    if name not in views:
        raise SystemExit(f"no view {name!r}; the views: {', '.join(sorted(views))}")
    return views[name]


def last_error(log: Path) -> str:
    """The viewer log's last line that reads like an error, for a one-line message."""
    try:
        lines = log.read_text(errors="replace").splitlines()
    except OSError:
        return "no viewer log"
    panics = [ln.strip() for ln in lines if "panicked at" in ln]  # before its backtrace
    errors = panics or [ln.strip() for ln in lines if "ERROR" in ln or "error:" in ln]
    if not errors:
        return "the viewer logged no error"
    line = errors[-1]
    if "adapter" in line.lower():
        return f"the viewer found no graphics adapter ({NO_VULKAN.split('; ', 1)[1]})"
    return f"the viewer said: {line[:200]}"


def small_copy(png: Path, width: int) -> Path:
    """NAME-small.png: at most `width` px wide, 256 colours."""
    image = Image.open(png).convert("RGB")
    if image.width > width:
        image = image.resize((width, round(image.height * width / image.width)), Image.LANCZOS)
    out = png.with_name(png.stem + "-small.png")
    # Octree keeps the small saturated marks (lanes, legend dots) their colour.
    image.quantize(256, method=Image.Quantize.FASTOCTREE).save(out, optimize=True)
    return out


def viewer_env(home: Path) -> dict[str, str]:
    """The environment of a viewer with a home of its own and lavapipe Vulkan."""
    home.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, WGPU_BACKEND="vulkan", HOME=str(home))
    for var in ("XDG_DATA_HOME", "XDG_CONFIG_HOME", "XDG_CACHE_HOME", "DISPLAY"):
        env.pop(var, None)
    return env


def web_screenshot(rrd: Path, out: Path, size: str, port: int) -> Path:
    """The web viewer's picture of `rrd` in headless Chromium (SwiftShader WebGL)."""
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        raise SystemExit("no chromium: apt-get install -y chromium")
    web_port, grpc_port = port, port + 1
    for p in (web_port, grpc_port):
        if not port_free(p):
            raise SystemExit(f"port {p} is in use: pick others with --port")
    cmd = [rerun_executable(), "--serve-web", str(rrd.resolve())]
    cmd += ["--web-viewer-port", str(web_port), "--port", str(grpc_port)]
    with (out / "web-viewer.log").open("w") as log:
        server = subprocess.Popen(
            cmd, stdout=log, stderr=subprocess.STDOUT, env=viewer_env(out / "viewer-home")
        )
    png = (out / f"{rrd.stem}_web.png").resolve()
    proxy = quote(f"rerun+http://127.0.0.1:{grpc_port}/proxy", safe="")
    try:
        time.sleep(3)  # the server starts
        subprocess.run(
            [chromium, "--headless=new", "--no-sandbox", "--use-angle=swiftshader",
             "--enable-unsafe-swiftshader", f"--window-size={size.replace('x', ',')}",
             "--virtual-time-budget=60000", f"--user-data-dir={out / 'chromium-profile'}",
             f"--screenshot={png}",
             f"http://127.0.0.1:{web_port}/?url={proxy}&renderer=webgl"],
            check=True, capture_output=True, timeout=300,
        )  # fmt: skip
    finally:
        server.terminate()
        server.wait(timeout=10)
    return png


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("rrd", type=Path)
    p.add_argument("--out", type=Path, default=Path("/tmp/rerun-shots"), help="folder")
    p.add_argument(
        "--at",
        action="append",
        help="seconds on the `time` timeline, or `end` (repeatable; default: end)",
    )
    p.add_argument("--size", default="1600x1000", help="viewer size in points (1600x1000)")
    p.add_argument("--port", type=int, default=9877)
    p.add_argument("--settle", type=float, default=2.0, help="s to wait after a time change")
    p.add_argument("--small", type=int, metavar="W", help="also write a W px wide copy")
    p.add_argument("--view", help="only the view with this name (default: the whole viewer)")
    p.add_argument("--web", action="store_true", help="the web viewer in headless Chromium")
    args = p.parse_args(argv)

    if not args.rrd.is_file():
        sys.exit(f"screenshot.py: {args.rrd}: no such recording")
    args.out.mkdir(parents=True, exist_ok=True)
    if args.web:
        print(web_screenshot(args.rrd, args.out, args.size, args.port))
        return 0
    if not vulkan_drivers():
        sys.exit(f"screenshot.py: {NO_VULKAN}")
    if not port_free(args.port):
        sys.exit(f"port {args.port} is in use (another viewer?): pick one with --port")
    log = args.out / "viewer.log"
    viewer = start_viewer(args.port, args.size, log)
    try:
        try:
            client = connect(args.port, viewer)
            end_ns = open_recording(client, args.rrd)
        except (RuntimeError, TimeoutError, ConnectionError) as err:
            sys.exit(f"screenshot.py: {err}; {last_error(log)} (whole log: {log})")
        for at in args.at or ["end"]:
            ns = end_ns if at == "end" else round(float(at) * 1e9)
            client.set_time("time", duration=ns * 1e-9, play_state="paused")
            time.sleep(args.settle)  # let the views catch up (latest-at queries, JPEG decode)
            stem = f"{args.rrd.stem}_{'end' if at == 'end' else f'{float(at):.2f}s'}"
            if args.view:
                stem += "_" + "".join(c if c.isalnum() else "-" for c in args.view)
            png = (args.out / f"{stem}.png").resolve()
            client.save_screenshot(str(png), view_id=view_id(client, args.view))
            print(png)
            if args.small:
                print(small_copy(png, args.small))
    finally:
        viewer.terminate()
        try:
            viewer.wait(timeout=10)
        except subprocess.TimeoutExpired:
            viewer.kill()
    return 0


if __name__ == "__main__":
    sys.exit(main())
