// auv_sim as a real process in a private network namespace: a client resets a vehicle, sends
// 1000 lockstep commands and receives 1000 states that match the in-process library step for
// step; malformed messages are dropped and counted; repeats are answered without a step.
#include <gtest/gtest.h>

#include <auvrl_lcm/sim_heartbeat_t.hpp>
#include <cmath>
#include <random>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/sim_client.hpp"
#include "sim/sim_server.hpp"

namespace {

using namespace auvrl;
using test_support::ChildProcess;

const std::string kVehicleFile = std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml";

class SimProcess : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test_support::make_temp_dir("auvrl_sim_process_");
    sim_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{test_support::bin_path("auv_sim"), "--vehicle", kVehicleFile,
                                 "--vehicles", "3", "--heartbeat-period", "0.1"},
        dir_ + "/auv_sim.log");
    transport_ = transport::make_transport({});
    heartbeat_ = std::make_unique<transport::Latest<auvrl_lcm::sim_heartbeat_t>>(
        *transport_, channels::kSimHeartbeat);
    ASSERT_TRUE(wait_heartbeat([](const auto&) { return true; })) << sim_->log();
  }

  /// Waits (up to 5 s) for a heartbeat that satisfies pred.
  template <class Pred>
  bool wait_heartbeat(Pred pred) {
    for (int i = 0; i < 100; ++i) {
      transport_->handle(50);
      if (auto hb = heartbeat_->take(); hb && pred(*hb)) {
        last_heartbeat_ = *hb;
        return true;
      }
    }
    return false;
  }

  std::string dir_;
  std::unique_ptr<ChildProcess> sim_;
  std::unique_ptr<transport::Transport> transport_;
  std::unique_ptr<transport::Latest<auvrl_lcm::sim_heartbeat_t>> heartbeat_;
  auvrl_lcm::sim_heartbeat_t last_heartbeat_{};
};

auvrl_lcm::vehicle_reset_t test_reset() {
  auvrl_lcm::vehicle_reset_t reset{};
  reset.seed = 42;
  reset.position_ned_m[2] = 5.0;
  reset.euler_rpy_rad[2] = 0.3;
  reset.velocity_body_mps[0] = 0.2;
  reset.current_constant_ned_mps[1] = 0.1;
  // A varying current makes the check cover the seeded random stream too.
  reset.current_gm_mean_speed_mps = 0.05;
  reset.current_gm_sigma_mps = 0.02;
  reset.current_gm_time_constant_s = 20.0;
  reset.current_gm_direction_sigma_rad = 0.1;
  return reset;
}

TEST_F(SimProcess, ThousandLockstepStepsMatchTheLibrary) {
  const sim::VehicleModel model = sim::load_vehicle_file(kVehicleFile);
  SimClient client(*transport_, 1);
  const auvrl_lcm::vehicle_reset_t reset_msg = test_reset();
  auto first = client.reset(reset_msg);
  ASSERT_TRUE(first.has_value()) << sim_->log();
  EXPECT_EQ(first->step_count, 0);

  sim::ResetSettings settings;
  ASSERT_EQ(sim::reset_settings_from_message(reset_msg, model.num_thrusters(), settings), "");
  sim::VehicleState local = sim::make_state(model, settings);

  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> thrust(-40.0, 40.0);
  std::vector<double> command(static_cast<std::size_t>(model.num_thrusters()));
  double max_difference = 0.0;
  for (int k = 1; k <= 1000; ++k) {
    for (double& f : command) f = thrust(rng);
    auto remote = client.step(command);
    ASSERT_TRUE(remote.has_value()) << "no answer to step " << k << "\n" << sim_->log();
    sim::step(model, local,
              Eigen::Map<const Eigen::VectorXd>(command.data(), model.num_thrusters()));
    const sim::Measurement m = sim::measure(model, local);
    ASSERT_EQ(remote->step_count, k);
    ASSERT_EQ(remote->status, 0);
    for (int i = 0; i < 3; ++i) {
      max_difference = std::max({max_difference, std::abs(remote->position_ned_m[i] - m.eta[i]),
                                 std::abs(remote->euler_rpy_rad[i] - m.eta[3 + i]),
                                 std::abs(remote->velocity_body_mps[i] - m.nu[i]),
                                 std::abs(remote->angular_rate_body_rad_s[i] - m.nu[3 + i])});
    }
    ASSERT_EQ(remote->num_thrusters, model.num_thrusters());
    for (int i = 0; i < model.num_thrusters(); ++i) {
      max_difference =
          std::max(max_difference, std::abs(remote->thrust_realised_n[i] - m.thrust_realised_n[i]));
    }
    ASSERT_LE(max_difference, 1e-9) << "diverged at step " << k;
  }
  // The same code on the same inputs: the process and the library agree to the last bit.
  EXPECT_EQ(max_difference, 0.0);
  EXPECT_EQ(client.retries(), 0);
  ASSERT_TRUE(wait_heartbeat([](const auto& hb) { return hb.steps_total >= 1000; }));
  EXPECT_EQ(last_heartbeat_.steps_total, 1000);
  EXPECT_EQ(last_heartbeat_.resets_total, 1);
  EXPECT_EQ(last_heartbeat_.num_vehicles, 3);
  EXPECT_TRUE(last_heartbeat_.lockstep);
}

