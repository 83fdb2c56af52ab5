// Fossen 6-DOF vehicle dynamics, thruster response, water current and sensor noise.
//
// Equations (Fossen 2011, Handbook of Marine Craft Hydrodynamics and Motion Control):
//   eta_dot = J(eta) nu                                           (eq. 2.40-2.41, ZYX Euler)
//   M nu_dot + C_RB(nu) nu + C_A(nu_r) nu_r + D(nu_r) nu_r + g(eta) = tau + M_A nu_c_dot
// with nu_r = nu - nu_c, nu_c = [R^T v_c; 0] the water velocity in the body frame, M = M_RB +
// M_A, C_RB in the linear-velocity-independent form of eq. 3.60 (with the CG offset), C_A the
// skew form of M_A (only when the model asks for it), D(nu_r) = -diag(linear) -
// diag(quadratic .* |nu_r|) and g(eta) of eq. 4.6. The M_A nu_c_dot term is what Fossen's
// M_A nu_r_dot leaves over once M nu_dot is taken out: for a current constant in NED,
// nu_c_dot = -omega x v_c,body (it vanishes unless the vehicle turns inside a current).
//
// Integration: within a control step the attitude is carried as a unit quaternion
// (Fossen eq. 2.82-2.86), the same kinematics as J(eta) without the singularity at pitch
// +-90 deg and without trigonometric functions in the inner loop; the Euler angles are read
// back once at the end of the control step. state_derivative() gives the same ODE in Euler
// form (eq. 2.40-2.41); the tests check the two against each other.
#include "sim/dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/random.hpp"

namespace auvrl::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// The inner loop runs 40 times per control step (RK4, 10 substeps): its small helpers are
/// forced inline, which GCC does not do on its own at that call depth.
#define AUVRL_HOT [[gnu::always_inline]] inline

/// Wraps an angle to (-pi, pi].
double wrap_angle(double angle_rad) {
  double a = std::remainder(angle_rad, 2.0 * kPi);
  if (a <= -kPi) a += 2.0 * kPi;
  return a;
}

/// Brings ZYX Euler angles to phi, psi in (-pi, pi] and theta in [-pi/2, pi/2] (the same
/// rotation: (phi, theta, psi) == (phi + pi, pi - theta, psi + pi)).
Vector3 normalised_euler(const Vector3& euler) {
  double phi = euler(0);
  double theta = wrap_angle(euler(1));
  double psi = euler(2);
  if (theta > kPi / 2) {
    theta = kPi - theta;
    phi += kPi;
    psi += kPi;
  } else if (theta < -kPi / 2) {
    theta = -kPi - theta;
    phi += kPi;
    psi += kPi;
  }
  return Vector3(wrap_angle(phi), theta, wrap_angle(psi));
}

/// R_b^n(Theta), Fossen eq. 2.18.
Matrix3 rotation_from_euler(double phi, double theta, double psi) {
  const double cphi = std::cos(phi), sphi = std::sin(phi);
  const double cth = std::cos(theta), sth = std::sin(theta);
  const double cpsi = std::cos(psi), spsi = std::sin(psi);
  Matrix3 r;
  r << cpsi * cth, -spsi * cphi + cpsi * sth * sphi, spsi * sphi + cpsi * cphi * sth,  //
      spsi * cth, cpsi * cphi + sphi * sth * spsi, -cpsi * sphi + sth * spsi * cphi,   //
      -sth, cth * sphi, cth * cphi;
  return r;
}

/// Integrator state, flat: [NED position (3); attitude quaternion w, x, y, z (4); nu (6)].
constexpr int kP = 0, kQ = 3, kNu = 7, kStateSize = 13;
using Motion = double[kStateSize];
/// Row-major rotation matrix R_b^n.
using Rotation = double[3][3];

/// R_b^n(q) = I + 2 w S(e) + 2 S(e)^2, Fossen eq. 2.65. Off the unit sphere (RK4 stages) this
/// is a smooth extension of the rotation, which keeps RK4's order: the exact flow never leaves
/// the sphere. No division, which keeps it off the critical path.
AUVRL_HOT void rotation_from_quaternion(const double* q, Rotation& r) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  r[0][0] = 1.0 - 2.0 * (y * y + z * z);
  r[0][1] = 2.0 * (x * y - w * z);
  r[0][2] = 2.0 * (x * z + w * y);
  r[1][0] = 2.0 * (x * y + w * z);
  r[1][1] = 1.0 - 2.0 * (x * x + z * z);
  r[1][2] = 2.0 * (y * z - w * x);
  r[2][0] = 2.0 * (x * z - w * y);
  r[2][1] = 2.0 * (y * z + w * x);
  r[2][2] = 1.0 - 2.0 * (x * x + y * y);
}

