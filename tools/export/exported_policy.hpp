// A trained policy as it leaves the system (`auvrl export`): the network, the state layout and
// scales it was trained with, and the vehicle whose thrusters its actions command; plus the
// description of every input and output that the C header and the ONNX model document.
//
// The layout is inferred from the network's input size and the vehicle's thruster count as
// `auvrl eval` infers it (eval::infer_layout), or given. The scales are the task's
// (task::ObservationScales defaults, the ones `auvrl eval` and every preset use): the network
// file does not store them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/nn/mlp.hpp"
#include "common/task/task.hpp"
#include "common/vehicle_facts.hpp"

namespace auvrl::tools {

/// A policy network with everything needed to run it outside auvrl (load_exported_policy).
struct ExportedPolicy {
  nn::Mlp network;  ///< state -> action, batch of 1
  /// Layout, scales, thruster count and maximum thrust the state vector is built with.
  task::TaskConfig task;
  VehicleFacts vehicle;            ///< thruster names (action order), maximum thrust
  std::string policy_path;         ///< the network file, as given
  std::uint32_t policy_crc32 = 0;  ///< CRC-32 (zlib's) of the network file's bytes
};

/// Loads the network file and the vehicle file and settles the layout: `layout` ("paper",
/// "extended", "extended_thrust") or, when empty, inferred from the network's input size.
/// Throws std::invalid_argument for a bad layout name, std::runtime_error naming the file for
/// an unreadable network or vehicle file, a network that is not a policy (an extra input, an
/// output other than one per thruster) or an input size that fits no layout or not the given
/// one.
ExportedPolicy load_exported_policy(const std::string& policy_path, const std::string& vehicle_path,
                                    const std::string& layout);

/// One entry of the state vector: entry = quantity / scale.
struct StateEntry {
  std::string name;     ///< identifier-like name, e.g. "goal_error_body_x"
  std::string meaning;  ///< what the quantity is, with its frame
  double scale = 1.0;   ///< the quantity is divided by this
  std::string unit;     ///< unit of the quantity and of the scale ("" when dimensionless)
};

/// The state vector of the task's layout, entry by entry, in task::build_state's order.
std::vector<StateEntry> describe_state(const task::TaskConfig& task,
                                       const std::vector<std::string>& thruster_names);

/// A multi-line description shared by the C header's comment and the ONNX model's doc
/// strings: the source files, the network, the layout, every state entry with its scale, and
/// every action with its thruster. Lines end with '\n'; no comment markers.
std::string describe_policy(const ExportedPolicy& policy);

/// The state part alone: "[ i] name: meaning, unit / scale" per entry.
std::string describe_state_text(const ExportedPolicy& policy);

/// The action part alone: "[i] thruster name" per action, with the thrust scale.
std::string describe_action_text(const ExportedPolicy& policy);

}  // namespace auvrl::tools
