"""An int8 candidate of the landmark model or the detector, for bench/int8_*.py to judge.

Static quantisation with onnxruntime's quantizer (QDQ format): weights int8 per output
channel, activations uint8 per tensor, ranges calibrated on landmark-model crops of
rendered frames and the shipped clip (written by `bench/int8_landmarks.py crops`). The
shipped float model stores its weights as fp16 + Cast, which the quantizer would take for
activations; they are turned back into float32 initializers first (lossless). The result
is NOT shipped unless the judge says it keeps the float model's landmark error (issue 21).

    .venv-models/bin/python tools/models/quantize.py --crops recordings/int8/calibration.npz \
        --out recordings/int8/pose_landmark_full_int8.onnx [--method minmax|percentile|entropy]
        [--deep-only PX] [--keep-outputs]

--keep-outputs keeps each output's nodes back to its last convolution in float (a uint8
landmark output would step by about a pixel; session 12: it did not help).

--deep-only PX quantizes only the convolutions whose output is at most PX pixels on a side
(the deep, many-channel layers, where int8 kernels gain most), keeping the early
high-resolution layers, the decoder and the heads in float.

The detector (issue 17's search frames, issue 21's CPU-seconds), for
bench/int8_detector.py to judge:

    .venv-models/bin/python tools/models/quantize.py --detector \
        --crops recordings/int8/detector_windows.npz --out recordings/int8/pose_detection_int8.onnx

calibrated on the letterboxed detector windows (uint8, scaled to [-1, 1] as the detector
takes them) written by `bench/int8_detector.py windows`; onnxruntime's QOperator format
(QLinearConv), its depthwise convolutions kept in float (on an AVX2 CPU without VNNI, int8
depthwise convolutions are slower than float ones).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
import onnx
from onnx import numpy_helper, shape_inference
from onnxruntime.quantization import (
    CalibrationDataReader,
    CalibrationMethod,
    QuantFormat,
    QuantType,
    quantize_static,
)

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
    """Each graph output's producing nodes back to and including its last convolution: a
    uint8 landmark output steps by about a pixel, so these stay float."""
    producer = {o: n for n in model.graph.node for o in n.output}
    tails = []
    for output in model.graph.output:
        node = producer.get(output.name)
        while node is not None:
            tails.append(node.name)
            if node.op_type == "Conv":
                break
            node = producer.get(node.input[0])
    return tails


class Crops(CalibrationDataReader):
    """The calibration crops, one at a time, scaled as the model expects: u8 / 255 for the
    landmark model (input `image`), u8 / 127.5 - 1 for the detector."""

    def __init__(self, crops: np.ndarray, name: str = "image", detector: bool = False) -> None:
        self._it = iter(crops)
        self._name = name
        self._detector = detector

    def get_next(self) -> dict[str, np.ndarray] | None:
        crop = next(self._it, None)
        if crop is None:
            return None
        x = crop.astype(np.float32)
        x = x / 127.5 - 1.0 if self._detector else x / 255.0
        return {self._name: x[None]}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--crops", type=Path, required=True)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--method", choices=list(METHODS), default="minmax")
    ap.add_argument("--deep-only", type=int, default=0, help="quantize only convs <= PX wide")
    ap.add_argument("--detector", action="store_true", help="the detector, not the landmarks")
    ap.add_argument("--keep-heads", action="store_true", help="detector: output convs in float")
    ap.add_argument(
        "--keep-outputs",
        action="store_true",
        help="landmarks: the nodes from each output's last convolution on stay float",
    )
    args = ap.parse_args()
    if not args.crops.is_file():
        raise SystemExit(f"quantize: --crops {args.crops}: no such file")
    with np.load(args.crops) as data:
        crops = data["crops"]
    model = onnx.load(DETECTOR_MODEL if args.detector else FLOAT_MODEL)
    print(f"{float32_weights(model)} fp16 weight tensors turned into float32")
    inferred = shape_inference.infer_shapes(model)
    side = {
        v.name: v.type.tensor_type.shape.dim[-1].dim_value
        for v in [*inferred.graph.value_info, *inferred.graph.output]
    }
    convs = [n for n in model.graph.node if n.op_type == "Conv"]
    exclude = [n.name for n in convs if args.deep_only and side[n.output[0]] > args.deep_only]
    if args.detector:  # depthwise (group > 1) convolutions stay float
        depthwise = [n for n in convs if any(a.name == "group" and a.i > 1 for a in n.attribute)]
        exclude += [n.name for n in depthwise]
        if args.keep_heads:  # the six output convolutions (boxes, keypoints, scores)
            exclude += [n.name for n in convs if n.name in _head_convs(model)]
    if args.keep_outputs:
        exclude += _output_tails(model)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "float32.onnx"
        onnx.save(model, src)
        quantize_static(
            str(src),
            str(args.out),
            Crops(crops, model.graph.input[0].name, args.detector),
            quant_format=QuantFormat.QOperator if args.detector else QuantFormat.QDQ,
            per_channel=True,
            activation_type=QuantType.QUInt8,
            weight_type=QuantType.QInt8,
            calibrate_method=METHODS[args.method],
            nodes_to_exclude=exclude,
        )
    print(f"wrote {args.out} ({args.out.stat().st_size:,} bytes; {len(crops)} calibration crops, "
          f"{args.method}, {len(exclude)} convolutions kept float)")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