/// q = q_z(psi) * q_y(theta) * q_x(phi) (ZYX), scalar first.
void quaternion_from_euler(const Vector3& euler, double* q) {
  const double cphi = std::cos(0.5 * euler(0)), sphi = std::sin(0.5 * euler(0));
  const double cth = std::cos(0.5 * euler(1)), sth = std::sin(0.5 * euler(1));
  const double cpsi = std::cos(0.5 * euler(2)), spsi = std::sin(0.5 * euler(2));
  q[0] = cphi * cth * cpsi + sphi * sth * spsi;
  q[1] = sphi * cth * cpsi - cphi * sth * spsi;
  q[2] = cphi * sth * cpsi + sphi * cth * spsi;
  q[3] = cphi * cth * spsi - sphi * sth * cpsi;
}

void normalise_quaternion(double* q) {
  const double inverse_norm =
      1.0 / std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (int i = 0; i < 4; ++i) q[i] *= inverse_norm;
}

/// ZYX Euler angles of a unit quaternion (Fossen eq. 2.77-2.79 via the rotation matrix).
Vector3 euler_from_quaternion(const double* q) {
  Rotation r;
  rotation_from_quaternion(q, r);
  const double sin_theta = std::fmax(-1.0, std::fmin(1.0, -r[2][0]));
  return Vector3(wrap_angle(std::atan2(r[2][1], r[2][2])), std::asin(sin_theta),
                 wrap_angle(std::atan2(r[1][0], r[0][0])));
}

AUVRL_HOT void cross(const double* a, const double* b, double* out) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

/// The model's constants laid out flat for the inner loop (plain arrays: small Eigen
/// expressions there were not inlined and cost twice the time), with the inputs held constant
/// over one control step (thruster forces and water velocity).
struct Plant {
  double mass_inverse_columns[6][6];  ///< column j of M^-1 at [j]: the product vectorises
  double inertia_origin[3][3];        ///< I_b = I_g - m S(r_g)^2, about the body origin
  double mass_kg;
  double cog[3];
  double added_mass[6];  ///< diagonal of M_A (finalize_vehicle_model builds M_A diagonal)
  double linear_damping[6];
  double quadratic_damping[6];
  double restoring_arm[3];  ///< W r_g - B r_b
  double net_weight_n;      ///< W - B
  bool added_mass_coriolis;
  double tau_body[6];
  double current_ned[3];
};

Plant make_plant(const VehicleModel& model, const Vector6& tau_body, const Vector3& current_ned) {
  Plant plant;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) plant.mass_inverse_columns[j][i] = model.mass_total_inverse(i, j);
    plant.added_mass[i] = -model.added_mass_derivatives(i);
    plant.linear_damping[i] = model.linear_damping(i);
    plant.quadratic_damping[i] = model.quadratic_damping(i);
    plant.tau_body[i] = tau_body(i);
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) plant.inertia_origin[i][j] = model.mass_rigid_body(3 + i, 3 + j);
    plant.cog[i] = model.cog_body_m(i);
    plant.restoring_arm[i] =
        model.weight_n * model.cog_body_m(i) - model.buoyancy_n * model.cob_body_m(i);
    plant.current_ned[i] = current_ned(i);
  }
  plant.mass_kg = model.mass_kg;
  plant.net_weight_n = model.weight_n - model.buoyancy_n;
  plant.added_mass_coriolis = model.added_mass_coriolis;
  return plant;
}

/// g(eta), eq. 4.6, from the unit "down" vector in the body frame, k_b = R^T e_z (the third
/// row of R) = [-sin(theta), cos(theta) sin(phi), cos(theta) cos(phi)]: g = -[f_g + f_b;
/// r_g x f_g + r_b x f_b] with f_g = W k_b, f_b = -B k_b. The yaw entry comes out with
/// sin(theta), as in Fossen (nessie7.md: the reference code's sin(phi) there is a known
/// mistake).
AUVRL_HOT void restoring(const Plant& plant, const double* down_body, double* g) {
  double moment[3];
  cross(plant.restoring_arm, down_body, moment);
  for (int i = 0; i < 3; ++i) {
    g[i] = -plant.net_weight_n * down_body[i];
    g[3 + i] = -moment[i];
  }
}

