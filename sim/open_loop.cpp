// Open-loop validation tool: CSV commands -> simulated trajectory CSV.
#include "sim/open_loop.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/csv.hpp"

namespace auvrl::sim {
namespace {

std::string trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  const auto end = s.find_last_not_of(" \t\r");
  return s.substr(begin, end - begin + 1);
}

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) fields.push_back(trim(field));
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

[[noreturn]] void fail(const std::string& path, int line, const std::string& what) {
  throw std::runtime_error(path + ":" + std::to_string(line) + ": " + what);
}

const char* status_name(StateStatus status) {
  switch (status) {
    case StateStatus::kOk:
      return "ok";
    case StateStatus::kNonFinite:
      return "non-finite state";
    case StateStatus::kSpeedLimit:
      return "speed beyond the blow-up limit";
    case StateStatus::kPositionLimit:
      return "position beyond the blow-up limit";
  }
  return "unknown";
}

OpenLoopSample sample_of(const VehicleState& state) {
  OpenLoopSample sample;
  sample.time_s = state.time_s;
  sample.eta = state.eta;
  sample.nu = state.nu;
  sample.thrust_realised_n = state.thrust_realised_n;
  return sample;
}

}  // namespace

OpenLoopCommands read_open_loop_csv(const std::string& path, int num_thrusters) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the input CSV");

  std::vector<std::string> expected_header{"t"};
  for (int i = 1; i <= num_thrusters; ++i) expected_header.push_back("f" + std::to_string(i));
  std::string expected_text;
  for (const auto& name : expected_header) {
    expected_text += (expected_text.empty() ? "" : ",") + name;
  }

  OpenLoopCommands commands;
  std::string line;
  int line_number = 0;
  bool have_header = false;
  while (std::getline(in, line)) {
    ++line_number;
    if (trim(line).empty()) continue;
    const std::vector<std::string> fields = split_fields(line);
    if (!have_header) {
      if (fields != expected_header) {
        fail(path, line_number,
             "expected the header '" + expected_text + "' (" + std::to_string(num_thrusters) +
                 " thrusters), got '" + trim(line) + "'");
      }
      have_header = true;
      continue;
    }
    if (static_cast<int>(fields.size()) != num_thrusters + 1) {
      fail(path, line_number,
           "expected " + std::to_string(num_thrusters + 1) + " columns (t and " +
               std::to_string(num_thrusters) + " thrusts), got " + std::to_string(fields.size()));
    }
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxThrusters + 1, 1> values(num_thrusters + 1);
    for (int c = 0; c <= num_thrusters; ++c) {
      const std::string& text = fields[static_cast<std::size_t>(c)];
      const std::string column = "column " + std::to_string(c + 1) + " (" +
                                 expected_header[static_cast<std::size_t>(c)] + ")";
      char* end = nullptr;
      errno = 0;
      const double value = std::strtod(text.c_str(), &end);
      if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE) {
        fail(path, line_number, column + ": '" + text + "' is not a number");
      }
      if (!std::isfinite(value)) fail(path, line_number, column + ": expected a finite number");
      values(c) = value;
    }
    const double t = values(0);
    if (t < 0) fail(path, line_number, "column 1 (t): expected a time >= 0");
    if (!commands.time_s.empty() && !(t > commands.time_s.back())) {
      fail(path, line_number,
           "column 1 (t): times must increase strictly (previous row has " +
               std::to_string(commands.time_s.back()) + ")");
    }
    commands.time_s.push_back(t);
    commands.thrust_command_n.push_back(values.tail(num_thrusters));
  }
  if (!have_header)
    fail(path, line_number, "empty file: expected the header '" + expected_text + "'");
  if (commands.time_s.empty()) fail(path, line_number, "no command rows after the header");
  return commands;
}

OpenLoopResult run_open_loop_commands(const VehicleModel& model, const ResetSettings& reset,
                                      const OpenLoopCommands& commands, double duration_s,
                                      bool ideal_thrusters) {
  const int n = model.num_thrusters();
  if (commands.time_s.size() != commands.thrust_command_n.size()) {
    throw std::invalid_argument("OpenLoopCommands: time_s and thrust_command_n differ in length");
  }
  for (const auto& command : commands.thrust_command_n) {
    if (command.size() != n) {
      throw std::invalid_argument("OpenLoopCommands: expected " + std::to_string(n) +
                                  " thrusts per row");
    }
  }
  if (duration_s < 0) duration_s = commands.time_s.empty() ? 0.0 : commands.time_s.back();
  const double dt = model.control_step_s;
  // Tolerance on time comparisons: rows written at multiples of dt in decimal (0.3) are meant
  // to land on that step, whatever the binary rounding.
  const double eps_s = 1e-9 * dt;
  const auto num_steps = static_cast<long>(std::floor(duration_s / dt + 1e-9));

  OpenLoopResult result;
  result.samples.reserve(static_cast<std::size_t>(num_steps) + 1);
  VehicleState state = make_state(model, reset);
  result.samples.push_back(sample_of(state));
  ThrusterVector command = ThrusterVector::Zero(n);
  std::size_t next_row = 0;
  for (long k = 0; k < num_steps; ++k) {
    const double step_start_s = static_cast<double>(k) * dt;
    while (next_row < commands.time_s.size() && commands.time_s[next_row] <= step_start_s + eps_s) {
      command = commands.thrust_command_n[next_row++];
    }
    if (ideal_thrusters) {
      step_ideal_thrusters(model, state, command);
    } else {
      step(model, state, command);
    }
    if (state.status != StateStatus::kOk) break;
    result.samples.push_back(sample_of(state));
  }
  result.status = state.status;
  return result;
}

void write_open_loop_csv(const std::string& path, const OpenLoopResult& result, int num_thrusters) {
  std::vector<std::string> header{"t", "x", "y", "z", "phi", "theta", "psi",
                                  "u", "v", "w", "p", "q",   "r"};
  for (int i = 1; i <= num_thrusters; ++i) header.push_back(fmt::format("thrust_{}", i));
  // Every digit of a double: the output reads back exactly.
  csv::Writer out(path, header, csv::Mode::kTruncate, std::numeric_limits<double>::max_digits10);
  for (const OpenLoopSample& s : result.samples) {
    out.cell(s.time_s);
    for (int i = 0; i < 6; ++i) out.cell(s.eta(i));
    for (int i = 0; i < 6; ++i) out.cell(s.nu(i));
    for (int i = 0; i < num_thrusters; ++i) out.cell(s.thrust_realised_n(i));
    out.end_row();
  }
  out.flush();
}

int run_open_loop(const OpenLoopOptions& options, std::ostream& err) {
  try {
    const VehicleModel model = load_vehicle_file(options.vehicle_path);
    const OpenLoopCommands commands = read_open_loop_csv(options.input_csv, model.num_thrusters());
    ResetSettings reset;
    reset.eta = options.initial_eta;
    const OpenLoopResult result =
        run_open_loop_commands(model, reset, commands, options.duration_s, options.ideal_thrusters);
    write_open_loop_csv(options.output_csv, result, model.num_thrusters());
    if (result.status != StateStatus::kOk) {
      err << "auv_sim: open loop: the vehicle state blew up (" << status_name(result.status)
          << ") after t = " << result.samples.back().time_s << " s; " << options.output_csv
          << " holds the run up to there\n";
      return kOpenLoopBlewUp;
    }
    return kOpenLoopOk;
  } catch (const std::exception& e) {
    err << "auv_sim: open loop: " << e.what() << "\n";
    return kOpenLoopInputError;
  }
}

}  // namespace auvrl::sim
