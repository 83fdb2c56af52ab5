#include "tools/export/policy_export.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <ostream>
#include <stdexcept>

#include "common/nn/file_io.hpp"
#include "tools/export/c_header.hpp"

namespace auvrl::tools {

void run_export_request(const ExportRequest& request, std::ostream& out) {
  if (request.policy_path.empty()) throw std::invalid_argument("--policy FILE is required");
  if (request.out_path.empty()) throw std::invalid_argument("--out PATH is required");
  if (request.vehicle_path.empty()) throw std::invalid_argument("--vehicle FILE is required");
  if (request.format != "c" && request.format != "onnx") {
    throw std::invalid_argument("--format '" + request.format + "': expected c or onnx");
  }
  ExportedPolicy policy =
      load_exported_policy(request.policy_path, request.vehicle_path, request.layout);
  request.driving.apply(policy.task);
  std::string what;
  if (request.format == "c") {
    const std::string header = policy_c_header(policy);
    nn::write_file_atomically(request.out_path,
                              std::vector<std::uint8_t>(header.begin(), header.end()));
    what = "C99 header";
  } else {
    write_onnx_model(policy, request.out_path, request.onnx);
    what = "ONNX model";
  }
  const nn::MlpSpec& spec = policy.network.spec();
  out << fmt::format(
      "auvrl export: wrote {} ({}, {} bytes): {} layout, {} inputs -> {} actions "
      "({}), vehicle {}\n",
      request.out_path, what, std::filesystem::file_size(request.out_path),
      task::to_string(policy.task.layout), spec.input_dim, spec.output_dim, spec.describe(),
      policy.vehicle.name);
}

}  // namespace auvrl::tools
