#include "common/task/fault_accommodation.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace auvrl::task {

bool has_fault_accommodation(const TaskConfig& task) {
  return task.fault_accommodation.enabled && task.layout == StateLayout::kExtendedThrust;
}

ThrusterFaultAccommodation::ThrusterFaultAccommodation(const TaskConfig& task) : task_(task) {
  const FaultAccommodationSettings& s = task.fault_accommodation;
  if (!s.enabled) throw std::invalid_argument("fault accommodation: it is off in the task");
  if (task.layout != StateLayout::kExtendedThrust) {
    throw std::invalid_argument(
        std::string("fault accommodation: the ") + to_string(task.layout) +
        " layout does not carry the realised thrust (extended_thrust does)");
  }
  const int n = task.num_thrusters;
  if (static_cast<int>(task.thruster_wrench.size()) != n) {
    throw std::invalid_argument("fault accommodation: the task has " +
                                std::to_string(task.thruster_wrench.size()) +
                                " thruster wrenches for " + std::to_string(n) +
                                " thrusters (task::apply_vehicle sets them)");
  }
  s.validate();
  if (!(task.control_step_s > 0)) {
    throw std::invalid_argument("fault accommodation: the control step must be > 0");
  }
  Eigen::MatrixXd wrench(6, n);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 6; ++k)
      wrench(k, i) = task.thruster_wrench[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)];
  }
  wrench_gram_ = wrench.transpose() * wrench;
  damping_ = s.damping * wrench_gram_.trace() / n;
  estimate_gain_ = 1.0 - std::exp(-task.control_step_s / s.estimate_time_constant_s);
  const ThrusterDynamics& td = task.thruster_dynamics;
  lag_blend_ = td.lag_enabled ? 1.0 - std::exp(-task.control_step_s / td.lag_time_constant_s) : 1.0;
  slew_step_n_ = td.slew_rate_n_per_s * task.control_step_s;
  reset();
}

void ThrusterFaultAccommodation::reset() {
  const int n = task_.num_thrusters;
  previous_command_ = realised_n_ = command_ = shortfall_ = rhs_ = makeup_ =
      Eigen::VectorXd::Zero(n);
  system_ = Eigen::MatrixXd::Zero(n, n);
  solver_ = Eigen::LDLT<Eigen::MatrixXd>(n);
  replica_delayed_n_ = replica_n_ = Eigen::VectorXd::Zero(n);
  moment_realised_replica_ = moment_replica_squared_ = Eigen::VectorXd::Zero(n);
  efficiency_ = healthy_ = Eigen::VectorXd::Ones(n);
  condition_.assign(static_cast<std::size_t>(n), Condition::kHealthy);
  any_faulty_ = false;
}

void ThrusterFaultAccommodation::apply(const Eigen::Ref<const StateVector>& state,
                                       ActionVector& action) {
  if (estimate(state)) factorise();
  if (any_faulty_) redistribute(action);
}

// The replica steps as sim::step treats a command: the one-step delay, the lag toward the
// delayed command, the slew limit. The state's previous action is the command that the
// vehicle took one step ago, its realised thrust the replica's thrust after this update.
bool ThrusterFaultAccommodation::estimate(const Eigen::Ref<const StateVector>& state) {
  const ThrusterDynamics& td = task_.thruster_dynamics;
  bool changed = false;
  previous_action_from_state(task_, state, previous_command_);
  realised_thrust_from_state(task_, state, realised_n_);
  const double min_squared = kMinReplicaThrustN * kMinReplicaThrustN;
  for (int i = 0; i < task_.num_thrusters; ++i) {
    const double command_n =
        std::clamp(previous_command_[i] * td.max_thrust_n, -td.max_thrust_n, td.max_thrust_n);
    const double target_n = td.delay_enabled ? replica_delayed_n_[i] : command_n;
    double change_n = lag_blend_ * (target_n - replica_n_[i]);
    if (td.slew_enabled) change_n = std::clamp(change_n, -slew_step_n_, slew_step_n_);
    replica_n_[i] += change_n;
    replica_delayed_n_[i] = command_n;
    const double f = replica_n_[i];
    moment_realised_replica_[i] +=
        estimate_gain_ * (realised_n_[i] * f - moment_realised_replica_[i]);
    moment_replica_squared_[i] += estimate_gain_ * (f * f - moment_replica_squared_[i]);
    if (moment_replica_squared_[i] >= min_squared) {
      efficiency_[i] =
          std::clamp(moment_realised_replica_[i] / moment_replica_squared_[i], 0.0, 1.0);
      changed = classify(i) || changed;
    }
  }
  return changed;
}

bool ThrusterFaultAccommodation::classify(int i) {
  const FaultAccommodationSettings& s = task_.fault_accommodation;
  const auto k = static_cast<std::size_t>(i);
  const Condition before = condition_[k];
  if (efficiency_[i] < s.dead_below) {
    condition_[k] = Condition::kDead;
  } else if (before == Condition::kHealthy && efficiency_[i] < s.weak_below) {
    condition_[k] = Condition::kWeak;
  }
  return condition_[k] != before;
}

void ThrusterFaultAccommodation::factorise() {
  any_faulty_ = true;
  for (int i = 0; i < task_.num_thrusters; ++i) {
    healthy_[i] = condition_[static_cast<std::size_t>(i)] == Condition::kHealthy ? 1.0 : 0.0;
  }
  system_.noalias() = healthy_.asDiagonal() * wrench_gram_ * healthy_.asDiagonal();
  system_.diagonal().array() += damping_;
  solver_.compute(system_);
}

void ThrusterFaultAccommodation::redistribute(ActionVector& action) {
  command_ = action.cast<double>();  // normalised: the scale cancels
  // Each thruster's share s of its command: 1 healthy, its estimate when weak, 0 dead.
  for (int i = 0; i < task_.num_thrusters; ++i) {
    const Condition c = condition_[static_cast<std::size_t>(i)];
    const double share = c == Condition::kHealthy ? 1.0
                         : c == Condition::kWeak  ? efficiency_[i]
                                                  : 0.0;
    shortfall_[i] = (1.0 - share) * command_[i];
  }
  rhs_.noalias() = wrench_gram_ * shortfall_;
  rhs_ = healthy_.cwiseProduct(rhs_);
  makeup_ = solver_.solve(rhs_);
  for (int i = 0; i < task_.num_thrusters; ++i) {
    const Condition c = condition_[static_cast<std::size_t>(i)];
    const double command = c == Condition::kDead      ? 0.0
                           : c == Condition::kHealthy ? command_[i] + makeup_[i]
                                                      : command_[i];
    action[i] = static_cast<float>(std::clamp(command, -1.0, 1.0));
  }
}

}  // namespace auvrl::task