/// nu_dot for a given rotation body -> NED: everything except the kinematics.
AUVRL_HOT void accelerate(const Plant& pl, const Rotation& r, const double* nu, double* nu_dot) {
  const double* v = nu;
  const double* omega = nu + 3;
  double current_body[3];  // R^T v_c
  for (int i = 0; i < 3; ++i) {
    current_body[i] =
        r[0][i] * pl.current_ned[0] + r[1][i] * pl.current_ned[1] + r[2][i] * pl.current_ned[2];
  }
  const double nu_r[6] = {v[0] - current_body[0],
                          v[1] - current_body[1],
                          v[2] - current_body[2],
                          omega[0],
                          omega[1],
                          omega[2]};
  double f[6];
  for (int i = 0; i < 6; ++i) f[i] = pl.tau_body[i];

  // C_RB(nu) nu in the form of eq. 3.60, C_RB = [m S(w), -m S(w) S(r_g); m S(r_g) S(w),
  // -S(I_b w)]: rows m (w x v + w x (w x r_g)) and m r_g x (w x v) + w x (I_b w).
  double w_x_v[3], w_x_rg[3], w_x_w_x_rg[3], rg_x_w_x_v[3], ib_w[3], w_x_ib_w[3];
  cross(omega, v, w_x_v);
  cross(omega, pl.cog, w_x_rg);
  cross(omega, w_x_rg, w_x_w_x_rg);
  cross(pl.cog, w_x_v, rg_x_w_x_v);
  for (int i = 0; i < 3; ++i) {
    ib_w[i] = pl.inertia_origin[i][0] * omega[0] + pl.inertia_origin[i][1] * omega[1] +
              pl.inertia_origin[i][2] * omega[2];
  }
  cross(omega, ib_w, w_x_ib_w);
  for (int i = 0; i < 3; ++i) {
    f[i] -= pl.mass_kg * (w_x_v[i] + w_x_w_x_rg[i]);
    f[3 + i] -= pl.mass_kg * rg_x_w_x_v[i] + w_x_ib_w[i];
  }

  // C_A(nu_r) nu_r with C_A = [0, -S(p1); -S(p1), -S(p2)], p = M_A nu_r (Fossen eq. 3.46
  // form): rows w x p1 and v_r x p1 + w x p2 (the Munk moment is v_r x p1).
  if (pl.added_mass_coriolis) {
    double p[6];
    for (int i = 0; i < 6; ++i) p[i] = pl.added_mass[i] * nu_r[i];
    double w_x_p1[3], vr_x_p1[3], w_x_p2[3];
    cross(omega, p, w_x_p1);
    cross(nu_r, p, vr_x_p1);
    cross(omega, p + 3, w_x_p2);
    for (int i = 0; i < 3; ++i) {
      f[i] -= w_x_p1[i];
      f[3 + i] -= vr_x_p1[i] + w_x_p2[i];
    }
  }

  // -D(nu_r) nu_r: the derivatives are <= 0, so these terms oppose the relative motion.
  for (int i = 0; i < 6; ++i) {
    f[i] += (pl.linear_damping[i] + pl.quadratic_damping[i] * std::abs(nu_r[i])) * nu_r[i];
  }

  double g[6];
  restoring(pl, r[2], g);
  for (int i = 0; i < 6; ++i) f[i] -= g[i];

  // + M_A nu_c_dot with nu_c_dot = [-w x v_c,body; 0] (current constant in NED).
  double w_x_c[3];
  cross(omega, current_body, w_x_c);
  for (int i = 0; i < 3; ++i) f[i] -= pl.added_mass[i] * w_x_c[i];

  // nu_dot = M^-1 f as a sum of scaled columns (no horizontal reductions).
  for (int i = 0; i < 6; ++i) nu_dot[i] = pl.mass_inverse_columns[0][i] * f[0];
  for (int j = 1; j < 6; ++j) {
    for (int i = 0; i < 6; ++i) nu_dot[i] += pl.mass_inverse_columns[j][i] * f[j];
  }
}

