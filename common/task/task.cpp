#include "common/task/task.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>
#include <utility>

#include "common/random.hpp"

namespace auvrl::task {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr int kPaperFixed = 3 + 3 + 6;             // x_pos, x_e, v
constexpr int kExtendedFixed = 3 + 1 + 6 + 6 + 1;  // e_body, d, sin/cos, v, depth
// Offsets of the extended layout.
constexpr int kExtError = 0, kExtDistance = 3, kExtTrig = 4, kExtVelocity = 10, kExtAction = 16;
// Offsets of the paper layout.
constexpr int kPaperPosition = 0, kPaperError = 3, kPaperVelocity = 6, kPaperAction = 12;
}  // namespace

StateLayout parse_layout(const std::string& name) {
  if (name == "paper") return StateLayout::kPaper;
  if (name == "extended") return StateLayout::kExtended;
  if (name == "extended_thrust") return StateLayout::kExtendedThrust;
  throw std::invalid_argument("state layout '" + name +
                              "': expected paper, extended or extended_thrust");
}

const char* to_string(StateLayout layout) {
  switch (layout) {
    case StateLayout::kPaper:
      return "paper";
    case StateLayout::kExtended:
      return "extended";
    case StateLayout::kExtendedThrust:
      return "extended_thrust";
  }
  return "?";
}

RewardKind parse_reward_kind(const std::string& name) {
  if (name == "paper") return RewardKind::kPaper;
  if (name == "shaped") return RewardKind::kShaped;
  throw std::invalid_argument("reward '" + name + "': expected paper or shaped");
}

const char* to_string(RewardKind kind) { return kind == RewardKind::kPaper ? "paper" : "shaped"; }

int TaskConfig::state_dim() const {
  if (layout == StateLayout::kPaper) return kPaperFixed + num_thrusters;
  return kExtendedFixed + (layout == StateLayout::kExtendedThrust ? 2 : 1) * num_thrusters;
}

void TaskConfig::validate() const {
  const auto positive = [](double v, const char* name) {
    if (!std::isfinite(v) || v <= 0) {
      throw std::invalid_argument(std::string("task.") + name + " must be finite and > 0");
    }
  };
  positive(scales.position_m, "scales.position_m");
  positive(scales.linear_velocity_mps, "scales.linear_velocity_mps");
  positive(scales.angular_rate_rad_s, "scales.angular_rate_rad_s");
  positive(scales.depth_m, "scales.depth_m");
  positive(max_thrust_n, "max_thrust_n");
  positive(beta_max_m, "beta_max_m");
  positive(flip_angle_rad, "flip_angle_rad");
  positive(control_step_s, "control_step_s");
  positive(precision_scale_m, "precision_scale_m");
  if (num_thrusters < 1 || num_thrusters > 64) {
    throw std::invalid_argument("task.num_thrusters must be in 1..64");
  }
  if (max_steps < 1) throw std::invalid_argument("task.max_steps must be >= 1");
  for (double v : {goal_reward, step_penalty, thrust_weight, failure_reward, progress_weight,
                   hold_reward_per_step, distance_weight, precision_reward, start_yaw_rad}) {
    if (!std::isfinite(v)) throw std::invalid_argument("task: a reward constant is not finite");
  }
  if (!(command_change_weight >= 0) || !std::isfinite(command_change_weight)) {
    throw std::invalid_argument("task.command_change_weight must be finite and >= 0");
  }
  if (!(random_start_fraction >= 0 && random_start_fraction <= 1)) {
    throw std::invalid_argument("task.random_start_fraction must be in [0, 1]");
  }
  const auto spread = [](const Eigen::Vector3d& v, double limit, const char* name) {
    if (!v.allFinite() || v.minCoeff() < 0 || v.maxCoeff() > limit) {
      throw std::invalid_argument(std::string("task.") + name + " must be 3 values in [0, " +
                                  std::to_string(limit) + "]");
    }
  };
  // Roll and pitch stay inside the flip angle (checked at the first step); the limits keep
  // the starts within what the vehicle can do (about 1.6 m/s and 0.6 rad/s at full thrust).
  spread(start_attitude_spread_rad, kPi, "start_attitude_spread_rad");
  if (std::max(start_attitude_spread_rad[0], start_attitude_spread_rad[1]) >= flip_angle_rad) {
    throw std::invalid_argument(
        "task.start_attitude_spread_rad: roll and pitch spreads must be below flip_angle_rad");
  }
  spread(start_velocity_max_body_mps, 5.0, "start_velocity_max_body_mps");
  spread(start_rate_max_body_rad_s, 2.0, "start_rate_max_body_rad_s");
  randomise.validate();
  if (!(integral.gain_per_s >= 0 && integral.gain_per_s <= GoalIntegralSettings::kMaxGainPerS)) {
    throw std::invalid_argument(fmt::format("task.integral.gain_per_s must be in [0, {}] (1/s)",
                                            GoalIntegralSettings::kMaxGainPerS));
  }
  positive(integral.radius_m, "integral.radius_m");
  if (!(position_filter.time_constant_s >= 0 &&
        position_filter.time_constant_s <= PositionFilterSettings::kMaxTimeConstantS)) {
    throw std::invalid_argument(
        fmt::format("task.position_filter.time_constant_s must be in [0, {}] (s), got {}",
                    PositionFilterSettings::kMaxTimeConstantS, position_filter.time_constant_s));
  }
  fault_accommodation.validate();
  if (!(integral.max_offset_m >= 0) || !std::isfinite(integral.max_offset_m)) {
    throw std::invalid_argument("task.integral.max_offset_m must be finite and >= 0");
  }
  if (!start_position_ned_m.allFinite() || !goal_min_ned_m.allFinite() ||
      !goal_max_ned_m.allFinite() || (goal_max_ned_m - goal_min_ned_m).minCoeff() < 0) {
    throw std::invalid_argument("task: goal region must be finite with min <= max");
  }
}

