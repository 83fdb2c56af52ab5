// Channel names of the system, in one place, so every process and tool agrees on them.
#pragma once

#include <iterator>
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
/// families of kChannelFamilies, and nowhere else.
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

/// A DDS topic of the system. Each carries the channels of one kind of publisher, so that
/// DDS Security can grant publishing and subscribing per role (common/dds_security.hpp), and
/// has the QoS of its channel class.
struct DdsTopic {
  const char* name;
  ChannelClass channel_class;
};

/// The topics (index = the topic's number; the last one takes every channel of no family).
inline constexpr DdsTopic kDdsTopics[] = {
    {"auvrl_weights", ChannelClass::kState},          // 0: POLICY_WEIGHTS, POLICY_SUMMARY
    {"auvrl_experience", ChannelClass::kQueue},       // 1: EXPERIENCE, EPISODE
    {"auvrl_weights_request", ChannelClass::kQueue},  // 2: WEIGHTS_REQUEST
    {"auvrl_sim_command", ChannelClass::kLockstep},   // 3: SIM_CMD_
    {"auvrl_sim_reset", ChannelClass::kLockstep},     // 4: SIM_RESET_
    {"auvrl_sim_state", ChannelClass::kLockstep},     // 5: SIM_STATE_
    {"auvrl_sim_event", ChannelClass::kLockstep},     // 6: SIM_FAULT_, SIM_CURRENT_
    {"auvrl_learner_stats", ChannelClass::kOther},    // 7: LEARNER_STATS
    {"auvrl_heartbeat", ChannelClass::kOther},        // 8: SIM_HEARTBEAT, LOGGER_HEARTBEAT
    {"auvrl_mission", ChannelClass::kOther},          // 9: MISSION_
    {"auvrl_mission_status", ChannelClass::kOther},   // 10: MISSION_STATUS
    {"auvrl_other", ChannelClass::kOther},            // 11: anything else
};
inline constexpr int kDdsTopicCount = static_cast<int>(std::size(kDdsTopics));
/// The topic of channels of no family.
inline constexpr int kOtherDdsTopic = kDdsTopicCount - 1;

/// A channel name prefix and the topic (and so the class) of the channels that begin with it.
struct ChannelFamily {
  const char* prefix;
  int dds_topic;  ///< index into kDdsTopics
};

/// The channel families, by prefix (first match wins; no match: kOtherDdsTopic).
inline constexpr ChannelFamily kChannelFamilies[] = {
    {"POLICY_", 0},         {"EXPERIENCE", 1},    {"EPISODE", 1},       {"WEIGHTS_REQUEST", 2},
    {"SIM_CMD_", 3},        {"SIM_RESET_", 4},    {"SIM_STATE_", 5},    {"SIM_FAULT_", 6},
    {"SIM_CURRENT_", 6},    {"LEARNER_STATS", 7}, {"SIM_HEARTBEAT", 8}, {"LOGGER_HEARTBEAT", 8},
    {"MISSION_STATUS", 10}, {"MISSION_", 9},
};

/// The DDS topic of a channel (see kChannelFamilies).
inline int dds_topic_of(const std::string& channel) {
  for (const ChannelFamily& f : kChannelFamilies) {
    if (channel.rfind(f.prefix, 0) == 0) return f.dds_topic;
  }
  return kOtherDdsTopic;
}

/// The class of a channel (that of its topic).
inline ChannelClass channel_class(const std::string& channel) {
  return kDdsTopics[dds_topic_of(channel)].channel_class;
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
