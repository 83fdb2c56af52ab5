// `auvrl export`: a trained policy out of the system, as a dependency-free C99 header
// (c_header.hpp) or an ONNX model (onnx_model.hpp). docs/export.md is the user's guide.
#pragma once

#include <iosfwd>
#include <string>

#include "tools/export/onnx_model.hpp"

namespace auvrl::tools {

/// What `auvrl export` was asked to do.
struct ExportRequest {
  std::string policy_path;   ///< network file (nn format), required
  std::string format;        ///< "c" or "onnx", required
  std::string out_path;      ///< the header or model to write, required
  std::string vehicle_path;  ///< vehicle file: thruster names, maximum thrust, thruster count
  std::string layout;        ///< "paper", "extended", "extended_thrust" or empty: inferred
  OnnxWriter onnx;           ///< how to run scripts/export_onnx.py (format "onnx")
  /// The policy's integral action, position filter and fault accommodation.
  task::DrivingAidOptions driving = {};
};

/// Loads the policy and the vehicle, writes the header or the model, prints one line saying
/// what was written (path, size in bytes, layout, inputs and outputs) to `out`. Throws
/// std::invalid_argument for a bad request (missing option, unknown format or layout) and
/// std::runtime_error for unusable files or a failed ONNX writer.
void run_export_request(const ExportRequest& request, std::ostream& out);

}  // namespace auvrl::tools
