// The client side of auv_sim's lockstep protocol, for actors, evaluation and tests: reset a
// vehicle, send a thrust command, wait for the state that answers it. Retries are safe because
// auv_sim answers a repeated sequence number with the same state instead of stepping again.
#pragma once

#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/vehicle_reset_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <cstdint>
#include <optional>
#include <vector>

#include "common/transport.hpp"

namespace auvrl {

/// How long to wait for an answer, and how often to ask again.
struct LockstepTiming {
  int timeout_ms = 200;  ///< per attempt
  int attempts = 5;      ///< total attempts before giving up
};

/// Drives one vehicle of auv_sim in lockstep.
class SimClient {
 public:
  SimClient(transport::Transport& transport, int vehicle_id, LockstepTiming timing = {});
  ~SimClient();
  SimClient(const SimClient&) = delete;
  SimClient& operator=(const SimClient&) = delete;

  /// Resets the vehicle (msg.vehicle_id and msg.seq are filled in) and returns the answering
  /// state, or nothing if auv_sim did not answer in time.
  std::optional<auvrl_lcm::vehicle_state_t> reset(auvrl_lcm::vehicle_reset_t msg);

  /// Commands thrust (N, one per thruster) for one control step and returns the new state, or
  /// nothing if auv_sim did not answer in time.
  std::optional<auvrl_lcm::vehicle_state_t> step(const std::vector<double>& thrust_n);

  int vehicle_id() const { return vehicle_id_; }
  std::int64_t retries() const { return retries_; }
  std::int64_t timeouts() const { return timeouts_; }

 private:
  template <class Msg>
  std::optional<auvrl_lcm::vehicle_state_t> request(const std::string& channel, const Msg& msg);

  transport::Transport& transport_;
  int vehicle_id_;
  LockstepTiming timing_;
  transport::SubscriptionId subscription_ = -1;
  std::int64_t next_seq_;
  std::int64_t awaited_seq_ = -1;
  std::optional<auvrl_lcm::vehicle_state_t> answer_;
  auvrl_lcm::thruster_cmd_t command_;
  std::string command_channel_;
  std::int64_t retries_ = 0;
  std::int64_t timeouts_ = 0;
};

}  // namespace auvrl
