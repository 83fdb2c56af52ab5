// Thruster fault accommodation for a policy that drives: find a weak or dead thruster from what
// it delivers and have the healthy ones make up the body wrench it fails to deliver.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <vector>

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
/// falls below weak_below is weak until reset(), its share s_i of a command the estimate (kept
/// up to date); below dead_below it is dead, s_i = 0. The policy's commands u (N) become
///   u'_i = u_i + d_i (healthy),  u_i (weak),  0 (dead),  where
///   (H B'B H + lambda I) d = H B'B ((1 - s) o u),
/// with B the thrusters' wrench matrix, H = diag(1 for a healthy thruster, 0 otherwise), o the
/// element-wise product and lambda = damping * trace(B'B) / n: the healthy thrusters make up
/// the wrench that the weak and dead ones fail to deliver, as far as the damping lets them (the
/// least-squares solution of B_h d_h = B (1 - s) o u, damped). With every thruster healthy
/// u' = u exactly. Commands are clamped to [-1, 1] again. A step allocates nothing (a vehicle's
/// control loop).
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
  bool dead(int i) const { return condition_[i] == Condition::kDead; }
  /// Whether thruster i (0-based) counts as weak (not dead).
  bool weak(int i) const { return condition_[i] == Condition::kWeak; }
  // The constants it runs with (the C export writes them out).
  const Eigen::MatrixXd& wrench_gram() const { return wrench_gram_; }  ///< B'B, n x n
  double damping() const { return damping_; }                          ///< lambda
  double estimate_gain() const { return estimate_gain_; }  ///< the estimate's weight per step
  double lag_blend() const { return lag_blend_; }          ///< the replica's lag per step
  double slew_step_n() const { return slew_step_n_; }      ///< the replica's largest step, N

 private:
  enum class Condition { kHealthy, kWeak, kDead };
  /// Updates the efficiency estimates; true if a thruster was found weak or dead this step.
  bool estimate(const Eigen::Ref<const StateVector>& state);
  /// Marks thruster i weak or dead as its estimate says; true if its condition changed.
  bool classify(int i);
  /// The damped least-squares system for the thrusters now healthy, factorised (it changes
  /// only when one more is found weak or dead).
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
  std::vector<Condition> condition_;
  Eigen::VectorXd healthy_;              ///< H's diagonal
  bool any_faulty_ = false;              ///< some thruster is weak or dead
  Eigen::MatrixXd system_;               ///< H B'B H + lambda I
  Eigen::LDLT<Eigen::MatrixXd> solver_;  ///< its factorisation
  // Scratch, sized once: a step allocates nothing.
  Eigen::VectorXd previous_command_, realised_n_, command_, shortfall_, rhs_, makeup_;
};

}  // namespace auvrl::task
