#include "agent/pid_controller.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace auvrl::agent {

namespace {

constexpr double kPi = 3.14159265358979323846;

double wrap_angle(double a) {
  a = std::fmod(a + kPi, 2.0 * kPi);
  if (a < 0) a += 2.0 * kPi;
  return a - kPi;
}

double clamp_abs(double v, double limit) { return std::clamp(v, -limit, limit); }

}  // namespace

PidController::PidController(const sim::VehicleModel& model, PidGains gains)
    : gains_(gains),
      num_thrusters_(model.num_thrusters()),
      max_thrust_n_(model.thruster_dynamics.max_thrust_n),
      control_step_s_(model.control_step_s),
      net_weight_n_(model.weight_n - model.buoyancy_n) {
  check_pid_gains(gains_);
  if (num_thrusters_ < 1 || !(max_thrust_n_ > 0) || !(control_step_s_ > 0)) {
    throw std::invalid_argument("PID controller: vehicle model '" + model.name +
                                "' has no thrusters, no maximum thrust or no control step");
  }
  mass_eff_ = model.mass_total.diagonal();
  drag_quad_ = model.quadratic_damping.cwiseAbs();

  // Only the DOF the thrusters drive independently (the model's controlled_axes) are asked
  // for: Nessie VII's roll row is almost zero (lateral thrusters 5 cm off the roll axis);
  // inverting it would ask for hundreds of newtons to make a roll moment the restoring moment
  // provides anyway. The other rows are dropped; the pseudo-inverse of the rest (a complete
  // orthogonal decomposition, once) is the minimum-norm thrust for the controlled DOF.
  axes_ = model.controlled_axes;
  for (int axis : {sim::kSurge, sim::kHeave, sim::kYaw}) {
    if (!axes_[static_cast<std::size_t>(axis)]) {
      throw std::invalid_argument("PID controller: vehicle model '" + model.name +
                                  "' does not control " + sim::kAxisNames[axis] +
                                  " (its controlled_axes); way-points need surge, heave and yaw");
    }
  }
  Eigen::MatrixXd b = model.allocation;
  for (Eigen::Index row = 0; row < 6; ++row) {
    if (!axes_[static_cast<std::size_t>(row)]) b.row(row).setZero();
  }
  pinv_ = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(b).pseudoInverse();
  // Every DOF the controller drives must be reachable: B pinv must reproduce it.
  const Eigen::MatrixXd reproduced = b * pinv_;
  for (int axis = 0; axis < 6; ++axis) {
    if (!axes_[static_cast<std::size_t>(axis)]) continue;
    Eigen::Matrix<double, 6, 1> unit = Eigen::Matrix<double, 6, 1>::Zero();
    unit[axis] = 1.0;
    if ((reproduced * unit - unit).norm() > 1e-9) {
      throw std::invalid_argument("PID controller: vehicle model '" + model.name +
                                  "' has no independent control authority in " +
                                  sim::kAxisNames[axis]);
    }
  }
  reset();
}

void PidController::reset() {
  heading_set_ = false;
  heading_ref_rad_ = 0.0;
  position_integral_ned_.setZero();
  yaw_integral_ = 0.0;
  tau_.setZero();
}

Eigen::VectorXd PidController::allocate(const Eigen::Matrix<double, 6, 1>& tau) const {
  Eigen::Matrix<double, 6, 1> primary = tau, secondary = Eigen::Matrix<double, 6, 1>::Zero();
  secondary[0] = tau[0];
  secondary[1] = tau[1];
  primary[0] = primary[1] = 0.0;
  Eigen::VectorXd f_primary = pinv_ * primary;
  const Eigen::VectorXd f_secondary = pinv_ * secondary;
  // Heave, roll, pitch and yaw first: if they alone exceed a thruster's limit, scale them together
  // (keeps the moment's direction, unlike clipping one thruster).
  const double peak = f_primary.cwiseAbs().maxCoeff();
  if (peak > max_thrust_n_) f_primary *= max_thrust_n_ / peak;
  // Then the largest share alpha in [0, 1] of surge/sway that keeps every thruster in range.
  double alpha = 1.0;
  for (Eigen::Index i = 0; i < f_primary.size(); ++i) {
    const double fs = f_secondary[i];
    if (std::abs(fs) < 1e-12) continue;
    const double room = (fs > 0 ? max_thrust_n_ : -max_thrust_n_) - f_primary[i];
    alpha = std::min(alpha, std::max(0.0, room / fs));
  }
  return f_primary + alpha * f_secondary;
}

