"""An int8 candidate of the landmark model or the detector, for bench/int8_*.py to judge.

Static quantisation with onnxruntime's quantizer (QDQ format; `--format qoperator` for its
QLinear operators): weights int8 per output channel, activations uint8 per tensor, ranges
calibrated on landmark-model crops of rendered frames and the shipped clip (written by
`.venv/bin/python -m bench.int8_landmarks crops`; the detector's windows with --detector,
below). The shipped float model stores its weights as fp16 + Cast, which the quantizer
would take for activations; they are turned back into float32 initializers first
(lossless). The result is NOT shipped unless the judge says it keeps the float model's
landmark error.

    .venv-models/bin/python -m tools.models.quantize --crops recordings/int8/calibration.npz \
        --out recordings/int8/pose_landmark_full_int8.onnx [--method minmax|percentile|entropy]
        [--deep-only PX] [--keep-outputs]

--keep-outputs keeps each output's nodes back to its last convolution (on every path) in
float (a uint8 landmark output would step by about a pixel; it did not help).

--deep-only PX quantizes only the convolutions whose output is at most PX pixels on a side
(the deep, many-channel layers, where int8 kernels gain most), keeping the early
high-resolution layers, the decoder and the heads in float.

The candidate that keeps the float model's landmark error, shipped as
monopic/pose/models/pose_landmark_full_int8.onnx (`make models-int8`; judged on the
AVX-512 VNNI EPYC; `.venv/bin/python -m bench.int8_landmarks judge ... --rounds 6`: int8 -
float +0.04 [-0.14, +0.20] px on 559 frames, passes; 0.74 of the float time at 1 thread):

    .venv-models/bin/python -m tools.models.quantize --crops recordings/int8/calibration.npz \
        --out monopic/pose/models/pose_landmark_full_int8.onnx --method percentile \
        --equalize 1.5 --float-ends --gptq

--float-ends keeps the stem (the first three convolutions, 128 px; no faster in int8) and
the regression branch in float (`--float-ends stem` or `branch`: one of them; for the
detector's, below). The branch is every node that feeds only the landmark and flag outputs,
not the heatmap (the 4 and 2 px blocks, their residual adds and the heads, 7 % of the
MACs). This is what matters: the uint8 residual tensors of those small blocks, which the
regressed points (and so the heatmap window the refinement reads) come from, carried most
of the landmark shift. Excluding their convolutions alone does not do it (their adds keep
the tensors uint8), the whole branch must stay float. Alone, with min-max calibration, it
already passes (+0.10 [-0.10, +0.29] px); the two options below add margin.

--equalize MARGIN raises each channel that a Clip(0, 6) ends (its calibration maximum M)
toward 6 / MARGIN before quantising: the producing convolution's row and bias divided by
M * MARGIN / 6, the consuming convolution's column (or depthwise row) multiplied by it.
Exact while the raised channel stays below 6 (+0.71 -> +0.36 px with all int8); it
gives the small channels of a uint8 ReLU6 tensor more of its 256 steps.

--gptq re-rounds the int8 weights on the same per-channel scales (GPTQ, Frantar et al.
2022): column by column, each rounding error is pushed onto the not yet rounded columns
through the inverse of H = E[x x^T] of the convolution's input patches in the float model
(64 of the calibration crops). Weights alone (activations float), rounding to nearest moved
the heatmap-refined landmarks 1.7 px in the 256 px crop, GPTQ 0.46 px.

Before quantising, the zero Pads that four strided depthwise convolutions read are folded
into those convolutions' `pads` (tools/models/onnx_post.py `fold_pad_into_conv`, as
onnxruntime does for the float model at load). Left in place, each sat between a
DequantizeLinear and a QuantizeLinear of equal scale, three kernels over the 128 and 64 px
tensors that onnxruntime does not fuse: the shipped model's outputs are identical without
them, and it runs in 0.84 of the time (7.18 against 8.59 ms at 1 thread).

Any convolution kept float whose input comes from a DequantizeLinear gets its own
DequantizeLinear with a per-channel (equal) scale: onnxruntime's level-1
WeightBiasQuantization transformer otherwise quantizes that convolution's float weights
per tensor (to it DQ -> Conv -> [Clip] -> Q is a QDQ node unit), which put a
depthwise-float model thousands of pixels off. --float-depthwise keeps the landmark
model's depthwise convolutions float that way: +0.45 [+0.19, +0.74] px and 1.12x the float
time, no better than all int8.

The detector (its search passes take about a quarter of a scenario run's time), for
bench/int8_detector.py to judge, calibrated on the letterboxed detector windows (uint8,
scaled to [-1, 1] as the detector takes them) written by `.venv/bin/python -m
bench.int8_detector windows`. Every option above applies to it (--equalize and --gptq run
the detector's own feeds; --keep-heads keeps only its six output convolutions float). Its
windows go through the calibrator in chunks (`_chunk`: it keeps every tensor of every
input until the end, 34 GB for 600 windows). For the detector --float-ends keeps the stem
(three convolutions, 112 px) and the feature pyramid float: every node the backbone's
deepest tensor does not depend on (the top-down path from the first Resize, its lateral
projections of the 28 and 14 px blocks, the six heads; 23 % of the MACs, the stem 4 %).
The uint8 tensors there are what moved the detections (800 windows of the calibration
frames that the calibration did not use): all int8 but the output tails, the regressed
keypoints moved a median 0.8-2.7 px of the 224 px window, and decoding float scores with
int8 boxes moved the detection as much as all int8, int8 scores with float boxes hardly at
all; the heads float, still 0.4-1.4 px (their inputs uint8); the heads and the top-down
path float, 0.1-0.5 px.

    .venv-models/bin/python -m tools.models.quantize --detector \
        --crops recordings/int8/detector_windows.npz \
        --out monopic/pose/models/pose_detection_int8.onnx \
        --method percentile --equalize 1.5 --float-ends --gptq

`.venv/bin/python -m bench.int8_detector judge ... --no-append` (600 frames x 27 windows,
the AVX-512 VNNI EPYC, 2026-12-03, load 3 from another job, so the time ratio is the
alternated one): tracker found 98.2 % of frames with either detector (differing on 0
frames); windows found by one detector only 42 float, 10 int8 (of 4635 float finds); the
farthest keypoint moved a median 1.0 % of the float box's height (p95 3.0 %); the
tracker's landmark error, int8 detector - float, -0.02 [-0.18, +0.17] px on 559 frames;
0.69 of the float pass time at 1 thread (9.13 vs 13.22 ms). With min-max calibration and
neither --equalize nor --gptq (`--detector --float-ends`): 54 / 12 windows, 1.2 % (p95 3.8
%), -0.05 [-0.19, +0.09] px, 0.66 (load 1.0). All int8 but the output tails (`--method
percentile --equalize 1.5 --gptq --keep-outputs`): 9 / 352 windows, the tracker 95.0 %,
7.5 % (p95 13.6 %), +0.38 [+0.04, +0.80] px, 0.63. The first is shipped (`make
models-int8`) as monopic/pose/models/pose_detection_int8.onnx, the tracker's
`detector="int8"` choice; the default detector stays the float one.

A first detector candidate (not shipped: the tracker found 68 % of frames against 98 %)
was `--detector --format qoperator --float-depthwise` with min-max calibration
(QLinearConv; on an AVX2 CPU without VNNI, int8 depthwise convolutions were slower than
float ones).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

import numpy as np
import onnx
import onnxruntime as ort
from onnx import TensorProto, helper, numpy_helper, shape_inference
from onnxruntime.quantization import (
    CalibrationDataReader,
    CalibrationMethod,
    QuantFormat,
    QuantType,
    quantize_static,
)

from tools.models.onnx_post import fold_pad_into_conv

REPO = Path(__file__).resolve().parents[2]
FLOAT_MODEL = REPO / "monopic" / "pose" / "models" / "pose_landmark_full.onnx"
DETECTOR_MODEL = REPO / "monopic" / "pose" / "models" / "pose_detection.onnx"
METHODS = {
    "minmax": CalibrationMethod.MinMax,
    "percentile": CalibrationMethod.Percentile,
    "entropy": CalibrationMethod.Entropy,
}


def float32_weights(model: onnx.ModelProto) -> int:
    """Replace every Cast of an fp16 initializer by a float32 initializer; return the count."""
    graph = model.graph
    inits = {i.name: i for i in graph.initializer}
    kept, folded = [], 0
    for node in graph.node:
        if node.op_type == "Cast" and node.input[0] in inits:
            value = numpy_helper.to_array(inits[node.input[0]]).astype(np.float32)
            graph.initializer.append(numpy_helper.from_array(value, node.output[0]))
            folded += 1
        else:
            kept.append(node)
    del graph.node[:]
    graph.node.extend(kept)
    used = {name for node in graph.node for name in node.input}
    live = [i for i in graph.initializer if i.name in used]
    del graph.initializer[:]
    graph.initializer.extend(live)
    return folded


def _head_convs(model: onnx.ModelProto) -> set[str]:
    """The convolutions whose outputs reach a Reshape through Transposes only: the heads."""
    producer = {o: n for n in model.graph.node for o in n.output}
    heads = set()
    for node in model.graph.node:
        if node.op_type != "Reshape":
            continue
        x = producer.get(node.input[0])
        while x is not None and x.op_type == "Transpose":
            x = producer.get(x.input[0])
        if x is not None and x.op_type == "Conv":
            heads.add(x.name)
    return heads


def _output_tails(model: onnx.ModelProto) -> list[str]:
    """Each graph output's producing nodes back to and including its last convolution on
    every path (the detector's outputs concatenate three heads each): a uint8 landmark
    output steps by about a pixel, so these stay float."""
    producer = {o: n for n in model.graph.node for o in n.output}
    tails: list[str] = []
    stack = [producer.get(o.name) for o in model.graph.output]
    while stack:
        node = stack.pop()
        if node is None or node.name in tails:
            continue
        tails.append(node.name)
        if node.op_type != "Conv":
            stack.extend(producer.get(name) for name in node.input)
    return tails


def _attr(node: onnx.NodeProto, name: str, default: object = None) -> object:
    """A node attribute's value, or `default` if the node does not set it."""
    for a in node.attribute:
        if a.name == name:
            return helper.get_attribute_value(a)
    return default


def _session(model: onnx.ModelProto, tensors: list[str]) -> ort.InferenceSession:
    """A one-thread session of `model` that also outputs `tensors` (float)."""
    m = onnx.ModelProto()
    m.CopyFrom(model)
    have = {o.name for o in m.graph.output} | {i.name for i in m.graph.input}
    for name in tensors:
        if name not in have:
            m.graph.output.append(helper.make_tensor_value_info(name, TensorProto.FLOAT, None))
    options = ort.SessionOptions()
    options.intra_op_num_threads = 1
    return ort.InferenceSession(m.SerializeToString(), options, providers=["CPUExecutionProvider"])


def _feeds(crops: np.ndarray, name: str, detector: bool = False) -> list[dict[str, np.ndarray]]:
    """The model's feeds of uint8 crops, as `Crops` gives them to the calibrator."""
    return list(iter(Crops(crops, name, detector).get_next, None))


def _clip6_pairs(model: onnx.ModelProto) -> list[tuple[onnx.NodeProto, list[onnx.NodeProto]]]:
    """(conv, consumers): convolutions whose output reaches only convolutions (as their data
    input), through exactly one Clip(0, 6) and any zero-padding Pads."""
    graph = model.graph
    inits = {i.name: numpy_helper.to_array(i) for i in graph.initializer}
    consumers = defaultdict(list)
    for node in graph.node:
        for name in node.input:
            consumers[name].append(node)
    outputs = {o.name for o in graph.output}
    pairs = []
    for node in graph.node:
        if node.op_type != "Conv":
            continue
        frontier, clipped, ok, convs = [node.output[0]], False, True, []
        while frontier and ok:
            tensor = frontier.pop()
            ok = tensor not in outputs
            for c in consumers[tensor] if ok else []:
                if not ok:
                    break
                if c.op_type == "Conv" and c.input[0] == tensor:
                    convs.append(c)
                elif c.op_type == "Clip" and not clipped:
                    bounds = tuple(float(inits[x]) for x in c.input[1:3] if x in inits)
                    ok, clipped = bounds == (0.0, 6.0), True
                    frontier.append(c.output[0])
                elif c.op_type == "Pad" and (len(c.input) < 3 or not c.input[2]):
                    ok = _attr(c, "mode", b"constant") in (b"constant", "constant")
                    frontier.append(c.output[0])
                else:
                    ok = False
        if ok and clipped and convs:
            pairs.append((node, convs))
    return pairs


def equalize_activations(
    model: onnx.ModelProto, crops: np.ndarray, margin: float, detector: bool = False
) -> int:
    """Raise each channel a Clip(0, 6) ends toward 6 / margin (module docstring, --equalize);
    channels whose calibration maximum times margin reaches 6 stay as they are. In place;
    returns the number of channels rescaled."""
    pairs = _clip6_pairs(model)
    session = _session(model, [c.output[0] for c, _ in pairs])
    names = [c.output[0] for c, _ in pairs]
    peak: dict[str, np.ndarray] = {}
    for feed in _feeds(crops, model.graph.input[0].name, detector):
        for name, out in zip(names, session.run(names, feed), strict=True):
            hi = out[0].reshape(out.shape[1], -1).max(axis=1)
            peak[name] = np.maximum(peak[name], hi) if name in peak else hi
    weights = {i.name: i for i in model.graph.initializer}

    def scaled(name: str, factor: np.ndarray, axis: int) -> None:
        w = numpy_helper.to_array(weights[name]).astype(np.float64)
        shape = [1] * w.ndim
        shape[axis] = -1
        w = (w * factor.reshape(shape)).astype(np.float32)
        weights[name].CopyFrom(numpy_helper.from_array(w, name))

    rescaled = 0
    for conv, nexts in pairs:
        m = peak[conv.output[0]].astype(np.float64)
        s = np.where(m > 0, np.clip(m * margin / 6.0, 1 / 64, 64), 1.0)
        s = np.where(m * margin >= 6.0, 1.0, s)
        rescaled += int((s != 1.0).sum())
        scaled(conv.input[1], 1.0 / s, 0)
        if len(conv.input) > 2 and conv.input[2]:
            scaled(conv.input[2], 1.0 / s, 0)
        for c in nexts:  # a dense conv's input channels are axis 1, a depthwise one's axis 0
            scaled(c.input[1], s, 0 if _attr(c, "group", 1) > 1 else 1)
    return rescaled


def float_conv_inputs_per_channel(model: onnx.ModelProto) -> int:
    """Give each float convolution fed by a per-tensor DequantizeLinear its own copy with an
    equal per-channel scale (module docstring): onnxruntime then leaves it float. In place;
    returns the count."""
    graph = model.graph
    inits = {i.name: i for i in graph.initializer}
    producer = {o: n for n in graph.node for o in n.output}
    added = []
    for node in graph.node:
        if node.op_type != "Conv" or node.input[1] not in inits:
            continue
        dq = producer.get(node.input[0])
        if dq is None or dq.op_type != "DequantizeLinear":
            continue
        scale = numpy_helper.to_array(inits[dq.input[1]])
        zero = numpy_helper.to_array(inits[dq.input[2]])
        if scale.size != 1:
            continue
        channels = numpy_helper.to_array(inits[node.input[1]]).shape[1] * _attr(node, "group", 1)
        name = f"{node.name}_input_per_channel"
        graph.initializer.extend(
            [
                numpy_helper.from_array(np.full(channels, scale, scale.dtype), f"{name}_scale"),
                numpy_helper.from_array(np.full(channels, zero, zero.dtype), f"{name}_zero"),
            ]
        )
        inputs = [dq.input[0], f"{name}_scale", f"{name}_zero"]
        added.append((node, helper.make_node("DequantizeLinear", inputs, [name], name, axis=1)))
        node.input[0] = name
    for node, dq in added:
        graph.node.insert(list(graph.node).index(node), dq)
    used = {i for n in graph.node for i in n.input} | {o.name for o in graph.output}
    kept = [n for n in graph.node if n.op_type != "DequantizeLinear" or n.output[0] in used]
    del graph.node[:]
    graph.node.extend(kept)
    return len(added)


def _patches(x: np.ndarray, conv: onnx.NodeProto, most: int = 4096) -> np.ndarray:
    """A conv's input (C, H, W) as (C, kh * kw, P) patches, P at most `most` (strided)."""
    kh, kw = _attr(conv, "kernel_shape")  # type: ignore[misc]
    sh, sw = _attr(conv, "strides", [1, 1])  # type: ignore[misc]
    top, left, bottom, right = _attr(conv, "pads", [0, 0, 0, 0])  # type: ignore[misc]
    c, h, w = x.shape
    xp = np.pad(x, ((0, 0), (top, bottom), (left, right)))
    ho, wo = (h + top + bottom - kh) // sh + 1, (w + left + right - kw) // sw + 1
    cols = [
        xp[:, i : i + sh * ho : sh, j : j + sw * wo : sw].reshape(c, -1)
        for i in range(kh)
        for j in range(kw)
    ]
    p = np.stack(cols, axis=1)
    return p[:, :, :: -(-p.shape[2] // most)]


def _gptq_rows(w: np.ndarray, scale: np.ndarray, h: np.ndarray, damp: float) -> np.ndarray:
    """GPTQ's int8 values of the rows of w (R, K) on per-row scales, H (K, K) shared."""
    w = w.astype(np.float64).copy()
    h = h.copy()
    dead = np.diag(h) == 0
    h[dead, dead] = 1.0
    w[:, dead] = 0.0
    h += damp * np.mean(np.diag(h)) * np.eye(len(h))
    u = np.linalg.cholesky(np.linalg.inv(h)).T  # upper Cholesky factor of H^-1
    q = np.zeros_like(w)
    for i in range(w.shape[1]):
        q[:, i] = np.clip(np.round(w[:, i] / scale), -128, 127)
        err = (w[:, i] - q[:, i] * scale) / u[i, i]
        w[:, i + 1 :] -= np.outer(err, u[i, i + 1 :])
    return q


def gptq_weights(
    model: onnx.ModelProto,
    quantized: onnx.ModelProto,
    crops: np.ndarray,
    damp: float = 0.01,
    detector: bool = False,
) -> int:
    """Re-round the int8 weights of `quantized` (QDQ, symmetric per-channel) on their own
    scales with GPTQ, H from `model`'s (the float model it was made from) convolution inputs
    on `crops`. In place; returns the number of convolutions re-rounded."""
    convs = [n for n in model.graph.node if n.op_type == "Conv"]
    inputs = list(dict.fromkeys(n.input[0] for n in convs))
    session = _session(model, inputs)
    hessians: dict[str, np.ndarray] = {}
    for feed in _feeds(crops, model.graph.input[0].name, detector):
        values = dict(zip(inputs, session.run(inputs, feed), strict=True))
        for conv in convs:
            p = _patches(values[conv.input[0]][0].astype(np.float64), conv)
            if _attr(conv, "group", 1) == 1:
                x = p.reshape(-1, p.shape[2])
                h = x @ x.T / x.shape[1]
            else:  # depthwise: one (k*k, k*k) H per channel
                h = np.einsum("ckp,clp->ckl", p, p) / p.shape[2]
            hessians[conv.name] = hessians.get(conv.name, 0) + h / len(crops)
    floats = {i.name: numpy_helper.to_array(i) for i in model.graph.initializer}
    inits = {i.name: i for i in quantized.graph.initializer}
    producer = {o: n for n in quantized.graph.node for o in n.output}
    qconvs = {n.name: n for n in quantized.graph.node if n.op_type == "Conv"}
    done = 0
    for conv in convs:
        dq = producer.get(qconvs[conv.name].input[1]) if conv.name in qconvs else None
        if dq is None or dq.op_type != "DequantizeLinear" or dq.input[0] not in inits:
            continue  # kept float
        target = inits[dq.input[0]]
        if len(dq.input) > 2 and np.any(numpy_helper.to_array(inits[dq.input[2]]) != 0):
            raise SystemExit(f"quantize: {conv.name}: --gptq needs symmetric weights")
        w = floats[conv.input[1]]
        rows = w.reshape(w.shape[0], -1).astype(np.float64)
        scale = np.broadcast_to(numpy_helper.to_array(inits[dq.input[1]]), w.shape[:1])
        h = hessians[conv.name]
        if _attr(conv, "group", 1) == 1:
            q = _gptq_rows(rows, scale, h, damp)
        else:
            q = np.stack(
                [
                    _gptq_rows(rows[r : r + 1], scale[r : r + 1], h[r], damp)[0]
                    for r in range(len(w))
                ]
            )
        dtype = numpy_helper.to_array(target).dtype
        target.CopyFrom(numpy_helper.from_array(q.reshape(w.shape).astype(dtype), target.name))
        done += 1
    return done


def _ancestors(model: onnx.ModelProto, tensor: str) -> set[str]:
    """The names of the nodes `tensor` depends on (its producer included)."""
    producer = {o: n for n in model.graph.node for o in n.output}
    seen: set[str] = set()
    stack = [tensor]
    while stack:
        node = producer.get(stack.pop())
        if node is not None and node.name not in seen:
            seen.add(node.name)
            stack.extend(node.input)
    return seen


def _regression_branch(model: onnx.ModelProto) -> list[str]:
    """The nodes that feed the landmark and flag outputs but not the heatmap."""
    names = [o.name for o in model.graph.output]
    heatmap = [n for n in names if "heatmap" in n]
    if len(heatmap) != 1:
        raise SystemExit(f"quantize: --float-ends expects one heatmap output, not {names}")
    regression = set().union(*(_ancestors(model, n) for n in names if n not in heatmap))
    shared = _ancestors(model, heatmap[0])
    return [n.name for n in model.graph.node if n.name in regression - shared]


def _pyramid(model: onnx.ModelProto) -> list[str]:
    """The detector's nodes that the backbone's deepest tensor (the first Resize's input)
    does not depend on: the feature pyramid's top-down path, its lateral projections of
    the 28 and 14 px blocks, and the six heads with their reshapes."""
    first = next((n for n in model.graph.node if n.op_type == "Resize"), None)
    if first is None:
        raise SystemExit("quantize: --float-ends expects the detector's Resize (its pyramid)")
    backbone = _ancestors(model, first.input[0])
    return [n.name for n in model.graph.node if n.name not in backbone]


class Crops(CalibrationDataReader):
    """The calibration crops, one at a time, scaled as the model expects: u8 / 255 for the
    landmark model (input `image`), u8 / 127.5 - 1 for the detector. `set_range` restricts
    them to a slice (the quantizer's chunked calibration, `CalibStridedMinMax`)."""

    def __init__(self, crops: np.ndarray, name: str = "image", detector: bool = False) -> None:
        self._crops = crops
        self._it = iter(crops)
        self._name = name
        self._detector = detector

    def __len__(self) -> int:
        return len(self._crops)

    def set_range(self, start_index: int, end_index: int) -> None:
        self._it = iter(self._crops[start_index:end_index])

    def get_next(self) -> dict[str, np.ndarray] | None:
        crop = next(self._it, None)
        if crop is None:
            return None
        x = crop.astype(np.float32)
        x = x / 127.5 - 1.0 if self._detector else x / 255.0
        return {self._name: x[None]}


def _chunk(n: int, most: int = 50) -> int:
    """The largest divisor of n up to `most` (onnxruntime's `CalibStridedMinMax` refuses a
    chunk that does not divide the count): the detector's calibration windows go through
    the calibrator in chunks of this many. It keeps every tensor of every input it runs
    until it computes the ranges (57 MB a detector window, 34 GB for 600); min-max ranges
    merge exactly, percentile histograms extend their bins from chunk to chunk. The
    landmark model's 185 crops fit whole and are not chunked, so its shipped ranges stay
    as calibrated."""
    return max(d for d in range(1, min(n, most) + 1) if n % d == 0)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--crops", type=Path, required=True)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--method", choices=list(METHODS), default="minmax")
    ap.add_argument("--deep-only", type=int, default=0, help="quantize only convs <= PX wide")
    ap.add_argument("--detector", action="store_true", help="the detector, not the landmarks")
    ap.add_argument(
        "--format", choices=["qdq", "qoperator"], default="qdq", help="quantised graph format"
    )
    ap.add_argument("--keep-heads", action="store_true", help="detector: output convs in float")
    ap.add_argument(
        "--keep-outputs",
        action="store_true",
        help="the nodes from each output's last convolution(s) on stay float",
    )
    ap.add_argument(
        "--equalize", type=float, default=0.0, metavar="MARGIN", help="raise ReLU6 channels"
    )
    ap.add_argument(
        "--float-ends",
        nargs="?",
        const="both",
        choices=["stem", "branch", "both"],
        help="stem and/or regression branch in float (no value: both)",
    )
    ap.add_argument("--float-depthwise", action="store_true", help="depthwise convs in float")
    ap.add_argument("--gptq", action="store_true", help="re-round the int8 weights (GPTQ)")
    args = ap.parse_args()
    if not args.crops.is_file():
        raise SystemExit(f"quantize: --crops {args.crops}: no such file")
    if args.keep_heads and not args.detector:
        raise SystemExit("quantize: --keep-heads is the detector's (with --detector)")
    qdq = args.format == "qdq"
    if args.gptq and not qdq:
        raise SystemExit("quantize: --gptq re-rounds QDQ weights (--format qdq)")
    with np.load(args.crops) as data:
        crops = data["crops"]
    model = onnx.load(DETECTOR_MODEL if args.detector else FLOAT_MODEL)
    print(f"{float32_weights(model)} fp16 weight tensors turned into float32")
    print(f"{fold_pad_into_conv(model, direct=True)} zero Pads folded into their Conv")
    if args.equalize:
        raised = equalize_activations(model, crops, args.equalize, args.detector)
        print(f"{raised} ReLU6 channels raised")
    inferred = shape_inference.infer_shapes(model)
    side = {
        v.name: v.type.tensor_type.shape.dim[-1].dim_value
        for v in [*inferred.graph.value_info, *inferred.graph.output]
    }
    convs = [n for n in model.graph.node if n.op_type == "Conv"]
    depthwise = [n.name for n in convs if _attr(n, "group", 1) > 1]
    exclude = [n.name for n in convs if args.deep_only and side[n.output[0]] > args.deep_only]
    if args.keep_heads:  # the six output convolutions (boxes, keypoints, scores)
        exclude += [n.name for n in convs if n.name in _head_convs(model)]
    if args.keep_outputs:
        exclude += _output_tails(model)
    if args.float_depthwise:
        exclude += depthwise
    if args.float_ends in ("stem", "both"):
        exclude += [n.name for n in convs[:3]]
    if args.float_ends in ("branch", "both"):
        exclude += _pyramid(model) if args.detector else _regression_branch(model)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "float32.onnx"
        onnx.save(model, src)
        quantize_static(
            str(src),
            str(args.out),
            Crops(crops, model.graph.input[0].name, args.detector),
            quant_format=QuantFormat.QDQ if qdq else QuantFormat.QOperator,
            per_channel=True,
            activation_type=QuantType.QUInt8,
            weight_type=QuantType.QInt8,
            calibrate_method=METHODS[args.method],
            nodes_to_exclude=exclude,
            extra_options={"CalibStridedMinMax": _chunk(len(crops))} if args.detector else None,
        )
        if qdq:
            quantized = onnx.load(args.out)
            fixed = float_conv_inputs_per_channel(quantized)
            if args.gptq:
                sample = crops[np.linspace(0, len(crops) - 1, min(64, len(crops))).astype(int)]
                done = gptq_weights(model, quantized, sample, detector=args.detector)
                print(f"{done} convolutions re-rounded (GPTQ)")
            onnx.save(quantized, args.out)
            print(f"{fixed} float convolutions given a per-channel input DequantizeLinear")
    print(f"wrote {args.out} ({args.out.stat().st_size:,} bytes; {len(crops)} calibration crops, "
          f"{args.method}, {len(set(exclude))} nodes kept float)")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