Eigen::Matrix3d body_to_ned(const Eigen::Vector3d& e) {
  const double cphi = std::cos(e[0]), sphi = std::sin(e[0]);
  const double cth = std::cos(e[1]), sth = std::sin(e[1]);
  const double cpsi = std::cos(e[2]), spsi = std::sin(e[2]);
  Eigen::Matrix3d r;
  r << cpsi * cth, -spsi * cphi + cpsi * sth * sphi, spsi * sphi + cpsi * cphi * sth,  //
      spsi * cth, cpsi * cphi + sphi * sth * spsi, -cpsi * sphi + sth * spsi * cphi,   //
      -sth, cth * sphi, cth * cphi;
  return r;
}

double yaw_facing_away_rad(const Eigen::Vector3d& position_ned_m,
                           const Eigen::Vector3d& goal_ned_m) {
  const Eigen::Vector3d to_goal = goal_ned_m - position_ned_m;
  return std::remainder(std::atan2(to_goal.y(), to_goal.x()) + kPi, 2.0 * kPi);
}

void build_state(const TaskConfig& c, const Observation& obs, const Eigen::Vector3d& goal,
                 const ActionVector& previous_action, StateVector& out,
                 const std::vector<double>& thrust_realised_n) {
  if (previous_action.size() != c.num_thrusters) {
    throw std::invalid_argument("build_state: previous action has " +
                                std::to_string(previous_action.size()) + " entries, expected " +
                                std::to_string(c.num_thrusters));
  }
  out.resize(c.state_dim());
  const Eigen::Vector3d error_ned = goal - obs.position_ned_m;
  const ObservationScales& k = c.scales;
  if (c.layout == StateLayout::kPaper) {
    out.segment<3>(kPaperPosition) = (obs.position_ned_m / k.position_m).cast<float>();
    out.segment<3>(kPaperError) = (error_ned / k.position_m).cast<float>();
    out.segment<3>(kPaperVelocity) = (obs.velocity_body_mps / k.linear_velocity_mps).cast<float>();
    out.segment<3>(kPaperVelocity + 3) =
        (obs.angular_rate_body_rad_s / k.angular_rate_rad_s).cast<float>();
    out.segment(kPaperAction, c.num_thrusters) = previous_action;
    return;
  }
  const Eigen::Vector3d error_body = body_to_ned(obs.euler_rpy_rad).transpose() * error_ned;
  out.segment<3>(kExtError) = (error_body / k.position_m).cast<float>();
  out[kExtDistance] = static_cast<float>(error_ned.norm() / k.position_m);
  for (int i = 0; i < 3; ++i) {
    out[kExtTrig + 2 * i] = static_cast<float>(std::sin(obs.euler_rpy_rad[i]));
    out[kExtTrig + 2 * i + 1] = static_cast<float>(std::cos(obs.euler_rpy_rad[i]));
  }
  out.segment<3>(kExtVelocity) = (obs.velocity_body_mps / k.linear_velocity_mps).cast<float>();
  out.segment<3>(kExtVelocity + 3) =
      (obs.angular_rate_body_rad_s / k.angular_rate_rad_s).cast<float>();
  out.segment(kExtAction, c.num_thrusters) = previous_action;
  out[kExtAction + c.num_thrusters] = static_cast<float>(obs.position_ned_m[2] / k.depth_m);
  if (c.layout == StateLayout::kExtendedThrust) {
    if (thrust_realised_n.size() != static_cast<std::size_t>(c.num_thrusters)) {
      throw std::invalid_argument("build_state: the extended_thrust layout needs the thrust of " +
                                  std::to_string(c.num_thrusters) + " thrusters, got " +
                                  std::to_string(thrust_realised_n.size()));
    }
    const int first = kExtAction + c.num_thrusters + 1;
    for (int i = 0; i < c.num_thrusters; ++i) {
      out[first + i] =
          static_cast<float>(thrust_realised_n[static_cast<std::size_t>(i)] / c.max_thrust_n);
    }
  }
}