double PidController::update_heading(const task::Observation& obs, const Eigen::Vector3d& error_ned,
                                     double horizontal_m) {
  const PidGains& g = gains_;
  const double yaw = obs.euler_rpy_rad[2];
  // Heading reference: the bearing to the goal while it is well defined, else frozen.
  if (!heading_set_) {
    heading_ref_rad_ = yaw;
    heading_set_ = true;
  }
  if (horizontal_m > g.heading_hold_radius_m) {
    heading_ref_rad_ = std::atan2(error_ned[1], error_ned[0]);
    // Without sway the heading alone takes lateral errors; near the goal the tail may point
    // at it instead of the nose (surge backs up there), whichever needs the smaller turn.
    if (!axes_[sim::kSway] && horizontal_m <= g.reverse_radius_m &&
        std::abs(wrap_angle(heading_ref_rad_ - yaw)) > kPi / 2.0) {
      heading_ref_rad_ = wrap_angle(heading_ref_rad_ + kPi);
    }
  }
  return wrap_angle(heading_ref_rad_ - yaw);
}

void PidController::translation_forces(const task::Observation& obs,
                                       const Eigen::Matrix3d& r_body_to_ned,
                                       const Eigen::Vector3d& error_ned, double horizontal_m,
                                       double facing) {
  const PidGains& g = gains_;
  const double dt = control_step_s_;
  const Eigen::Vector3d error_body = r_body_to_ned.transpose() * error_ned;
  const double distance_m = error_ned.norm();

  // Outer loops: velocity references in the body frame (no sway without sway authority).
  double u_ref = clamp_abs(g.surge_position_gain_per_s * error_body[0], g.surge_speed_max_mps);
  if (horizontal_m > g.reverse_radius_m) u_ref = std::max(0.0, u_ref) * facing * facing;
  const double v_ref = axes_[sim::kSway] ? clamp_abs(g.sway_position_gain_per_s * error_body[1],
                                                     g.sway_speed_max_mps)
                                         : 0.0;
  const double w_ref =
      clamp_abs(g.heave_position_gain_per_s * error_body[2], g.heave_speed_max_mps);
  const Eigen::Vector3d vel_ref(u_ref, v_ref, w_ref);

  // Position integral near the goal only (anti-windup: cleared when far, clamped as force).
  if (distance_m < g.integral_radius_m) {
    position_integral_ned_ += error_ned * dt;
  } else {
    position_integral_ned_.setZero();
  }
  const Eigen::Vector3d integral_body = r_body_to_ned.transpose() * position_integral_ned_;

  // Restoring force of the net buoyancy in the body frame, cancelled by feed-forward.
  const Eigen::Vector3d down_body = r_body_to_ned.transpose() * Eigen::Vector3d::UnitZ();

  for (int i = 0; i < 3; ++i) {
    const double v = obs.velocity_body_mps[i];
    const double feedback = mass_eff_[i] * g.velocity_gain_per_s * (vel_ref[i] - v);
    const double drag_ff = drag_quad_[i] * vel_ref[i] * std::abs(vel_ref[i]);
    const double integral = clamp_abs(
        mass_eff_[i] * g.position_integral_gain_per_s2 * integral_body[i], g.integral_force_max_n);
    tau_[i] = feedback + drag_ff + integral - net_weight_n_ * down_body[i];
  }
  if (!axes_[sim::kSway]) tau_[1] = 0.0;
}

