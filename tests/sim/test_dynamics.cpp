// Vehicle dynamics against closed-form physics: equilibria, terminal speeds, passive stability,
// energy, integrator accuracy, current, the Munk instability, blow-up and determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "sim_test_util.hpp"  // first: see the note on Eigen warnings there

namespace auvrl::sim::test {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kFullThrustN = 39.24;

/// Steps `seconds` of simulated time with a constant command.
void run_for(const VehicleModel& model, VehicleState& state, const ThrusterVector& command,
             double seconds, bool ideal = true) {
  const long steps = std::lround(seconds / model.control_step_s);
  for (long k = 0; k < steps; ++k) {
    if (ideal) {
      step_ideal_thrusters(model, state, command);
    } else {
      step(model, state, command);
    }
  }
}

ThrusterVector zero_thrust(const VehicleModel& model) {
  return ThrusterVector::Zero(model.num_thrusters());
}

// ---- Equilibria and terminal speeds. -----------------------------------------------------

TEST(Dynamics, StaticEquilibriumOnlyBuoyancyExcessActs) {
  const VehicleModel& m = nessie();
  // At rest and level the only unbalanced force is B - W = 1 N upwards, against the heave
  // mass m - Z_wdot (the CG offset couples heave to nothing when level).
  const double heave_mass_kg = m.mass_kg - m.added_mass_derivatives(2);
  const double expected_w_dot = (m.weight_n - m.buoyancy_n) / heave_mass_kg;
  const auto d = state_derivative(m, reset_at_depth(50).eta, Vector6::Zero(), Vector6::Zero(),
                                  Vector3::Zero());
  EXPECT_NEAR(d(8), expected_w_dot, 1e-15);
  for (int i = 0; i < 12; ++i) {
    if (i != 8) {
      EXPECT_EQ(d(i), 0.0) << "component " << i;
    }
  }
  std::printf("[ figure   ] heave acceleration at rest %.7f m/s^2 (expected (W-B)/(m-Z_wdot))\n",
              d(8));

  VehicleState s = make_state(m, reset_at_depth(50));
  run_for(m, s, zero_thrust(m), 0.1);
  // After 0.1 s, drag (Z_ww w^2 ~ 1e-4 N at w ~ 5e-4 m/s) is 1e-4 of the net force.
  EXPECT_NEAR(s.nu(2), expected_w_dot * 0.1, 1e-4 * std::abs(expected_w_dot * 0.1));

  run_for(m, s, zero_thrust(m), 150.0);
  // Terminal rise speed: Z_ww w^2 = B - W.
  const double terminal_w = -std::sqrt((m.buoyancy_n - m.weight_n) / -m.quadratic_damping(2));
  EXPECT_NEAR(s.nu(2), terminal_w, 1e-9);
  EXPECT_LT(s.eta(2), 50.0 - 8.0);  // it rose
  // No other motion at all.
  for (int i : {0, 1, 3, 4, 5}) EXPECT_EQ(s.eta(i), 0.0) << "eta " << i;
  for (int i : {0, 1, 3, 4, 5}) EXPECT_EQ(s.nu(i), 0.0) << "nu " << i;
}

TEST(Dynamics, SteadySurgeAtFullThrust) {
  // T1 = T2 = 39.24 N against X_uu u^2: u = sqrt(2 * 39.24 / 31.8086) = 1.57075 m/s. Thrust
  // and drag both act on the CB's horizontal plane, so steady surge needs no pitch; the 1 N of
  // buoyancy adds a steady rise at the heave terminal speed.
  const VehicleModel& m = nessie();
  const double expected_u = std::sqrt(2 * kFullThrustN / -m.quadratic_damping(0));
  const double expected_w = -std::sqrt((m.buoyancy_n - m.weight_n) / -m.quadratic_damping(2));
  const ThrusterVector command = thrusts({kFullThrustN, kFullThrustN, 0, 0, 0, 0});
  const Vector6 tau = m.allocation * command;

  // That state is an exact equilibrium of the equations.
  Vector6 nu_star;
  nu_star << expected_u, 0, expected_w, 0, 0, 0;
  const auto d = state_derivative(m, reset_at_depth(50).eta, nu_star, tau, Vector3::Zero());
  EXPECT_LT(d.tail<6>().cwiseAbs().maxCoeff(), 1e-13) << d.transpose();

  // Simulated: the thrust step pitches the hull (it pushes 6 cm above the CG) and that pitch
  // oscillation, damped only quadratically (amplitude ~ 1/t), modulates the surge speed for
  // minutes: u(60 s) = 1.5698 (the prototype's "1.5700"). Its mid-range converges to the
  // closed form.
  for (bool ideal : {true, false}) {
    VehicleState s = make_state(m, reset_at_depth(500));
    run_for(m, s, command, 60.0, ideal);
    const double u_60 = s.nu(0);
    double u_min = 1e9, u_max = -1e9;
    for (int k = 0; k < 2600; ++k) {
      if (ideal) {
        step_ideal_thrusters(m, s, command);
      } else {
        step(m, s, command);
      }
      if (k >= 2400) {
        u_min = std::min(u_min, s.nu(0));
        u_max = std::max(u_max, s.nu(0));
      }
    }
    std::printf(
        "[ figure   ] surge, %s thrusters: u(60 s) %.5f m/s; over 300-320 s %.6f..%.6f, "
        "mid %.6f (closed form %.6f)\n",
        ideal ? "ideal" : "full-dynamics", u_60, u_min, u_max, 0.5 * (u_min + u_max), expected_u);
    EXPECT_NEAR(u_60, expected_u, 3e-3);
    EXPECT_NEAR(0.5 * (u_min + u_max), expected_u, 1e-4);
    EXPECT_LT(u_max - u_min, 2e-3);
    // Symmetric thrust: no sway or yaw beyond round-off (FMA contraction breaks the mirror
    // symmetry of the arithmetic at the 1e-12 level over 3200 steps).
    EXPECT_NEAR(s.nu(1), 0.0, 1e-9);
    EXPECT_NEAR(s.nu(5), 0.0, 1e-9);
  }

  // The semi-implicit Euler alternative agrees on the steady state.
  VehicleModel euler = m;
  euler.integrator = Integrator::kSemiImplicitEuler;
  VehicleState se = make_state(euler, reset_at_depth(50));
  run_for(euler, se, command, 60.0);
  EXPECT_NEAR(se.nu(0), expected_u, 3e-3);
}

TEST(Dynamics, SteadyYawRateUnderPureYawMoment) {
  // T1 = -T2 = 39.24 N: N = 2 * 0.185 m * 39.24 N = 14.52 N m against N_rr r^2.
  const VehicleModel& m = nessie();
  const double moment_nm = 2 * 0.185 * kFullThrustN;
  const double expected_r = std::sqrt(moment_nm / -m.quadratic_damping(5));
  VehicleState s = make_state(m, reset_at_depth(50));
  run_for(m, s, thrusts({kFullThrustN, -kFullThrustN, 0, 0, 0, 0}), 40.0);
  std::printf("[ figure   ] steady yaw rate %.6f rad/s (closed form %.6f)\n", s.nu(5), expected_r);
  EXPECT_NEAR(s.nu(5), expected_r, 1e-6);
  EXPECT_NEAR(s.nu(0), 0.0, 1e-9);
  EXPECT_NEAR(s.nu(1), 0.0, 1e-9);
  EXPECT_NEAR(s.eta(0), 0.0, 1e-9);
  EXPECT_NEAR(s.eta(1), 0.0, 1e-9);
  EXPECT_GT(s.eta(5), -kPi);  // heading wrapped to (-pi, pi]
  EXPECT_LE(s.eta(5), kPi);
}

TEST(Dynamics, BlueRov2SinksAtTerminalSpeedAndHoversWithVerticalThrust) {
  const VehicleModel& m = bluerov();
  const double excess_weight_n = m.weight_n - m.buoyancy_n;  // about 0.98 N
  ASSERT_GT(excess_weight_n, 0.9);
  // Z_w w + Z_ww w^2 = W - B (both derivatives negative): the positive root.
  const double a = -m.quadratic_damping(2), b = -m.linear_damping(2);
  const double terminal_w = (-b + std::sqrt(b * b + 4 * a * excess_weight_n)) / (2 * a);
  VehicleState s = make_state(m, reset_at_depth(20));
  run_for(m, s, zero_thrust(m), 30.0);
  std::printf("[ figure   ] BlueROV2 sink rate %.6f m/s (closed form %.6f)\n", s.nu(2), terminal_w);
  EXPECT_NEAR(s.nu(2), terminal_w, 1e-9);
  EXPECT_LT(s.eta.segment<2>(3).cwiseAbs().maxCoeff(), 1e-12);

  // Four vertical thrusters carrying the excess weight: it hovers.
  const double each_n = excess_weight_n / 4;
  VehicleState hover = make_state(m, reset_at_depth(20));
  run_for(m, hover, thrusts({0, 0, 0, 0, each_n, each_n, each_n, each_n}), 30.0);
  EXPECT_LT(hover.nu.cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(hover.eta(2), 20.0, 1e-12);
}

// ---- Passive stability and energy. ------------------------------------------------------

struct Disturbance {
  const char* vehicle;
  int axis;  // 3 = roll, 4 = pitch
};

void PrintTo(const Disturbance& d, std::ostream* os) {
  *os << d.vehicle << (d.axis == 3 ? " roll" : " pitch");
}

class ReturnsToLevel : public ::testing::TestWithParam<Disturbance> {};

TEST_P(ReturnsToLevel, EnergyDecreasesAndAttitudeDecays) {
  const Disturbance& d = GetParam();
  const VehicleModel& m = std::string(d.vehicle) == "nessie7" ? nessie() : bluerov();
  ResetSettings reset = reset_at_depth(50);
  const double initial_rad = 0.3;
  reset.eta(d.axis) = initial_rad;
  VehicleState s = make_state(m, reset);
  double energy = mechanical_energy_j(m, s);
  const double initial_energy = energy;
  double max_abs_late = 0.0;
  const ThrusterVector zero = zero_thrust(m);
  for (int k = 1; k <= 600; ++k) {  // 60 s
    step_ideal_thrusters(m, s, zero);
    const double e = mechanical_energy_j(m, s);
    // Non-increasing, up to round-off on energies of order 10 J.
    ASSERT_LE(e, energy + 1e-9) << "step " << k;
    energy = e;
    if (k > 500) max_abs_late = std::max(max_abs_late, std::abs(s.eta(d.axis)));
  }
  std::printf("[ figure   ] %s %s: energy %.4f -> %.4f J, |angle| over 50-60 s <= %.5f rad\n",
              d.vehicle, d.axis == 3 ? "roll" : "pitch", initial_energy, energy, max_abs_late);
  EXPECT_LT(max_abs_late, 0.25 * initial_rad);
}

INSTANTIATE_TEST_SUITE_P(BothVehicles, ReturnsToLevel,
                         ::testing::Values(Disturbance{"nessie7", 3}, Disturbance{"nessie7", 4},
                                           Disturbance{"bluerov2_heavy", 3},
                                           Disturbance{"bluerov2_heavy", 4}));

TEST(Dynamics, PitchDecayFollowsQuadraticDampingTheory) {
  // theta'' + c |theta'| theta' + w0^2 theta = 0 with c = |M_qq| / I and w0^2 = W z_g / I
  // decays in amplitude as A(t) = A0 / (1 + K A0 t), K = 4 / (3 pi) c w0 (averaging over a
  // cycle). I = I_y + m z_g^2 - M_qdot about the body origin.
  const VehicleModel& m = nessie();
  const double inertia = m.mass_total(4, 4);
  const double c = -m.quadratic_damping(4) / inertia;
  const double w0 = std::sqrt(m.weight_n * m.cog_body_m.z() / inertia);
  const double k = 4.0 / (3.0 * kPi) * c * w0;
  const double a0 = 0.2;
  ResetSettings reset = reset_at_depth(50);
  reset.eta(4) = a0;
  VehicleState s = make_state(m, reset);
  double peak = 0.0;
  for (int step_index = 1; step_index <= 650; ++step_index) {
    step_ideal_thrusters(m, s, zero_thrust(m));
    if (s.time_s > 60.0 - 1e-9) peak = std::max(peak, std::abs(s.eta(4)));
  }
  // The window 60-65 s spans most of a period (7.1 s) so the peak is near the envelope at 62 s.
  const double expected = a0 / (1 + k * a0 * 62.0);
  std::printf("[ figure   ] pitch amplitude at ~62 s %.5f rad, averaging theory %.5f rad\n", peak,
              expected);
  EXPECT_NEAR(peak, expected, 0.05 * expected);
}

TEST(Dynamics, CoriolisTermsDoNoWork) {
  // Without damping and with weight and buoyancy balanced at one point, kinetic energy
  // 1/2 nu^T M nu must be conserved: C_RB (eq. 3.60, with the CG offset) and C_A are
  // skew-symmetric. A wrong sign or a double-counted term shows up as drift.
  VehicleModel m = nessie_munk();
  m.linear_damping.setZero();
  m.quadratic_damping.setZero();
  m.buoyancy_n = m.weight_n;
  m.cob_body_m = m.cog_body_m;
  finalize_vehicle_model(m);
  ResetSettings reset = reset_at_depth(50);
  reset.nu << 0.5, 0.2, -0.1, 0.3, -0.2, 0.4;
  VehicleState s = make_state(m, reset);
  const double initial = 0.5 * s.nu.dot(m.mass_total * s.nu);
  double worst = 0.0;
  for (int k = 0; k < 200; ++k) {
    step_ideal_thrusters(m, s, zero_thrust(m));
    const double kinetic = 0.5 * s.nu.dot(m.mass_total * s.nu);
    worst = std::max(worst, std::abs(kinetic - initial) / initial);
  }
  ASSERT_EQ(s.status, StateStatus::kOk);
  std::printf("[ figure   ] kinetic energy drift without damping over 20 s: %.2e (relative)\n",
              worst);
  EXPECT_LT(worst, 1e-7);
}

TEST(Dynamics, RestoringForcesMatchFossenEq46) {
  VehicleModel m = nessie();
  m.cog_body_m << 0.01, -0.02, 0.06;
  m.cob_body_m << 0.005, 0.01, -0.01;
  finalize_vehicle_model(m);
  const double w = m.weight_n, b = m.buoyancy_n;
  const Vector3 rg = m.cog_body_m, rb = m.cob_body_m;
  Vector6 eta;
  eta << 1, 2, 3, 0.4, -0.3, 2.0;
  const double sphi = std::sin(eta(3)), cphi = std::cos(eta(3));
  const double sth = std::sin(eta(4)), cth = std::cos(eta(4));
  Vector6 expected;  // Fossen 2011 eq. 4.6, written out
  expected << (w - b) * sth, -(w - b) * cth * sphi, -(w - b) * cth * cphi,
      -(rg.y() * w - rb.y() * b) * cth * cphi + (rg.z() * w - rb.z() * b) * cth * sphi,
      (rg.z() * w - rb.z() * b) * sth + (rg.x() * w - rb.x() * b) * cth * cphi,
      -(rg.x() * w - rb.x() * b) * cth * sphi - (rg.y() * w - rb.y() * b) * sth;
  EXPECT_LT((restoring_forces(m, eta) - expected).cwiseAbs().maxCoeff(), 1e-12);
}

// ---- Integrator accuracy. -----------------------------------------------------------------

/// A 70 s manoeuvre exercising every thruster with the full thruster model.
ThrusterVector rich_command(int step_index) {
  const double t = 0.1 * step_index;
  return thrusts({kFullThrustN * std::sin(0.31 * t), kFullThrustN * std::cos(0.23 * t),
                  30.0 * std::sin(0.5 * t + 1.0), -25.0 * std::cos(0.41 * t),
                  35.0 * std::sin(0.17 * t + 0.5), 20.0 * std::sin(0.73 * t)});
}

std::vector<Vector6> rich_trajectory(const VehicleModel& m, int steps) {
  ResetSettings reset = reset_at_depth(5);
  reset.current.constant_velocity_ned_mps << 0.1, -0.05, 0.0;
  VehicleState s = make_state(m, reset);
  std::vector<Vector6> eta{s.eta};
  for (int k = 0; k < steps; ++k) {
    step(m, s, rich_command(k));
    EXPECT_EQ(s.status, StateStatus::kOk);
    eta.push_back(s.eta);
  }
  return eta;
}

TEST(Integrator, Rk4TenSubstepsAgainstFineReference) {
  VehicleModel fine = nessie();
  fine.substeps = 1000;
  const auto reference = rich_trajectory(fine, 700);
  double travelled_m = 0.0;
  for (std::size_t k = 1; k < reference.size(); ++k) {
    travelled_m += (reference[k].head<3>() - reference[k - 1].head<3>()).norm();
  }
  for (Integrator integrator : {Integrator::kRk4, Integrator::kSemiImplicitEuler}) {
    VehicleModel coarse = nessie();
    coarse.integrator = integrator;
    const auto trajectory = rich_trajectory(coarse, 700);
    double max_position_error_m = 0.0, max_angle_error_rad = 0.0;
    for (std::size_t k = 0; k < reference.size(); ++k) {
      max_position_error_m =
          std::max(max_position_error_m, (trajectory[k].head<3>() - reference[k].head<3>()).norm());
      for (int i = 3; i < 6; ++i) {
        max_angle_error_rad =
            std::max(max_angle_error_rad,
                     std::abs(std::remainder(trajectory[k](i) - reference[k](i), 2 * kPi)));
      }
    }
    const bool rk4 = integrator == Integrator::kRk4;
    std::printf(
        "[ figure   ] %s, 10 substeps vs RK4 1000 substeps over 70 s (%.1f m travelled): max "
        "position error %.3e m, max angle error %.3e rad\n",
        rk4 ? "RK4" : "semi-implicit Euler", travelled_m, max_position_error_m,
        max_angle_error_rad);
    if (rk4) {
      // Measured 1.4e-7 m and 2.9e-8 rad (fourth order: h = 0.01 s).
      EXPECT_LT(max_position_error_m, 1e-6);
      EXPECT_LT(max_angle_error_rad, 2e-7);
    } else {
      // Measured 0.061 m and 0.016 rad (first order).
      EXPECT_LT(max_position_error_m, 0.15);
      EXPECT_LT(max_angle_error_rad, 0.04);
    }
  }
}

TEST(Integrator, QuaternionStepMatchesEulerAngleOde) {
  // step() carries attitude as a quaternion; state_derivative() is the Euler-angle form of
  // Fossen eq. 2.40-2.41. RK4 on the Euler form with fine steps must give the same motion.
  const VehicleModel& m = nessie_munk();
  ResetSettings reset = reset_at_depth(5);
  reset.eta(3) = 0.2;
  reset.eta(5) = 3.0;
  reset.current.constant_velocity_ned_mps << 0.2, -0.1, 0.05;
  VehicleModel fine = m;
  fine.substeps = 200;
  VehicleState s = make_state(fine, reset);
  Eigen::Matrix<double, 12, 1> x;
  x << s.eta, s.nu;
  const Vector3 current = reset.current.constant_velocity_ned_mps;
  const double h = fine.control_step_s / fine.substeps;
  double max_diff = 0.0;
  for (int k = 0; k < 100; ++k) {
    const ThrusterVector command = rich_command(k);
    step_ideal_thrusters(fine, s, command);
    const Vector6 tau = fine.allocation * command;
    for (int i = 0; i < fine.substeps; ++i) {
      const auto f = [&](const Eigen::Matrix<double, 12, 1>& y) {
        return state_derivative(fine, y.head<6>(), y.tail<6>(), tau, current);
      };
      const auto k1 = f(x);
      const auto k2 = f(x + 0.5 * h * k1);
      const auto k3 = f(x + 0.5 * h * k2);
      const auto k4 = f(x + h * k3);
      x += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    Vector6 diff = s.eta - x.head<6>();
    diff(5) = std::remainder(diff(5), 2 * kPi);
    max_diff = std::max(
        {max_diff, diff.cwiseAbs().maxCoeff(), (s.nu - x.tail<6>()).cwiseAbs().maxCoeff()});
  }
  EXPECT_LT(max_diff, 1e-9);
}

// ---- Water current. -----------------------------------------------------------------------

TEST(Current, PassiveVehicleDriftsWithTheWater) {
  // Heading north in a 0.3 m/s northward current: the relative surge speed obeys
  // (m - X_udot) u_r' = X_uu |u_r| u_r, so |u_r|(t) = 0.3 / (1 + c 0.3 t), c = |X_uu| / 66 kg.
  const VehicleModel& m = nessie();
  ResetSettings reset = reset_at_depth(50);
  reset.current.constant_velocity_ned_mps << 0.3, 0.0, 0.0;
  VehicleState s = make_state(m, reset);
  const double c = -m.quadratic_damping(0) / (m.mass_kg - m.added_mass_derivatives(0));
  double worst = 0.0;
  for (int k = 1; k <= 600; ++k) {
    step_ideal_thrusters(m, s, zero_thrust(m));
    const double expected_u = 0.3 - 0.3 / (1 + c * 0.3 * s.time_s);
    worst = std::max(worst, std::abs(s.nu(0) - expected_u));
  }
  std::printf(
      "[ figure   ] drift in 0.3 m/s current: u(60 s) = %.5f m/s, max deviation from the "
      "surge-only closed form %.2e m/s\n",
      s.nu(0), worst);
  // The only departure from the closed form: drag acts at the CB, 6 cm above the CG, which
  // pitches the hull by a few milliradians and couples back through m z_g.
  EXPECT_LT(worst, 2e-3);
  EXPECT_EQ(s.current_velocity_ned_mps, Vector3(0.3, 0.0, 0.0));

  // Any heading, any horizontal direction: the ground velocity converges to the current.
  ResetSettings oblique = reset_at_depth(50);
  oblique.eta(5) = 0.5;
  oblique.current.constant_velocity_ned_mps << 0.3 * std::cos(2.0), 0.3 * std::sin(2.0), 0.0;
  VehicleState o = make_state(m, oblique);
  double previous_gap = 1e9;
  for (int k = 0; k < 1200; ++k) {
    step_ideal_thrusters(m, o, zero_thrust(m));
    const Matrix3 r = Eigen::AngleAxisd(o.eta(5), Vector3::UnitZ()) *
                      Eigen::AngleAxisd(o.eta(4), Vector3::UnitY()) *
                      Eigen::AngleAxisd(o.eta(3), Vector3::UnitX()).toRotationMatrix();
    Vector3 ground = r * o.nu.head<3>();
    ground(2) = 0.0;  // the vertical rise is buoyancy, not current
    const double gap = (ground - oblique.current.constant_velocity_ned_mps).norm();
    if (k % 50 == 49) {
      EXPECT_LT(gap, previous_gap);
      previous_gap = gap;
    }
  }
  EXPECT_LT(previous_gap, 0.02);
}

TEST(Current, SetOnALiveVehicleActsFromTheNextStepAsAtAReset) {
  // A current set mid-run (a mission's event) gives the same motion as one set at the reset,
  // and keeps the varying Gauss-Markov part.
  const VehicleModel& m = nessie();
  ResetSettings reset = reset_at_depth(50);
  reset.current.gauss_markov_speed_mean_mps = 0.1;
  VehicleState live = make_state(m, reset);
  reset.current.constant_velocity_ned_mps << 0.2, -0.1, 0.0;
  VehicleState from_reset = make_state(m, reset);
  set_constant_current(live, reset.current.constant_velocity_ned_mps);
  EXPECT_EQ(live.current_velocity_ned_mps, from_reset.current_velocity_ned_mps);
  for (int k = 0; k < 50; ++k) {
    step_ideal_thrusters(m, live, zero_thrust(m));
    step_ideal_thrusters(m, from_reset, zero_thrust(m));
  }
  EXPECT_EQ(live.eta, from_reset.eta);
  EXPECT_EQ(live.nu, from_reset.nu);
  EXPECT_THROW(set_constant_current(live, Vector3(std::nan(""), 0.0, 0.0)), std::invalid_argument);
}

TEST(Current, GaussMarkovSpeedHasTheDesignedStatistics) {
  // V_{k+1} - mu = a (V_k - mu) + sigma sqrt(dt) n_k, a = 1 - dt / T: stationary variance
  // sigma^2 dt / (1 - a^2). 200k steps over T = 5 s: ~2000 independent samples, so the
  // standard error of the variance is ~3 %; the bounds are 4 of those.
  const VehicleModel& m = nessie();
  ResetSettings reset = reset_at_depth(50);
  reset.current.gauss_markov_speed_mean_mps = 0.2;
  reset.current.gauss_markov_speed_sigma_mps = 0.05;
  reset.current.gauss_markov_time_constant_s = 5.0;
  reset.current.gauss_markov_direction_rad = 1.0;
  reset.current.gauss_markov_direction_sigma_rad = 0.1;
  reset.seed = 7;
  VehicleState s = make_state(m, reset);
  const ThrusterVector zero = zero_thrust(m);
  const int n = 200000;
  double sum = 0.0, sum_sq = 0.0;
  Vector3 current_sum = Vector3::Zero();
  for (int k = 0; k < n; ++k) {
    step_ideal_thrusters(m, s, zero);
    if (s.status != StateStatus::kOk) break;
    sum += s.gauss_markov_speed_mps;
    sum_sq += s.gauss_markov_speed_mps * s.gauss_markov_speed_mps;
    current_sum += s.current_velocity_ned_mps;
  }
  ASSERT_EQ(s.status, StateStatus::kOk);
  const double mean = sum / n, variance = sum_sq / n - mean * mean;
  const double mean_heading = std::atan2(current_sum.y(), current_sum.x());
  const double a = 1.0 - 0.1 / 5.0;
  const double expected_variance = 0.05 * 0.05 * 0.1 / (1 - a * a);
  std::printf("[ figure   ] Gauss-Markov speed mean %.4f (0.2), std %.5f (%.5f)\n", mean,
              std::sqrt(variance), std::sqrt(expected_variance));
  EXPECT_NEAR(mean, 0.2, 4 * std::sqrt(expected_variance / 2000));
  EXPECT_NEAR(variance, expected_variance, 0.12 * expected_variance);
  EXPECT_NEAR(mean_heading, 1.0, 0.01);
  EXPECT_EQ(current_sum.z(), 0.0);
}

// ---- Munk moment. ---------------------------------------------------------------------------

TEST(Munk, FullSurgeTumblesWithAddedMassCoriolisOnly) {
  // With C_A the slender hull's Munk moment (Z_wdot - X_udot) u w is destabilising and there
  // are no hull lift terms to balance it: full surge pitches away and tumbles. Without C_A
  // (the vehicle's own simulator) it runs straight. Shown, not hidden.
  const ThrusterVector command = thrusts({kFullThrustN, kFullThrustN, 0, 0, 0, 0});
  for (const VehicleModel* m : {&nessie(), &nessie_munk()}) {
    VehicleState s = make_state(*m, reset_at_depth(50));
    double max_tilt = 0.0, max_u = 0.0, tilt_time_s = -1.0;
    for (int k = 0; k < 700 && s.status == StateStatus::kOk; ++k) {
      step(*m, s, command);
      const double tilt = std::max(std::abs(s.eta(3)), std::abs(s.eta(4)));
      if (tilt > 1.2 && tilt_time_s < 0) tilt_time_s = s.time_s;
      max_tilt = std::max(max_tilt, tilt);
      max_u = std::max(max_u, s.nu(0));
    }
    std::printf(
        "[ figure   ] %s full surge 70 s: max |roll|,|pitch| %.3f rad%s, max u %.3f m/s, "
        "u(end) %.3f m/s, status %d\n",
        m->name.c_str(), max_tilt,
        tilt_time_s > 0 ? (" (flip at " + std::to_string(tilt_time_s) + " s)").c_str() : "", max_u,
        s.nu(0), static_cast<int>(s.status));
    if (m->added_mass_coriolis) {
      EXPECT_GT(max_tilt, 1.2);  // a flip by the learning notes' definition
      EXPECT_LT(tilt_time_s, 15.0);
      EXPECT_LT(s.nu(0), 1.0);  // tumbling, it never settles at the straight-running speed
    } else {
      // Only the pitch-up of the thrust step (thrust 6 cm above the CG), then straight running.
      EXPECT_LT(max_tilt, 0.15);
      EXPECT_NEAR(s.nu(0), 1.5708, 3e-3);
    }
  }
}

// ---- Blow-up detection. ---------------------------------------------------------------------

void expect_same_state(const VehicleState& a, const VehicleState& b) {
  for (int i = 0; i < 6; ++i) {
    EXPECT_TRUE(a.eta(i) == b.eta(i) || (std::isnan(a.eta(i)) && std::isnan(b.eta(i))));
    EXPECT_TRUE(a.nu(i) == b.nu(i) || (std::isnan(a.nu(i)) && std::isnan(b.nu(i))));
  }
  EXPECT_EQ(a.time_s, b.time_s);
  EXPECT_EQ(a.step_count, b.step_count);
  EXPECT_EQ(a.thrust_realised_n, b.thrust_realised_n);
}

TEST(BlowUp, HugeInitialVelocityIsFlaggedAndFrozen) {
  const VehicleModel& m = nessie();
  ResetSettings reset = reset_at_depth(5);
  reset.nu(0) = 1000.0;
  VehicleState s = make_state(m, reset);
  EXPECT_EQ(s.status, StateStatus::kSpeedLimit);
  const VehicleState before = s;
  step(m, s, thrusts({10, 10, 10, 10, 10, 10}));
  EXPECT_EQ(s.status, StateStatus::kSpeedLimit);
  expect_same_state(s, before);
}

TEST(BlowUp, NanStateOrCommandIsFlaggedAndFrozen) {
  const VehicleModel& m = nessie();
  VehicleState s = make_state(m, reset_at_depth(5));
  run_for(m, s, thrusts({10, 10, 0, 0, 0, 0}), 1.0, false);
  s.nu(3) = std::nan("");
  const VehicleState before = s;
  step(m, s, thrusts({10, 10, 0, 0, 0, 0}));
  EXPECT_EQ(s.status, StateStatus::kNonFinite);
  expect_same_state(s, before);
  step(m, s, thrusts({10, 10, 0, 0, 0, 0}));
  expect_same_state(s, before);

  VehicleState t = make_state(m, reset_at_depth(5));
  run_for(m, t, thrusts({10, 10, 0, 0, 0, 0}), 1.0, false);
  const VehicleState t_before = t;
  step(m, t, thrusts({10, std::nan(""), 0, 0, 0, 0}));
  EXPECT_EQ(t.status, StateStatus::kNonFinite);
  expect_same_state(t, t_before);
}

TEST(BlowUp, SpeedAndPositionLimitsKeepTheLastValidState) {
  VehicleModel m = nessie();
  m.blow_up.max_linear_speed_mps = 1.0;
  VehicleState s = make_state(m, reset_at_depth(5));
  VehicleState last_ok = s;
  for (int k = 0; k < 200 && s.status == StateStatus::kOk; ++k) {
    last_ok = s;
    step_ideal_thrusters(m, s, thrusts({kFullThrustN, kFullThrustN, 0, 0, 0, 0}));
  }
  EXPECT_EQ(s.status, StateStatus::kSpeedLimit);
  expect_same_state(s, last_ok);
  EXPECT_LE(s.nu.head<3>().norm(), 1.0);
  EXPECT_GT(s.nu(0), 0.9);

  VehicleModel p = nessie();
  p.blow_up.max_position_m = 10.0;
  ResetSettings reset = reset_at_depth(5);
  reset.eta(0) = 9.9;
  reset.nu(0) = 1.5;
  VehicleState q = make_state(p, reset);
  for (int k = 0; k < 20; ++k) step(p, q, zero_thrust(p));
  EXPECT_EQ(q.status, StateStatus::kPositionLimit);
  EXPECT_LE(q.eta(0), 10.0);
}

TEST(BlowUp, WrongCommandSizeThrows) {
  VehicleState s = make_state(nessie(), reset_at_depth(5));
  EXPECT_THROW(step(nessie(), s, thrusts({1, 2, 3})), std::invalid_argument);
}

// ---- Determinism, resets, measurement noise. ----------------------------------------------

ResetSettings noisy_reset(std::uint64_t seed) {
  ResetSettings reset = reset_at_depth(5);
  reset.current.constant_velocity_ned_mps << 0.05, 0.0, 0.0;
  reset.current.gauss_markov_speed_mean_mps = 0.2;
  reset.current.gauss_markov_speed_sigma_mps = 0.05;
  reset.current.gauss_markov_time_constant_s = 20.0;
  reset.current.gauss_markov_direction_sigma_rad = 0.2;
  reset.sensor_noise.position_sigma_m = 0.1;
  reset.sensor_noise.attitude_sigma_rad = 0.01;
  reset.sensor_noise.linear_velocity_sigma_mps = 0.02;
  reset.sensor_noise.angular_velocity_sigma_rad_s = 0.01;
  reset.seed = seed;
  return reset;
}

std::vector<double> noisy_run(const ResetSettings& reset) {
  const VehicleModel& m = nessie();
  VehicleState s = make_state(m, reset);
  std::vector<double> out;
  for (int k = 0; k < 200; ++k) {
    step(m, s, rich_command(k));
    const Measurement z = measure(m, s);
    for (int i = 0; i < 6; ++i) out.push_back(z.eta(i));
    for (int i = 0; i < 6; ++i) out.push_back(z.nu(i));
    for (int i = 0; i < 6; ++i) out.push_back(s.eta(i));
  }
  return out;
}

TEST(Determinism, SameSeedSameRunDifferentSeedDifferentRun) {
  const auto a = noisy_run(noisy_reset(42));
  const auto b = noisy_run(noisy_reset(42));
  const auto c = noisy_run(noisy_reset(43));
  EXPECT_EQ(a, b);  // bit for bit
  EXPECT_NE(a, c);
  // A copied state carries its random stream: both copies continue identically.
  const VehicleModel& m = nessie();
  VehicleState s = make_state(m, noisy_reset(5));
  run_for(m, s, rich_command(3), 2.0, false);
  VehicleState copy = s;
  for (int k = 0; k < 50; ++k) {
    step(m, s, rich_command(k));
    step(m, copy, rich_command(k));
    EXPECT_EQ(measure(m, s).eta, measure(m, copy).eta);
  }
}

TEST(Measurement, NoiseHasTheConfiguredSpreadAndZeroSigmaIsExact) {
  const VehicleModel& m = nessie();
  ResetSettings reset = reset_at_depth(5);
  VehicleState quiet = make_state(m, reset);
  const Measurement exact = measure(m, quiet);
  EXPECT_EQ(exact.eta, quiet.eta);
  EXPECT_EQ(exact.nu, quiet.nu);
  reset.sensor_noise.position_sigma_m = 0.5;
  VehicleState noisy = make_state(m, reset);
  const int n = 20000;
  double sum_sq = 0.0;
  for (int k = 0; k < n; ++k) {
    const Measurement z = measure(m, noisy);
    sum_sq += (z.eta(0) - noisy.eta(0)) * (z.eta(0) - noisy.eta(0));
    EXPECT_EQ(z.nu, noisy.nu);  // only the position is noisy
  }
  // Sample std of 20000 Gaussian draws: standard error 0.5 %; bound 2 % (4 of those).
  EXPECT_NEAR(std::sqrt(sum_sq / n), 0.5, 0.01);
}

TEST(Reset, MakeStateValidatesAndNamesTheField) {
  const VehicleModel& m = nessie();
  const auto message_of = [&](const ResetSettings& reset) {
    try {
      make_state(m, reset);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  ResetSettings r = reset_at_depth(5);
  r.thruster_efficiency = thrusts({1, 1, 1, 1, 1});
  EXPECT_NE(message_of(r).find("thruster_efficiency"), std::string::npos) << message_of(r);
  r.thruster_efficiency = thrusts({1, 1, 1.5, 1, 1, 1});
  EXPECT_NE(message_of(r).find("thruster_efficiency[2]"), std::string::npos) << message_of(r);
  r = reset_at_depth(5);
  r.eta(4) = std::nan("");
  EXPECT_NE(message_of(r).find("ResetSettings.eta"), std::string::npos) << message_of(r);
  r = reset_at_depth(5);
  r.current.gauss_markov_time_constant_s = 0.0;
  EXPECT_NE(message_of(r).find("gauss_markov_time_constant_s"), std::string::npos);
  r = reset_at_depth(5);
  r.sensor_noise.attitude_sigma_rad = -1.0;
  EXPECT_NE(message_of(r).find("attitude_sigma_rad"), std::string::npos);
  // Angles come back normalised: psi in (-pi, pi], theta folded into [-pi/2, pi/2].
  r = reset_at_depth(5);
  r.eta.tail<3>() << 0.0, 0.0, 3 * kPi / 2;
  EXPECT_NEAR(make_state(m, r).eta(5), -kPi / 2, 1e-12);
  r.eta.tail<3>() << 0.0, kPi - 0.2, 0.0;
  const VehicleState folded = make_state(m, r);
  EXPECT_NEAR(folded.eta(4), 0.2, 1e-12);
  EXPECT_NEAR(std::abs(folded.eta(3)), kPi, 1e-12);
}

}  // namespace
}  // namespace auvrl::sim::test
