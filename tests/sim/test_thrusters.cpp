// Thruster response: saturation, one-sample delay, first-order lag, slew limit, faults.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "sim_test_util.hpp"  // first: see the note on Eigen warnings there

namespace auvrl::sim::test {
namespace {

constexpr double kFullThrustN = 39.24;

VehicleModel nessie_with(bool delay, bool lag, bool slew) {
  VehicleModel m = nessie();
  m.thruster_dynamics.delay_enabled = delay;
  m.thruster_dynamics.lag_enabled = lag;
  m.thruster_dynamics.slew_enabled = slew;
  return m;
}

/// Realised thrust of T1 after each of `steps` control steps of a constant T1 command.
std::vector<double> t1_response(const VehicleModel& m, double command_n, int steps) {
  VehicleState s = make_state(m, reset_at_depth(50));
  std::vector<double> out;
  for (int k = 0; k < steps; ++k) {
    step(m, s, thrusts({command_n, 0, 0, 0, 0, 0}));
    out.push_back(s.thrust_realised_n(0));
  }
  return out;
}

TEST(Thrusters, LagTimeConstantFromStepResponse) {
  // Delay on, lag on, slew off. The realised thrust after step k (t = 0.1 k) is
  // Y (1 - exp(-(t - 0.1) / T)): nothing during the first step (the delay), then the exact
  // first-order response, so 63.2 % is reached at t = 0.1 s + T.
  const VehicleModel m = nessie_with(true, true, false);
  const double tau_s = m.thruster_dynamics.lag_time_constant_s;
  const auto y = t1_response(m, kFullThrustN, 30);
  EXPECT_EQ(y[0], 0.0);
  for (int k = 1; k + 1 < 30; ++k) {
    // Time constant from two consecutive samples of the remaining error.
    const double t_est = 0.1 / std::log((kFullThrustN - y[k - 1]) / (kFullThrustN - y[k]));
    ASSERT_NEAR(t_est, tau_s, 1e-9) << "sample " << k;
  }
  const double target = kFullThrustN * (1 - std::exp(-1.0));
  double t63 = -1;
  for (int k = 1; k < 30; ++k) {
    if (y[k] >= target) {  // linear interpolation between the samples at 0.1 k and 0.1 (k+1)
      t63 = 0.1 * k + 0.1 * (target - y[k - 1]) / (y[k] - y[k - 1]);
      break;
    }
  }
  std::printf(
      "[ figure   ] thruster step response: 63.2 %% at t = %.4f s (delay 0.1 s + T = "
      "%.4f s); T from consecutive samples %.4f s\n",
      t63, 0.1 + tau_s, tau_s);
  // Linear interpolation across 0.1 s of an exponential with T = 0.29 s errs by < 3 ms.
  EXPECT_NEAR(t63, 0.1 + tau_s, 0.003);
}

TEST(Thrusters, SlewLimitRate) {
  // Slew only: the realised thrust climbs 21.582 N/s * 0.1 s = 2.1582 N per step to 39.24 N.
  const VehicleModel m = nessie_with(false, false, true);
  const double per_step_n = m.thruster_dynamics.slew_rate_n_per_s * m.control_step_s;
  const auto y = t1_response(m, kFullThrustN, 25);
  for (int k = 0; k < 25; ++k) {
    EXPECT_NEAR(y[k], std::min(per_step_n * (k + 1), kFullThrustN), 1e-12) << "step " << k;
  }
  // Full throttle takes 39.24 / 21.582 = 1.82 s: 19 steps.
  EXPECT_LT(y[17], kFullThrustN);
  EXPECT_EQ(y[18], kFullThrustN);
  // Downwards too.
  const auto down = t1_response(m, -kFullThrustN, 3);
  EXPECT_NEAR(down[2], -3 * per_step_n, 1e-12);
}

TEST(Thrusters, OneSampleDelay) {
  // Delay only: the force of step k is the (saturated) command of step k - 1.
  const VehicleModel m = nessie_with(true, false, false);
  VehicleState s = make_state(m, reset_at_depth(50));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-60.0, 60.0);
  double previous = 0.0;
  for (int k = 0; k < 50; ++k) {
    const double command = u(rng);
    step(m, s, thrusts({command, 0, 0, 0, 0, 0}));
    EXPECT_EQ(s.thrust_realised_n(0), previous);
    EXPECT_EQ(s.thrust_command_n(0), std::clamp(command, -kFullThrustN, kFullThrustN));
    previous = std::clamp(command, -kFullThrustN, kFullThrustN);
  }
  // Without the delay (and nothing else) the command acts at once.
  const VehicleModel none = nessie_with(false, false, false);
  EXPECT_EQ(t1_response(none, 12.5, 1)[0], 12.5);
}

TEST(Thrusters, LagWithoutDelayAndSaturation) {
  const VehicleModel m = nessie_with(false, true, false);
  const double a = std::exp(-0.1 / m.thruster_dynamics.lag_time_constant_s);
  const auto y = t1_response(m, 1000.0, 2);  // saturated to 39.24 N first
  EXPECT_NEAR(y[0], kFullThrustN * (1 - a), 1e-12);
  EXPECT_NEAR(y[1], kFullThrustN * (1 - a * a), 1e-12);
  VehicleState s = make_state(m, reset_at_depth(50));
  step_ideal_thrusters(m, s, thrusts({-500, 500, 1, 0, 0, 0}));
  EXPECT_EQ(s.thrust_realised_n, thrusts({-kFullThrustN, kFullThrustN, 1, 0, 0, 0}));
}

TEST(Thrusters, FaultScalesTheRealisedForce) {
  // The paper's fault: T1 at 10 % of its command (efficiency 0.1).
  const VehicleModel& m = nessie();
  ResetSettings reset = reset_at_depth(50);
  reset.thruster_efficiency = thrusts({0.1, 1, 1, 1, 1, 1});
  VehicleState s = make_state(m, reset);
  const ThrusterVector command = thrusts({kFullThrustN, kFullThrustN, 0, 0, 0, 0});
  for (int k = 0; k < 150; ++k) step(m, s, command);  // past the 1.8 s slew ramp and the lag
  EXPECT_NEAR(s.thrust_realised_n(0), 0.1 * kFullThrustN, 1e-12);
  EXPECT_NEAR(s.thrust_realised_n(1), kFullThrustN, 1e-12);
  EXPECT_NEAR(s.thrust_filtered_n(0), kFullThrustN, 1e-12);  // the thruster itself is spun up
  // Ideal thrusters keep the fault: it is the thruster, not its dynamics.
  VehicleState ideal = make_state(m, reset);
  step_ideal_thrusters(m, ideal, command);
  EXPECT_NEAR(ideal.thrust_realised_n(0), 3.924, 1e-12);

  // Injected on a live vehicle: takes effect at the next step.
  VehicleState live = make_state(m, reset_at_depth(50));
  for (int k = 0; k < 150; ++k) step(m, live, command);
  set_thruster_efficiency(m, live, thrusts({0.1, 1, 1, 1, 1, 1}));
  step(m, live, command);
  EXPECT_NEAR(live.thrust_realised_n(0), 3.924, 1e-12);
  // With 10 % on the port thruster the vehicle turns to port (negative yaw rate).
  for (int k = 0; k < 100; ++k) step(m, live, command);
  EXPECT_LT(live.nu(5), -0.1);
  EXPECT_THROW(set_thruster_efficiency(m, live, thrusts({-0.1, 1, 1, 1, 1, 1})),
               std::invalid_argument);
}

}  // namespace
}  // namespace auvrl::sim::test