TEST_F(SimProcess, MalformedMessagesAreDroppedAndCounted) {
  SimClient client(*transport_, 0);
  ASSERT_TRUE(client.reset(test_reset()).has_value());

  auvrl_lcm::thruster_cmd_t cmd{};
  cmd.num_thrusters = 6;
  cmd.thrust_n.assign(6, 1.0);
  cmd.seq = INT64_MAX - 1;
  cmd.vehicle_id = 7;  // unknown vehicle
  transport::publish(*transport_, channels::sim_command(7), cmd);
  cmd.vehicle_id = 1;  // id not matching the channel
  transport::publish(*transport_, channels::sim_command(0), cmd);
  cmd.vehicle_id = 0;
  cmd.num_thrusters = 5;  // wrong thruster count
  cmd.thrust_n.assign(5, 1.0);
  transport::publish(*transport_, channels::sim_command(0), cmd);
  cmd.num_thrusters = 6;
  cmd.thrust_n.assign(6, std::nan(""));
  transport::publish(*transport_, channels::sim_command(0), cmd);
  cmd.vehicle_id = 2;  // valid but never reset
  cmd.thrust_n.assign(6, 1.0);
  transport::publish(*transport_, channels::sim_command(2), cmd);
  auvrl_lcm::thruster_fault_t fault{};
  fault.vehicle_id = 0;
  fault.num_thrusters = 6;
  fault.thruster_efficiency.assign(6, 1.5);  // outside [0, 1]
  transport::publish(*transport_, channels::sim_fault(0), fault);
  const std::uint8_t garbage[3] = {1, 2, 3};
  transport_->publish(channels::sim_command(0), garbage, sizeof garbage);

  ASSERT_TRUE(wait_heartbeat([](const auto& hb) {
    return hb.dropped_vehicle_id >= 2 && hb.dropped_thrusters >= 1 && hb.dropped_non_finite >= 1 &&
           hb.dropped_not_reset >= 1 && hb.dropped_out_of_range >= 1 && hb.dropped_decode >= 1;
  })) << "counters: vehicle_id "
      << last_heartbeat_.dropped_vehicle_id;
  EXPECT_EQ(last_heartbeat_.steps_total, 0);
  EXPECT_TRUE(sim_->running());

  // The vehicle still works after all that.
  auto state = client.step(std::vector<double>(6, 10.0));
  ASSERT_TRUE(state.has_value());
  EXPECT_EQ(state->step_count, 1);
}

