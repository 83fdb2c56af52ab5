// auv_sim's logic: K simulated vehicles served over the transport. Lockstep mode (training):
// a command for vehicle i advances vehicle i one control step and publishes its state.
// Real-time mode (deployment, demos): every vehicle steps at wall-clock rate with its latest
// command. Physics only: no reward, no goal.
#pragma once

#include <auvrl_lcm/sim_heartbeat_t.hpp>
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/thruster_fault_t.hpp>
#include <auvrl_lcm/vehicle_reset_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <auvrl_lcm/water_current_t.hpp>
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "common/transport.hpp"
#include "sim/dynamics.hpp"
#include "sim/model_variation.hpp"

namespace auvrl::sim {

/// How auv_sim serves its vehicles.
struct SimServerConfig {
  int num_vehicles = 1;
  /// Vehicle ids served: first_vehicle_id .. first_vehicle_id + num_vehicles - 1 (several
  /// auv_sim processes on one bus, e.g. one per actor, each pinned beside its actor).
  int first_vehicle_id = 0;
  bool lockstep = true;
  double realtime_factor = 1.0;     ///< real-time mode: simulated seconds per wall second
  double heartbeat_period_s = 1.0;  ///< wall-clock period of SIM_HEARTBEAT
  std::string vehicle_file;         ///< reported in the heartbeat
};

/// Counters reported in the heartbeat (and read by tests).
struct SimServerCounters {
  std::int64_t steps_total = 0;
  std::int64_t resets_total = 0;
  std::int64_t faults_total = 0;
  std::int64_t currents_total = 0;
  std::int64_t blow_ups_total = 0;
  std::int64_t duplicates_answered = 0;
  std::int64_t dropped_decode = 0;
  std::int64_t dropped_vehicle_id = 0;
  std::int64_t dropped_thrusters = 0;
  std::int64_t dropped_non_finite = 0;
  std::int64_t dropped_out_of_range = 0;
  std::int64_t dropped_stale = 0;
  std::int64_t dropped_not_reset = 0;
};

/// Converts a reset message into library reset settings; returns an empty string if valid,
/// else what is wrong (naming the field). num_thrusters is the model's.
std::string reset_settings_from_message(const auvrl_lcm::vehicle_reset_t& msg, int num_thrusters,
                                        ResetSettings& out);

/// The model variation a reset message asks for (the identity when model_varied is false);
/// returns an empty string if usable, else what is wrong, naming the field: "non-finite ..." for
/// NaN or inf, else a value out of range (a scale not > 0).
std::string model_variation_from_message(const auvrl_lcm::vehicle_reset_t& msg,
                                         ModelVariation& out);

/// Fills a state message from a measurement of vehicle id of `model`, answering sequence number
/// seq; the message names the vehicle (name, file CRC-32, thruster count).
void state_message_from_measurement(const VehicleModel& model, const Measurement& measurement,
                                    const VehicleState& state, int vehicle_id, std::int64_t seq,
                                    auvrl_lcm::vehicle_state_t& out);

/// Serves the vehicles of one model over a transport. A reset may vary a vehicle's model
/// (vehicle_reset_t.model_varied): that vehicle then steps and reports with its own varied copy
/// until a reset says otherwise; the copy is built only when the variation changes.
class SimServer {
 public:
  /// Lockstep traffic (commands, resets, faults, states) on `transport`; the heartbeat on
  /// `heartbeat_transport` (the same one, or the system's main bus when each simulator and its
  /// actor have a lockstep bus of their own, so nobody else receives that traffic).
  SimServer(const VehicleModel& model, transport::Transport& transport, SimServerConfig config,
            transport::Transport* heartbeat_transport = nullptr);
  ~SimServer();
  SimServer(const SimServer&) = delete;
  SimServer& operator=(const SimServer&) = delete;

  /// Handles messages for up to timeout_ms; in real-time mode also steps the vehicles that
  /// are due. Publishes the heartbeat when due.
  void poll(int timeout_ms);

  /// Runs until stop() returns true (checked at least every 50 ms).
  template <class StopFn>
  void run(StopFn stop) {
    while (!stop()) poll(config_.lockstep ? 50 : next_realtime_wait_ms());
    publish_heartbeat();
  }

  /// Counters so far (decode failures included).
  SimServerCounters counters() const {
    SimServerCounters c = counters_;
    c.dropped_decode = decode_stats_.failed;
    return c;
  }
  const VehicleState* vehicle(int id) const;

 private:
  struct Vehicle {
    bool active = false;  ///< reset at least once
    VehicleState state;
    ThrusterVector held_command_n;  ///< real-time mode: latest command
    std::int64_t last_seq = 0;
    std::vector<std::uint8_t> last_state_bytes;  ///< re-sent when a command is repeated
    std::string state_channel;                   ///< SIM_STATE_<id>, built once
    ModelVariation variation;                    ///< of the last reset
    std::optional<VehicleModel> varied_model;    ///< the file's model with it; none: identity
  };

  /// The model a vehicle runs: its varied copy, or the file's.
  const VehicleModel& model_of(const Vehicle& vehicle) const {
    return vehicle.varied_model ? *vehicle.varied_model : model_;
  }
  /// Makes the vehicle's model the file's with `variation` (varied again only if it changed);
  /// false (counted) if vary_model refuses it, the vehicle unchanged then.
  bool set_variation(Vehicle& vehicle, const ModelVariation& variation);

  void on_command(const std::string& channel, const auvrl_lcm::thruster_cmd_t& msg);
  void on_reset(const std::string& channel, const auvrl_lcm::vehicle_reset_t& msg);
  void on_fault(const std::string& channel, const auvrl_lcm::thruster_fault_t& msg);
  void on_current(const std::string& channel, const auvrl_lcm::water_current_t& msg);
  /// The vehicle a message addresses, or nullptr (counted) if the id is unknown or does not
  /// match the channel.
  Vehicle* addressed_vehicle(const std::string& channel, int vehicle_id);
  bool thrusters_valid(int num_thrusters, const std::vector<double>& values, bool efficiency);
  void step_vehicle(int id, Vehicle& vehicle, const ThrusterVector& command_n);
  void publish_state(int id, Vehicle& vehicle);
  void realtime_tick();
  int next_realtime_wait_ms() const;
  void publish_heartbeat();

  const VehicleModel& model_;
  transport::Transport& transport_;
  transport::Transport& heartbeat_transport_;
  SimServerConfig config_;
  std::vector<Vehicle> vehicles_;
  SimServerCounters counters_;
  transport::DecodeStats decode_stats_;
  std::vector<transport::SubscriptionId> subscriptions_;
  auvrl_lcm::vehicle_state_t state_msg_;  ///< reused to avoid allocation per step
  std::chrono::steady_clock::time_point next_heartbeat_;
  std::chrono::steady_clock::time_point next_realtime_step_;
  std::chrono::steady_clock::time_point rate_window_start_;
  std::int64_t rate_window_steps_ = 0;
  double steps_per_s_ = 0.0;
};

}  // namespace auvrl::sim