/// Pose rates: p_dot = R v and q_dot = 1/2 q (x) [0; omega] (Fossen eq. 2.86).
AUVRL_HOT void pose_rates(const Rotation& r, const double* x, double* dx) {
  const double* q = x + kQ;
  const double* nu = x + kNu;
  for (int i = 0; i < 3; ++i) dx[kP + i] = r[i][0] * nu[0] + r[i][1] * nu[1] + r[i][2] * nu[2];
  const double p = nu[3], q_rate = nu[4], r_rate = nu[5];
  dx[kQ + 0] = -0.5 * (q[1] * p + q[2] * q_rate + q[3] * r_rate);
  dx[kQ + 1] = 0.5 * (q[0] * p + q[2] * r_rate - q[3] * q_rate);
  dx[kQ + 2] = 0.5 * (q[0] * q_rate + q[3] * p - q[1] * r_rate);
  dx[kQ + 3] = 0.5 * (q[0] * r_rate + q[1] * q_rate - q[2] * p);
}

/// d/dt of the whole integrator state.
AUVRL_HOT void motion_rates(const Plant& pl, const double* x, double* dx) {
  Rotation r;
  rotation_from_quaternion(x + kQ, r);
  pose_rates(r, x, dx);
  accelerate(pl, r, x + kNu, dx + kNu);
}

AUVRL_HOT void rk4_substep(const Plant& pl, Motion& x, double h) {
  Motion k1, k2, k3, k4, stage;
  motion_rates(pl, x, k1);
  for (int i = 0; i < kStateSize; ++i) stage[i] = x[i] + 0.5 * h * k1[i];
  motion_rates(pl, stage, k2);
  for (int i = 0; i < kStateSize; ++i) stage[i] = x[i] + 0.5 * h * k2[i];
  motion_rates(pl, stage, k3);
  for (int i = 0; i < kStateSize; ++i) stage[i] = x[i] + h * k3[i];
  motion_rates(pl, stage, k4);
  const double w = h / 6.0;
  for (int i = 0; i < kStateSize; ++i) x[i] += w * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
}

/// Symplectic (semi-implicit) Euler: velocities first, then the pose with the new velocities.
void semi_implicit_euler_substep(const Plant& pl, Motion& x, double h) {
  Rotation r;
  rotation_from_quaternion(x + kQ, r);
  double nu_dot[6];
  accelerate(pl, r, x + kNu, nu_dot);
  for (int i = 0; i < 6; ++i) x[kNu + i] += h * nu_dot[i];
  double dx[kNu];
  pose_rates(r, x, dx);
  for (int i = 0; i < kNu; ++i) x[i] += h * dx[i];
  normalise_quaternion(x + kQ);  // an Euler step leaves the sphere by O(h^2)
}

StateStatus classify(const VehicleModel& model, const Vector6& eta, const Vector6& nu) {
  if (!eta.allFinite() || !nu.allFinite()) return StateStatus::kNonFinite;
  if (nu.head<3>().norm() > model.blow_up.max_linear_speed_mps ||
      nu.tail<3>().norm() > model.blow_up.max_angular_rate_rad_s) {
    return StateStatus::kSpeedLimit;
  }
  if (eta.head<3>().cwiseAbs().maxCoeff() > model.blow_up.max_position_m) {
    return StateStatus::kPositionLimit;
  }
  return StateStatus::kOk;
}

Vector3 current_from_speed(const CurrentSettings& current, double speed_mps, double heading_rad) {
  return current.constant_velocity_ned_mps +
         speed_mps * Vector3(std::cos(heading_rad), std::sin(heading_rad), 0.0);
}

[[noreturn]] void invalid(const std::string& field, const std::string& what) {
  throw std::invalid_argument(field + ": " + what);
}

void check_finite_non_negative(double value, const std::string& field) {
  if (!std::isfinite(value) || value < 0) {
    invalid(field, "expected a finite number >= 0, got " + std::to_string(value));
  }
}

ThrusterVector checked_efficiency(const VehicleModel& model, const ThrusterVector& efficiency,
                                  const std::string& field) {
  const int n = model.num_thrusters();
  if (efficiency.size() == 0) return ThrusterVector::Ones(n);
  if (efficiency.size() != n) {
    invalid(field, "expected " + std::to_string(n) + " values (one per thruster) or none, got " +
                       std::to_string(efficiency.size()));
  }
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(efficiency(i)) || efficiency(i) < 0.0 || efficiency(i) > 1.0) {
      invalid(field + "[" + std::to_string(i) + "]",
              "expected a value in [0, 1], got " + std::to_string(efficiency(i)));
    }
  }
  return efficiency;
}