namespace {
/// Body-to-NED rotation from the sin/cos entries of an extended observation vector.
Eigen::Matrix3d rotation_from_state(const Eigen::Ref<const StateVector>& state) {
  Eigen::Vector3d euler;
  for (int i = 0; i < 3; ++i) {
    euler[i] = std::atan2(state[kExtTrig + 2 * i], state[kExtTrig + 2 * i + 1]);
  }
  return body_to_ned(euler);
}
}  // namespace

void relabel_state(const TaskConfig& c, const Eigen::Vector3d& old_goal,
                   const Eigen::Vector3d& new_goal, Eigen::Ref<StateVector> state) {
  const Eigen::Vector3d shift = new_goal - old_goal;
  if (c.layout == StateLayout::kPaper) {
    state.segment<3>(kPaperError) += (shift / c.scales.position_m).cast<float>();
    return;
  }
  const Eigen::Matrix3d r = rotation_from_state(state);
  Eigen::Vector3d error_body = state.segment<3>(kExtError).cast<double>() * c.scales.position_m;
  error_body += r.transpose() * shift;
  state.segment<3>(kExtError) = (error_body / c.scales.position_m).cast<float>();
  state[kExtDistance] = static_cast<float>(error_body.norm() / c.scales.position_m);
}

void relabel_state(const TaskConfig& c, const Eigen::Vector3d& old_goal,
                   const Eigen::Vector3d& new_goal, const Eigen::Vector3d& shift_ned_m,
                   Eigen::Ref<StateVector> state) {
  // The vehicle further along by the shift sees the goal as if it were that much nearer.
  relabel_state(c, old_goal, new_goal - shift_ned_m, state);
  if (c.layout == StateLayout::kPaper) {
    state.segment<3>(kPaperPosition) += (shift_ned_m / c.scales.position_m).cast<float>();
  } else {
    state[kExtAction + c.num_thrusters] += static_cast<float>(shift_ned_m.z() / c.scales.depth_m);
  }
}

void FaultAccommodationSettings::validate() const {
  if (!(dead_below >= 0 && dead_below < 1)) {
    throw std::invalid_argument(
        fmt::format("task.fault_accommodation.dead_below must be in [0, 1) (an efficiency), got {}",
                    dead_below));
  }
  if (!(weak_below >= dead_below && weak_below < 1)) {
    throw std::invalid_argument(
        fmt::format("task.fault_accommodation.weak_below must be in [dead_below = {}, 1) (an "
                    "efficiency), got {}",
                    dead_below, weak_below));
  }
  for (const auto& [value, name] : {std::pair{estimate_time_constant_s, "estimate_time_constant_s"},
                                    std::pair{damping, "damping"}}) {
    if (!std::isfinite(value) || value <= 0) {
      throw std::invalid_argument(
          fmt::format("task.fault_accommodation.{} must be finite and > 0, got {}", name, value));
    }
  }
}

void DrivingAidOptions::apply(TaskConfig& task) const {
  task.integral.gain_per_s = integral_gain_per_s;
  task.position_filter.time_constant_s = position_filter_s;
  task.fault_accommodation.enabled = fault_accommodation;
}

