#include "common/task/task_yaml.hpp"

#include <fmt/format.h>

#include <cmath>

#include "common/cli.hpp"
#include "common/config/table.hpp"

namespace auvrl::task {
namespace {

config::Table<ObservationScales> make_scales_table() {
  using S = ObservationScales;
  config::Table<S> t("scales", "fixed scales that bring every input to roughly [-1, 1]");
  t.field("position_m", &S::position_m, "m", "scale of positions and goal errors");
  t.field("linear_velocity_mps", &S::linear_velocity_mps, "m/s", "scale of body velocities");
  t.field("angular_rate_rad_s", &S::angular_rate_rad_s, "rad/s", "scale of body rates");
  t.field("depth_m", &S::depth_m, "m", "scale of the depth input");
  return t;
}

/// Randomised training episodes: per kind a probability and [low, high] ranges (uniform).
config::Table<EpisodeRandomisation> make_randomise_table() {
  using R = EpisodeRandomisation;
  config::Table<R> t("randomise",
                     "randomised episodes (task.randomise: the actors'; finetune.randomise: the "
                     "fine-tuning's): per kind, the share of episodes that get it and [low, "
                     "high] ranges drawn uniformly");
  t.field("fault_probability", &R::fault_probability, "",
          "share of episodes with one thruster, chosen uniformly, impaired")
      .range(0.0, 1.0);
  t.field("fault_efficiency", &R::fault_efficiency, "[low, high] in 0..1",
          "the share of its thrust that thruster gives");
  t.field("current_probability", &R::current_probability, "",
          "share of episodes with a constant horizontal current from a uniform direction")
      .range(0.0, 1.0);
  t.field("current_speed_mps", &R::current_speed_mps, "[low, high] m/s", "its speed");
  t.field("varying_current_probability", &R::varying_current_probability, "",
          "share of episodes with a slowly varying (Gauss-Markov) current, uniform heading")
      .range(0.0, 1.0);
  t.field("varying_current_sigma_mps", &R::varying_current_sigma_mps, "[low, high] m/s",
          "white-noise intensity of its speed (from 0)");
  t.field("varying_current_time_constant_s", &R::varying_current_time_constant_s,
          "[low, high] s, > 0", "its time constant");
  t.field("sensor_noise_probability", &R::sensor_noise_probability, "",
          "share of episodes with Gaussian noise on what the vehicle reports")
      .range(0.0, 1.0);
  t.field("sensor_noise_scale", &R::sensor_noise_scale, "[low, high], >= 0",
          "one factor per episode on the four levels below");
  t.field("sensor_noise_position_m", &R::sensor_noise_position_m, "m", "position noise level")
      .range(0.0);
  t.field("sensor_noise_attitude_rad", &R::sensor_noise_attitude_rad, "rad",
          "roll, pitch, yaw noise level")
      .range(0.0);
  t.field("sensor_noise_velocity_mps", &R::sensor_noise_velocity_mps, "m/s",
          "body velocity noise level")
      .range(0.0);
  t.field("sensor_noise_angular_rate_rad_s", &R::sensor_noise_angular_rate_rad_s, "rad/s",
          "body rate noise level")
      .range(0.0);
  t.field("model_probability", &R::model_probability, "",
          "share of episodes on a model that differs from the vehicle file (all below drawn)")
      .range(0.0, 1.0);
  t.field("quadratic_damping_scale", &R::quadratic_damping_scale, "[low, high], > 0",
          "x every quadratic damping coefficient");
  t.field("added_mass_scale", &R::added_mass_scale, "[low, high], > 0",
          "x every added-mass derivative");
  t.field("mass_scale", &R::mass_scale, "[low, high], > 0",
          "x mass and inertia (ballasted to the file's trim)");
  t.field("thrust_scale", &R::thrust_scale, "[low, high] in (0, 1]",
          "x every thruster's efficiency");
  t.field("thruster_lag_time_constant_s", &R::thruster_lag_time_constant_s,
          "[low, high] s; [0, 0]: the file's", "the thrusters' lag time constant");
  t.field("extra_buoyancy_n", &R::extra_buoyancy_n, "[low, high] N",
          "added to the buoyancy (> 0: lighter)");
  t.validate([](const config::Section& s, R& r) {
    std::string key;
    const std::string what = r.check(key);
    if (!what.empty()) s.fail(key, what);
  });
  return t;
}

config::Table<GoalIntegralSettings> make_integral_table() {
  using G = GoalIntegralSettings;
  config::Table<G> t("integral",
                     "integral action of a driving policy (evaluation, fine-tuning, missions, "
                     "deployment; not the actors' training episodes): the goal it is shown moves "
                     "by the integral of the position error");
  t.field("gain_per_s", &G::gain_per_s, "1/s, 0: off",
          "per control step within radius_m: offset += gain * step * (goal - position)")
      .range(0.0, G::kMaxGainPerS);
  t.field("radius_m", &G::radius_m, "m", "the integrator runs only this close to the goal");
  t.field("max_offset_m", &G::max_offset_m, "m", "the offset's largest length (anti-windup)")
      .range(0.0);
  return t;
}

config::Table<PositionFilterSettings> make_position_filter_table() {
  using F = PositionFilterSettings;
  config::Table<F> t("position_filter",
                     "the position a driving policy is shown (evaluation, fine-tuning, missions, "
                     "deployment; not the actors' training episodes): dead-reckoned from the "
                     "measured velocity and pulled toward each position fix");
  t.field("time_constant_s", &F::time_constant_s, "s, 0: off",
          "how fast the estimate follows the position fixes")
      .range(0.0, F::kMaxTimeConstantS);
  return t;
}

config::Table<FaultAccommodationSettings> make_fault_accommodation_table() {
  using F = FaultAccommodationSettings;
  config::Table<F> t("fault_accommodation",
                     "a driving policy's answer to a weak or dead thruster (evaluation, missions, "
                     "deployment; not the fine-tuning's episodes nor the actors'; extended_thrust "
                     "layout): detected from its realised thrust; the healthy thrusters make up "
                     "the wrench it fails to deliver, and a dead one is no longer commanded");
  t.field("enabled", &F::enabled, "", "accommodate weak and dead thrusters when a policy drives");
  t.field("dead_below", &F::dead_below, "efficiency",
          "a thruster whose estimated efficiency falls below this counts as dead")
      .range(0.0, 1.0);
  t.field("weak_below", &F::weak_below, "efficiency",
          "a thruster whose estimated efficiency falls below this counts as weak: it keeps the "
          "policy's commands and the healthy ones make up its shortfall (dead_below: dead "
          "thrusters only)")
      .range(0.0, 1.0);
  t.field("estimate_time_constant_s", &F::estimate_time_constant_s, "s",
          "time constant of the efficiency estimate")
      .positive();
  t.field("damping", &F::damping, "",
          "damping of the redistribution (small: rebuild the whole wrench; large: leave the "
          "healthy thrusters' commands alone, a dead one still gets none)")
      .positive();
  return t;
}

/// The reward's terms.
void add_reward_fields(config::Table<TaskConfig>& t) {
  using C = TaskConfig;
  t.choice("reward", &C::reward, parse_reward_kind, to_string, "paper, shaped",
           "reward: paper (Eq. 14) or shaped (dense progress term)");
  t.field("goal_reward", &C::goal_reward, "", "reward on reaching the goal radius beta");
  t.field("step_penalty", &C::step_penalty, "per step", "the -1 of Eq. 14");
  t.field("thrust_weight", &C::thrust_weight, "", "weight of the thrust cost mean(u_i^2)");
  t.field("failure_reward", &C::failure_reward, "",
          "reward on leaving beta_max or flipping (paper -10; -1/(1-gamma) fixes it)");
  t.field("progress_weight", &C::progress_weight, "per m",
          "shaped reward: per metre of progress toward the goal");
  t.field("beta_max_m", &C::beta_max_m, "m", "safety sphere around the goal");
  t.field("flip_angle_rad", &C::flip_angle_rad, "rad",
          "|roll| or |pitch| beyond this ends the episode");
  t.field("hold_mode", &C::hold_mode, "",
          "reaching does not end the episode; each step inside beta earns hold_reward_per_step");
  t.field("hold_reward_per_step", &C::hold_reward_per_step, "per step", "hold mode's reward");
  t.field("distance_weight", &C::distance_weight, "per m and step",
          "shaped reward: -distance_weight * d");
  t.field("precision_reward", &C::precision_reward, "per step",
          "shaped reward: +precision_reward * exp(-d / precision_scale_m)");
  t.field("precision_scale_m", &C::precision_scale_m, "m", "scale of the precision term");
  t.field("command_change_weight", &C::command_change_weight, "0: off",
          "price of command changes: -w * mean((u_t - u_t-1)^2) per step (u_t-1 is in the state)")
      .range(0.0);
}

/// Episode length, start and goal region.
void add_episode_fields(config::Table<TaskConfig>& t) {
  using C = TaskConfig;
  t.field("max_steps", &C::max_steps, "steps", "episode length limit (700 = 70 s)");
  t.field("start_position_ned_m", &C::start_position_ned_m, "m, NED", "start position");
  t.field("start_yaw_rad", &C::start_yaw_rad, "rad", "start heading");
  t.field("goal_min_ned_m", &C::goal_min_ned_m, "m, NED",
          "way-points are drawn uniformly in the box from here...");
  t.field("goal_max_ned_m", &C::goal_max_ned_m, "m, NED", "...to here");
  t.field("random_start_fraction", &C::random_start_fraction, "0..1",
          "share of training episodes started in a random state (exploring starts)");
  t.field("start_attitude_spread_rad", &C::start_attitude_spread_rad, "rad",
          "random starts: roll, pitch, yaw uniform in +- this");
  t.field("start_velocity_max_body_mps", &C::start_velocity_max_body_mps, "m/s",
          "random starts: u, v, w uniform in +- this");
  t.field("start_rate_max_body_rad_s", &C::start_rate_max_body_rad_s, "rad/s",
          "random starts: p, q, r uniform in +- this");
  t.section("randomise", randomise_table(), &C::randomise);
  t.section("integral", make_integral_table(), &C::integral);
  t.section("position_filter", make_position_filter_table(), &C::position_filter);
  t.section("fault_accommodation", make_fault_accommodation_table(), &C::fault_accommodation);
}

config::Table<TaskConfig> make_task_table() {
  using C = TaskConfig;
  config::Table<C> t("task", "the task every process shares: observation, reward, episodes");
  t.choice("layout", &C::layout, parse_layout, to_string, "paper, extended, extended_thrust",
           "state layout (observation vector)");
  t.section("scales", make_scales_table(), &C::scales);
  add_reward_fields(t);
  add_episode_fields(t);
  return t;
}

config::Table<GoalScheduleConfig> make_schedule_table() {
  using C = GoalScheduleConfig;
  config::Table<C> t("schedule", "the goal radius beta as a function of finished episodes");
  t.choice("interpolation", &C::interpolation, parse_interpolation, to_string,
           "log_linear, linear, step", "how beta moves between two knots");
  t.field("knots", &C::knots, "[episode, m]",
          "knots [[episode, beta_m], ...], episodes strictly increasing, beta > 0");
  return t;
}

}  // namespace

const config::Table<EpisodeRandomisation>& randomise_table() {
  static const config::Table<EpisodeRandomisation> table = make_randomise_table();
  return table;
}

const config::Table<TaskConfig>& task_table() {
  static const config::Table<TaskConfig> table = make_task_table();
  return table;
}

const config::Table<GoalScheduleConfig>& goal_schedule_table() {
  static const config::Table<GoalScheduleConfig> table = make_schedule_table();
  return table;
}

void add_driving_aid_options(cli::CommandLine& cmd, DrivingAidOptions& options) {
  cmd.option("integral-gain", &options.integral_gain_per_s,
             "the policy's integral action, 1/s (0: off; docs/usage.md, \"Integral action\")");
  cmd.check("integral-gain", CLI::Range(0.0, GoalIntegralSettings::kMaxGainPerS));
  cmd.option("position-filter", &options.position_filter_s,
             "the policy's position filter, time constant in s (0: off; docs/usage.md, "
             "\"Position filter\")");
  cmd.check("position-filter", CLI::Range(0.0, PositionFilterSettings::kMaxTimeConstantS));
  cmd.option("fault-accommodation", &options.fault_accommodation,
             "the policy's thruster fault accommodation, true or false (docs/usage.md, \"Fault "
             "accommodation\")");
}

void read_task_config(config::Section s, TaskConfig& c) {
  task_table().read(s, c);
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    throw config::ConfigError(fmt::format("{}: {}", s.file(), e.what()));
  }
}

GoalSchedule to_goal_schedule(const GoalScheduleConfig& c) {
  std::vector<ScheduleKnot> knots;
  for (const auto& row : c.knots) {
    if (row.size() != 2) throw std::invalid_argument("each knot is [episode, beta_m]");
    // Checked before the conversion: a double beyond int64's range does not convert (found by
    // fuzz_run_config).
    if (!(row[0] >= 0 && row[0] <= 1e15 && row[0] == std::floor(row[0]))) {
      throw std::invalid_argument("a knot's episode must be a whole number from 0 to 1e15");
    }
    knots.push_back({static_cast<std::int64_t>(row[0]), row[1]});
  }
  return GoalSchedule(knots, c.interpolation);
}

GoalSchedule read_goal_schedule(config::Section s, const GoalSchedule& fallback) {
  GoalScheduleConfig c;
  c.interpolation = fallback.interpolation();
  c.knots.clear();
  for (const ScheduleKnot& k : fallback.knots()) {
    c.knots.push_back({static_cast<double>(k.episode), k.beta_m});
  }
  goal_schedule_table().read(s, c);
  try {
    return to_goal_schedule(c);
  } catch (const std::invalid_argument& e) {
    s.fail("knots", e.what());
  }
}

}  // namespace auvrl::task