/// Thruster quantities after one control step, committed only if the step succeeds.
struct ThrusterUpdate {
  ThrusterVector command_n;
  ThrusterVector delayed_n;
  ThrusterVector filtered_n;
  ThrusterVector realised_n;
};

/// Saturation, one-sample delay, first-order lag (exact discretisation), slew limit,
/// efficiency: the order of the tank identification.
void advance_thrusters(const VehicleModel& model, const VehicleState& state,
                       const ThrusterVector& command_n, bool ideal, ThrusterUpdate& out) {
  const ThrusterDynamics& td = model.thruster_dynamics;
  // Element loops rather than cwiseMax/cwiseMin: GCC 12 reports a false maybe-uninitialized
  // inside Eigen's AVX-512 min/max for these fixed-capacity vectors.
  const Eigen::Index n = command_n.size();
  out.command_n.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    out.command_n(i) = std::clamp(command_n(i), -td.max_thrust_n, td.max_thrust_n);
  }
  if (ideal) {
    out.delayed_n = out.command_n;
    out.filtered_n = out.command_n;
  } else {
    const double dt = model.control_step_s;
    const ThrusterVector& target = td.delay_enabled ? state.thrust_delayed_n : out.command_n;
    out.filtered_n = target;
    if (td.lag_enabled) {
      const double blend = 1.0 - std::exp(-dt / td.lag_time_constant_s);
      out.filtered_n = state.thrust_filtered_n + blend * (target - state.thrust_filtered_n);
    }
    if (td.slew_enabled) {
      const double max_change_n = td.slew_rate_n_per_s * dt;
      for (Eigen::Index i = 0; i < n; ++i) {
        out.filtered_n(i) =
            state.thrust_filtered_n(i) +
            std::clamp(out.filtered_n(i) - state.thrust_filtered_n(i), -max_change_n, max_change_n);
      }
    }
    out.delayed_n = out.command_n;
  }
  out.realised_n = state.thruster_efficiency.cwiseProduct(out.filtered_n);
}

void step_impl(const VehicleModel& model, VehicleState& state,
               const ThrusterVector& thrust_command_n, bool ideal) {
  if (state.status != StateStatus::kOk) return;
  if (thrust_command_n.size() != model.num_thrusters()) {
    invalid("thrust_command_n", "expected " + std::to_string(model.num_thrusters()) +
                                    " values, got " + std::to_string(thrust_command_n.size()));
  }
  if (!thrust_command_n.allFinite()) {
    state.status = StateStatus::kNonFinite;
    return;
  }
  const double dt = model.control_step_s;

  ThrusterUpdate thrust;
  advance_thrusters(model, state, thrust_command_n, ideal, thrust);
  const Vector6 tau_body = model.allocation * thrust.realised_n;

  // Current: Euler-Maruyama step of dV = -(V - mean)/T dt + sigma dW, heading perturbed by
  // white Gaussian noise; zero sigmas draw nothing.
  const CurrentSettings& cs = state.current;
  double speed_mps = state.gauss_markov_speed_mps -
                     (state.gauss_markov_speed_mps - cs.gauss_markov_speed_mean_mps) * dt /
                         cs.gauss_markov_time_constant_s;
  if (cs.gauss_markov_speed_sigma_mps > 0) {
    speed_mps += cs.gauss_markov_speed_sigma_mps * std::sqrt(dt) * draw::standard_normal(state.rng);
  }
  double heading_rad = cs.gauss_markov_direction_rad;
  if (cs.gauss_markov_direction_sigma_rad > 0) {
    heading_rad += cs.gauss_markov_direction_sigma_rad * draw::standard_normal(state.rng);
  }
  const Vector3 current_ned_mps = current_from_speed(cs, speed_mps, heading_rad);

  const Plant plant = make_plant(model, tau_body, current_ned_mps);
  Motion x;
  for (int i = 0; i < 3; ++i) x[kP + i] = state.eta(i);
  quaternion_from_euler(state.eta.tail<3>(), x + kQ);
  for (int i = 0; i < 6; ++i) x[kNu + i] = state.nu(i);
  const double h = dt / model.substeps;
  if (model.integrator == Integrator::kRk4) {
    for (int i = 0; i < model.substeps; ++i) rk4_substep(plant, x, h);
  } else {
    for (int i = 0; i < model.substeps; ++i) semi_implicit_euler_substep(plant, x, h);
  }
  // The exact flow keeps |q| = 1; an RK4 substep departs from it by O((h |omega| / 2)^6)
  // (1e-14 at 1 rad/s), so one normalisation per control step suffices.
  normalise_quaternion(x + kQ);
  Vector6 eta;
  eta << x[0], x[1], x[2], euler_from_quaternion(x + kQ);
  Vector6 nu;
  for (int i = 0; i < 6; ++i) nu(i) = x[kNu + i];

  const StateStatus status = classify(model, eta, nu);
  if (status != StateStatus::kOk) {
    // Report, never propagate: the state keeps its last valid values.
    state.status = status;
    return;
  }
  state.eta = eta;
  state.nu = nu;
  state.thrust_command_n = thrust.command_n;
  state.thrust_delayed_n = thrust.delayed_n;
  state.thrust_filtered_n = thrust.filtered_n;
  state.thrust_realised_n = thrust.realised_n;
  state.gauss_markov_speed_mps = speed_mps;
  state.current_velocity_ned_mps = current_ned_mps;
  state.time_s += dt;
  ++state.step_count;
}

}  // namespace

