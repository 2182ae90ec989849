"""onnxruntime sessions with an explicit thread budget.

Parallel sweep workers each run their own pipeline; sessions that spin-wait or take every
core would fight, so the thread count is always explicit (sweep workers use one).
"""

from __future__ import annotations

import json
import platform
from importlib import resources
from pathlib import Path

import onnxruntime as ort

# The person detector: MediaPipe's (converted by `make models`), or "int8", that model
# quantised (`make models-int8`; its stem and feature pyramid kept float): 0.65 of the
# float pass at one thread and 0.68 at two on an AVX-512 VNNI core, the tracker's found
# frames and landmark error the same within the paired interval (`bench/int8_detector.py
# judge`; monopic/pose/models/NOTICE.md).
DETECTOR_MODELS = {"float": "pose_detection.onnx", "int8": "pose_detection_int8.onnx"}
DEFAULT_DETECTOR_MODEL = "float"
# MediaPipe's three landmark models (its model_complexity 0, 1, 2), all converted by
# `make models` from MediaPipe's own files (monopic/pose/models/NOTICE.md says where each
# comes from). Full is the one the paper and MediaPipe's Pose solution use by default.
# full-int8 is the full model quantised (`make models-int8`; int8 weights and activations,
# its stem and regression branch kept float): 0.67 of the full model's time at one
# thread on an AVX-512 VNNI core, 0.82 at two; its landmark error equal to the full
# model's within the paired interval (`bench/int8_landmarks.py judge`; NOTICE.md).
LANDMARK_MODELS = {
    "lite": "pose_landmark_lite.onnx",
    "full": "pose_landmark_full.onnx",
    "heavy": "pose_landmark_heavy.onnx",
    "full-int8": "pose_landmark_full_int8.onnx",
}
DEFAULT_LANDMARK_MODEL = "full"
LANDMARK_FILE = LANDMARK_MODELS[DEFAULT_LANDMARK_MODEL]


QUANTISED = frozenset({"full-int8", "int8"})
# The x86 CPU features whose int8 dot products do not saturate: onnxruntime's quantisation
# guide warns that its u8s8 kernels can saturate on x86 CPUs without VNNI. The shipped
# int8 files were judged only where one of these is present; on an AVX2 CPU without them
# the int8 landmark model lost the walker of the test clip in 8 of its first 30 frames
# that the float model tracked in all 30.
INT8_SAFE_X86_FLAGS = frozenset({"avx512_vnni", "avx_vnni", "amx_int8"})


def x86_cpu_flags() -> frozenset[str] | None:
    """The CPU's flags from /proc/cpuinfo on an x86 machine; None elsewhere or unreadable."""
    if platform.machine().lower() not in ("x86_64", "amd64", "i686", "i386"):
        return None
    try:
        text = Path("/proc/cpuinfo").read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
    for line in text.splitlines():
        key, _, value = line.partition(":")
        if key.strip() == "flags":
            return frozenset(value.split())
    return None


def quantised_unavailable(flags: frozenset[str] | None = None) -> str | None:
    """Why the int8 models cannot be trusted on this CPU, or None when they can (or when
    the CPU's flags cannot be read: a machine this project has no figure for)."""
    flags = x86_cpu_flags() if flags is None else flags
    if flags is None or flags & INT8_SAFE_X86_FLAGS:
        return None
    return (
        "the int8 models need a CPU with VNNI (AVX512_VNNI, AVX_VNNI or AMX): without it "
        "onnxruntime's int8 kernels saturate and lose the person; use the float models"
    )


def landmark_file(model: str) -> str:
    """The shipped file of landmark model `model` (lite, full, heavy or full-int8).

    ValueError for an unknown name, or for full-int8 on a CPU where it is wrong."""
    return _choice("landmark", LANDMARK_MODELS, model)


def detector_file(model: str) -> str:
    """The shipped file of detector model `model` (float or int8); ValueError as above."""
    return _choice("detector", DETECTOR_MODELS, model)


def _choice(kind: str, files: dict[str, str], model: str) -> str:
    try:
        name = files[model]
    except KeyError:
        raise ValueError(
            f"unknown {kind} model {model!r}: choose one of {', '.join(files)}"
        ) from None
    if model in QUANTISED and (problem := quantised_unavailable()):
        raise ValueError(f"{kind} model {model!r}: {problem}")
    return name


def model_path(name: str) -> Path:
    """Path of a model shipped inside the package (monopic/pose/models/)."""
    path = Path(str(resources.files("monopic.pose") / "models" / name))
    if not path.is_file():
        raise FileNotFoundError(
            f"pose model {path} is missing: reinstall the package or run `make models`"
        )
    return path


