"""Create .venv-reference/: MediaPipe 0.10.14 (the paper's reference pipeline) for benchmarks only.

mediapipe 0.10.14 pulls opencv-contrib-python, jax and an old protobuf, which clash with
the project's own pins, so it lives in its own venv that only bench/ uses; this script
never touches .venv. Idempotent: a stamp file records a finished install.

The wheel ships only the full landmark model; for model_complexity 0 and 2 MediaPipe's
Python solution downloads pose_landmark_lite.tflite / pose_landmark_heavy.tflite at run
time unless they are already in its package. This script puts them there at install
time, from the same registry package `make models` converts ours from (Google's npm
package @mediapipe/pose, fetched with `npm pack`, sha256-checked), so the reference never
downloads anything while it runs.

    python3.11 -m bench.reference_env [--python python3.11] [--venv .venv-reference]
"""

from __future__ import annotations

import argparse
import hashlib
import shutil
import subprocess
import sys
import tarfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_VENV = ROOT / ".venv-reference"
# The wheel the paper's authors used and the one whose models we converted.
REQUIREMENTS = ("mediapipe==0.10.14",)
STAMP = ".installed-stamp"
# The lite and heavy models, as in tools/models/convert.py (same package, same files).
NPM_POSE = "@mediapipe/pose@0.5.1675469404"
NPM_POSE_TARBALL = "mediapipe-pose-0.5.1675469404.tgz"
NPM_POSE_SHA256 = "8bb349a7b3a3ba699df23be804ddd3b3eab810b50b15406894be257859388a84"
EXTRA_MODELS = {  # file name: sha256
    "pose_landmark_lite.tflite": (
        "f17bfbecadb61c3be1baa8b8d851cc6619c870a87167b32848ad20db306b9d61"
    ),
    "pose_landmark_heavy.tflite": (
        "59e42d71bcd44cbdbabc419f0ff76686595fd265419566bd4009ef703ea8e1fe"
    ),
}


def venv_python(venv: Path) -> Path:
    return venv / "bin" / "python"


def ensure(venv: Path = DEFAULT_VENV, python: str = "python3.11") -> Path:
    """The reference venv's interpreter, creating and installing the venv when missing."""
    venv = venv.resolve()
    if venv == (ROOT / ".venv").resolve():
        raise SystemExit("refusing to install mediapipe into the project's .venv")
    stamp = venv / STAMP
    wanted = "\n".join([*REQUIREMENTS, NPM_POSE]) + "\n"
    if stamp.is_file() and stamp.read_text() == wanted and venv_python(venv).exists():
        return venv_python(venv)
    if not venv_python(venv).exists():
        exe = shutil.which(python) or python
        subprocess.run([exe, "-m", "venv", str(venv)], check=True)
    pip = [str(venv_python(venv)), "-m", "pip", "--disable-pip-version-check", "-q"]
    subprocess.run([*pip, "install", *REQUIREMENTS], check=True)
    install_extra_models(venv)
    # Fail here, not in the middle of a benchmark, if the solution cannot load.
    subprocess.run(
        [str(venv_python(venv)), "-c", "import mediapipe as mp; mp.solutions.pose.Pose"],
        check=True,
    )
    stamp.write_text(wanted)
    return venv_python(venv)


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def install_extra_models(venv: Path) -> None:
    """Copy the lite and heavy landmark models from the npm package into mediapipe."""
    cache = venv / "npm"
    cache.mkdir(exist_ok=True)
    tgz = cache / NPM_POSE_TARBALL
    if not tgz.is_file():
        subprocess.run(["npm", "pack", NPM_POSE, "--pack-destination", str(cache)], check=True)
    if _sha256(tgz.read_bytes()) != NPM_POSE_SHA256:
        raise SystemExit(f"sha256 mismatch for {tgz}")
    found = subprocess.run(
        [
            str(venv_python(venv)),
            "-c",
            "import mediapipe, os; print(os.path.dirname(mediapipe.__file__))",
        ],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    dest = Path(found) / "modules" / "pose_landmark"
    with tarfile.open(tgz, "r:gz") as tar:
        for name, digest in EXTRA_MODELS.items():
            handle = tar.extractfile(f"package/{name}")
            data = handle.read() if handle is not None else b""
            if _sha256(data) != digest:
                raise SystemExit(f"sha256 mismatch for {name} in {tgz}")
            (dest / name).write_bytes(data)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--venv", type=Path, default=DEFAULT_VENV)
    ap.add_argument("--python", default="python3.11")
    args = ap.parse_args()
    print(ensure(args.venv, args.python))


if __name__ == "__main__":
    sys.exit(main())
