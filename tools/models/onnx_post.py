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


def fold_pad_into_conv(model: onnx.ModelProto, direct: bool = False) -> int:
    """Move zero Pads that reach a Conv through a layout Transpose into the Conv's pads.

    tf2onnx writes TFLite's explicit SAME padding of the first, strided convolution as
    Pad (NHWC) -> Transpose (to NCHW) -> Conv. onnxruntime fuses a Pad into the Conv that
    reads it directly, but not across the Transpose, so the first Pad ran as its own
    kernel over the whole 256x256x3 input on every frame (1.3 % of the landmark model's
    kernel time on a loaded host, bench/landmark_profile.py). Rewired as Transpose ->
    Conv with the pad amounts in the Conv's `pads` (permuted to NCHW), the outputs are
    the same. Returns the number of Pads folded.

    `direct` also folds the Pads a Conv reads directly. The float file keeps those
    (onnxruntime fuses them at load), but a quantised graph holds each one between a
    DequantizeLinear and a QuantizeLinear, which onnxruntime leaves as three kernels on
    the full-resolution tensor (about 1 ms a frame of the int8 landmark model).
    """
    graph = model.graph
    inits = {i.name: i for i in graph.initializer}
    users: dict[str, list[onnx.NodeProto]] = {}
    for node in graph.node:
        for name in node.input:
            users.setdefault(name, []).append(node)
    folded: list[onnx.NodeProto] = []
    for pad in [n for n in graph.node if n.op_type == "Pad"]:
        mode = next((a.s for a in pad.attribute if a.name == "mode"), b"constant")
        if mode != b"constant" or len(pad.input) < 2 or pad.input[1] not in inits:
            continue
        if (
            len(pad.input) > 2
            and pad.input[2]
            and (pad.input[2] not in inits or numpy_helper.to_array(inits[pad.input[2]]).any())
        ):
            continue
        nexts = users.get(pad.output[0], [])
        if len(nexts) != 1 or nexts[0].op_type not in ("Transpose", "Conv"):
            continue
        amounts = numpy_helper.to_array(inits[pad.input[1]]).astype(int)
        rank = len(amounts) // 2
        if nexts[0].op_type == "Transpose":
            reader = nexts[0]
            perm = list(next(a.ints for a in reader.attribute if a.name == "perm"))
        elif direct:
            reader, perm = None, list(range(rank))
        else:
            continue
        conv_input = pad.output[0] if reader is None else reader.output[0]
        convs = [nexts[0]] if reader is None else users.get(conv_input, [])
        if len(convs) != 1 or convs[0].op_type != "Conv" or convs[0].input[0] != conv_input:
            continue
        conv = convs[0]
        begin, end = amounts[:rank][perm], amounts[rank:][perm]  # in the Conv's axis order
        if begin[:2].any() or end[:2].any():
            continue  # padding batch or channels is not a Conv padding
        if any(a.name == "auto_pad" and a.s not in (b"", b"NOTSET") for a in conv.attribute):
            continue
        old = next((list(a.ints) for a in conv.attribute if a.name == "pads"), [0] * 2 * (rank - 2))
        spatial = rank - 2
        new = [int(old[i] + begin[2 + i]) for i in range(spatial)]
        new += [int(old[spatial + i] + end[2 + i]) for i in range(spatial)]
        kept = [a for a in conv.attribute if a.name != "pads"]
        del conv.attribute[:]
        conv.attribute.extend([*kept, helper.make_attribute("pads", new)])
        (conv if reader is None else reader).input[0] = pad.input[0]
        folded.append(pad)
    for pad in folded:
        graph.node.remove(pad)
    used = {name for node in graph.node for name in node.input}
    kept_inits = [i for i in graph.initializer if i.name in used]
    del graph.initializer[:]
    graph.initializer.extend(kept_inits)
    return len(folded)


def output_channels_first(model: onnx.ModelProto, name: str) -> bool:
    """Drop the final NCHW -> NHWC Transpose in front of output `name` (True if dropped).

    The landmark model's heatmap leaves its last Conv as NCHW and tf2onnx transposes it
    back to TFLite's NHWC. monopic reads 7x7 windows of it, in any layout, so the output
    can stay NCHW. (With its NCHWc layout onnxruntime already folds this Transpose into
    the last layout reorder, so on such CPUs the saving is not measurable; the graph is
    one node simpler wherever that transformer does not run.)
    """
    graph = model.graph
    node = next((n for n in graph.node if name in n.output), None)
    if node is None or node.op_type != "Transpose":
        return False
    if list(next(a.ints for a in node.attribute if a.name == "perm")) != [0, 2, 3, 1]:
        return False
    source = node.input[0]
    for other in graph.node:
        if other is not node:
            other.input[:] = [name if n == source else n for n in other.input]
            other.output[:] = [name if n == source else n for n in other.output]
    graph.node.remove(node)
    out = next(o for o in graph.output if o.name == name)
    dims = out.type.tensor_type.shape.dim
    values = [d.dim_value for d in dims]
    n, h, w, c = values
    for d, v in zip(dims, (n, c, h, w), strict=True):
        d.dim_value = v
    return True
