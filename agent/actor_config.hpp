// auv_actor's configuration from a run file: the task, the goal schedule (its first radius is
// used until the learner's weights say otherwise) and the `actor:` section.
#pragma once

#include <string>

#include "agent/actor_node.hpp"
#include "common/config/yaml_config.hpp"

namespace auvrl::agent {

/// Reads task, schedule and actor from a run file into `config`. Throws config::ConfigError
/// naming file and key. The run file's vehicle (resolved against the file's folder) goes to
/// `vehicle_path` when given: the demonstrator is built from it.
void read_actor_config_file(const std::string& path, ActorNodeConfig& config,
                            std::string* vehicle_path = nullptr);

}  // namespace auvrl::agent
