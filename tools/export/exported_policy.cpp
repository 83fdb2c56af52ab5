#include "tools/export/exported_policy.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <stdexcept>
#include <utility>

#include "common/nn/checksum.hpp"
#include "common/nn/file_io.hpp"
#include "common/nn/serialize.hpp"
#include "common/task/fault_accommodation.hpp"
#include "eval/evaluation.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::tools {

namespace {

/// The network in `path`; errors name the file.
nn::Mlp read_policy_network(const std::string& path, std::uint32_t& crc) {
  std::vector<std::uint8_t> bytes;
  try {
    bytes = nn::read_file(path);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("policy file (--policy): ") + e.what());
  }
  crc = nn::crc32(bytes.data(), bytes.size());
  try {
    return nn::network_from_bytes(bytes, 1);
  } catch (const std::exception& e) {
    throw std::runtime_error("policy file " + path + ": not a usable network file: " + e.what());
  }
}

/// Throws unless the network maps a state to one action per thruster.
void check_policy_shape(const nn::MlpSpec& spec, const std::string& where, int num_thrusters) {
  if (spec.extra_input_dim != 0) {
    throw std::runtime_error(where + ": network " + spec.describe() +
                             " has a second input: a critic, not a policy");
  }
  if (spec.output_dim != num_thrusters) {
    throw std::runtime_error(where + ": network " + spec.describe() + " has " +
                             std::to_string(spec.output_dim) + " outputs, the vehicle " +
                             std::to_string(num_thrusters) + " thrusters");
  }
}

}  // namespace

ExportedPolicy load_exported_policy(const std::string& policy_path, const std::string& vehicle_path,
                                    const std::string& layout) {
  task::TaskConfig task;
  if (!layout.empty()) task.layout = task::parse_layout(layout);
  const VehicleFacts vehicle = sim::load_vehicle_file(vehicle_path).facts();
  task::apply_vehicle(vehicle, task);
  std::uint32_t crc = 0;
  nn::Mlp network = read_policy_network(policy_path, crc);
  const std::string where = "policy file " + policy_path + " (vehicle " + vehicle.name + ")";
  check_policy_shape(network.spec(), where, vehicle.num_thrusters());
  const int inputs = network.spec().input_dim;
  if (layout.empty()) {
    try {
      task.layout = eval::infer_layout(inputs, vehicle.num_thrusters());
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(where + ": " + e.what());
    }
  } else if (task.state_dim() != inputs) {
    throw std::runtime_error(where + ": the " + layout + " layout has " +
                             std::to_string(task.state_dim()) + " inputs, the network " +
                             std::to_string(inputs));
  }
  return ExportedPolicy{std::move(network), task, vehicle, policy_path, crc};
}

namespace {

/// The entries shared by the extended layouts up to the previous action.
void extended_head(const task::ObservationScales& k, std::vector<StateEntry>& out) {
  const char* axes[3] = {"x (forward)", "y (starboard)", "z (down)"};
  for (int i = 0; i < 3; ++i) {
    out.push_back({std::string("goal_error_body_") + "xyz"[i],
                   std::string("way-point minus position, body frame ") + axes[i], k.position_m,
                   "m"});
  }
  out.push_back({"goal_distance", "distance to the way-point", k.position_m, "m"});
  const char* angles[3] = {"roll", "pitch", "yaw"};
  for (const char* a : angles) {
    out.push_back({std::string("sin_") + a, std::string("sin of ") + a + " (ZYX Euler)", 1, ""});
    out.push_back({std::string("cos_") + a, std::string("cos of ") + a + " (ZYX Euler)", 1, ""});
  }
}

/// Body velocities and rates (both layouts).
void velocities(const task::ObservationScales& k, std::vector<StateEntry>& out) {
  const char* linear[3] = {"u (surge)", "v (sway)", "w (heave)"};
  const char* angular[3] = {"p (roll rate)", "q (pitch rate)", "r (yaw rate)"};
  for (int i = 0; i < 3; ++i) {
    out.push_back({std::string("velocity_body_") + "uvw"[i],
                   std::string("body-frame velocity ") + linear[i], k.linear_velocity_mps, "m/s"});
  }
  for (int i = 0; i < 3; ++i) {
    out.push_back({std::string("rate_body_") + "pqr"[i],
                   std::string("body-frame angular rate ") + angular[i], k.angular_rate_rad_s,
                   "rad/s"});
  }
}

}  // namespace

std::vector<StateEntry> describe_state(const task::TaskConfig& task,
                                       const std::vector<std::string>& thruster_names) {
  const task::ObservationScales& k = task.scales;
  std::vector<StateEntry> out;
  if (task.layout == task::StateLayout::kPaper) {
    const char* ned[3] = {"north", "east", "down"};
    for (int i = 0; i < 3; ++i) {
      out.push_back({std::string("position_ned_") + "ned"[i],
                     std::string("vehicle position, NED ") + ned[i], k.position_m, "m"});
    }
    for (int i = 0; i < 3; ++i) {
      out.push_back({std::string("goal_error_ned_") + "ned"[i],
                     std::string("way-point minus position, NED ") + ned[i], k.position_m, "m"});
    }
  } else {
    extended_head(k, out);
  }
  velocities(k, out);
  for (std::size_t i = 0; i < thruster_names.size(); ++i) {
    out.push_back({fmt::format("previous_action_{}", i),
                   "previous action of " + thruster_names[i] + " (+-1 = +-max thrust)", 1, ""});
  }
  if (task.layout == task::StateLayout::kPaper) return out;
  out.push_back({"depth", "depth (NED down position)", k.depth_m, "m"});
  if (task.layout == task::StateLayout::kExtendedThrust) {
    for (std::size_t i = 0; i < thruster_names.size(); ++i) {
      out.push_back({fmt::format("thrust_realised_{}", i),
                     "realised thrust of " + thruster_names[i] + " (as reported)",
                     task.max_thrust_n, "N"});
    }
  }
  return out;
}

