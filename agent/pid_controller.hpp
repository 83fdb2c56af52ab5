// The classical baseline the learned policy must beat: a cascaded PID way-point controller on
// the same plant, with the same inputs (the vehicle's observation and the goal) and the same
// outputs (six normalised thruster commands) as the policy.
#pragma once

#include <Eigen/Core>
#include <string>

#include "agent/controller.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::agent {

/// Gains and limits of PidController. Outer loops turn a position or angle error into a
/// velocity or rate reference (gain in 1/s, reference saturated); inner loops turn the velocity
/// error into a force or moment, F = m_eff * gain * (v_ref - v) plus a feed-forward of the
/// model's quadratic drag at v_ref, so that every inner gain is a bandwidth in 1/s whatever the
/// axis' mass (m_eff: the diagonal of M_RB + M_A).
///
/// How the defaults were tuned (once, config/vehicles/nessie7.yaml): a first hand-set version
/// (inner bandwidths 2-3 1/s) reached every goal but then limit-cycled with the thrusters
/// slamming between +-39 N and the pitch swinging +-0.3 rad: the thrusters ramp at only
/// 21.6 N/s and lag 0.29 s plus one 0.1 s sample, which bounds every inner loop's bandwidth
/// to about 1.5 1/s. Then a random local search (3 gains perturbed at a time, kept if better)
/// minimised, summed over test1, test2, fault, current and the 100-goal suite (seed 1): mean
/// time to reach + 20 x mean hold error + 2 x worst distance after reaching + 500 x missed
/// fraction + 0.02 x thrust energy. The values below are that optimum rounded; every gain
/// moved by +-25 % changes the sum by at most 13 % (most by under 2 %), and suites drawn with
/// seeds 2, 3 and 4 still reach 100/100 with the same times and hold errors.
struct PidGains {
  // Translation (body frame).
  /// u_ref = gain * goal error along body x: braking starts about 3 m out, early enough for
  /// thrusters that need 3.6 s to swing from full ahead to full astern.
  double surge_position_gain_per_s = 0.5;
  /// Deliberately above the 1.57 m/s full-thrust speed: far from the goal the loop asks for
  /// full surge and the thrusters' limit (the allocation's headroom) is the only cap; lower
  /// values (1.5-1.6) cost a second on test1.
  double surge_speed_max_mps = 2.0;
  double sway_position_gain_per_s = 0.5;   ///< v_ref = gain * lateral error; 0.9+ oscillates
  double sway_speed_max_mps = 0.3;         ///< sway only trims lateral errors
  double heave_position_gain_per_s = 0.6;  ///< w_ref = gain * goal error along body z
  double heave_speed_max_mps = 0.55;       ///< the full-thrust heave speed: depth is the
                                           ///< slowest axis, so it may use all it has
  double velocity_gain_per_s = 1.4;        ///< inner loops, all three axes

  /// Position integral (NED, then rotated into the body frame) for what the proportional
  /// loops leave: the water current, the fault's lost thrust, the 1 N of buoyancy the
  /// feed-forward does not quite cancel once pitched. Only integrates within
  /// integral_radius_m of the goal so that the long approach does not wind it up.
  double position_integral_gain_per_s2 = 0.09;  ///< F_i = m_eff * gain * integral(e dt)
  double integral_radius_m = 1.5;
  double integral_force_max_n = 30.0;  ///< anti-windup clamp per axis

  // Yaw: heading toward the goal while it is farther than heading_hold_radius_m horizontally;
  // nearer than that the bearing swings wildly with small position errors, so the heading
  // reference is frozen and the surge and sway loops hold position on their own.
  double yaw_gain_per_s = 0.45;      ///< r_ref = gain * heading error
  double yaw_rate_max_rad_s = 0.7;   ///< a half turn (test 2) in about 5 s
  double yaw_rate_gain_per_s = 3.5;  ///< inner yaw-rate loop (saturates on large errors)
  /// Removes the fault's steady yaw moment (T1 at 10 % makes surge thrust yaw the vehicle).
  double yaw_integral_gain_per_s2 = 0.35;
  double yaw_integral_moment_max_nm = 15.0;
  double yaw_integral_window_rad = 0.3;  ///< integrate only within this heading error
  double heading_hold_radius_m = 1.8;
  /// Far from the goal, surge is scaled by max(0, cos(heading error))^2: the vehicle turns
  /// first and drives only when roughly facing the goal (test 2 starts facing away), while
  /// sway and heave already work on their errors. Within this horizontal distance it may
  /// also back up (station keeping).
  double reverse_radius_m = 1.5;

  // Pitch: the nose toward the goal while driving to it (surge then helps the slow heave),
  // faded out between two and one heading-hold radii so that the vehicle arrives and holds
  // level; roll is not controlled (no authority; the CG 6 cm below the CB makes it stable).
  double pitch_max_rad = 0.5;          ///< at most this nose up/down, rad
  double pitch_gain_per_s = 1.2;       ///< q_ref = gain * (theta_ref - theta)
  double pitch_rate_gain_per_s = 1.4;  ///< inner pitch-rate loop; 3 limit-cycles
};

/// Way-point controller on the plant: heading (yaw) toward the goal, surge on the goal error
/// along the body x axis (slowing down near the goal, so it stops and holds), sway on the
/// lateral error, depth by heave, the nose pitched toward the goal on the way and level on
/// arrival. The desired body force/moment
/// tau = [X Y Z K M N] (N, N m) is allocated to the thrusters through the pseudo-inverse of
/// the model's allocation matrix, with attitude and depth (Z, M, N) served first and surge
/// and sway (X, Y) scaled down to what the thrusters have left, then normalised by the
/// maximum thrust and clipped to [-1, 1].
///
/// It knows the model (masses, drag, allocation, maximum thrust) but not faults or currents:
/// those it must reject by feedback, as the learned policy must.
class PidController final : public Controller {
 public:
  /// Throws std::invalid_argument if the model has no control authority in surge, sway,
  /// heave, pitch or yaw, or a gain is negative or non-finite.
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
  PidGains gains_;
  int num_thrusters_;
  double max_thrust_n_;
  double control_step_s_;
  Eigen::Matrix<double, 6, 1> mass_eff_;   ///< diagonal of M = M_RB + M_A
  Eigen::Matrix<double, 6, 1> drag_quad_;  ///< |quadratic damping|
  double net_weight_n_;                    ///< W - B (negative: positively buoyant)
  Eigen::MatrixXd pinv_;

  // Episode state.
  bool heading_set_ = false;
  double heading_ref_rad_ = 0.0;
  Eigen::Vector3d position_integral_ned_ = Eigen::Vector3d::Zero();  ///< m s
  double yaw_integral_ = 0.0;                                        ///< rad s
  Eigen::Matrix<double, 6, 1> tau_ = Eigen::Matrix<double, 6, 1>::Zero();
};

}  // namespace auvrl::agent
