// auv_actor's process logic, callable from tests: completing the node's configuration from the
// command line's extras, pinning to a CPU and the episode loop with its periodic log lines.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "agent/actor_node.hpp"
#include "common/transport_options.hpp"

namespace auvrl::agent {

/// auv_actor's options that are not keys of ActorNodeConfig.
struct ActorProcessOptions {
  int vehicle_id = -1;       ///< its vehicle in auv_sim (-1: the actor id)
  int pin_cpu = -1;          ///< pin the process to this CPU (-1: no)
  int report_every = 50;     ///< a log line every N policy episodes
  std::int64_t seed = 1;     ///< way-points and noise
  std::string vehicle_path;  ///< the vehicle file ("": default_vehicle_file())
  /// Before its first episode, wait for readers of these roles (learner, logger) on its
  /// experience and episode channels (and for the learner on its weights requests), so that
  /// the first messages are not lost to readers not yet discovered (Transport::wait_for_readers).
  std::vector<std::string> wait_for_readers;
  double wait_for_readers_s = 30;  ///< at most this long; then it starts anyway, saying so
};

/// Completes `config` from `options` (vehicle id, seed, the vehicle file's facts into the task),
/// validates the task and builds the demonstrator and expert from the vehicle file when the
/// configuration asks for them. Throws whatever validating or loading throws.
void finish_actor_config(const ActorProcessOptions& options, ActorNodeConfig& config);

/// Pins the calling process to `cpu`; false (and a warning on `log`) when that fails.
bool pin_to_cpu(int cpu, std::ostream& log);

/// Runs episodes until a stop signal, the learner's "training done" or config.max_episodes,
/// logging the policy's mean return and successes every `report_every` policy episodes and a
/// final line of counters.
void run_actor_episodes(ActorNode& node, const ActorNodeConfig& config, int report_every,
                        std::ostream& log);

/// The actor's lifecycle: transports (and the lockstep bus if configured), stop handlers, the
/// node, a start line and run_actor_episodes(). Throws on transport or node errors.
void run_actor_process(const ActorNodeConfig& config, const ActorProcessOptions& options,
                       const transport::TransportConfig& transport_config,
                       const transport::LockstepBusOptions& lockstep_bus, std::ostream& log);

}  // namespace auvrl::agent
