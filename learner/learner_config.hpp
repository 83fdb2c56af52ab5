// auv_learner's configuration from a run file: the task (dimensions, HER's reward), the goal
// schedule and the `learner:` section.
#pragma once

#include <string>

#include "common/config/yaml_config.hpp"
#include "learner/learner_node.hpp"

namespace auvrl::learner {

/// Fills `config` from a `learner:` section (keys named as the DdpgConfig and
/// LearnerNodeConfig members). Throws config::ConfigError naming file and key.
void read_learner_section(config::Section section, LearnerNodeConfig& config);

/// Reads task, schedule and learner from a run file into `config`; state and action sizes
/// come from the task.
void read_learner_config_file(const std::string& path, LearnerNodeConfig& config);

}  // namespace auvrl::learner
