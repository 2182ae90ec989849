"""Create .venv-reference/: MediaPipe 0.10.14 (the paper's reference pipeline) for benchmarks only.

mediapipe 0.10.14 pulls opencv-contrib-python, jax and an old protobuf, which clash with
the project's own pins, so it lives in its own venv that only bench/ uses; this script
never touches .venv. Idempotent: a stamp file records a finished install.

    python3.11 bench/reference_env.py [--python python3.11] [--venv .venv-reference]
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_VENV = ROOT / ".venv-reference"
# The wheel the paper's authors used and the one whose models we converted.
REQUIREMENTS = ("mediapipe==0.10.14",)
STAMP = ".installed-stamp"


def venv_python(venv: Path) -> Path:
    return venv / "bin" / "python"


def ensure(venv: Path = DEFAULT_VENV, python: str = "python3.11") -> Path:
    """The reference venv's interpreter, creating and installing the venv when missing."""
    venv = venv.resolve()
    if venv == (ROOT / ".venv").resolve():
        raise SystemExit("refusing to install mediapipe into the project's .venv")
    stamp = venv / STAMP
    wanted = "\n".join(REQUIREMENTS) + "\n"
    if stamp.is_file() and stamp.read_text() == wanted and venv_python(venv).exists():
        return venv_python(venv)
    if not venv_python(venv).exists():
        exe = shutil.which(python) or python
        subprocess.run([exe, "-m", "venv", str(venv)], check=True)
    pip = [str(venv_python(venv)), "-m", "pip", "--disable-pip-version-check", "-q"]
    subprocess.run([*pip, "install", *REQUIREMENTS], check=True)
    # Fail here, not in the middle of a benchmark, if the solution cannot load.
    subprocess.run(
        [str(venv_python(venv)), "-c", "import mediapipe as mp; mp.solutions.pose.Pose"],
        check=True,
    )
    stamp.write_text(wanted)
    return venv_python(venv)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--venv", type=Path, default=DEFAULT_VENV)
    ap.add_argument("--python", default="python3.11")
    args = ap.parse_args()
    print(ensure(args.venv, args.python))


if __name__ == "__main__":
    sys.exit(main())
