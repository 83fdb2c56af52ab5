// Channel names of the system, in one place, so every process and tool agrees on them.
#pragma once

#include <string>

namespace auvrl::channels {

/// Thrust commands for vehicle id (thruster_cmd_t).
inline std::string sim_command(int vehicle_id) { return "SIM_CMD_" + std::to_string(vehicle_id); }
/// States of vehicle id (vehicle_state_t).
inline std::string sim_state(int vehicle_id) { return "SIM_STATE_" + std::to_string(vehicle_id); }
/// Resets of vehicle id (vehicle_reset_t).
inline std::string sim_reset(int vehicle_id) { return "SIM_RESET_" + std::to_string(vehicle_id); }
/// Live thruster faults for vehicle id (thruster_fault_t).
inline std::string sim_fault(int vehicle_id) { return "SIM_FAULT_" + std::to_string(vehicle_id); }
/// auv_sim's heartbeat (sim_heartbeat_t).
inline const std::string kSimHeartbeat = "SIM_HEARTBEAT";

/// Actors' transitions for the learner (experience_batch_t).
inline const std::string kExperience = "EXPERIENCE";
/// The learner's actor network (policy_weights_t, large) and its small companion
/// (policy_summary_t, same version).
inline const std::string kPolicyWeights = "POLICY_WEIGHTS";
inline const std::string kPolicySummary = "POLICY_SUMMARY";
/// An actor asks for the current weights (weights_request_t).
inline const std::string kWeightsRequest = "WEIGHTS_REQUEST";
/// The learner's figures (learner_stats_t).
inline const std::string kLearnerStats = "LEARNER_STATS";
/// One finished episode of an actor (episode_report_t).
inline const std::string kEpisode = "EPISODE";
/// auv_logger's heartbeat (logger_heartbeat_t).
inline const std::string kLoggerHeartbeat = "LOGGER_HEARTBEAT";

/// Regexes auv_sim subscribes to (all vehicle ids; the id is parsed and checked).
inline const std::string kSimCommandPattern = "SIM_CMD_[0-9]+";
inline const std::string kSimResetPattern = "SIM_RESET_[0-9]+";
inline const std::string kSimFaultPattern = "SIM_FAULT_[0-9]+";

/// The vehicle id at the end of a per-vehicle channel name, or -1 if there is none.
inline int vehicle_id_of(const std::string& channel) {
  const auto underscore = channel.rfind('_');
  if (underscore == std::string::npos || underscore + 1 >= channel.size()) return -1;
  int id = 0;
  for (std::size_t i = underscore + 1; i < channel.size(); ++i) {
    const char c = channel[i];
    if (c < '0' || c > '9' || id > 100000000) return -1;
    id = id * 10 + (c - '0');
  }
  return id;
}

}  // namespace auvrl::channels
