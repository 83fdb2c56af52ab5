#include "common/task/task_yaml.hpp"

#include <cmath>

namespace auvrl::task {

void read_task_config(config::Section s, TaskConfig& c) {
  std::string layout = to_string(c.layout), reward = to_string(c.reward);
  s.read("layout", layout);
  s.read("reward", reward);
  try {
    c.layout = parse_layout(layout);
  } catch (const std::invalid_argument& e) {
    s.fail("layout", e.what());
  }
  try {
    c.reward = parse_reward_kind(reward);
  } catch (const std::invalid_argument& e) {
    s.fail("reward", e.what());
  }
  config::Section scales = s.child("scales");
  scales.read("position_m", c.scales.position_m);
  scales.read("linear_velocity_mps", c.scales.linear_velocity_mps);
  scales.read("angular_rate_rad_s", c.scales.angular_rate_rad_s);
  scales.read("depth_m", c.scales.depth_m);
  scales.finish();
  s.read("num_thrusters", c.num_thrusters);
  s.read("max_thrust_n", c.max_thrust_n);
  s.read("goal_reward", c.goal_reward);
  s.read("step_penalty", c.step_penalty);
  s.read("thrust_weight", c.thrust_weight);
  s.read("failure_reward", c.failure_reward);
  s.read("progress_weight", c.progress_weight);
  s.read("beta_max_m", c.beta_max_m);
  s.read("flip_angle_rad", c.flip_angle_rad);
  s.read("hold_mode", c.hold_mode);
  s.read("hold_reward_per_step", c.hold_reward_per_step);
  s.read("distance_weight", c.distance_weight);
  s.read("precision_reward", c.precision_reward);
  s.read("precision_scale_m", c.precision_scale_m);
  s.read("max_steps", c.max_steps);
  s.read("control_step_s", c.control_step_s);
  s.read("start_position_ned_m", c.start_position_ned_m);
  s.read("start_yaw_rad", c.start_yaw_rad);
  s.read("goal_min_ned_m", c.goal_min_ned_m);
  s.read("goal_max_ned_m", c.goal_max_ned_m);
  s.read("random_start_fraction", c.random_start_fraction);
  s.read("start_attitude_spread_rad", c.start_attitude_spread_rad);
  s.read("start_velocity_max_body_mps", c.start_velocity_max_body_mps);
  s.read("start_rate_max_body_rad_s", c.start_rate_max_body_rad_s);
  s.finish();
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    throw config::ConfigError(s.file() + ": " + e.what());
  }
}

GoalSchedule read_goal_schedule(config::Section s, const GoalSchedule& fallback) {
  std::string interpolation = to_string(fallback.interpolation());
  std::vector<std::vector<double>> knots;
  for (const ScheduleKnot& k : fallback.knots()) {
    knots.push_back({static_cast<double>(k.episode), k.beta_m});
  }
  s.read("interpolation", interpolation);
  s.read("knots", knots);
  s.finish();
  std::vector<ScheduleKnot> parsed;
  for (const auto& row : knots) {
    if (row.size() != 2) s.fail("knots", "each knot is [episode, beta_m]");
    // Checked before the conversion: a double beyond int64's range does not convert (found by
    // fuzz_run_config).
    if (!(row[0] >= 0 && row[0] <= 1e15 && row[0] == std::floor(row[0]))) {
      s.fail("knots", "a knot's episode must be a whole number from 0 to 1e15");
    }
    parsed.push_back({static_cast<std::int64_t>(row[0]), row[1]});
  }
  try {
    return GoalSchedule(parsed, parse_interpolation(interpolation));
  } catch (const std::invalid_argument& e) {
    s.fail("knots", e.what());
  }
}

}  // namespace auvrl::task
