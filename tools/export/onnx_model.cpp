#include "tools/export/onnx_model.hpp"

#include <fmt/format.h>
#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "common/nn/checksum.hpp"
#include "common/process.hpp"

namespace auvrl::tools {

namespace {

/// A JSON string literal.
std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += fmt::format("\\u{:04x}", static_cast<int>(c));
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

/// Float32 values as a JSON array (9 significant digits read back to the same float32); feeds
/// their little-endian bytes to crc.
std::string json_floats(const float* values, Eigen::Index n, nn::Crc32& crc) {
  std::string out = "[";
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!std::isfinite(values[i])) {
      throw std::invalid_argument("a network parameter is not finite: cannot export it");
    }
    out += fmt::format("{}{:.9g}", i == 0 ? "" : ",", values[i]);
    crc.update(&values[i], sizeof(float));  // x86-64 and aarch64 are little-endian
  }
  return out + "]";
}

/// The "layers" array, filling crc with the parameters' bytes in file order.
std::string json_layers(const nn::Mlp& net, nn::Crc32& crc) {
  const nn::MlpSpec& spec = net.spec();
  std::string out = "[";
  for (int l = 0; l < spec.num_layers(); ++l) {
    // Row-major out x in is the transpose's column-major storage.
    const Eigen::MatrixXf w_rows = net.weight(l).transpose();
    out += fmt::format("{}\n  {{\"inputs\": {}, \"outputs\": {}, \"activation\": \"{}\",\n",
                       l == 0 ? "" : ",", spec.layer_in(l), spec.layer_out(l),
                       nn::to_string(spec.layer_activation(l)));
    out += "   \"weight\": " + json_floats(w_rows.data(), w_rows.size(), crc) + ",\n";
    out += "   \"bias\": " + json_floats(net.bias(l).data(), net.bias(l).size(), crc) + "}";
  }
  return out + "]";
}

/// The model's metadata_props.
std::string json_metadata(const ExportedPolicy& policy) {
  const task::ObservationScales& k = policy.task.scales;
  std::string thrusters;
  for (const std::string& name : policy.vehicle.thruster_names) {
    thrusters += (thrusters.empty() ? "" : ",") + name;
  }
  const std::pair<std::string, std::string> entries[] = {
      {"auvrl.layout", task::to_string(policy.task.layout)},
      {"auvrl.vehicle", policy.vehicle.name},
      {"auvrl.vehicle_file_crc32", fmt::format("0x{:08x}", policy.vehicle.file_crc32)},
      {"auvrl.thrusters", thrusters},
      {"auvrl.max_thrust_n", fmt::format("{}", policy.task.max_thrust_n)},
      {"auvrl.scale_position_m", fmt::format("{}", k.position_m)},
      {"auvrl.scale_linear_velocity_mps", fmt::format("{}", k.linear_velocity_mps)},
      {"auvrl.scale_angular_rate_rad_s", fmt::format("{}", k.angular_rate_rad_s)},
      {"auvrl.scale_depth_m", fmt::format("{}", k.depth_m)},
      {"auvrl.control_step_s", fmt::format("{}", policy.vehicle.control_step_s)},
      {"auvrl.policy_file", std::filesystem::path(policy.policy_path).filename().string()},
      {"auvrl.policy_file_crc32", fmt::format("0x{:08x}", policy.policy_crc32)},
  };
  std::string out = "{";
  for (const auto& [key, value] : entries) {
    out += (out.size() > 1 ? ",\n  " : "\n  ") + json_string(key) + ": " + json_string(value);
  }
  return out + "}";
}

}  // namespace