std::string describe_state_text(const ExportedPolicy& policy) {
  const std::vector<StateEntry> entries =
      describe_state(policy.task, policy.vehicle.thruster_names);
  std::string out = fmt::format("State vector ({} inputs, {} layout; entry = quantity / scale):\n",
                                entries.size(), task::to_string(policy.task.layout));
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const StateEntry& e = entries[i];
    out += fmt::format("  [{:2}] {} = {}", i, e.name, e.meaning);
    out += e.unit.empty() ? "\n" : fmt::format(" [{}] / {}\n", e.unit, e.scale);
  }
  return out;
}

std::string describe_action_text(const ExportedPolicy& policy) {
  std::string out = fmt::format(
      "Action vector ({} values in [-1, 1]; thrust command of thruster i = action[i] * {} N):\n",
      policy.vehicle.num_thrusters(), policy.task.max_thrust_n);
  for (int i = 0; i < policy.vehicle.num_thrusters(); ++i) {
    out +=
        fmt::format("  [{}] {}\n", i, policy.vehicle.thruster_names[static_cast<std::size_t>(i)]);
  }
  return out;
}

std::string describe_policy(const ExportedPolicy& policy) {
  const nn::MlpSpec& spec = policy.network.spec();
  const task::ObservationScales& k = policy.task.scales;
  const auto file_name = [](const std::string& path) {
    return std::filesystem::path(path).filename().string();
  };
  std::string out = fmt::format(
      "Policy: {} (CRC-32 0x{:08x}), network {},\n"
      "  float32, ReLU hidden layers.\n"
      "Vehicle: {} ({}, CRC-32 0x{:08x}), {} thrusters, maximum thrust {} N each.\n"
      "State layout: {} (auvrl's task::build_state). Scales: position {} m, linear\n"
      "  velocity {} m/s, angular rate {} rad/s, depth {} m, thrust {} N.\n"
      "Frames: NED world (x north, y east, z down); body (x forward, y starboard, z down).\n",
      file_name(policy.policy_path), policy.policy_crc32, spec.describe(), policy.vehicle.name,
      file_name(policy.vehicle.source_file), policy.vehicle.file_crc32,
      policy.vehicle.num_thrusters(), policy.task.max_thrust_n, task::to_string(policy.task.layout),
      k.position_m, k.linear_velocity_mps, k.angular_rate_rad_s, k.depth_m,
      policy.task.max_thrust_n);
  const task::GoalIntegralSettings& integral = policy.task.integral;
  out += integral.enabled()
             ? fmt::format(
                   "Integral action: the state is built for the way-point moved by an offset\n"
                   "  that grows by {} x {} s x (way-point - position) each control step within\n"
                   "  {} m of it, at most {} m long (auvrl's task::advance_goal_integral; the C\n"
                   "  export's auvrl_policy_integrate_goal).\n",
                   integral.gain_per_s, policy.task.control_step_s, integral.radius_m,
                   integral.max_offset_m)
             : std::string("Integral action: off (the state is built for the way-point).\n");
  const task::PositionFilterSettings& filter = policy.task.position_filter;
  out += filter.enabled()
             ? fmt::format(
                   "Position filter: the state and the integral action take the position\n"
                   "  dead-reckoned from the measured velocity and attitude and pulled toward\n"
                   "  each position fix with a {} s time constant (auvrl's task::PositionFilter;\n"
                   "  the C export's auvrl_policy_filter_position).\n",
                   filter.time_constant_s)
             : std::string("Position filter: off (the state takes the measured position).\n");
  const task::FaultAccommodationSettings& faults = policy.task.fault_accommodation;
  if (!faults.enabled) {
    out += "Fault accommodation: off (the actions go to the thrusters as they are).\n";
  } else if (!task::has_fault_accommodation(policy.task)) {
    out += "Fault accommodation: none (this layout does not carry the realised thrust).\n";
  } else {
    out += fmt::format(
        "Fault accommodation: a thruster whose realised thrust falls below {} of a healthy\n"
        "  thruster's (estimated over {} s) is dead: its action becomes 0 and the others take up\n"
        "  its share of the body wrench (damping {}; auvrl's task::ThrusterFaultAccommodation;\n"
        "  the C export's auvrl_policy_accommodate_faults).\n",
        faults.dead_below, faults.estimate_time_constant_s, faults.damping);
  }
  return out + describe_state_text(policy) + describe_action_text(policy);
}

}  // namespace auvrl::tools