VehicleState make_state(const VehicleModel& model, const ResetSettings& reset) {
  if (!reset.eta.allFinite()) invalid("ResetSettings.eta", "expected finite numbers");
  if (!reset.nu.allFinite()) invalid("ResetSettings.nu", "expected finite numbers");
  const CurrentSettings& c = reset.current;
  if (!c.constant_velocity_ned_mps.allFinite()) {
    invalid("ResetSettings.current.constant_velocity_ned_mps", "expected finite numbers");
  }
  if (!std::isfinite(c.gauss_markov_speed_mean_mps)) {
    invalid("ResetSettings.current.gauss_markov_speed_mean_mps", "expected a finite number");
  }
  if (!std::isfinite(c.gauss_markov_direction_rad)) {
    invalid("ResetSettings.current.gauss_markov_direction_rad", "expected a finite number");
  }
  check_finite_non_negative(c.gauss_markov_speed_sigma_mps,
                            "ResetSettings.current.gauss_markov_speed_sigma_mps");
  check_finite_non_negative(c.gauss_markov_direction_sigma_rad,
                            "ResetSettings.current.gauss_markov_direction_sigma_rad");
  if (!std::isfinite(c.gauss_markov_time_constant_s) || !(c.gauss_markov_time_constant_s > 0)) {
    invalid("ResetSettings.current.gauss_markov_time_constant_s", "expected a positive number");
  }
  const SensorNoise& s = reset.sensor_noise;
  check_finite_non_negative(s.position_sigma_m, "ResetSettings.sensor_noise.position_sigma_m");
  check_finite_non_negative(s.attitude_sigma_rad, "ResetSettings.sensor_noise.attitude_sigma_rad");
  check_finite_non_negative(s.linear_velocity_sigma_mps,
                            "ResetSettings.sensor_noise.linear_velocity_sigma_mps");
  check_finite_non_negative(s.angular_velocity_sigma_rad_s,
                            "ResetSettings.sensor_noise.angular_velocity_sigma_rad_s");

  VehicleState state;
  state.thruster_efficiency =
      checked_efficiency(model, reset.thruster_efficiency, "ResetSettings.thruster_efficiency");
  state.eta.head<3>() = reset.eta.head<3>();
  state.eta.tail<3>() = normalised_euler(reset.eta.tail<3>());
  state.nu = reset.nu;
  const int n = model.num_thrusters();
  state.thrust_command_n = ThrusterVector::Zero(n);
  state.thrust_delayed_n = ThrusterVector::Zero(n);
  state.thrust_filtered_n = ThrusterVector::Zero(n);
  state.thrust_realised_n = ThrusterVector::Zero(n);
  state.current = c;
  state.sensor_noise = s;
  state.gauss_markov_speed_mps = c.gauss_markov_speed_mean_mps;
  state.current_velocity_ned_mps =
      current_from_speed(c, c.gauss_markov_speed_mean_mps, c.gauss_markov_direction_rad);
  state.rng.seed(reset.seed);
  // A state that starts outside the limits is reported at once, like one that gets there.
  state.status = classify(model, state.eta, state.nu);
  return state;
}