PositionFilter::PositionFilter(const PositionFilterSettings& settings, double control_step_s)
    : control_step_s_(control_step_s),
      gain_(-std::expm1(-control_step_s / settings.time_constant_s)) {
  if (!settings.enabled() || !(control_step_s > 0.0)) {
    throw std::invalid_argument(fmt::format(
        "PositionFilter: needs time_constant_s > 0 (got {}) and a positive control step (got {})",
        settings.time_constant_s, control_step_s));
  }
}

const Eigen::Vector3d& PositionFilter::update(const Observation& measured) {
  const Eigen::Vector3d velocity_ned_mps =
      body_to_ned(measured.euler_rpy_rad) * measured.velocity_body_mps;
  if (!started_) {
    position_ned_m_ = measured.position_ned_m;
    started_ = true;
  } else {
    position_ned_m_ += 0.5 * control_step_s_ * (velocity_ned_mps + velocity_ned_mps_);
    position_ned_m_ += gain_ * (measured.position_ned_m - position_ned_m_);
  }
  velocity_ned_mps_ = velocity_ned_mps;
  return position_ned_m_;
}

Eigen::Vector3d advance_goal_integral(const TaskConfig& c, const Eigen::Vector3d& goal_ned_m,
                                      const Eigen::Vector3d& position_ned_m,
                                      Eigen::Vector3d& offset_ned_m) {
  const GoalIntegralSettings& s = c.integral;
  const Eigen::Vector3d error_ned_m = goal_ned_m - position_ned_m;
  if (s.enabled() && error_ned_m.norm() <= s.radius_m) {
    offset_ned_m += s.gain_per_s * c.control_step_s * error_ned_m;
    const double length_m = offset_ned_m.norm();
    if (length_m > s.max_offset_m) offset_ned_m *= s.max_offset_m / length_m;
  }
  return goal_ned_m + offset_ned_m;
}

void previous_action_from_state(const TaskConfig& c, const Eigen::Ref<const StateVector>& state,
                                Eigen::VectorXd& previous_action) {
  const int first = c.layout == StateLayout::kPaper ? kPaperAction : kExtAction;
  previous_action = state.segment(first, c.num_thrusters).cast<double>();
}

void realised_thrust_from_state(const TaskConfig& c, const Eigen::Ref<const StateVector>& state,
                                Eigen::VectorXd& thrust_realised_n) {
  if (c.layout != StateLayout::kExtendedThrust) {
    throw std::invalid_argument(std::string("realised_thrust_from_state: the ") +
                                to_string(c.layout) + " layout does not carry the realised thrust");
  }
  const int first = kExtAction + c.num_thrusters + 1;  // as build_state writes it
  thrust_realised_n = state.segment(first, c.num_thrusters).cast<double>() * c.max_thrust_n;
}

Eigen::Vector3d position_from_state(const TaskConfig& c, const Eigen::Vector3d& goal,
                                    const Eigen::Ref<const StateVector>& state) {
  if (c.layout == StateLayout::kPaper) {
    return state.segment<3>(kPaperPosition).cast<double>() * c.scales.position_m;
  }
  const Eigen::Vector3d error_body =
      state.segment<3>(kExtError).cast<double>() * c.scales.position_m;
  return goal - rotation_from_state(state) * error_body;
}

double thrust_cost(const TaskConfig& c, const ActionVector& action) {
  return c.thrust_weight * static_cast<double>(action.squaredNorm()) /
         static_cast<double>(std::max<Eigen::Index>(1, action.size()));
}

double command_change_cost(const TaskConfig& c, const ActionVector& action,
                           const ActionVector& previous) {
  if (c.command_change_weight == 0.0 || previous.size() == 0) return 0.0;
  if (previous.size() != action.size()) {
    throw std::invalid_argument("command_change_cost: the previous action has " +
                                std::to_string(previous.size()) + " entries, the action " +
                                std::to_string(action.size()));
  }
  return c.command_change_weight * static_cast<double>((action - previous).squaredNorm()) /
         static_cast<double>(std::max<Eigen::Index>(1, action.size()));
}

void previous_action_from_state(const TaskConfig& c, const Eigen::Ref<const StateVector>& state,
                                ActionVector& out) {
  const int first = c.layout == StateLayout::kPaper ? kPaperAction : kExtAction;
  out = state.segment(first, c.num_thrusters);
}

bool is_flipped(const TaskConfig& c, const Eigen::Vector3d& euler) {
  return std::abs(euler[0]) > c.flip_angle_rad || std::abs(euler[1]) > c.flip_angle_rad;
}

