// The gains of the PID way-point controller, and where a vehicle's own gains live: in a YAML
// file beside its vehicle file (config/vehicles/X.yaml -> config/vehicles/X.pid.yaml), read
// through a config::Table so that a bad key or value names the file, the key and the line.
#pragma once

#include <string>

namespace auvrl::config {
template <class T>
class Table;
}  // namespace auvrl::config

namespace auvrl::sim {
struct VehicleModel;
}  // namespace auvrl::sim

namespace auvrl::agent {

/// Gains and limits of PidController (agent/pid_controller.hpp). Outer loops turn a position or
/// angle error into a velocity or rate reference (gain in 1/s, reference saturated); inner loops
/// turn the velocity error into a force or moment, F = m_eff * gain * (v_ref - v) plus a
/// feed-forward of the model's quadratic drag at v_ref, so that every inner gain is a bandwidth in
/// 1/s whatever the axis' mass (m_eff: the diagonal of M_RB + M_A).
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
/// seeds 2, 3 and 4 still reach 100/100 with the same times and hold errors. These defaults
/// are what a vehicle gets without a gains file; `auvrl tune-pid` (tuning/pid_tuning.hpp)
/// tunes them for another vehicle into the file beside its vehicle file (pid_gains_for).
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

  // Pitch (only on vehicles whose thrusters drive it: sim::VehicleModel::controlled_axes):
  // the nose toward the goal while driving to it (surge then helps the slow heave), faded out
  // between two and one heading-hold radii so that the vehicle arrives and holds level.
  double pitch_max_rad = 0.5;          ///< at most this nose up/down, rad
  double pitch_gain_per_s = 1.2;       ///< q_ref = gain * (theta_ref - theta)
  double pitch_rate_gain_per_s = 1.4;  ///< inner pitch-rate loop; 3 limit-cycles

  // Roll (only on vehicles whose thrusters drive it), held level: p_ref = gain * (0 - phi),
  // K = I_eff * rate gain * (p_ref - p). Off (0) by default: Nessie VII has no roll authority
  // (the CG 6 cm below the CB keeps it level), and the defaults must not change how a vehicle
  // with roll authority behaves without its own gains file. A vehicle whose CB sits barely
  // above its CG (BlueROV2 Heavy: 1 cm) needs it once a thruster is lost: the unbalanced
  // horizontal thrusters, 8.5 cm below the CG, then roll it over within a second.
  double roll_gain_per_s = 0.0;       ///< p_ref = gain * (0 - phi); 0: no attitude loop
  double roll_rate_gain_per_s = 0.0;  ///< inner roll-rate loop; 0: no roll loop at all
};

/// The keys of a gains file: every PidGains member under its own name, each >= 0.
const config::Table<PidGains>& pid_gains_table();

/// Throws std::invalid_argument naming the first gain that is negative or not finite.
void check_pid_gains(const PidGains& gains);

/// The gains file of a vehicle file: its sibling with ".pid.yaml" in place of ".yaml" (or
/// ".yml"); any other name gets ".pid.yaml" appended.
std::string pid_gains_path(const std::string& vehicle_file);

/// Reads a gains file. Keys are pid_gains_table()'s; a key left out keeps its compiled default.
/// Throws config::ConfigError naming the file, the key and the line (unknown key, wrong type,
/// negative or non-finite gain) or the file alone (missing, not YAML).
PidGains read_pid_gains_file(const std::string& path);

/// The text of a gains file: `header` (its lines as YAML comments), then one `key: value` line
/// per gain with its unit and doc as a comment. Values are written in the shortest form that
/// reads back to the same double, so that a file reproduces the gains exactly.
std::string pid_gains_text(const PidGains& gains, const std::string& header);

/// Writes pid_gains_text() to path; throws std::runtime_error naming the path on failure.
void write_pid_gains_file(const std::string& path, const PidGains& gains,
                          const std::string& header);

/// A vehicle's PID gains and where they came from.
struct VehiclePidGains {
  PidGains gains;
  std::string file;        ///< the gains file looked for ("" for a model built in code)
  bool from_file = false;  ///< false: no such file, the compiled defaults
};

/// The gains for a model: read from pid_gains_path(model.source_file) when that file exists,
/// else the compiled defaults (from_file false; telling the user is the caller's business).
/// A file that exists but cannot be used throws config::ConfigError.
VehiclePidGains pid_gains_for(const sim::VehicleModel& model);

}  // namespace auvrl::agent
