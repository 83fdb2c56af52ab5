// The mutable state of one simulated vehicle (MuJoCo's mjData) and the step function that
// advances it by one control step: step(model, state, thrust_command_n).
#pragma once

#include <cstdint>
#include <random>

#include "sim/vehicle_model.hpp"

namespace auvrl::sim {

/// Water current: a constant part plus a first-order Gauss-Markov speed (Fossen 2011, 8.3),
/// all in the NED frame. The vehicle's damping and added mass act on the relative velocity.
struct CurrentSettings {
  Vector3 constant_velocity_ned_mps = Vector3::Zero();
  double gauss_markov_speed_mean_mps = 0.0;       ///< mean of the varying speed
  double gauss_markov_speed_sigma_mps = 0.0;      ///< white-noise intensity driving the speed
  double gauss_markov_time_constant_s = 60.0;     ///< 1/mu of the first-order process
  double gauss_markov_direction_rad = 0.0;        ///< heading of the varying part, NED
  double gauss_markov_direction_sigma_rad = 0.0;  ///< Gaussian perturbation of that heading
};

/// Gaussian noise on what the vehicle reports (not on the true state).
struct SensorNoise {
  double position_sigma_m = 0.0;
  double attitude_sigma_rad = 0.0;
  double linear_velocity_sigma_mps = 0.0;
  double angular_velocity_sigma_rad_s = 0.0;
};

/// Everything a reset sets: pose, velocity, faults, current, noise and the seed.
struct ResetSettings {
  Vector6 eta = Vector6::Zero();       ///< [x y z (NED, m) phi theta psi (ZYX Euler, rad)]
  Vector6 nu = Vector6::Zero();        ///< [u v w (body, m/s) p q r (body, rad/s)]
  ThrusterVector thruster_efficiency;  ///< in [0, 1]; empty = all 1
  CurrentSettings current;
  SensorNoise sensor_noise;
  std::uint64_t seed = 1;
};

/// Why a state is no longer valid.
enum class StateStatus : int { kOk = 0, kNonFinite = 1, kSpeedLimit = 2, kPositionLimit = 3 };

/// The mutable state of one vehicle. Copyable; holds its own random stream.
struct VehicleState {
  double time_s = 0.0;
  std::int64_t step_count = 0;
  Vector6 eta = Vector6::Zero();       ///< true pose, NED / ZYX Euler
  Vector6 nu = Vector6::Zero();        ///< true body velocity
  ThrusterVector thrust_command_n;     ///< last command received (after saturation)
  ThrusterVector thrust_delayed_n;     ///< command waiting out the one-sample delay
  ThrusterVector thrust_filtered_n;    ///< thruster output after lag and slew, before efficiency
  ThrusterVector thrust_realised_n;    ///< force each thruster produces now (after efficiency)
  ThrusterVector thruster_efficiency;  ///< in [0, 1], 1 = healthy
  Vector3 current_velocity_ned_mps = Vector3::Zero();  ///< water velocity now
  double gauss_markov_speed_mps = 0.0;
  CurrentSettings current;
  SensorNoise sensor_noise;
  StateStatus status = StateStatus::kOk;
  std::mt19937_64 rng;
};

/// What the vehicle reports: the state plus sensor noise, never the hidden parts.
struct Measurement {
  double time_s = 0.0;
  Vector6 eta = Vector6::Zero();
  Vector6 nu = Vector6::Zero();
  ThrusterVector thrust_realised_n;
  StateStatus status = StateStatus::kOk;
};

/// A fresh state from reset settings; throws std::invalid_argument on a wrong-size or
/// out-of-range efficiency vector or non-finite values (the message names the field). Euler
/// angles are normalised; a state that starts beyond the blow-up limits gets its status at once.
VehicleState make_state(const VehicleModel& model, const ResetSettings& reset);

/// Sets thruster efficiencies on a live vehicle (fault injection); same checks as make_state.
void set_thruster_efficiency(const VehicleModel& model, VehicleState& state,
                             const ThrusterVector& efficiency);

/// Sets the constant part of the water current on a live vehicle (NED, m/s), from the next step
/// on; the varying Gauss-Markov part is kept. Throws std::invalid_argument on a non-finite value.
void set_constant_current(VehicleState& state, const Vector3& current_ned_mps);

/// Advances the state by one control step holding thrust_command_n (size num_thrusters, N).
/// Commands are saturated; thruster delay, lag, slew and efficiency applied; current updated;
/// the rigid body integrated with the model's integrator (attitude carried as a quaternion
/// inside the step, so pitch through +-90 deg integrates cleanly; eta holds ZYX Euler angles
/// with phi, psi in (-pi, pi], theta in [-pi/2, pi/2]). If the result is non-finite or beyond
/// the blow-up limits (a non-finite command counts as kNonFinite), only status changes and the
/// state keeps its last valid values; a state whose status is not kOk is left unchanged.
/// Throws std::invalid_argument on a command of the wrong size. Never allocates.
void step(const VehicleModel& model, VehicleState& state, const ThrusterVector& thrust_command_n);

/// Same as step but the commanded forces act at once (saturation only): --ideal-thrusters.
/// Thruster efficiency still applies: a fault is the thruster's, not its dynamics'.
void step_ideal_thrusters(const VehicleModel& model, VehicleState& state,
                          const ThrusterVector& thrust_command_n);

/// Time derivative of [eta; nu] for given body forces tau (thrusters) and water velocity:
/// the Fossen equations with Euler-angle kinematics (singular at theta = +-90 deg). Same
/// dynamics as step(). Exposed for tests (equilibria, finite differences).
Eigen::Matrix<double, 12, 1> state_derivative(const VehicleModel& model, const Vector6& eta,
                                              const Vector6& nu, const Vector6& tau_thrusters,
                                              const Vector3& current_ned_mps);

/// Restoring forces g(eta) (Fossen 2011, eq. 4.6), body frame.
Vector6 restoring_forces(const VehicleModel& model, const Vector6& eta);

/// The vehicle's report of its state, with the configured sensor noise drawn from state.rng
/// (a zero sigma draws nothing).
Measurement measure(const VehicleModel& model, VehicleState& state);

}  // namespace auvrl::sim