double PidController::yaw_moment(const task::Observation& obs, double heading_error) {
  const PidGains& g = gains_;
  // Heading error -> yaw-rate reference -> moment, with an integral for a steady moment (the
  // fault's asymmetric surge thrust).
  const double r_ref = clamp_abs(g.yaw_gain_per_s * heading_error, g.yaw_rate_max_rad_s);
  const double r = obs.angular_rate_body_rad_s[2];
  // Integrate only once the heading is nearly acquired: a half turn would otherwise wind it
  // up and overshoot. Stop at the clamp (anti-windup).
  if (std::abs(heading_error) < g.yaw_integral_window_rad) {
    const double next = yaw_integral_ + heading_error * control_step_s_;
    if (std::abs(mass_eff_[5] * g.yaw_integral_gain_per_s2 * next) <=
        g.yaw_integral_moment_max_nm) {
      yaw_integral_ = next;
    }
  }
  return mass_eff_[5] * g.yaw_rate_gain_per_s * (r_ref - r) +
         drag_quad_[5] * r_ref * std::abs(r_ref) +
         clamp_abs(mass_eff_[5] * g.yaw_integral_gain_per_s2 * yaw_integral_,
                   g.yaw_integral_moment_max_nm);
}

double PidController::pitch_moment(const task::Observation& obs, const Eigen::Vector3d& error_ned,
                                   double horizontal_m, double facing) const {
  const PidGains& g = gains_;
  // Nose toward the goal while driving to it far away, so that surge helps the slow heave
  // (Nessie VII's full heave is only 0.55 m/s); faded out between two and one heading-hold
  // radii so the vehicle arrives and holds level.
  double pitch_ref = 0.0;
  if (g.heading_hold_radius_m > 0) {
    const double fade =
        std::clamp(horizontal_m / g.heading_hold_radius_m - 1.0, 0.0, 1.0) * facing * facing;
    pitch_ref = fade * clamp_abs(-std::atan2(error_ned[2], horizontal_m), g.pitch_max_rad);
  }
  const double q_ref = g.pitch_gain_per_s * (pitch_ref - obs.euler_rpy_rad[1]);
  return mass_eff_[4] * g.pitch_rate_gain_per_s * (q_ref - obs.angular_rate_body_rad_s[1]);
}

double PidController::roll_moment(const task::Observation& obs) const {
  const PidGains& g = gains_;
  if (!(g.roll_rate_gain_per_s > 0)) return 0.0;  // off: exactly no roll moment
  const double p_ref = g.roll_gain_per_s * (0.0 - obs.euler_rpy_rad[0]);
  return mass_eff_[3] * g.roll_rate_gain_per_s * (p_ref - obs.angular_rate_body_rad_s[0]);
}

void PidController::act(const task::Observation& obs, const Eigen::Vector3d& goal_ned_m,
                        const task::StateVector& /*state*/, task::ActionVector& action) {
  const Eigen::Matrix3d r_body_to_ned = task::body_to_ned(obs.euler_rpy_rad);
  const Eigen::Vector3d error_ned = goal_ned_m - obs.position_ned_m;
  const double horizontal_m = error_ned.head<2>().norm();
  const double heading_error = update_heading(obs, error_ned, horizontal_m);
  const double facing = std::max(0.0, std::cos(heading_error));

  tau_.setZero();
  translation_forces(obs, r_body_to_ned, error_ned, horizontal_m, facing);
  tau_[5] = yaw_moment(obs, heading_error);
  // Pitch and roll only where the thrusters drive them (else the vehicle's own stability).
  tau_[4] = axes_[sim::kPitch] ? pitch_moment(obs, error_ned, horizontal_m, facing) : 0.0;
  tau_[3] = axes_[sim::kRoll] ? roll_moment(obs) : 0.0;

  const Eigen::VectorXd thrust_n = allocate(tau_);
  action.resize(num_thrusters_);
  for (int i = 0; i < num_thrusters_; ++i) {
    action[i] = static_cast<float>(std::clamp(thrust_n[i] / max_thrust_n_, -1.0, 1.0));
  }
}

}  // namespace auvrl::agent
