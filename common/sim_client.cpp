#include "common/sim_client.hpp"

#include <chrono>

#include "common/channels.hpp"

namespace auvrl {

SimClient::SimClient(transport::Transport& transport, int vehicle_id, LockstepTiming timing)
    : transport_(transport),
      vehicle_id_(vehicle_id),
      timing_(timing),
      // Start above any sequence number an earlier client of this vehicle used, so that
      // auv_sim never mistakes a new command for a stale one.
      next_seq_(transport::now_utime()) {
  subscription_ = transport::subscribe<auvrl_lcm::vehicle_state_t>(
      transport_, channels::sim_state(vehicle_id),
      [this](const std::string&, const auvrl_lcm::vehicle_state_t& state) {
        if (state.seq == awaited_seq_ && state.vehicle_id == vehicle_id_) answer_ = state;
      });
  command_.vehicle_id = vehicle_id;
  command_channel_ = channels::sim_command(vehicle_id);
}

SimClient::~SimClient() { transport_.unsubscribe(subscription_); }

template <class Msg>
std::optional<auvrl_lcm::vehicle_state_t> SimClient::request(const std::string& channel,
                                                             const Msg& msg) {
  using Clock = std::chrono::steady_clock;
  answer_.reset();
  awaited_seq_ = msg.seq;
  for (int attempt = 0; attempt < timing_.attempts; ++attempt) {
    if (attempt > 0) ++retries_;
    transport::publish(transport_, channel, msg);
    const auto deadline = Clock::now() + std::chrono::milliseconds(timing_.timeout_ms);
    while (!answer_) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (left <= 0) break;
      transport_.handle_one(static_cast<int>(left));
    }
    if (answer_) return std::move(answer_);
  }
  ++timeouts_;
  return std::nullopt;
}

std::optional<auvrl_lcm::vehicle_state_t> SimClient::reset(auvrl_lcm::vehicle_reset_t msg) {
  msg.vehicle_id = vehicle_id_;
  msg.seq = ++next_seq_;
  msg.utime = transport::now_utime();
  return request(channels::sim_reset(vehicle_id_), msg);
}

std::optional<auvrl_lcm::vehicle_state_t> SimClient::step(const std::vector<double>& thrust_n) {
  command_.seq = ++next_seq_;
  command_.utime = transport::now_utime();
  command_.num_thrusters = static_cast<std::int8_t>(thrust_n.size());
  command_.thrust_n = thrust_n;
  return request(command_channel_, command_);
}

}  // namespace auvrl
