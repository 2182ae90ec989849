"""Write the dense-convolution benchmark models bench/landmark_profile.py times (the roofline).

Each is one 3x3 convolution (stride 1, same padding, ReLU6 as the landmark model's
convolutions have) whose weights come from ConstantOfShape, so the files are a few hundred
bytes and onnxruntime folds the weights into a constant at load, exactly as it treats a
model's initializers (prepacked, NCHWc layout). The int8 twin puts QuantizeLinear /
DequantizeLinear around it (per-tensor, u8 activations, s8 weights), which onnxruntime
fuses into one QLinearConv: the rate its VNNI / AMX kernels reach on a dense convolution.
Shapes are a dense layer big enough to keep the kernels busy (256 -> 256 channels at
32x32, 604 M multiply-accumulates), the best case the landmark model's layers can reach.

    .venv-models/bin/python -m tools.models.dense_conv   (run by `make models`)
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

OUT = Path(__file__).resolve().parents[2] / "bench" / "data"
CHANNELS = 256
SIDE = 32
KERNEL = 3
OPSET = 17


def _const(name: str, value: np.ndarray) -> onnx.NodeProto:
    return helper.make_node("Constant", [], [name], value=numpy_helper.from_array(value, name))


def model(int8: bool) -> onnx.ModelProto:
    """The dense 3x3 conv, float or quantized (QDQ)."""
    c, k = CHANNELS, KERNEL
    w_shape = np.array([c, c, k, k], dtype=np.int64)
    fill = np.array([1 if int8 else 0.01], dtype=np.int8 if int8 else np.float32)
    nodes = [
        _const("w_shape", w_shape),
        helper.make_node(
            "ConstantOfShape", ["w_shape"], ["w"], value=numpy_helper.from_array(fill)
        ),
        _const("bias", np.zeros(c, dtype=np.float32)),
        _const("lo", np.array(0.0, dtype=np.float32)),
        _const("hi", np.array(6.0, dtype=np.float32)),
    ]
    x, w = "x", "w"
    if int8:
        nodes += [
            _const("xs", np.array(1 / 255, dtype=np.float32)),
            _const("xz", np.array(0, dtype=np.uint8)),
            _const("ws", np.array(0.01, dtype=np.float32)),
            _const("wz", np.array(0, dtype=np.int8)),
            _const("ys", np.array(6 / 255, dtype=np.float32)),
            helper.make_node("QuantizeLinear", ["x", "xs", "xz"], ["xq"]),
            helper.make_node("DequantizeLinear", ["xq", "xs", "xz"], ["xd"]),
            helper.make_node("DequantizeLinear", ["w", "ws", "wz"], ["wd"]),
        ]
        x, w = "xd", "wd"
    pad = k // 2
    nodes += [
        helper.make_node("Conv", [x, w, "bias"], ["conv"], pads=[pad] * 4),
        helper.make_node("Clip", ["conv", "lo", "hi"], ["act"]),
    ]
    if int8:
        nodes += [
            helper.make_node("QuantizeLinear", ["act", "ys", "xz"], ["yq"]),
            helper.make_node("DequantizeLinear", ["yq", "ys", "xz"], ["y"]),
        ]
    else:
        nodes.append(helper.make_node("Identity", ["act"], ["y"]))
    shape = [1, c, SIDE, SIDE]
    graph = helper.make_graph(
        nodes,
        f"dense_conv_{'int8' if int8 else 'fp32'}",
        [helper.make_tensor_value_info("x", TensorProto.FLOAT, shape)],
        [helper.make_tensor_value_info("y", TensorProto.FLOAT, shape)],
    )
    m = helper.make_model(graph, opset_imports=[helper.make_opsetid("", OPSET)])
    m.producer_name = "monopic tools/models/dense_conv.py"
    m.ir_version = 8
    onnx.checker.check_model(m)
    return m


def main() -> int:
    OUT.mkdir(parents=True, exist_ok=True)
    for int8 in (False, True):
        path = OUT / f"dense_conv_{'int8' if int8 else 'fp32'}.onnx"
        path.write_bytes(model(int8).SerializeToString(deterministic=True))
        print(f"wrote {path.relative_to(OUT.parents[1])} ({path.stat().st_size} bytes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