std::string onnx_spec_json(const ExportedPolicy& policy) {
  const nn::MlpSpec& spec = policy.network.spec();
  const std::string input_doc =
      describe_state_text(policy) + "Shape [batch, " + std::to_string(spec.input_dim) +
      "], float32: one state vector a row, built as auvrl's task::build_state builds it (the C "
      "export's auvrl_policy_build_state).";
  const std::string output_doc = describe_action_text(policy) + "Shape [batch, " +
                                 std::to_string(spec.output_dim) + "], float32, tanh output.";
  const std::string model_doc =
      "A trained auvrl policy, exported by `auvrl export --format onnx` (docs/export.md).\n" +
      describe_policy(policy);
  const std::string graph_doc = fmt::format(
      "{} -> {}: {}, each weight layer Gemm (transB = 1) then ReLU (hidden) or tanh "
      "(output). Layout {}; thrust command of thruster i = action[i] * {} N.",
      kOnnxInputName, kOnnxOutputName, spec.describe(), task::to_string(policy.task.layout),
      policy.task.max_thrust_n);
  nn::Crc32 crc;
  const std::string layers = json_layers(policy.network, crc);
  return fmt::format(
      "{{\"format\": \"auvrl-policy-onnx-spec\", \"version\": 1,\n"
      "\"graph_name\": \"auvrl_policy\",\n\"model_doc\": {},\n\"graph_doc\": {},\n"
      "\"input\": {{\"name\": \"{}\", \"size\": {}, \"doc\": {}}},\n"
      "\"output\": {{\"name\": \"{}\", \"size\": {}, \"doc\": {}}},\n"
      "\"metadata\": {},\n\"params_crc32\": {},\n\"layers\": {}}}\n",
      json_string(model_doc), json_string(graph_doc), kOnnxInputName, spec.input_dim,
      json_string(input_doc), kOnnxOutputName, spec.output_dim, json_string(output_doc),
      json_metadata(policy), crc.value(), layers);
}

namespace {

/// The last lines of a log, for an error message.
std::string tail(const std::string& text, std::size_t max_chars = 2000) {
  return text.size() <= max_chars ? text : "..." + text.substr(text.size() - max_chars);
}

/// Runs the writer on spec_path; throws std::runtime_error as write_onnx_model says.
void run_writer(const OnnxWriter& writer, const std::string& spec_path,
                const std::string& out_path) {
  const std::string install =
      "install it with `apt-get install python3-onnx` "
      "(scripts/install-deps.sh installs every dependency)";
  if (writer.python.empty() || !std::filesystem::exists(writer.python.front())) {
    throw std::runtime_error(
        "ONNX export needs python3 with python3-onnx: no interpreter " +
        (writer.python.empty() ? std::string("given") : writer.python.front()) + "; " + install);
  }
  if (!std::filesystem::exists(writer.script)) {
    throw std::runtime_error("ONNX export: no script " + writer.script);
  }
  std::vector<std::string> argv = writer.python;
  argv.insert(argv.end(), {writer.script, spec_path, out_path});
  const std::string log_path = spec_path + ".log";
  process::ChildProcess child(argv, log_path);
  int status = child.wait_for_exit(std::chrono::minutes(5));
  if (status == -1) status = child.terminate();
  const std::string log = child.log();
  std::filesystem::remove(log_path);
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == kOnnxMissingExitCode) {
    throw std::runtime_error("ONNX export needs python3-onnx, which " + writer.python.front() +
                             " cannot import: " + install + "\n" + tail(log));
  }
  if (code != 0) {
    throw std::runtime_error(fmt::format("ONNX export: {} failed (exit status {}):\n{}",
                                         writer.script, code, tail(log)));
  }
}

}  // namespace

void write_onnx_model(const ExportedPolicy& policy, const std::string& out_path,
                      const OnnxWriter& writer) {
  const std::string spec_path = out_path + ".spec.json";
  {
    std::ofstream spec(spec_path, std::ios::binary | std::ios::trunc);
    spec << onnx_spec_json(policy);
    if (!spec.flush()) throw std::runtime_error("cannot write " + spec_path);
  }
  try {
    run_writer(writer, spec_path, out_path);
  } catch (...) {
    std::filesystem::remove(spec_path);
    throw;
  }
  std::filesystem::remove(spec_path);
}

}  // namespace auvrl::tools
