// `auvrl export --format onnx`: a trained policy as an ONNX model, written by
// scripts/export_onnx.py with python3-onnx (Debian's package; opset 17, IR version 8, what
// onnx 1.12 writes) from an intermediate file this side writes, so that only the C++ side
// reads the network format.
//
// The intermediate ("policy spec", JSON, format "auvrl-policy-onnx-spec" version 1):
//   format, version        "auvrl-policy-onnx-spec", 1
//   graph_name             the ONNX graph's name ("auvrl_policy")
//   model_doc, graph_doc   doc strings of the model and the graph
//   input, output          {name, size, doc}: "state" (batch x state size) and "action"
//                          (batch x thrusters), with their doc strings
//   metadata               string -> string: the model's metadata_props (layout, scales,
//                          vehicle, thruster names, source file and CRC-32)
//   layers                 per weight layer, input first: {inputs, outputs, activation
//                          ("identity", "relu", "tanh"), weight (outputs x inputs values,
//                          row-major: W[o][i] at o * inputs + i), bias (outputs values)};
//                          float32 values printed with 9 significant digits (exact)
//   params_crc32           CRC-32 (zlib's) of the float32 little-endian bytes of every layer's
//                          weight then bias, in the order above: the script checks it, so the
//                          model holds exactly the network's parameters
// Each layer becomes Gemm(x, W, b, transB = 1) followed by Relu or Tanh.
#pragma once

#include <string>
#include <vector>

#include "tools/export/exported_policy.hpp"

namespace auvrl::tools {

/// Name of the model's input (batch x state size, float32) and output (batch x thrusters).
inline constexpr const char* kOnnxInputName = "state";
inline constexpr const char* kOnnxOutputName = "action";

/// The intermediate file's text (format above).
std::string onnx_spec_json(const ExportedPolicy& policy);

/// How to run the ONNX writer.
struct OnnxWriter {
  /// The interpreter and its options; Debian's python3 is where python3-onnx is installed.
  std::vector<std::string> python = {"/usr/bin/python3"};
  std::string script;  ///< scripts/export_onnx.py
};

/// Exit status of scripts/export_onnx.py when `import onnx` fails.
inline constexpr int kOnnxMissingExitCode = 3;

/// Writes the spec beside out_path, runs the script on it (which checks the model with
/// onnx.checker and writes out_path), removes the spec. Throws std::runtime_error: naming
/// python3-onnx and how to install it when the interpreter or the module is missing; with the
/// script's output when it fails.
void write_onnx_model(const ExportedPolicy& policy, const std::string& out_path,
                      const OnnxWriter& writer);

}  // namespace auvrl::tools
