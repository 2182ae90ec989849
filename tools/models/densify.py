"""Replace a TFLite model's DENSIFY ops with the dense constants they compute.

MediaPipe's pose detector stores 38 fp16 weight tensors in TFLite's sparse format
behind DENSIFY ops. tf2onnx cannot convert DENSIFY, but the op only ever turns a
constant into another constant, so we let TensorFlow's reference interpreter run it
once, store its result as an ordinary constant buffer and drop the op. Consumers
(DEQUANTIZE ops for fp16 weights) already read the DENSIFY output tensor, so they
need no rewiring; the now-unreferenced sparse input tensor keeps its index (tensor
indices must not shift) but loses its data and sparsity record.
"""

from __future__ import annotations

from pathlib import Path

import flatbuffers
import numpy as np
import tensorflow as tf
from tensorflow.lite.python import schema_py_generated as schema

_FILE_IDENTIFIER = b"TFL3"


def _load(path: Path) -> schema.ModelT:
    buf = path.read_bytes()
    return schema.ModelT.InitFromObj(schema.Model.GetRootAsModel(buf, 0))


def _dump(model: schema.ModelT) -> bytes:
    builder = flatbuffers.Builder(1024)
    builder.Finish(model.Pack(builder), file_identifier=_FILE_IDENTIFIER)
    return bytes(builder.Output())


def _densify_outputs(path: Path, tensor_ids: list[int]) -> dict[int, np.ndarray]:
    """Run the original model once and read every DENSIFY output tensor.

    Default delegates (XNNPACK) are disabled: they would take over the graph and the
    intermediate tensors would not be observable.
    """
    interp = tf.lite.Interpreter(
        model_path=str(path),
        num_threads=1,
        experimental_op_resolver_type=(
            tf.lite.experimental.OpResolverType.BUILTIN_WITHOUT_DEFAULT_DELEGATES
        ),
        experimental_preserve_all_tensors=True,
    )
    interp.allocate_tensors()
    for detail in interp.get_input_details():
        interp.set_tensor(detail["index"], np.zeros(detail["shape"], detail["dtype"]))
    interp.invoke()
    return {i: np.array(interp.get_tensor(i)) for i in tensor_ids}


def densify(src: Path, dst: Path) -> int:
    """Write a copy of ``src`` without DENSIFY ops to ``dst``; return how many were removed."""
    model = _load(src)
    if len(model.subgraphs) != 1:
        raise ValueError(f"{src}: expected one subgraph, found {len(model.subgraphs)}")
    graph = model.subgraphs[0]
    densify_codes = {
        i
        for i, code in enumerate(model.operatorCodes)
        if max(code.builtinCode, code.deprecatedBuiltinCode) == schema.BuiltinOperator.DENSIFY
    }
    dense_ops = [op for op in graph.operators if op.opcodeIndex in densify_codes]
    values = _densify_outputs(src, [int(op.outputs[0]) for op in dense_ops])

    for op in dense_ops:
        sparse_id, dense_id = int(op.inputs[0]), int(op.outputs[0])
        sparse, dense = graph.tensors[sparse_id], graph.tensors[dense_id]
        value = values[dense_id]
        if list(value.shape) != [int(d) for d in dense.shape]:
            raise ValueError(f"{dense.name!r}: densified shape {value.shape} != {dense.shape}")
        buffer = schema.BufferT()
        buffer.data = np.frombuffer(np.ascontiguousarray(value).tobytes(), dtype=np.uint8)
        model.buffers.append(buffer)
        dense.buffer = len(model.buffers) - 1
        model.buffers[sparse.buffer].data = None
        sparse.sparsity = None

    graph.operators = [op for op in graph.operators if op.opcodeIndex not in densify_codes]
    for tensor in graph.tensors:
        tensor.sparsity = None
    dst.write_bytes(_dump(model))
    return len(dense_ops)
