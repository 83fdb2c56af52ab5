// Thruster fault accommodation for a policy that drives: find a dead thruster from what it
// delivers, stop commanding it and give its share of the body wrench to the others.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "common/task/task.hpp"

namespace auvrl::task {

/// Whether a policy driving on this task has a fault accommodation: it is on and the layout
/// carries the realised thrust (extended_thrust; the others drive without it).
bool has_fault_accommodation(const TaskConfig& task);

/// Task::FaultAccommodationSettings at work, one control step at a time. Each step it reads
/// from the observation vector (extended_thrust layout) the commands of the step before and
/// the thrust each thruster realised; a replica of a healthy thruster (the vehicle's delay, lag
/// and slew, ThrusterDynamics) says what each should have realised, and an exponentially
/// weighted least-squares ratio of the two estimates its efficiency. A thruster whose estimate
/// falls below dead_below is dead until reset(): the policy's commands u (N) become u' solving
///   (E B'B E + lambda I) u' = E B'B u + lambda E u,
/// with B the thrusters' wrench matrix, E = diag(0 for a dead thruster, 1 otherwise) and
/// lambda = damping * trace(B'B) / n. With every thruster healthy u' = u exactly; a dead one
/// gets 0; the others take up its wrench as far as the damping lets them. Commands are clamped
/// to [-1, 1] again. A step allocates nothing (a vehicle's control loop).
class ThrusterFaultAccommodation {
 public:
  /// The estimate moves only while a healthy thruster would deliver at least this much (RMS
  /// over the estimate's window), N: below it a ratio says nothing.
  static constexpr double kMinReplicaThrustN = 2.0;

  /// Throws std::invalid_argument if the settings are off or unusable, the layout does not
  /// carry the realised thrust, or the task has no thruster wrenches (task::apply_vehicle).
  explicit ThrusterFaultAccommodation(const TaskConfig& task);
  /// Every thruster healthy, the replica at rest (the start of an episode or mission).
  void reset();
  /// One control step: state is the observation vector the policy was given, action its
  /// normalised commands, rewritten in place.
  void apply(const Eigen::Ref<const StateVector>& state, ActionVector& action);
  /// Each thruster's estimated efficiency (1 until enough thrust was asked of it).
  const Eigen::VectorXd& efficiency_estimate() const { return efficiency_; }
  /// Whether thruster i (0-based) counts as dead.
  bool dead(int i) const { return keep_[i] == 0.0; }
  // The constants it runs with (the C export writes them out).
  const Eigen::MatrixXd& wrench_gram() const { return wrench_gram_; }  ///< B'B, n x n
  double damping() const { return damping_; }                          ///< lambda
  double estimate_gain() const { return estimate_gain_; }  ///< the estimate's weight per step
  double lag_blend() const { return lag_blend_; }          ///< the replica's lag per step
  double slew_step_n() const { return slew_step_n_; }      ///< the replica's largest step, N

 private:
  /// Updates the efficiency estimates; true if a thruster was found dead this step.
  bool estimate(const Eigen::Ref<const StateVector>& state);
  /// The damped least-squares system for the thrusters now dead, factorised (it changes only
  /// when one more dies).
  void factorise();
  void redistribute(ActionVector& action);

  TaskConfig task_;
  Eigen::MatrixXd wrench_gram_;                    ///< B'B, n x n
  double damping_;                                 ///< lambda
  double estimate_gain_;                           ///< 1 - exp(-dt / time constant)
  double lag_blend_;                               ///< the replica's lag per step (1 without lag)
  double slew_step_n_;                             ///< the replica's largest change per step, N
  Eigen::VectorXd replica_delayed_n_, replica_n_;  ///< a healthy thruster's command and thrust
  Eigen::VectorXd moment_realised_replica_, moment_replica_squared_;
  Eigen::VectorXd efficiency_;
  Eigen::VectorXd keep_;                 ///< E: 0 for a thruster found dead, 1 otherwise
  bool any_dead_ = false;                ///< some entry of keep_ is 0
  Eigen::MatrixXd system_;               ///< E B'B E + lambda I
  Eigen::LDLT<Eigen::MatrixXd> solver_;  ///< its factorisation
  // Scratch, sized once: a step allocates nothing.
  Eigen::VectorXd previous_command_, realised_n_, command_, rhs_, spread_;
};

}  // namespace auvrl::task