StepOutcome evaluate_step(const TaskConfig& c, double d_before, double d_after, bool flipped,
                          const ActionVector& action, double beta_m, int steps_taken,
                          const ActionVector& previous_action) {
  StepOutcome out;
  out.distance_m = d_after;
  out.inside_goal = d_after <= beta_m;
  if (flipped || d_after > c.beta_max_m) {
    out.reward = c.failure_reward;
    out.terminal = out.done = true;
    out.reason = flipped ? EndReason::kFlipped : EndReason::kLeftRegion;
    return out;
  }
  const double cost = thrust_cost(c, action) + command_change_cost(c, action, previous_action);
  if (out.inside_goal && !c.hold_mode) {
    out.reward = c.goal_reward;
    out.terminal = out.done = true;
    out.reason = EndReason::kReached;
    return out;
  }
  if (c.reward == RewardKind::kPaper) {
    out.reward = -c.step_penalty - cost;
  } else {
    out.reward = c.progress_weight * (d_before - d_after) - c.step_penalty - cost -
                 c.distance_weight * d_after +
                 c.precision_reward * std::exp(-d_after / c.precision_scale_m);
  }
  if (out.inside_goal) out.reward += c.hold_reward_per_step;  // hold mode only
  if (steps_taken >= c.max_steps) {
    out.done = true;  // a cut-off: the learner bootstraps through it
    out.reason = EndReason::kTimeLimit;
  }
  return out;
}

namespace {
/// Uniform in centre +- half_width, per component.
Eigen::Vector3d spread_draw(const Eigen::Vector3d& centre, const Eigen::Vector3d& half_width,
                            std::mt19937_64& rng) {
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v[i] = centre[i] + (2.0 * draw::unit(rng) - 1.0) * half_width[i];
  return v;
}
}  // namespace

Eigen::Vector3d sample_goal(const TaskConfig& c, std::mt19937_64& rng) {
  Eigen::Vector3d g;
  for (int i = 0; i < 3; ++i) {
    g[i] = c.goal_min_ned_m[i] + draw::unit(rng) * (c.goal_max_ned_m[i] - c.goal_min_ned_m[i]);
  }
  return g;
}

StartState sample_start(const TaskConfig& c, std::mt19937_64& rng) {
  StartState rest;
  rest.position_ned_m = c.start_position_ned_m;
  rest.euler_rpy_rad = Eigen::Vector3d(0.0, 0.0, c.start_yaw_rad);
  const bool random = draw::unit(rng) < c.random_start_fraction;
  StartState drawn = rest;
  drawn.euler_rpy_rad = spread_draw(rest.euler_rpy_rad, c.start_attitude_spread_rad, rng);
  // Yaw wraps to (-pi, pi], the range the vehicle reports.
  drawn.euler_rpy_rad[2] = std::remainder(drawn.euler_rpy_rad[2], 2.0 * kPi);
  drawn.velocity_body_mps =
      spread_draw(Eigen::Vector3d::Zero(), c.start_velocity_max_body_mps, rng);
  drawn.angular_rate_body_rad_s =
      spread_draw(Eigen::Vector3d::Zero(), c.start_rate_max_body_rad_s, rng);
  return random ? drawn : rest;
}

void apply_vehicle(const VehicleFacts& vehicle, TaskConfig& task) {
  task.num_thrusters = vehicle.num_thrusters();
  task.max_thrust_n = vehicle.max_thrust_n();
  task.control_step_s = vehicle.control_step_s;
  task.thruster_dynamics = vehicle.thruster_dynamics;
  task.thruster_wrench = vehicle.thruster_wrench;
}

StateLayout infer_layout(int input_dim, int num_thrusters) {
  std::string expected;
  for (StateLayout layout :
       {StateLayout::kPaper, StateLayout::kExtended, StateLayout::kExtendedThrust}) {
    TaskConfig sized;
    sized.layout = layout;
    sized.num_thrusters = num_thrusters;
    if (input_dim == sized.state_dim()) return layout;
    expected += (expected.empty()                         ? ""
                 : layout == StateLayout::kExtendedThrust ? " or "
                                                          : ", ") +
                std::to_string(sized.state_dim()) + " (" + to_string(layout) + ")";
  }
  throw std::invalid_argument("a policy with " + std::to_string(input_dim) +
                              " inputs fits no state layout for " + std::to_string(num_thrusters) +
                              " thrusters: expected " + expected);
}

}  // namespace auvrl::task