TEST_F(SimProcess, RepeatedCommandIsAnsweredWithoutASecondStep) {
  SimClient client(*transport_, 0);
  ASSERT_TRUE(client.reset(test_reset()).has_value());
  auto a = client.step(std::vector<double>(6, 20.0));
  ASSERT_TRUE(a.has_value());

  // Resend the same seq by hand: the answer is the same state, and no step is taken.
  std::optional<auvrl_lcm::vehicle_state_t> again;
  auto sub = transport::subscribe<auvrl_lcm::vehicle_state_t>(
      *transport_, channels::sim_state(0),
      [&](const std::string&, const auvrl_lcm::vehicle_state_t& s) { again = s; });
  auvrl_lcm::thruster_cmd_t cmd{};
  cmd.vehicle_id = 0;
  cmd.seq = a->seq;
  cmd.num_thrusters = 6;
  cmd.thrust_n.assign(6, -20.0);
  transport::publish(*transport_, channels::sim_command(0), cmd);
  for (int i = 0; i < 40 && !again; ++i) transport_->handle(50);
  transport_->unsubscribe(sub);
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(again->step_count, 1);
  EXPECT_EQ(again->position_ned_m[0], a->position_ned_m[0]);
  ASSERT_TRUE(wait_heartbeat([](const auto& hb) { return hb.duplicates_answered >= 1; }));
  EXPECT_EQ(last_heartbeat_.steps_total, 1);
}

TEST_F(SimProcess, LiveFaultScalesTheThruster) {
  SimClient client(*transport_, 0);
  ASSERT_TRUE(client.reset(test_reset()).has_value());
  auvrl_lcm::thruster_fault_t fault{};
  fault.vehicle_id = 0;
  fault.num_thrusters = 6;
  fault.thruster_efficiency = {0.1, 1, 1, 1, 1, 1};
  transport::publish(*transport_, channels::sim_fault(0), fault);
  ASSERT_TRUE(wait_heartbeat([](const auto& hb) { return hb.faults_total >= 1; }));
  std::optional<auvrl_lcm::vehicle_state_t> state;
  for (int k = 0; k < 100; ++k) state = client.step(std::vector<double>(6, 30.0));
  ASSERT_TRUE(state.has_value());
  // After 10 s of a constant command every thruster has settled; T1 gives 10 % of T2.
  EXPECT_NEAR(state->thrust_realised_n[0], 0.1 * state->thrust_realised_n[1], 1e-6);
  EXPECT_NEAR(state->thrust_realised_n[1], 30.0, 1e-3);
}

TEST_F(SimProcess, StopsCleanlyOnSigterm) {
  const int status = sim_->terminate();
  ASSERT_TRUE(WIFEXITED(status)) << sim_->log();
  EXPECT_EQ(WEXITSTATUS(status), 0) << sim_->log();
}

}  // namespace

namespace {

TEST(SimProcessRealTime, StepsAtWallClockRateWithTheLatestCommand) {
  const std::string dir = test_support::make_temp_dir("auvrl_sim_realtime_");
  ChildProcess sim({test_support::bin_path("auv_sim"), "--vehicle", kVehicleFile, "--realtime",
                    "--vehicles", "1"},
                   dir + "/auv_sim.log");
  auto transport = transport::make_transport({});
  std::vector<auvrl_lcm::vehicle_state_t> states;
  transport::subscribe<auvrl_lcm::vehicle_state_t>(
      *transport, channels::sim_state(0),
      [&](const std::string&, const auvrl_lcm::vehicle_state_t& s) { states.push_back(s); });
  auvrl_lcm::vehicle_reset_t reset = test_reset();
  reset.vehicle_id = 0;
  reset.seq = 1;
  // auv_sim may still be starting: reset until it answers.
  for (int i = 0; i < 50 && states.empty(); ++i) {
    transport::publish(*transport, channels::sim_reset(0), reset);
    transport->handle(100);
  }
  ASSERT_FALSE(states.empty()) << sim.log();
  auvrl_lcm::thruster_cmd_t cmd{};
  cmd.vehicle_id = 0;
  cmd.seq = 2;
  cmd.num_thrusters = 6;
  cmd.thrust_n = {30, 30, 0, 0, 0, 0};
  transport::publish(*transport, channels::sim_command(0), cmd);
  states.clear();
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - start < std::chrono::seconds(2)) transport->handle(50);
  // 2 s of wall clock at 0.1 s per step: about 20 states, each one step further.
  EXPECT_GE(states.size(), 17u) << sim.log();
  EXPECT_LE(states.size(), 23u) << sim.log();
  for (std::size_t i = 1; i < states.size(); ++i) {
    EXPECT_EQ(states[i].step_count, states[i - 1].step_count + 1);
  }
  // The held command drives the vehicle forward.
  EXPECT_GT(states.back().velocity_body_mps[0], states.front().velocity_body_mps[0]);
}

}  // namespace