void set_thruster_efficiency(const VehicleModel& model, VehicleState& state,
                             const ThrusterVector& efficiency) {
  state.thruster_efficiency = checked_efficiency(model, efficiency, "thruster_efficiency");
}

void set_constant_current(VehicleState& state, const Vector3& current_ned_mps) {
  if (!current_ned_mps.allFinite()) {
    invalid("current.constant_velocity_ned_mps", "expected finite numbers");
  }
  // The water velocity is the constant part plus the varying one (current_from_speed).
  state.current_velocity_ned_mps += current_ned_mps - state.current.constant_velocity_ned_mps;
  state.current.constant_velocity_ned_mps = current_ned_mps;
}

void step(const VehicleModel& model, VehicleState& state, const ThrusterVector& thrust_command_n) {
  step_impl(model, state, thrust_command_n, /*ideal=*/false);
}

void step_ideal_thrusters(const VehicleModel& model, VehicleState& state,
                          const ThrusterVector& thrust_command_n) {
  step_impl(model, state, thrust_command_n, /*ideal=*/true);
}

Eigen::Matrix<double, 12, 1> state_derivative(const VehicleModel& model, const Vector6& eta,
                                              const Vector6& nu, const Vector6& tau_thrusters,
                                              const Vector3& current_ned_mps) {
  const double phi = eta(3), theta = eta(4), psi = eta(5);
  const Matrix3 r = rotation_from_euler(phi, theta, psi);
  // T_Theta, eq. 2.29 (singular at theta = +-90 deg).
  const double cphi = std::cos(phi), sphi = std::sin(phi);
  const double cth = std::cos(theta), tth = std::tan(theta);
  Matrix3 t;
  t << 1.0, sphi * tth, cphi * tth,  //
      0.0, cphi, -sphi,              //
      0.0, sphi / cth, cphi / cth;
  Eigen::Matrix<double, 12, 1> derivative;
  derivative.head<3>() = r * nu.head<3>();
  derivative.segment<3>(3) = t * nu.tail<3>();
  // The same dynamics as step() uses.
  const Plant plant = make_plant(model, tau_thrusters, current_ned_mps);
  Rotation rotation;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) rotation[i][j] = r(i, j);
  }
  double nu_array[6], nu_dot[6];
  for (int i = 0; i < 6; ++i) nu_array[i] = nu(i);
  accelerate(plant, rotation, nu_array, nu_dot);
  for (int i = 0; i < 6; ++i) derivative(6 + i) = nu_dot[i];
  return derivative;
}

Vector6 restoring_forces(const VehicleModel& model, const Vector6& eta) {
  const double phi = eta(3), theta = eta(4);
  const double down_body[3] = {-std::sin(theta), std::cos(theta) * std::sin(phi),
                               std::cos(theta) * std::cos(phi)};
  const Plant plant = make_plant(model, Vector6::Zero(), Vector3::Zero());
  double g[6];
  restoring(plant, down_body, g);
  Vector6 out;
  for (int i = 0; i < 6; ++i) out(i) = g[i];
  return out;
}

Measurement measure(const VehicleModel& /*model*/, VehicleState& state) {
  Measurement out;
  out.time_s = state.time_s;
  out.eta = state.eta;
  out.nu = state.nu;
  out.thrust_realised_n = state.thrust_realised_n;
  out.status = state.status;
  // Zero sigmas draw nothing, so the stream (and the current after it) stays the same for a
  // given configuration whether or not noise is on elsewhere.
  const SensorNoise& noise = state.sensor_noise;
  const auto add_noise = [&state](auto&& block, double sigma) {
    if (sigma > 0) {
      for (Eigen::Index i = 0; i < block.size(); ++i)
        block(i) += sigma * draw::standard_normal(state.rng);
    }
  };
  add_noise(out.eta.head<3>(), noise.position_sigma_m);
  add_noise(out.eta.tail<3>(), noise.attitude_sigma_rad);
  add_noise(out.nu.head<3>(), noise.linear_velocity_sigma_mps);
  add_noise(out.nu.tail<3>(), noise.angular_velocity_sigma_rad_s);
  out.eta(3) = wrap_angle(out.eta(3));
  out.eta(5) = wrap_angle(out.eta(5));
  return out;
}

#undef AUVRL_HOT

}  // namespace auvrl::sim
