// The `task:` and `schedule:` sections of a run configuration (config/presets/*.yaml), read
// through their tables (task_table(), goal_schedule_table()), and the task's command-line
// options.
#pragma once

#include "common/config/yaml_config.hpp"
#include "common/task/goal_schedule.hpp"
#include "common/task/task.hpp"

namespace auvrl::cli {
class CommandLine;
}  // namespace auvrl::cli

namespace auvrl::task {

/// `--integral-gain PER_S` and `--position-filter S` into a DrivingAidOptions, checked against
/// GoalIntegralSettings::kMaxGainPerS and PositionFilterSettings::kMaxTimeConstantS.
void add_driving_aid_options(cli::CommandLine& cmd, DrivingAidOptions& options);

/// Fills `config` from a `task:` section (keys named as the TaskConfig members; absent keys
/// keep their values) and validates it. Throws config::ConfigError naming file and key.
void read_task_config(config::Section section, TaskConfig& config);

/// A `schedule:` section: interpolation (log_linear | linear | step) and knots
/// [[episode, beta_m], ...]; absent: `fallback`.
GoalSchedule read_goal_schedule(config::Section section, const GoalSchedule& fallback);

/// The schedule a `schedule:` section describes; throws std::invalid_argument when unusable.
GoalSchedule to_goal_schedule(const GoalScheduleConfig& config);

}  // namespace auvrl::task
