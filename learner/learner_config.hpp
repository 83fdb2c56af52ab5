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

/// Loads the vehicle file's facts into `config` (vehicle, the task's thruster fields) and sizes
/// the networks from the task's layout and the thruster count. Throws sim::VehicleFileError.
void apply_vehicle_file(const std::string& vehicle_path, LearnerNodeConfig& config);

/// Reads task, schedule and learner from a run file into `config`, and the run file's vehicle
/// (apply_vehicle_file; its path to `vehicle_path` when given): state and action sizes come
/// from the task's layout and the vehicle's thrusters.
void read_learner_config_file(const std::string& path, LearnerNodeConfig& config,
                              std::string* vehicle_path = nullptr);

}  // namespace auvrl::learner
