// The classical baseline the learned policy must beat: a cascaded PID way-point controller on
// the same plant, with the same inputs (the vehicle's observation and the goal) and the same
// outputs (six normalised thruster commands) as the policy.
#pragma once

#include <Eigen/Core>
#include <string>

#include "agent/controller.hpp"
#include "agent/pid_gains.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::agent {

/// Way-point controller on the plant: heading (yaw) toward the goal, surge on the goal error
/// along the body x axis (slowing down near the goal, so it stops and holds), sway on the
/// lateral error, depth by heave, the nose pitched toward the goal on the way and level on
/// arrival, roll held level. It drives only the DOF the vehicle's thrusters drive
/// independently (sim::VehicleModel::controlled_axes): surge, heave and yaw always; sway,
/// pitch and roll where the vehicle has them. Without pitch it asks no pitch moment (no nose
/// toward the goal); without sway it asks no sway force and leaves lateral errors to the
/// heading, which then may also point the tail at a goal behind it within reverse_radius_m;
/// without roll it asks no roll moment. The desired body force/moment
/// tau = [X Y Z K M N] (N, N m) is allocated to the thrusters through the pseudo-inverse of
/// the model's allocation matrix (the rows of the other DOF dropped), with attitude and depth
/// (Z, K, M, N) served first and surge and sway (X, Y) scaled down to what the thrusters have
/// left, then normalised by the maximum thrust and clipped to [-1, 1].
///
/// It knows the model (masses, drag, allocation, maximum thrust) but not faults or currents:
/// those it must reject by feedback, as the learned policy must. Per-vehicle gains:
/// pid_gains_for() (agent/pid_gains.hpp).
class PidController final : public Controller {
 public:
  /// Throws std::invalid_argument if the model's controlled_axes leave out surge, heave or
  /// yaw, if its allocation does not drive every controlled DOF independently, or if a gain is
  /// negative or non-finite.
  explicit PidController(const sim::VehicleModel& model, PidGains gains = PidGains{});

  void reset() override;
  void act(const task::Observation& observation, const Eigen::Vector3d& goal_ned_m,
           const task::StateVector& state, task::ActionVector& action) override;
  std::string name() const override { return "pid"; }

  /// The body force/moment [X Y Z K M N] asked for at the last act() (N, N m).
  const Eigen::Matrix<double, 6, 1>& last_tau() const { return tau_; }
  /// The allocation's pseudo-inverse (n x 6), thrust_n = pinv * tau.
  const Eigen::MatrixXd& allocation_pseudo_inverse() const { return pinv_; }
  const PidGains& gains() const { return gains_; }

  /// Thrusts (N, before normalisation) for tau: attitude/depth first, surge/sway scaled to the
  /// headroom left, each within +-max thrust. Public for tests.
  Eigen::VectorXd allocate(const Eigen::Matrix<double, 6, 1>& tau) const;

 private:
  /// Updates the heading reference (frozen near the goal); returns the heading error, rad.
  double update_heading(const task::Observation& obs, const Eigen::Vector3d& error_ned,
                        double horizontal_m);
  /// tau_[0..2]: surge, sway and heave forces (position -> velocity -> force, integral).
  void translation_forces(const task::Observation& obs, const Eigen::Matrix3d& r_body_to_ned,
                          const Eigen::Vector3d& error_ned, double horizontal_m, double facing);
  /// Yaw moment (heading -> yaw rate -> moment, integral), N m.
  double yaw_moment(const task::Observation& obs, double heading_error);
  /// Pitch moment (nose toward the goal far away, level near it), N m.
  double pitch_moment(const task::Observation& obs, const Eigen::Vector3d& error_ned,
                      double horizontal_m, double facing) const;
  /// Roll moment (held level; 0 while roll_rate_gain_per_s is 0), N m.
  double roll_moment(const task::Observation& obs) const;

  PidGains gains_;
  int num_thrusters_;
  double max_thrust_n_;
  double control_step_s_;
  Eigen::Matrix<double, 6, 1> mass_eff_;   ///< diagonal of M = M_RB + M_A
  Eigen::Matrix<double, 6, 1> drag_quad_;  ///< |quadratic damping|
  double net_weight_n_;                    ///< W - B (negative: positively buoyant)
  Eigen::MatrixXd pinv_;
  sim::AxisSet axes_{};  ///< the DOF driven (the model's controlled_axes)

  // Episode state.
  bool heading_set_ = false;
  double heading_ref_rad_ = 0.0;
  Eigen::Vector3d position_integral_ned_ = Eigen::Vector3d::Zero();  ///< m s
  double yaw_integral_ = 0.0;                                        ///< rad s
  Eigen::Matrix<double, 6, 1> tau_ = Eigen::Matrix<double, 6, 1>::Zero();
};

}  // namespace auvrl::agent
