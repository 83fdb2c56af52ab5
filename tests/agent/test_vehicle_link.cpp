// Both vehicle links start an episode where EpisodeStart says: pose and body velocities (the
// exploring starts of training depend on it), sensor noise, faults, current and model variation,
// in this process and through auv_sim's server over the in-process transport; only the
// in-process link takes a mission's events mid-run.
#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "agent/vehicle_link.hpp"
#include "common/transport.hpp"
#include "common/unrecoverable.hpp"
#include "sim/sim_server.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::agent {
namespace {

EpisodeStart moving_start() {
  EpisodeStart start;
  start.position_ned_m = Eigen::Vector3d(1.0, -2.0, 6.0);
  start.euler_rpy_rad = Eigen::Vector3d(0.05, -0.2, 2.5);
  start.velocity_body_mps = Eigen::Vector3d(1.2, -0.3, 0.2);
  start.angular_rate_body_rad_s = Eigen::Vector3d(0.01, 0.1, -0.4);
  return start;
}

/// The first report is the start itself (no sensor noise); one step later, with no thrust,
/// the vehicle has moved along its initial body velocity and is slowing down.
void expect_starts_moving(VehicleLink& link) {
  const EpisodeStart start = moving_start();
  const std::optional<VehicleReport> first = link.reset(start);
  ASSERT_TRUE(first.has_value());
  EXPECT_TRUE(first->observation.position_ned_m.isApprox(start.position_ned_m, 1e-9));
  EXPECT_TRUE(first->observation.euler_rpy_rad.isApprox(start.euler_rpy_rad, 1e-9));
  EXPECT_TRUE(first->observation.velocity_body_mps.isApprox(start.velocity_body_mps, 1e-9));
  EXPECT_TRUE(
      first->observation.angular_rate_body_rad_s.isApprox(start.angular_rate_body_rad_s, 1e-9));

  const std::optional<VehicleReport> next = link.step(std::vector<double>(6, 0.0));
  ASSERT_TRUE(next.has_value());
  const Eigen::Vector3d moved = next->observation.position_ned_m - start.position_ned_m;
  // Facing 2.5 rad with u = 1.2 m/s: 0.1 s later about 0.12 m along that heading.
  const Eigen::Vector3d heading(std::cos(2.5), std::sin(2.5), 0.0);
  EXPECT_GT(moved.dot(heading), 0.09);
  EXPECT_LT(next->observation.velocity_body_mps.x(), 1.2);
  EXPECT_GT(next->observation.velocity_body_mps.x(), 1.0);

  // A start at rest stays (nearly) at rest: nothing carries over from the last episode.
  EpisodeStart rest;
  const std::optional<VehicleReport> again = link.reset(rest);
  ASSERT_TRUE(again.has_value());
  EXPECT_TRUE(again->observation.velocity_body_mps.isZero());
  EXPECT_TRUE(again->observation.angular_rate_body_rad_s.isZero());
}

sim::VehicleModel nessie() {
  return sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml");
}

TEST(VehicleLink, InProcessLinkStartsAtTheGivenPoseAndVelocity) {
  const sim::VehicleModel model = nessie();
  std::unique_ptr<VehicleLink> link = make_in_process_link(model);
  expect_starts_moving(*link);
}

TEST(VehicleLink, LockstepLinkSendsThePoseAndVelocityToTheSimulator) {
  const sim::VehicleModel model = nessie();
  std::unique_ptr<transport::Transport> bus = transport::make_in_process_transport();
  sim::SimServerConfig config;
  config.heartbeat_period_s = 3600;
  sim::SimServer server(model, *bus, config);  // answers inside the link's own handle calls
  std::unique_ptr<VehicleLink> link = make_lockstep_link(*bus, 0, model.facts());
  expect_starts_moving(*link);
  ASSERT_NE(server.vehicle(0), nullptr);
  EXPECT_EQ(server.vehicle(0)->step_count, 0);  // reset last
}

TEST(VehicleLink, BothLinksDrawTheStartsSensorNoiseOnlyInProcessTakesEventsMidRun) {
  const sim::VehicleModel model = nessie();
  EpisodeStart start = moving_start();
  start.sensor_noise.position_sigma_m = 0.5;
  start.seed = 7;
  std::unique_ptr<VehicleLink> in_process = make_in_process_link(model);
  const std::optional<VehicleReport> local = in_process->reset(start);
  ASSERT_TRUE(local.has_value());
  EXPECT_GT((local->observation.position_ned_m - start.position_ned_m).norm(), 1e-3);

  std::unique_ptr<transport::Transport> bus = transport::make_in_process_transport();
  sim::SimServerConfig config;
  config.heartbeat_period_s = 3600;
  sim::SimServer server(model, *bus, config);
  std::unique_ptr<VehicleLink> lockstep = make_lockstep_link(*bus, 0, model.facts());
  const std::optional<VehicleReport> remote = lockstep->reset(start);
  ASSERT_TRUE(remote.has_value());
  // The same noise from the same seed: the wire carries the sigmas.
  EXPECT_TRUE(remote->observation.position_ned_m.isApprox(local->observation.position_ned_m, 1e-9));

  EXPECT_TRUE(in_process->set_thruster_efficiency(std::vector<double>(6, 0.5)));
  EXPECT_TRUE(in_process->set_current(Eigen::Vector3d(0.1, 0.0, 0.0)));
  EXPECT_THROW(in_process->set_thruster_efficiency(std::vector<double>(6, 1.5)),
               std::invalid_argument);
  EXPECT_FALSE(lockstep->set_thruster_efficiency(std::vector<double>(6, 0.5)));
  EXPECT_FALSE(lockstep->set_current(Eigen::Vector3d(0.1, 0.0, 0.0)));
}

// What training's randomisation draws (a weak thruster, a current, a wrong model) reaches auv_sim
// through the lockstep link: the same episode as in process, step for step.
TEST(VehicleLink, BothLinksRunTheSameVariedEpisode) {
  const sim::VehicleModel model = nessie();
  EpisodeStart start = moving_start();
  start.thruster_efficiency = {0.7, 0.1, 0.7, 0.7, 0.7, 0.7};
  start.current_ned_mps = Eigen::Vector3d(0.2, -0.3, 0.0);
  start.current_varying_sigma_mps = 0.05;
  start.current_varying_time_constant_s = 30.0;
  start.current_varying_direction_rad = 1.0;
  start.model_variation.quadratic_damping_scale = 0.6;
  start.model_variation.added_mass_scale = 1.5;
  start.model_variation.mass_scale = 1.2;
  start.model_variation.thruster_lag_time_constant_s = 0.6;
  start.model_variation.extra_buoyancy_n = 19.6;
  start.seed = 11;
  std::unique_ptr<VehicleLink> in_process = make_in_process_link(model);
  std::unique_ptr<transport::Transport> bus = transport::make_in_process_transport();
  sim::SimServerConfig config;
  config.heartbeat_period_s = 3600;
  sim::SimServer server(model, *bus, config);
  std::unique_ptr<VehicleLink> lockstep = make_lockstep_link(*bus, 0, model.facts());
  // Twice: the second episode reuses the simulator's varied model.
  for (int episode = 0; episode < 2; ++episode) {
    ASSERT_TRUE(in_process->reset(start).has_value());
    ASSERT_TRUE(lockstep->reset(start).has_value());
    std::optional<VehicleReport> local, remote;
    for (int k = 0; k < 30; ++k) {
      const std::vector<double> thrust = {30, 30, -10, 10, 5, -5};
      local = in_process->step(thrust);
      remote = lockstep->step(thrust);
      ASSERT_TRUE(local.has_value() && remote.has_value());
    }
    EXPECT_TRUE(
        remote->observation.position_ned_m.isApprox(local->observation.position_ned_m, 1e-12));
    EXPECT_TRUE(remote->observation.velocity_body_mps.isApprox(local->observation.velocity_body_mps,
                                                               1e-12));
    EXPECT_EQ(remote->thrust_realised_n, local->thrust_realised_n);
    // T2 at 10 %: its realised thrust is a seventh of T1's (both commanded 30 N).
    EXPECT_NEAR(remote->thrust_realised_n[1], remote->thrust_realised_n[0] / 7.0, 1e-9);
  }
  // The same start without the variation steps differently.
  EpisodeStart plain = start;
  plain.model_variation = sim::ModelVariation{};
  ASSERT_TRUE(lockstep->reset(plain).has_value());
  ASSERT_TRUE(in_process->reset(start).has_value());
  std::optional<VehicleReport> local, remote;
  for (int k = 0; k < 30; ++k) {
    local = in_process->step(std::vector<double>(6, 20.0));
    remote = lockstep->step(std::vector<double>(6, 20.0));
  }
  EXPECT_GT((remote->observation.position_ned_m - local->observation.position_ned_m).norm(), 0.01);
}

TEST(VehicleLink, LockstepLinkRefusesAnotherVehicleNamingBoth) {
  const sim::VehicleModel served =
      sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/bluerov2_heavy.yaml");
  const sim::VehicleModel expected = nessie();
  std::unique_ptr<transport::Transport> bus = transport::make_in_process_transport();
  sim::SimServerConfig config;
  config.heartbeat_period_s = 3600;
  sim::SimServer server(served, *bus, config);
  std::unique_ptr<VehicleLink> link = make_lockstep_link(*bus, 0, expected.facts());
  try {
    link->reset(EpisodeStart{});
    FAIL() << "a reset answered by another vehicle was accepted";
  } catch (const UnrecoverableFault& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'nessie7'"), std::string::npos) << what;
    EXPECT_NE(what.find("nessie7.yaml: 6 thrusters"), std::string::npos) << what;
    EXPECT_NE(what.find("'bluerov2_heavy' (8 thrusters"), std::string::npos) << what;
  }
}

TEST(VehicleLink, LockstepLinkRefusesTheSameNameFromAnotherFile) {
  // An edited copy of the file: same name and thrusters, other bytes (another model).
  sim::VehicleModel served = nessie();
  served.file_crc32 ^= 1u;
  const sim::VehicleModel expected = nessie();
  std::unique_ptr<transport::Transport> bus = transport::make_in_process_transport();
  sim::SimServerConfig config;
  config.heartbeat_period_s = 3600;
  sim::SimServer server(served, *bus, config);
  std::unique_ptr<VehicleLink> link = make_lockstep_link(*bus, 0, expected.facts());
  EXPECT_THROW(link->reset(EpisodeStart{}), UnrecoverableFault);
}

}  // namespace
}  // namespace auvrl::agent
