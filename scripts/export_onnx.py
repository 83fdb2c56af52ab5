#!/usr/bin/python3
"""Writes an auvrl policy as an ONNX model: `auvrl export --format onnx` runs it.

    /usr/bin/python3 scripts/export_onnx.py SPEC.json OUT.onnx

SPEC.json is the intermediate `auvrl export` writes (format "auvrl-policy-onnx-spec" version 1,
documented in tools/export/onnx_model.hpp): doc strings, metadata and every weight layer. The
model takes "state" (float32, [batch, state size]) and gives "action" (float32, [batch,
thrusters]); each layer is Gemm(x, W, b, transB=1) followed by Relu or Tanh. Written with
Debian 12's python3-onnx (onnx 1.12): opset 17, IR version 8. The model is checked with
onnx.checker before it is written (atomically: OUT.onnx.tmp, then renamed).

Exit status: 0 written; 2 bad usage or spec; 3 python3-onnx is missing.
"""
import json
import os
import sys
import zlib

try:
    import numpy as np
    import onnx
    from onnx import TensorProto, helper, numpy_helper
except ImportError as error:
    sys.stderr.write(f"export_onnx.py: python3-onnx is missing ({error}); install it with "
                     "`apt-get install python3-onnx`\n")
    sys.exit(3)

OPSET = 17       # the newest opset onnx 1.12 (Debian 12's python3-onnx) knows
IR_VERSION = 8   # the IR version onnx 1.12 writes
SPEC_FORMAT = ("auvrl-policy-onnx-spec", 1)
ACTIVATIONS = {"identity": None, "relu": "Relu", "tanh": "Tanh"}


def fail(message):
    sys.stderr.write(f"export_onnx.py: {message}\n")
    sys.exit(2)


def read_layers(spec):
    """Every layer's weight (outputs x inputs) and bias as float32; checks sizes and CRC."""
    layers, crc, width = [], 0, spec["input"]["size"]
    for index, layer in enumerate(spec["layers"]):
        n_in, n_out = layer["inputs"], layer["outputs"]
        if n_in != width or layer["activation"] not in ACTIVATIONS:
            fail(f"layer {index}: {n_in} inputs after {width} outputs, or unknown activation")
        weight = np.asarray(layer["weight"], dtype=np.float32)
        bias = np.asarray(layer["bias"], dtype=np.float32)
        if weight.size != n_in * n_out or bias.size != n_out:
            fail(f"layer {index}: {weight.size} weights and {bias.size} biases for {n_in} x {n_out}")
        weight = weight.reshape(n_out, n_in)
        crc = zlib.crc32(bias.astype("<f4").tobytes(), zlib.crc32(weight.astype("<f4").tobytes(), crc))
        layers.append((weight, bias, ACTIVATIONS[layer["activation"]]))
        width = n_out
    if width != spec["output"]["size"]:
        fail(f"the last layer has {width} outputs, the output {spec['output']['size']}")
    if crc != spec["params_crc32"]:
        fail(f"parameters' CRC-32 0x{crc:08x}, the spec says 0x{spec['params_crc32']:08x}")
    return layers


def build_model(spec):
    """The ONNX model of the spec, checked."""
    layers = read_layers(spec)
    nodes, initializers = [], []
    current, out_name = spec["input"]["name"], spec["output"]["name"]
    for index, (weight, bias, activation) in enumerate(layers):
        last = index + 1 == len(layers)
        w_name, b_name = f"layer{index}_weight", f"layer{index}_bias"
        initializers += [numpy_helper.from_array(weight, w_name),
                         numpy_helper.from_array(bias, b_name)]
        gemm_out = out_name if last and activation is None else f"layer{index}_linear"
        nodes.append(helper.make_node("Gemm", [current, w_name, b_name], [gemm_out],
                                      name=f"layer{index}_gemm", transB=1))
        current = gemm_out
        if activation is not None:
            act_out = out_name if last else f"layer{index}_{activation.lower()}"
            nodes.append(helper.make_node(activation, [current], [act_out],
                                          name=f"layer{index}_{activation.lower()}"))
            current = act_out
    state = helper.make_tensor_value_info(spec["input"]["name"], TensorProto.FLOAT,
                                          ["batch", spec["input"]["size"]], spec["input"]["doc"])
    action = helper.make_tensor_value_info(out_name, TensorProto.FLOAT,
                                           ["batch", spec["output"]["size"]], spec["output"]["doc"])
    graph = helper.make_graph(nodes, spec["graph_name"], [state], [action], initializers,
                              doc_string=spec["graph_doc"])
    model = helper.make_model(graph, producer_name="auvrl export",
                              opset_imports=[helper.make_opsetid("", OPSET)],
                              doc_string=spec["model_doc"])
    model.ir_version = IR_VERSION
    helper.set_model_props(model, spec["metadata"])
    onnx.checker.check_model(model, full_check=True)
    return model


def main(argv):
    if len(argv) != 3:
        fail("usage: export_onnx.py SPEC.json OUT.onnx")
    try:
        with open(argv[1], encoding="utf-8") as f:
            spec = json.load(f)
    except (OSError, ValueError) as error:
        fail(f"cannot read {argv[1]}: {error}")
    if (spec.get("format"), spec.get("version")) != SPEC_FORMAT:
        fail(f"{argv[1]}: not an {SPEC_FORMAT[0]} version {SPEC_FORMAT[1]} file")
    model = build_model(spec)
    tmp = argv[2] + ".tmp"
    onnx.save(model, tmp)
    os.replace(tmp, argv[2])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
