#include "logger/bridge.hpp"

namespace auvrl::logger {

Bridge::Bridge(transport::Transport& from, transport::Transport& to, BridgeConfig config)
    : from_(from), to_(to) {
  subscription_ = from_.subscribe(
      config.channels,
      [this](const transport::RawMessage& m) {
        try {
          to_.publish(m.channel, m.data, m.size);
          ++forwarded_;
          bytes_ += static_cast<std::int64_t>(m.size);
        } catch (const transport::TransportError&) {
          ++failed_;
        }
      },
      config.queue_capacity);
}

Bridge::~Bridge() { from_.unsubscribe(subscription_); }

int Bridge::poll(int timeout_ms) {
  const std::int64_t before = forwarded_;
  from_.handle(timeout_ms);
  return static_cast<int>(forwarded_ - before);
}

}  // namespace auvrl::logger
