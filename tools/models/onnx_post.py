"""Post-process tf2onnx output so the shipped files are small, stable and self-describing."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper


def rename_values(model: onnx.ModelProto, names: Mapping[str, str]) -> None:
    """Rename graph inputs/outputs (tf2onnx keeps TFLite's ``input_1``/``Identity_N``)."""
    graph = model.graph
    for value in [*graph.input, *graph.output, *graph.value_info]:
        value.name = names.get(value.name, value.name)
    for node in graph.node:
        node.input[:] = [names.get(n, n) for n in node.input]
        node.output[:] = [names.get(n, n) for n in node.output]


def store_fp16_weights(model: onnx.ModelProto, min_elements: int = 64) -> int:
    """Store fp32 initializers that are exact fp16 values as fp16 + Cast; return the count.

    The TFLite sources keep their weights in fp16 behind DEQUANTIZE ops, which tf2onnx
    folds into fp32 constants. Casting back is lossless (checked per tensor), halves
    the files, and onnxruntime folds the Cast away when the session is created.
    """
    graph = model.graph
    kept: list[TensorProto] = []
    casts: list[onnx.NodeProto] = []
    for init in graph.initializer:
        arr = numpy_helper.to_array(init)
        if init.data_type != TensorProto.FLOAT or arr.size < min_elements:
            kept.append(init)
            continue
        half = arr.astype(np.float16)
        if not np.array_equal(half.astype(np.float32), arr):
            kept.append(init)
            continue
        half_name = f"{init.name}__fp16"
        kept.append(numpy_helper.from_array(half, half_name))
        casts.append(
            helper.make_node(
                "Cast", [half_name], [init.name], name=f"{init.name}__cast", to=TensorProto.FLOAT
            )
        )
    del graph.initializer[:]
    graph.initializer.extend(kept)
    nodes = [*casts, *graph.node]
    del graph.node[:]
    graph.node.extend(nodes)
    return len(casts)


def canonicalize(model: onnx.ModelProto) -> None:
    """Reorder and rename nodes, values and initializers from the graph's structure alone.

    tf2onnx's generated names and node order vary between runs (its optimizers iterate
    over id-hashed sets), so identical graphs would serialise differently. Nodes are
    put in depth-first post-order from the graph outputs (inputs visited in order),
    then named ``<OpType>_<index>``; initializers become ``const_<index>`` in order of
    first use. Graph input/output names are kept.
    """
    graph = model.graph
    producer = {out: node for node in graph.node for out in node.output}
    order: list[onnx.NodeProto] = []
    seen: set[int] = set()
    for out in graph.output:
        stack: list[tuple[onnx.NodeProto, int]] = []
        if out.name in producer:
            stack.append((producer[out.name], 0))
        while stack:
            node, pos = stack.pop()
            if id(node) in seen:
                continue
            if pos < len(node.input):
                stack.append((node, pos + 1))
                dep = producer.get(node.input[pos])
                if dep is not None and id(dep) not in seen:
                    stack.append((dep, 0))
                continue
            seen.add(id(node))
            order.append(node)

    keep = {v.name for v in [*graph.input, *graph.output]}
    inits = {init.name: init for init in graph.initializer}
    names: dict[str, str] = {}
    init_order: list[TensorProto] = []
    for i, node in enumerate(order):
        for name in node.input:
            if name in inits and name not in names:
                names[name] = f"const_{len(init_order):03d}"
                init_order.append(inits[name])
        node.name = f"{node.op_type}_{i:03d}"
        for j, name in enumerate(node.output):
            if name and name not in keep:
                names[name] = node.name if len(node.output) == 1 else f"{node.name}:{j}"

    for init in init_order:
        init.name = names[init.name]
    del graph.initializer[:]
    graph.initializer.extend(init_order)
    del graph.value_info[:]
    del graph.node[:]
    graph.node.extend(order)
    rename_values(model, names)


def stamp(model: onnx.ModelProto, doc: str, metadata: Mapping[str, str]) -> None:
    """Replace path-dependent doc strings with fixed text and record provenance."""
    model.doc_string = doc
    model.graph.doc_string = ""
    model.graph.name = metadata.get("name", model.graph.name)
    del model.metadata_props[:]
    for key, value in sorted(metadata.items()):
        entry = model.metadata_props.add()
        entry.key, entry.value = key, value


def keep_outputs(model: onnx.ModelProto, names: Sequence[str]) -> int:
    """Keep only the graph outputs `names` (in that order) and the nodes they need.

    onnxruntime executes every node of a graph whatever outputs a caller asks for, so
    outputs nobody reads still cost their whole branch on every run. Nodes, initializers
    and value infos that no kept output depends on are removed; the rest is untouched,
    so the kept outputs compute exactly as before. Returns the number of nodes removed.
    """
    graph = model.graph
    outputs = {o.name: o for o in graph.output}
    if missing := [n for n in names if n not in outputs]:
        raise ValueError(f"no graph output named {missing}; outputs are {list(outputs)}")
    if any(a.type in (onnx.AttributeProto.GRAPH, onnx.AttributeProto.GRAPHS)
           for node in graph.node for a in node.attribute):  # fmt: skip
        raise ValueError("graphs with subgraphs (If/Loop/Scan) are not supported")
    producer = {out: i for i, node in enumerate(graph.node) for out in node.output if out}
    live: set[int] = set()
    stack = list(names)
    while stack:
        i = producer.get(stack.pop())
        if i is not None and i not in live:
            live.add(i)
            stack.extend(name for name in graph.node[i].input if name)
    nodes = [node for i, node in enumerate(graph.node) if i in live]
    used = {name for node in nodes for name in (*node.input, *node.output)}
    inits = [init for init in graph.initializer if init.name in used]
    infos = [info for info in graph.value_info if info.name in used]
    removed = len(graph.node) - len(nodes)
    for field, values in (
        (graph.node, nodes),
        (graph.initializer, inits),
        (graph.value_info, infos),
        (graph.output, [outputs[n] for n in names]),
    ):
        del field[:]
        field.extend(values)
    return removed
