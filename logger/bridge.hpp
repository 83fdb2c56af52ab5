// Forwards chosen channels from one transport to another, byte for byte: a system running over
// Cyclone DDS shown to LCM tools (lcm-spy, lcm-logger) that only speak LCM. The bytes are the
// same LCM-encoded messages on the same channel names, so nothing needs decoding here.
#pragma once

#include <cstdint>
#include <string>

#include "common/transport.hpp"

namespace auvrl::logger {

/// What a bridge forwards.
struct BridgeConfig {
  /// Full-match regex of the channels to forward.
  std::string channels = ".*";
  /// Messages the source may hold between polls.
  int queue_capacity = 10000;
};

/// Forwards every message on the matching channels of `from` to `to` (one thread: call poll()
/// in a loop). Not a loop guard: bridging both ways between the same buses echoes forever.
class Bridge {
 public:
  Bridge(transport::Transport& from, transport::Transport& to, BridgeConfig config);
  ~Bridge();
  Bridge(const Bridge&) = delete;
  Bridge& operator=(const Bridge&) = delete;

  /// Waits up to timeout_ms for a message on `from`, forwards it and everything else
  /// pending. Returns how many were forwarded.
  int poll(int timeout_ms);

  /// Messages forwarded so far.
  std::int64_t forwarded() const { return forwarded_; }
  /// Messages the destination refused (counted, not fatal: the bridge is a tap).
  std::int64_t failed() const { return failed_; }
  /// Bytes forwarded so far.
  std::int64_t bytes_forwarded() const { return bytes_; }

 private:
  transport::Transport& from_;
  transport::Transport& to_;
  transport::SubscriptionId subscription_ = -1;
  std::int64_t forwarded_ = 0;
  std::int64_t failed_ = 0;
  std::int64_t bytes_ = 0;
};

}  // namespace auvrl::logger
