// The `task:` and `schedule:` sections of a run configuration (config/presets/*.yaml), read
// through their tables (task_table(), goal_schedule_table()), and the task's one command-line
// option.
#pragma once

#include "common/config/yaml_config.hpp"
#include "common/task/goal_schedule.hpp"
#include "common/task/task.hpp"

namespace auvrl::cli {
class CommandLine;
}  // namespace auvrl::cli

namespace auvrl::task {

/// `--integral-gain PER_S` (task.integral.gain_per_s, 0: off, checked against
/// GoalIntegralSettings::kMaxGainPerS), for the programs that drive a policy from a file
/// (`auvrl eval`, `auvrl export`, `auv_controller`).
void add_integral_gain_option(cli::CommandLine& cmd, double& gain_per_s);

/// `--position-filter S` (task.position_filter.time_constant_s, 0: off, checked against
/// PositionFilterSettings::kMaxTimeConstantS), for the same programs.
void add_position_filter_option(cli::CommandLine& cmd, double& time_constant_s);

/// Fills `config` from a `task:` section (keys named as the TaskConfig members; absent keys
/// keep their values) and validates it. Throws config::ConfigError naming file and key.
void read_task_config(config::Section section, TaskConfig& config);

/// A `schedule:` section: interpolation (log_linear | linear | step) and knots
/// [[episode, beta_m], ...]; absent: `fallback`.
GoalSchedule read_goal_schedule(config::Section section, const GoalSchedule& fallback);

/// The schedule a `schedule:` section describes; throws std::invalid_argument when unusable.
GoalSchedule to_goal_schedule(const GoalScheduleConfig& config);

}  // namespace auvrl::task
