// auv_sim's handling of hostile messages with a valid LCM encoding, in-process (memq): wrong
// thruster counts, NaN and inf, out-of-range values, unknown or mismatched vehicle ids, stale
// sequence numbers and undecodable bytes are dropped and counted, and never change a vehicle. A
// reset that varies the model gives that vehicle its own dynamics, until a reset says otherwise.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/channels.hpp"
#include "common/transport.hpp"
#include "sim/model_variation.hpp"
#include "sim/sim_server.hpp"
#include "sim/vehicle_model.hpp"

namespace {

using namespace auvrl;

constexpr double kInf = std::numeric_limits<double>::infinity();

class SimServerInput : public ::testing::Test {
 protected:
  SimServerInput()
      : model_(sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml")),
        transport_(transport::make_in_process_transport()),
        server_(model_, *transport_, config()) {}

  static sim::SimServerConfig config() {
    sim::SimServerConfig c;
    c.num_vehicles = 2;
    c.heartbeat_period_s = 3600;
    return c;
  }
  static auvrl_lcm::vehicle_reset_t reset(int id, std::int64_t seq = 1) {
    auvrl_lcm::vehicle_reset_t m{};
    m.vehicle_id = id;
    m.seq = seq;
    m.position_ned_m[2] = 5.0;
    m.current_gm_time_constant_s = 10.0;
    return m;
  }
  static auvrl_lcm::thruster_cmd_t command(int id, std::int64_t seq, double thrust = 10.0) {
    auvrl_lcm::thruster_cmd_t m{};
    m.vehicle_id = id;
    m.seq = seq;
    m.num_thrusters = 6;
    m.thrust_n.assign(6, thrust);
    return m;
  }
  template <class Msg>
  void send(const std::string& channel, const Msg& msg) {
    transport::publish(*transport_, channel, msg);
    server_.poll(0);
    transport_->drain();
  }
  std::int64_t steps(int id) const { return server_.vehicle(id)->step_count; }

  sim::VehicleModel model_;
  std::unique_ptr<transport::Transport> transport_;
  sim::SimServer server_;
};

TEST_F(SimServerInput, WrongThrusterCountsAreDroppedAndCounted) {
  send(channels::sim_reset(0), reset(0));
  auto cmd = command(0, 2);
  cmd.num_thrusters = 5;
  cmd.thrust_n.resize(5);
  send(channels::sim_command(0), cmd);
  auvrl_lcm::thruster_fault_t fault{};
  fault.num_thrusters = 7;
  fault.thruster_efficiency.assign(7, 0.5);
  send(channels::sim_fault(0), fault);
  auto bad_reset = reset(1);
  bad_reset.num_thrusters = 3;
  bad_reset.thruster_efficiency.assign(3, 1.0);
  send(channels::sim_reset(1), bad_reset);
  const auto c = server_.counters();
  EXPECT_EQ(c.dropped_thrusters, 3);
  EXPECT_EQ(c.steps_total, 0);
  EXPECT_EQ(c.faults_total, 0);
  EXPECT_EQ(server_.vehicle(1), nullptr) << "a refused reset must not activate the vehicle";
  EXPECT_DOUBLE_EQ(server_.vehicle(0)->thruster_efficiency.minCoeff(), 1.0);
}

TEST_F(SimServerInput, NanAndInfAnywhereAreDroppedAndNeverApplied) {
  send(channels::sim_reset(0), reset(0));
  const sim::Vector6 eta_before = server_.vehicle(0)->eta;
  auto cmd = command(0, 2);
  cmd.thrust_n[3] = std::nan("");
  send(channels::sim_command(0), cmd);
  cmd = command(0, 3);
  cmd.thrust_n[0] = -kInf;
  send(channels::sim_command(0), cmd);
  auto r = reset(0, 4);
  r.position_ned_m[1] = kInf;
  send(channels::sim_reset(0), r);
  r = reset(0, 5);
  r.noise_attitude_rad = std::nan("");
  send(channels::sim_reset(0), r);
  auvrl_lcm::thruster_fault_t fault{};
  fault.num_thrusters = 6;
  fault.thruster_efficiency = {1, 1, std::nan(""), 1, 1, 1};
  send(channels::sim_fault(0), fault);
  const auto c = server_.counters();
  EXPECT_EQ(c.dropped_non_finite, 5);
  EXPECT_EQ(c.steps_total, 0);
  EXPECT_EQ(c.resets_total, 1);
  EXPECT_EQ(c.faults_total, 0);
  EXPECT_EQ(steps(0), 0);
  EXPECT_EQ(server_.vehicle(0)->eta, eta_before);
  // The vehicle still steps on a good command.
  send(channels::sim_command(0), command(0, 6));
  EXPECT_EQ(steps(0), 1);
}

TEST_F(SimServerInput, OutOfRangeResetAndFaultValuesAreDropped) {
  send(channels::sim_reset(0), reset(0));
  auto r = reset(0, 2);
  r.noise_position_m = -0.1;  // negative standard deviation
  send(channels::sim_reset(0), r);
  r = reset(0, 3);
  r.current_gm_time_constant_s = 0.0;  // a varying current without a time constant
  r.current_gm_sigma_mps = 0.1;
  send(channels::sim_reset(0), r);
  r = reset(0, 4);
  r.num_thrusters = 6;
  r.thruster_efficiency = {1, 1, 1, 1, 1, -0.5};
  send(channels::sim_reset(0), r);
  auvrl_lcm::thruster_fault_t fault{};
  fault.num_thrusters = 6;
  fault.thruster_efficiency = {1, 1, 1, 1e9, 1, 1};
  send(channels::sim_fault(0), fault);
  const auto c = server_.counters();
  EXPECT_EQ(c.dropped_out_of_range, 4);
  EXPECT_EQ(c.resets_total, 1);
  EXPECT_EQ(c.faults_total, 0);
}

// A live current change (water_current_t, what `auvrl run` injects for a mission's current event)
// sets the constant current of a running vehicle; NaN, a vehicle never reset and a mismatched id
// are dropped and counted.
TEST_F(SimServerInput, LiveCurrentChangesApplyAndBadOnesAreDropped) {
  auvrl_lcm::water_current_t current{};
  current.vehicle_id = 0;
  current.current_constant_ned_mps[0] = 0.3;
  send(channels::sim_current(0), current);  // before any reset
  EXPECT_EQ(server_.counters().dropped_not_reset, 1);
  send(channels::sim_reset(0), reset(0));
  send(channels::sim_current(0), current);
  const sim::VehicleState* vehicle = server_.vehicle(0);
  EXPECT_EQ(vehicle->current.constant_velocity_ned_mps, Eigen::Vector3d(0.3, 0.0, 0.0));
  EXPECT_EQ(vehicle->current_velocity_ned_mps, Eigen::Vector3d(0.3, 0.0, 0.0));
  current.current_constant_ned_mps[1] = std::nan("");
  send(channels::sim_current(0), current);
  current.current_constant_ned_mps[1] = 0.0;
  current.vehicle_id = 1;  // on vehicle 0's channel
  send(channels::sim_current(0), current);
  const auto c = server_.counters();
  EXPECT_EQ(c.currents_total, 1);
  EXPECT_EQ(c.dropped_non_finite, 1);
  EXPECT_EQ(c.dropped_vehicle_id, 1);
  EXPECT_EQ(vehicle->current.constant_velocity_ned_mps, Eigen::Vector3d(0.3, 0.0, 0.0));
}

TEST_F(SimServerInput, UnknownAndMismatchedVehicleIdsAreDropped) {
  send(channels::sim_reset(0), reset(0));
  send(channels::sim_reset(2), reset(2));                 // past the served range
  send(channels::sim_command(99999), command(99999, 2));  // far out
  send(channels::sim_command(1), command(0, 2));          // id not matching the channel
  send("SIM_CMD_99999999999999999999", command(0, 2));    // id that overflows an int
  auto negative = command(-1, 2);
  send(channels::sim_command(0), negative);
  const auto c = server_.counters();
  EXPECT_EQ(c.dropped_vehicle_id, 5);
  EXPECT_EQ(c.steps_total, 0);
  EXPECT_EQ(steps(0), 0);
}

TEST_F(SimServerInput, StaleUnresetAndUndecodableMessagesAreDropped) {
  send(channels::sim_command(1), command(1, 2));  // vehicle 1 never reset
  send(channels::sim_reset(0), reset(0, 10));
  send(channels::sim_command(0), command(0, 9));  // older than the reset
  const std::uint8_t garbage[7] = {0xde, 0xad, 0xbe, 0xef, 0, 1, 2};
  transport_->publish(channels::sim_command(0), garbage, sizeof garbage);
  server_.poll(0);
  // A command whose thrust_n claims more elements than the message holds.
  auto cmd = command(0, 11);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(cmd.getEncodedSize()));
  cmd.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  bytes.resize(bytes.size() - 8);
  transport_->publish(channels::sim_command(0), bytes.data(), bytes.size());
  server_.poll(0);
  const auto c = server_.counters();
  EXPECT_EQ(c.dropped_not_reset, 1);
  EXPECT_EQ(c.dropped_stale, 1);
  EXPECT_EQ(c.dropped_decode, 2);
  EXPECT_EQ(c.steps_total, 0);
}

/// A reset of vehicle id whose model has 1.5 x the drag and 19.6 N (2 kg) of extra buoyancy.
auvrl_lcm::vehicle_reset_t varied_reset(int id, std::int64_t seq) {
  auvrl_lcm::vehicle_reset_t m{};
  m.vehicle_id = id;
  m.seq = seq;
  m.position_ned_m[2] = 5.0;
  m.model_varied = true;
  m.model_quadratic_damping_scale = 1.5;
  m.model_added_mass_scale = 1.0;
  m.model_mass_scale = 1.0;
  m.model_thruster_lag_time_constant_s = -1.0;  // the file's
  m.model_extra_buoyancy_n = 19.6;
  return m;
}

// Two vehicles driven alike: the varied one is slower and rises, exactly as the dynamics library
// steps that variation of the file's model; the next plain reset gives the file's model back.
TEST_F(SimServerInput, AVariedResetGivesThatVehicleItsOwnDynamicsUntilTheNextReset) {
  send(channels::sim_reset(0), reset(0));
  send(channels::sim_reset(1), varied_reset(1, 1));
  sim::ModelVariation variation;
  variation.quadratic_damping_scale = 1.5;
  variation.extra_buoyancy_n = 19.6;
  const sim::VehicleModel varied = sim::vary_model(model_, variation);
  sim::ResetSettings settings;
  settings.eta[2] = 5.0;
  sim::VehicleState local = sim::make_state(varied, settings);
  sim::ThrusterVector thrust = sim::ThrusterVector::Zero(6);
  thrust.head(2).setConstant(30.0);  // both surge thrusters
  for (int k = 2; k < 52; ++k) {
    auto cmd = command(0, k, 0.0);
    cmd.thrust_n = {30.0, 30.0, 0, 0, 0, 0};
    send(channels::sim_command(0), cmd);
    cmd.vehicle_id = 1;
    send(channels::sim_command(1), cmd);
    sim::step(varied, local, thrust);
  }
  const sim::VehicleState& nominal = *server_.vehicle(0);
  const sim::VehicleState& remote = *server_.vehicle(1);
  EXPECT_EQ(remote.eta, local.eta);
  EXPECT_EQ(remote.nu, local.nu);
  EXPECT_LT(remote.nu[0], nominal.nu[0] - 0.05) << "more drag: slower";
  EXPECT_LT(remote.eta[2], nominal.eta[2] - 0.1) << "more buoyancy: shallower";

  // A plain reset (model_varied false) is the file's model again: both vehicles step alike.
  send(channels::sim_reset(0), reset(0, 100));
  send(channels::sim_reset(1), reset(1, 100));
  for (int k = 101; k < 111; ++k) {
    send(channels::sim_command(0), command(0, k));
    send(channels::sim_command(1), command(1, k));
  }
  EXPECT_EQ(server_.vehicle(0)->eta, server_.vehicle(1)->eta);
  EXPECT_EQ(server_.counters().resets_total, 4);
}

// A variation that is not finite or has a scale not above 0 is dropped (counted like the other
// reset fields) and leaves the vehicle as it was; with model_varied false the fields are ignored.
TEST_F(SimServerInput, BadModelVariationsAreDroppedAndCounted) {
  send(channels::sim_reset(0), varied_reset(0, 1));
  const sim::Vector6 eta_before = server_.vehicle(0)->eta;
  auto r = varied_reset(0, 2);
  r.model_mass_scale = std::nan("");
  send(channels::sim_reset(0), r);
  r = varied_reset(0, 3);
  r.model_extra_buoyancy_n = kInf;
  send(channels::sim_reset(0), r);
  r = varied_reset(0, 4);
  r.model_added_mass_scale = 0.0;  // as a zero-initialised field would be
  send(channels::sim_reset(0), r);
  r = varied_reset(0, 5);
  r.model_quadratic_damping_scale = -1.5;
  send(channels::sim_reset(0), r);
  auto c = server_.counters();
  EXPECT_EQ(c.dropped_non_finite, 2);
  EXPECT_EQ(c.dropped_out_of_range, 2);
  EXPECT_EQ(c.resets_total, 1);
  EXPECT_EQ(server_.vehicle(0)->eta, eta_before);
  // The varied model stays: it still rises faster than the file's vehicle would.
  send(channels::sim_reset(1), reset(1));
  for (int k = 2; k < 32; ++k) {
    send(channels::sim_command(0), command(0, k, 0.0));
    send(channels::sim_command(1), command(1, k, 0.0));
  }
  EXPECT_LT(server_.vehicle(0)->eta[2], server_.vehicle(1)->eta[2] - 0.05);

  r = reset(0, 40);  // model_varied false: the zero scales mean nothing
  r.model_mass_scale = std::nan("");
  send(channels::sim_reset(0), r);
  c = server_.counters();
  EXPECT_EQ(c.resets_total, 3);
  EXPECT_EQ(c.dropped_non_finite, 2);
}

}  // namespace
