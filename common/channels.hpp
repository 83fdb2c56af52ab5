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
/// Live water current changes for vehicle id (water_current_t).
inline std::string sim_current(int vehicle_id) {
  return "SIM_CURRENT_" + std::to_string(vehicle_id);
}
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
/// A new mission for vehicle id's running auv_controller (mission_t).
inline std::string mission(int vehicle_id) { return "MISSION_" + std::to_string(vehicle_id); }
/// auv_controller's mission progress and safety state (mission_status_t).
inline const std::string kMissionStatus = "MISSION_STATUS";

/// Regexes auv_sim subscribes to (all vehicle ids; the id is parsed and checked).
inline const std::string kSimCommandPattern = "SIM_CMD_[0-9]+";
inline const std::string kSimResetPattern = "SIM_RESET_[0-9]+";
inline const std::string kSimFaultPattern = "SIM_FAULT_[0-9]+";
inline const std::string kSimCurrentPattern = "SIM_CURRENT_[0-9]+";

/// How a transport that distinguishes kinds of traffic (Cyclone DDS; LCM treats every channel
/// alike) must carry a channel. Which class a channel belongs to is decided here, by the
/// prefixes of kChannelClassPrefixes, and nowhere else.
enum class ChannelClass {
  /// Self-superseding state (policy weights and their summary): only the newest matters, and a
  /// late joiner must get it at once without asking (reliable, keep-last-1, transient-local).
  kState,
  /// Every message matters (experience, episode reports, weights requests): reliable with a
  /// bounded history, so a slow reader makes the writer wait (back-pressure) instead of losing.
  kQueue,
  /// The simulator's lockstep loop (commands, states, resets, faults, currents): latency first; the
  /// sim
  /// client asks again by sequence number if an answer is missing.
  kLockstep,
  /// Everything else (heartbeats, statistics): reliable, a small keep-last history.
  kOther,
};

/// A channel name prefix and the class of the channels that begin with it.
struct ChannelClassPrefix {
  const char* prefix;
  ChannelClass channel_class;
};

/// The channel classes, by prefix (first match wins; no match: kOther).
inline constexpr ChannelClassPrefix kChannelClassPrefixes[] = {
    {"POLICY_", ChannelClass::kState},          // POLICY_WEIGHTS, POLICY_SUMMARY
    {"EXPERIENCE", ChannelClass::kQueue},       //
    {"EPISODE", ChannelClass::kQueue},          //
    {"WEIGHTS_REQUEST", ChannelClass::kQueue},  //
    {"SIM_CMD_", ChannelClass::kLockstep},      //
    {"SIM_STATE_", ChannelClass::kLockstep},    //
    {"SIM_RESET_", ChannelClass::kLockstep},    //
    {"SIM_FAULT_", ChannelClass::kLockstep},    //
    {"SIM_CURRENT_", ChannelClass::kLockstep},
};

/// The class of a channel (see kChannelClassPrefixes).
inline ChannelClass channel_class(const std::string& channel) {
  for (const ChannelClassPrefix& p : kChannelClassPrefixes) {
    if (channel.rfind(p.prefix, 0) == 0) return p.channel_class;
  }
  return ChannelClass::kOther;
}

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