# onnxruntime's execution providers the pose models can run on, by the name commands take.
# "cpu": onnxruntime's own CPU kernels (MLAS), always there. "openvino": Intel's OpenVINO
# execution provider, a plug-in library for the same onnxruntime (the optional extra
# `.[openvino]`, package onnxruntime-ep-openvino), in float32: its CPU kernels use the
# AVX-512 depthwise convolutions MLAS lacks (docs/benchmarks.md). Nodes it does
# not take run on the CPU provider.
RUNTIMES = ("cpu", "openvino")
DEFAULT_RUNTIME = "cpu"
OPENVINO_EP = "OpenVINOExecutionProvider"


def _known_runtime(runtime: str) -> None:
    if runtime not in RUNTIMES:
        raise ValueError(f"unknown runtime {runtime!r}: choose one of {', '.join(RUNTIMES)}")


def check_runtime(runtime: str) -> None:
    """ValueError (naming the choices, or the extra to install) unless `runtime` can run."""
    _known_runtime(runtime)
    if runtime == "openvino":
        _openvino_devices()


def runtime_unavailable(runtime: str) -> str | None:
    """Why `runtime` cannot run on this machine, or None when it can.

    OpenVINO's plug-in offers a CPU device only on Intel CPUs (on an AMD EPYC it lists
    none), so tests and benchmarks ask this rather than whether the extra is installed.
    """
    try:
        check_runtime(runtime)
    except ValueError as err:
        return str(err)
    return None


def _openvino_devices() -> list:
    """OpenVINO's CPU device, its plug-in registered with onnxruntime on first use."""
    try:
        import onnxruntime_ep_openvino as plugin
    except ImportError:
        raise ValueError(
            "runtime 'openvino' needs the optional extra: pip install -e '.[openvino]'"
        ) from None
    if not any(d.ep_name == OPENVINO_EP for d in ort.get_ep_devices()):
        try:
            ort.register_execution_provider_library(OPENVINO_EP, plugin.get_library_path())
        except Exception as err:  # onnxruntime's Fail; registered before, with no device
            if "already registered" not in str(err):
                raise
    devices = [
        d
        for d in ort.get_ep_devices()
        if d.ep_name == OPENVINO_EP and d.device.type == ort.OrtHardwareDeviceType.CPU
    ]
    if not devices:
        raise ValueError(
            "runtime 'openvino': its plug-in offers no CPU device on this machine"
            " (OpenVINO's execution provider lists Intel CPUs only); use --runtime cpu"
        )
    return devices


def make_session(
    path: Path, threads: int = 1, spin: bool = False, runtime: str = DEFAULT_RUNTIME
) -> ort.InferenceSession:
    """A session using exactly `threads` intra-op threads, on `runtime` (RUNTIMES).

    `spin` lets a multi-threaded session's idle threads spin-wait between the operators
    of a run, and stops them when the run returns (onnxruntime's
    session.force_spinning_stop), so nothing spins between frames or while the other
    model runs. Waking a sleeping thread for each of a model's ~160 small operators costs
    more than the operator: on a quiet AVX-512 host spinning took each pose model 0.82-0.84
    of its time at 2 threads, at about the same CPU time (`bench/spin.py`). Beside other
    work on the cores it took twice the
    time (`bench/spin.py --busy 2`), so no session spins by default: it is for a machine
    whose cores are the pipeline's own. One thread has no pool: nothing spins.

    On "openvino" the thread count and float32 precision are OpenVINO's own settings:
    on a CPU with AMX it would otherwise compute in bfloat16, which moves landmarks.
    """
    if threads < 1:
        raise ValueError(f"threads must be >= 1, got {threads}")
    _known_runtime(runtime)  # the openvino branch below finds its plug-in (or says why not)
    opts = ort.SessionOptions()
    opts.intra_op_num_threads = threads
    opts.inter_op_num_threads = 1
    opts.execution_mode = ort.ExecutionMode.ORT_SEQUENTIAL
    opts.graph_optimization_level = ort.GraphOptimizationLevel.ORT_ENABLE_ALL
    spinning = spin and threads > 1
    opts.add_session_config_entry("session.intra_op.allow_spinning", "1" if spinning else "0")
    if spinning:  # spin during a run only: stop when it returns
        opts.add_session_config_entry("session.force_spinning_stop", "1")
    if threads > 1:  # smaller blocks, taken dynamically: a delayed thread does less
        opts.add_session_config_entry("session.dynamic_block_base", "4")
    opts.add_session_config_entry("session.inter_op.allow_spinning", "0")
    if runtime == "openvino":
        config = {"CPU": {"INFERENCE_PRECISION_HINT": "f32", "INFERENCE_NUM_THREADS": str(threads)}}
        opts.add_provider_for_devices(_openvino_devices(), {"load_config": json.dumps(config)})
        return ort.InferenceSession(str(path), sess_options=opts)
    return ort.InferenceSession(str(path), sess_options=opts, providers=["CPUExecutionProvider"])
